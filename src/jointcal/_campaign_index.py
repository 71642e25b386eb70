"""The campaign as the workflow's DAG sees it, and what Snakemake still plans to remake.

`campaign_index` reads the campaign's manifest once, with `jointcal.io.read_manifest`, for
the names the workflow's DAG is built from (run ids, record files, assemblies, excitation).
`modal_units` reads the modal stage's table for the (assembly, mode) pairs the later stages run on
(`unit_of` reads the pair back from a per-unit output's path). `pending_outputs` reads Snakemake's
``--summary`` table for the files still planned to be remade.
"""
from __future__ import annotations

import os
import warnings
from dataclasses import dataclass
from pathlib import Path

__all__ = ["CampaignIndex", "campaign_index", "modal_units", "unit_table", "unit_outputs", "unit_of", "unit_labels", "pending_outputs"]


@dataclass(frozen=True)
class CampaignIndex:
    """What the workflow's DAG is built from, read from a campaign's manifest at parse time.

    Attributes
    ----------
    run_files : dict of str to str
        run_id -> the run's record file (the manifest's folder joined with its ``file``), in manifest order.
    run_assembly : dict of str to str
        run_id -> its assembly.
    excitation : {'base', 'force', 'voltage'}
        The campaign's reference, from its level column (``level_g``, ``level_lbf``, ``level_V``).
    problem : str or None
        `read_manifest`'s one-sentence error when the manifest fails its checks (then the names
        above come from its ``run_id``, ``assembly`` and ``file`` columns alone), else None.
    reference_files : tuple of str
        The files the manifest's ``reference_file`` column names (a lab export holding a run's
        reference apart), joined with the manifest's folder; inputs of the rules that read records.
    """

    run_files: dict[str, str]
    run_assembly: dict[str, str]
    excitation: str
    problem: str | None = None
    reference_files: tuple[str, ...] = ()

    @property
    def assemblies(self) -> list[str]:
        """The assemblies, in order of first appearance."""
        return list(dict.fromkeys(a for a in self.run_assembly.values() if a))

    def assembly_files(self, assembly: str) -> list[str]:
        """The record files of one assembly's runs, in manifest order."""
        return [f for r, f in self.run_files.items() if self.run_assembly.get(r) == assembly]


def campaign_index(manifest: str | os.PathLike[str]) -> CampaignIndex:
    """Read a campaign's manifest once for the workflow: `jointcal.io.read_manifest`, every check.

    A manifest that fails the checks (a missing record, a Windows path, an empty cell) does not stop
    the parse: its ``run_id``, ``assembly`` and ``file`` columns still name the jobs, and the error is
    kept in ``problem`` for the rules that read raw records, which stop on it with its sentence. So a
    workflow of the later stages, run on their tables with a manifest of those three columns, builds.

    Parameters
    ----------
    manifest : path-like
        The campaign's ``manifest.csv`` (it must exist).

    Returns
    -------
    CampaignIndex
    """
    import pandas as pd

    from jointcal.io import CampaignError, CampaignWarning, excitation_kind, read_manifest

    manifest = Path(manifest)
    problem = None
    try:
        with warnings.catch_warnings():  # notes on the manifest (trailing empty rows) are the ingest stage's
            warnings.simplefilter("ignore", CampaignWarning)
            table = read_manifest(manifest)
    except CampaignError as exc:
        problem = str(exc)
        try:
            table = pd.read_csv(manifest, dtype=str, keep_default_na=False, encoding="utf-8-sig")
        except (ValueError, UnicodeDecodeError):
            table = pd.DataFrame()
        table = table.rename(columns=lambda c: str(c).strip()).apply(lambda c: c.str.strip())
        if not {"run_id", "assembly"} <= set(table.columns):
            table = pd.DataFrame(columns=["run_id", "assembly", "file"])
        table = table[table["run_id"] != ""]
    files = table["file"] if "file" in table else pd.Series("", index=table.index)
    ids = [str(r) for r in table["run_id"]]
    return CampaignIndex(run_files={r: str(manifest.parent / str(f)) for r, f in zip(ids, files)},
                         run_assembly=dict(zip(ids, (str(a) for a in table["assembly"]))),
                         excitation=excitation_kind(table.columns),
                         problem=problem,
                         reference_files=tuple(str(manifest.parent / str(f)) for f in
                                               (table["reference_file"] if "reference_file" in table else [])
                                               if isinstance(f, str) and f.strip()))


