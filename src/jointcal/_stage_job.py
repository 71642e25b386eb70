"""The frame of a workflow stage's script: its log, its warnings, its one-sentence exit and its pool.

A stage script (``workflow/scripts/<stage>.py``) is one block::

    with stage_job(snakemake) as job:
        notes = run_<stage>(..., progress=job.log)
        job.log(...)

`stage_job` opens the rule's log line-buffered (progress can be read while the job runs) and
closes it at the end; writes every warning raised inside to the log and to stderr as
``jointcal: warning: <message>``, as it is raised (under the filters in force: by Python's
default, a repeat from the same line once, no deprecations); and turns an error of the inputs
or settings (`ValueError`, of which `jointcal.io.CampaignError` and
`jointcal.calibrate.CalibrationInputError` are kinds) into its one sentence, after the
warnings, in the log and on stderr, and a non-zero exit without a traceback. `Job.pool` and
`Job.map` spread work over ``snakemake.threads`` processes, or run it in this one.
`console_job` is the same frame for the command line (``jointcal <stage>``): its log is stdout, its
warnings go to stderr, and the command turns the errors into its exit status (`jointcal.cli`).
Imports nothing of the package, so a stage's code hash (`jointcal._workflow.stage_hash`) gains
only this file.

One BLAS thread per process: a job's threads are its processes (`Job.pool`), but Snakemake sets
the BLAS and OpenMP thread variables to the rule's threads, so each worker of a pool of two would
run two BLAS threads (four on two cores; a least-squares SVD of the discrepancy fits took 5x the
CPU with two). Importing this module sets them to 1; it must come before numpy's first import, as
the stage scripts and `jointcal.cli` import it first.

Freed memory kept for reuse (glibc's malloc; elsewhere nothing changes): the fast model's arrays
of a few hundred kB each were handed back to the system on every free and faulted in again on
the next evaluation, 2.8 million page faults and 4.6 s of system time in the 50 s of a discrepancy
job (0.3 s with the memory kept, 27 MB more resident). Where memory comes from changes no value.
"""
from __future__ import annotations

import ctypes
import os
import sys
import time
import warnings
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import Executor, ProcessPoolExecutor
from contextlib import contextmanager
from pathlib import Path
from types import SimpleNamespace
from typing import IO, Any

__all__ = ["Job", "console_job", "stage_job"]

BLAS_THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "VECLIB_MAXIMUM_THREADS",
                         "NUMEXPR_NUM_THREADS")
for _var in BLAS_THREAD_VARIABLES:
    os.environ[_var] = "1"


def _keep_freed_memory(trim_bytes: int = 256 << 20, mmap_bytes: int = 32 << 20) -> None:
    """glibc's malloc: return the heap's free top to the system only beyond `trim_bytes`, and map blocks of
    their own only from `mmap_bytes` (its largest fixed threshold on 64 bits); a no-op without glibc."""
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return
    mallopt(-1, trim_bytes)  # M_TRIM_THRESHOLD
    mallopt(-3, mmap_bytes)  # M_MMAP_THRESHOLD


_keep_freed_memory()


class Job:
    """A running stage: `log` and `warn` write to its log, `pool` and `map` use its threads.

    Attributes
    ----------
    smk : snakemake.script.Snakemake
        The rule's ``snakemake`` object (input, output, params, wildcards, threads, log).
    threads : int
        Processes the job may use (``snakemake.threads``, at least 1).
    """

    def __init__(self, smk: Any, log_file: IO[str], *, warn_in_log: bool = True) -> None:
        self.smk = smk
        self.threads = max(1, int(getattr(smk, "threads", 1) or 1))
        self._file = log_file
        self._warn_in_log = warn_in_log
        self._t0 = time.perf_counter()

    @property
    def elapsed(self) -> float:
        """Seconds since the job started."""
        return time.perf_counter() - self._t0

    def log(self, line: str) -> None:
        """Write ``jointcal: <line>`` to the log (progress, and the result in words)."""
        self._file.write(f"jointcal: {line}\n")

    def warn(self, line: str) -> None:
        """Write ``jointcal: warning: <line>`` to the log (unless it is the console's stdout) and to stderr."""
        if self._warn_in_log:
            self.log(f"warning: {line}")
        print(f"jointcal: warning: {line}", file=sys.stderr)

    def workers(self, n_tasks: int | None = None) -> int:
        """Processes for `n_tasks` tasks: the job's threads, at most one per task."""
        return self.threads if n_tasks is None else max(1, min(self.threads, n_tasks))

    @contextmanager
    def pool(self, n_tasks: int | None = None) -> Iterator[Executor | None]:
        """A process pool of `workers` processes, or None (run here) when that is one."""
        n = self.workers(n_tasks)
        if n == 1:
            yield None
            return
        with ProcessPoolExecutor(max_workers=n) as ex:
            yield ex

    def map(self, fn: Callable[..., Any], *iterables: Iterable[Any]) -> list[Any]:
        """``[fn(*args) for args in zip(*iterables)]``, over the pool when it has more than one process."""
        tasks = list(zip(*iterables))
        with self.pool(len(tasks)) as ex:
            return list(ex.map(fn, *zip(*tasks))) if ex is not None else [fn(*a) for a in tasks]


@contextmanager
def stage_job(smk: Any, *, errors: tuple[type[BaseException], ...] = (ValueError,)) -> Iterator[Job]:
    """Run a stage script's body as a `Job` (see the module notes).

    Parameters
    ----------
    smk : snakemake.script.Snakemake
        The rule's ``snakemake`` object; its ``log[0]`` is the log written.
    errors : tuple of exception types, optional
        The errors that end the job with their one sentence (others keep their traceback).

    Raises
    ------
    SystemExit
        ``jointcal: <the error's sentence>`` on one of `errors`.
    """
    log = Path(smk.log[0])
    log.parent.mkdir(parents=True, exist_ok=True)
    with open(log, "w", buffering=1) as f, warnings.catch_warnings():
        job = Job(smk, f)
        warnings.showwarning = lambda message, *_, **__: job.warn(str(message))
        try:
            yield job
        except errors as exc:
            job.log(str(exc))
            sys.exit(f"jointcal: {exc}")


@contextmanager
def console_job(threads: int = 1) -> Iterator[Job]:
    """A `Job` for the command line: `Job.log` prints to stdout, `Job.warn` (every warning raised inside,
    as it is raised) to stderr alone; errors pass through to the caller (`jointcal.cli.main`).

    Parameters
    ----------
    threads : int, optional
        Processes `Job.pool` and `Job.map` may use.
    """
    with warnings.catch_warnings():
        job = Job(SimpleNamespace(threads=threads), sys.stdout, warn_in_log=False)
        warnings.showwarning = lambda message, *_, **__: job.warn(str(message))
        yield job
