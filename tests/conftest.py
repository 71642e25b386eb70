"""Shared fixtures: the committed small campaign and a writable copy of it; two runs of the example campaign
to break; synthetic campaigns made once per session (the exact time simulation of a 24-run campaign takes tens of
seconds)."""
from __future__ import annotations

import os

# One BLAS thread per process, set before numpy is imported (here, in the process that starts the xdist workers,
# so they inherit it): the suite already runs one worker per core (-n 2), and a second OpenBLAS thread per worker
# oversubscribes the cores. The sweep fit's least squares takes an SVD of a (~1850, 14) Jacobian per step: 2.5 ms
# with one thread, 60-380 ms with two on a busy 2-core machine (tests/benchmarks/bench_sweep_jacobian.py sets
# the same). Snakemake sets these variables for its own jobs from each rule's `threads:`.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import shutil  # noqa: E402
import tempfile  # noqa: E402
import threading  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import pandas as pd  # noqa: E402
import pytest  # noqa: E402

pytest.register_assert_rewrite("tests._support")  # the helpers' asserts report as the tests' own do

from jointcal.synth import generate  # noqa: E402
from tests._support.campaign import DEFAULT_SPEC, SMALL_CAMPAIGN, example_copy, voltage_campaign  # noqa: E402
from tests._support.ingest import OTHER, RUN  # noqa: E402
from tests._support.modal_helpers import modal_table  # noqa: E402


def pytest_configure(config: pytest.Config) -> None:
    """Compile the numba kernels into numba's cache once, here in the controller (a worker inherits nothing but the
    cache). On a fresh clone the cache is empty, and each worker, and each Snakemake job a test starts, compiled the
    kernels it called for itself: one discrepancy test took 62 s of CPU cold, 26 s warm. A warm cache makes this a
    2 s load; the workers then load the kernels too.

    With xdist the compilation runs in a thread while the workers start and collect (each takes about 6 s of its
    own: imports and collection), and each worker waits for it before its first test (`pytest_runtestloop`), so the
    compilation no longer precedes the workers' start: on a fresh clone it took 15-30 s of wall time with the other
    core idle. Without workers it runs here, before the tests, as before. With workers the measure package's kernels
    are compiled beside it, in a process of their own (`_compile_measure_kernels_aside`)."""
    if hasattr(config, "workerinput"):  # an xdist worker: the controller compiles them
        return
    from jointcal.models.kernels import compile_kernels

    if not (getattr(config.option, "numprocesses", None) and getattr(config.option, "dist", "no") != "no"):
        compile_kernels()
        return
    done = Path(tempfile.mkdtemp(prefix="jointcal-kernels-")) / "compiled"
    os.environ[KERNELS_DONE] = str(done)  # the workers, started after this hook, inherit the environment
    measure = _compile_measure_kernels_aside(config)

    def compile_then_say_so() -> None:
        try:
            compile_kernels()
        finally:  # a failure too: the workers then compile what they call, as without this
            if measure is not None:
                measure.wait()
            done.write_text("compiled\n")

    threading.Thread(target=compile_then_say_so, name="compile_kernels", daemon=True).start()


def _compile_measure_kernels_aside(config: pytest.Config):
    """The measure package's kernels (`tests._support.kernels.compile_measure_kernels`) compiled in a process of
    their own, beside the controller's compilation of the models' (`pytest_configure`), on the core that compilation
    leaves idle while the workers start; the workers wait for both. Without it each of them was compiled by the
    first worker or Snakemake job that called it, in the middle of a test (test_coil's first read 25.6 s cold, 4.4 s
    warm), and again by any other that called it before the cache was written. Returns the process (None if it
    could not start: the kernels are then compiled where they are called, as before)."""
    import subprocess
    import sys

    import jointcal

    path = [str(Path(jointcal.__file__).resolve().parents[1]), str(config.rootpath)]  # the jointcal the workers import
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(path + [os.environ.get("PYTHONPATH", "")])}
    try:
        return subprocess.Popen([sys.executable, "-c", "from tests._support.kernels import compile_measure_kernels; "
                                 "compile_measure_kernels()"], cwd=config.rootpath, env=env,
                                stdout=subprocess.DEVNULL)
    except OSError:
        return None


KERNELS_DONE = "JOINTCAL_TESTS_KERNELS_COMPILED"  # the file the controller writes once the kernels are in the cache
KERNELS_WAIT_S = 900.0  # s: a bound on the wait (a cold compilation takes 15-30 s)


@pytest.hookimpl(tryfirst=True)
def pytest_runtestloop(session: pytest.Session) -> None:
    """An xdist worker, collected, waits for the controller's compilation (`pytest_configure`) before its first
    test; it then loads the kernels from numba's cache. Returns None: the test loop then runs as usual."""
    done = os.environ.get(KERNELS_DONE)
    if not done or not hasattr(session.config, "workerinput"):
        return
    deadline = time.monotonic() + KERNELS_WAIT_S
    while not Path(done).exists() and time.monotonic() < deadline:
        time.sleep(0.05)


