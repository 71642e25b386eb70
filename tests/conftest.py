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
from pathlib import Path  # noqa: E402

import pandas as pd  # noqa: E402
import pytest  # noqa: E402

pytest.register_assert_rewrite("tests._support")  # the helpers' asserts report as the tests' own do

from jointcal.synth import generate  # noqa: E402
from tests._support.campaign import DEFAULT_SPEC, SMALL_CAMPAIGN, example_copy, voltage_campaign  # noqa: E402
from tests._support.ingest import OTHER, RUN  # noqa: E402
from tests._support.modal_helpers import modal_table  # noqa: E402


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
    (read only). Its truth is ``truth.json`` beside the campaign folder."""
    tmp = tmp_path_factory.mktemp("default_campaign")
    generate(DEFAULT_SPEC, tmp / "c", tmp / "truth.json")
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