def unit_table(modal, assembly: str, mode: str):
    """The rows of one (assembly, mode) of a modal table (`jointcal.measure.modes.with_modes`)."""
    from jointcal.measure.modes import with_modes

    t = with_modes(modal)
    return t[(t["assembly"].astype(str) == assembly) & (t["mode"] == mode)]


def modal_units(modal_csv: str | os.PathLike[str]) -> list[tuple[str, str]]:
    """The (assembly, mode) pairs calibrated, from the modal stage's table (`jointcal.measure.modes.units`)."""
    import pandas as pd

    from jointcal.measure.modes import units

    return units(pd.read_csv(modal_csv, dtype={"assembly": str, "mode": str, "flags": str}))


def unit_of(path: str | os.PathLike[str]) -> tuple[str, str]:
    """(assembly, mode) of a per-unit output ``<stage>/<assembly>/<mode>/<file>``."""
    p = Path(path)
    return p.parent.parent.name, p.parent.name


def unit_labels(paths) -> list[str]:
    """How the report names the unit of each per-unit output: its assembly, followed by the mode
    (``bert_5Nm m95``) wherever one assembly has more than one unit calibrated."""
    units = [unit_of(p) for p in paths]
    per_assembly = {}
    for a, m in units:
        per_assembly.setdefault(a, set()).add(m)
    return [a if len(per_assembly[a]) == 1 else f"{a} {m}" for a, m in units]


def unit_outputs(results: str | os.PathLike[str], *, before: float,
                 stages=("modal", "calibration", "posterior", "validation", "discrepancy", "design"),
                 mode_re: str = r"m\d+(?:_\d+p\d)?") -> list[Path]:
    """The files of every (assembly, mode) unit under `results`, last written before `before`.

    A unit's outputs are the files under ``<stage>/<assembly>/<mode>/`` and the figures and captions
    named ``*_<assembly>_<mode>.png`` / ``.rst``. When the modal checkpoint is to be remade, Snakemake's
    summary cannot name the jobs after it (its table names them), so after a failed run these are the
    outputs that may be out of date.
    """
    import re

    results = Path(results)
    units = {(d.parent.name, d.name) for d in (results / "modal").glob("*/*")
             if d.is_dir() and re.fullmatch(mode_re, d.name)}
    out = []
    for a, m in sorted(units):
        for stage in stages:
            out += [f for f in (results / stage / a / m).rglob("*") if f.is_file()]
        for folder in ("figures", "report"):
            out += [f for f in (results / folder).glob(f"*_{a}_{m}.*") if f.is_file()]
    return [f for f in out if f.stat().st_mtime < before]


def pending_outputs(summary: str, *, before: float) -> list[Path]:
    """The existing output files that Snakemake's summary plans to remake, last written before `before`.

    Parameters
    ----------
    summary : str
        The text ``snakemake --summary`` prints: a tab-separated table with the columns
        ``output_file`` and ``plan`` (``update pending`` for an output whose job is to run).
    before : float
        A time (s since the epoch, as `time.time`); files written since are left out.

    Returns
    -------
    list of Path
        Regular files only (a ``directory()`` output is left alone), in the summary's order.
    """
    lines = [ln.split("\t") for ln in summary.splitlines() if "\t" in ln]
    if not lines or "output_file" not in lines[0] or "plan" not in lines[0]:
        return []
    col_file, col_plan = lines[0].index("output_file"), lines[0].index("plan")
    out = []
    for row in lines[1:]:
        if len(row) > max(col_file, col_plan) and row[col_plan] == "update pending":
            f = Path(row[col_file])
            if f.is_file() and f.stat().st_mtime < before:
                out.append(f)
    return out