def pytest_unconfigure(config: pytest.Config) -> None:
    """The controller removes the folder of its compilation's file (`pytest_configure`)."""
    done = os.environ.get(KERNELS_DONE)
    if done and not hasattr(config, "workerinput"):
        shutil.rmtree(Path(done).parent, ignore_errors=True)


@pytest.fixture(scope="session")
def small_campaign() -> Path:
    """The committed valid campaign (read only)."""
    return SMALL_CAMPAIGN


@pytest.fixture
def campaign(tmp_path: Path) -> Path:
    """A writable copy of the small campaign, to break in a test."""
    return Path(shutil.copytree(SMALL_CAMPAIGN, tmp_path / "campaign"))


@pytest.fixture(scope="session")
def voltage_source(tmp_path_factory) -> Path:
    """A synthetic voltage-driven campaign, made once per session (read only)."""
    return voltage_campaign(tmp_path_factory.mktemp("voltage") / "campaign")


@pytest.fixture
def voltage(tmp_path: Path, voltage_source: Path) -> Path:
    """A writable copy of the synthetic voltage-driven campaign, to break in a test."""
    return Path(shutil.copytree(voltage_source, tmp_path / "voltage"))


@pytest.fixture(scope="session")
def default_campaign_dir(tmp_path_factory) -> Path:
    """The default generator's campaign (`DEFAULT_SPEC`: the paper's Table 3.1 series for both assemblies
    with Table 3.2 parameters, 300 Hz/s, 0.3% noise, the DAQ chain; no hidden effect), made once per session
    (read only). Its truth is ``truth.json`` beside the campaign folder. Written as plain .csv: the committed
    campaigns test reading .csv.gz, and gzip was 5 of the 12.7 s of CPU this campaign took to make."""
    tmp = tmp_path_factory.mktemp("default_campaign")
    generate({**DEFAULT_SPEC, "file_format": "csv"}, tmp / "c", tmp / "truth.json")
    return tmp / "c"


@pytest.fixture(scope="session")
def default_modal(default_campaign_dir: Path) -> pd.DataFrame:
    """The modal stage's table of `default_campaign_dir` (every run through `jointcal.modal.measure_run`);
    a copy per use is the caller's to make before editing it."""
    return modal_table(default_campaign_dir)


@pytest.fixture
def example(tmp_path: Path) -> Path:
    """Two clean runs of the example campaign, to break the first."""
    return example_copy(tmp_path / "campaign", RUN, OTHER)


# ------------------------------------------------------------------ xdist: which worker runs what, in which order
# pyproject's `--dist loadgroup` hands out one group at a time: each file is its own group (as `loadfile` did: its
# module fixtures made once), except the files in SHARED, which share a session fixture too expensive to make on both
# workers. Groups are handed out heaviest first (FIRST, by each group's CPU seconds in a fresh clone's run on
# 2026-11-26: 75-83 s for the first three, 20-30 s for the last), then the rest in collection order, so that a long
# file does not start last and leave one worker idle at the end; the order only decides when a file runs, never what
# it runs.
SHARED = {"tests/test_pipeline.py": "default_campaign",  # default_campaign_dir and default_modal
          "tests/measure/test_modal.py": "default_campaign"}
FIRST = ("default_campaign", "tests/workflow/test_calibration.py", "tests/discrepancy/test_select.py",
         "tests/workflow/test_mechanics.py", "tests/io/test_transmissibility.py", "tests/workflow/test_snakefile.py",
         "tests/discrepancy/test_decays.py", "tests/calibrate/test_readouts.py", "tests/validate/test_assembly.py",
         "tests/measure/test_coil.py", "tests/workflow/test_modal_stage.py", "tests/calibrate/test_fit.py",
         "tests/workflow/test_input_mistakes.py", "tests/discrepancy/test_stage.py")


@pytest.hookimpl(tryfirst=True)  # before xdist's own hook reads the xdist_group marks
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    def group(item: pytest.Item) -> str:
        mark = item.get_closest_marker("xdist_group")
        if mark is not None:
            return str(mark.args[0] if mark.args else mark.kwargs.get("name", "default"))
        path = item.nodeid.split("::", 1)[0]
        return SHARED.get(path, path)

    for item in items:
        if item.get_closest_marker("xdist_group") is None:
            item.add_marker(pytest.mark.xdist_group(group(item)))
    rank = {name: i for i, name in enumerate(FIRST)}
    items.sort(key=lambda item: rank.get(group(item), len(FIRST)))  # stable: the rest keep their order
