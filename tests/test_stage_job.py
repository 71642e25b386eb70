"""jointcal._stage_job, the frame of every stage script: log, warnings, one-sentence exit, pool."""
from __future__ import annotations

import os
import warnings
from types import SimpleNamespace

import pytest

from jointcal._stage_job import stage_job


def _smk(tmp_path, threads=1):
    return SimpleNamespace(log=[str(tmp_path / "logs" / "stage.log")], threads=threads)


def test_log_lines_are_readable_while_the_job_runs_and_the_file_is_closed_after(tmp_path):
    smk = _smk(tmp_path)
    with stage_job(smk) as job:
        job.log("GA generation 2/4")
        assert (tmp_path / "logs" / "stage.log").read_text() == "jointcal: GA generation 2/4\n"  # line-buffered
        handle = job._file
    assert handle.closed


def test_warnings_go_to_the_log_and_stderr_as_raised_then_an_error_is_one_sentence(tmp_path, capsys):
    with pytest.raises(SystemExit) as end, stage_job(_smk(tmp_path)) as job:
        warnings.warn("run01.csv.gz: 9600 NaN/inf values", UserWarning)
        job.log("read 5 runs")
        raise ValueError("run04.csv.gz: the measured sample rate is 12800 Hz; correct sample_rate_hz")
    assert str(end.value.code) == "jointcal: run04.csv.gz: the measured sample rate is 12800 Hz; correct sample_rate_hz"
    log = (tmp_path / "logs" / "stage.log").read_text().splitlines()
    assert log == ["jointcal: warning: run01.csv.gz: 9600 NaN/inf values", "jointcal: read 5 runs",
                   "jointcal: run04.csv.gz: the measured sample rate is 12800 Hz; correct sample_rate_hz"]
    assert "jointcal: warning: run01.csv.gz" in capsys.readouterr().err
    assert warnings.showwarning.__module__ == "warnings"  # restored


def test_other_errors_keep_their_traceback(tmp_path):
    with pytest.raises(KeyError), stage_job(_smk(tmp_path)):
        raise KeyError("a bug")


def _pid(x: int) -> tuple[int, int]:
    return x * x, os.getpid()


@pytest.mark.parametrize("threads", [1, 2])
def test_map_gives_the_serial_results_in_order_over_a_pool_of_the_threads(tmp_path, threads):
    with stage_job(_smk(tmp_path, threads)) as job:
        out = job.map(_pid, range(5))
        assert job.workers() == threads and job.workers(1) == 1
        with job.pool() as ex:
            assert (ex is None) == (threads == 1)
    assert [v for v, _ in out] == [0, 1, 4, 9, 16]
    assert ({p for _, p in out} == {os.getpid()}) == (threads == 1)
