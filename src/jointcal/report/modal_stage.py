"""The modal stage's figures on files: Figs. 3.5 and 3.6 and a spectrogram (rule ``modal_figures``).

One module per report rule, so that each rule's code hash (`jointcal._workflow.stage_hash`) holds the
code it runs and no more (this one: no stage after modal).
"""
from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import pandas as pd

from ..io import level_column, listed_record, read_run, run_test_kind
from ..measure.envelopes import window_length
from .modal import plot_envelopes, plot_frequency_damping, plot_spectrogram

__all__ = ["run_modal_figures"]

_Path = str | os.PathLike[str]


def run_modal_figures(table_csv: _Path, runs_csv: _Path, envelope_files: Sequence[_Path],
                      record_files: Sequence[_Path], envelopes: Mapping[str, Any], *, envelopes_png: _Path,
                      amplitude_png: _Path, spectrogram_png: _Path) -> str:
    """Figs. 3.5 and 3.6 and a spectrogram, from the modal table, the envelopes and one record.

    Fig. 3.5 shows the sweeps' envelopes (a dwell or ring-down run has none); the spectrogram is of the
    strongest sweep, or of the strongest run (a 2 s window) in a campaign without sweeps.

    Parameters
    ----------
    table_csv : path
        ``modal_properties.csv``.
    runs_csv : path
        ``runs.csv``.
    envelope_files : sequence of paths
        Every run's ``<run_id>.csv`` of the envelope stage.
    record_files : sequence of paths
        The campaign's record files (a run's file is found by its whole relative path).
    envelopes : mapping
        The config's ``envelopes`` section (its ``zeta_min`` sets the spectrogram's window).
    envelopes_png, amplitude_png, spectrogram_png : path
        Where Fig. 3.5, Fig. 3.6 and the spectrogram go.

    Returns
    -------
    str
        The line for the log, naming the spectrogram's run.
    """
    table = pd.read_csv(table_csv, dtype={"flags": str})
    runs = pd.read_csv(runs_csv, dtype={"flags": str}).set_index("run_id", drop=False)
    envs = {Path(p).stem: pd.read_csv(p) for p in envelope_files}
    sweeps = runs[[run_test_kind(r).swept for r in runs.to_dict("records")]]
    plot_envelopes(table[table["run_id"].isin(sweeps["run_id"])], envs, envelopes_png)
    plot_frequency_damping(table, amplitude_png)
    level = level_column(runs.columns) or "level_g"
    rid = (sweeps if len(sweeps) else runs).sort_values([level, "sequence"]).iloc[-1]["run_id"]  # the strongest run
    row = runs.loc[rid]
    if len(sweeps):
        lo = min(row["f_start_hz"], row["f_stop_hz"])
        n = window_length(row["sample_rate_hz"], row["sweep_rate_hz_per_s"], lo, **{
            k: v for k, v in envelopes.items() if k == "zeta_min"})
    else:
        n = int(round(2.0 * row["sample_rate_hz"]))
    record = read_run(listed_record(row["file"], list(record_files)), row)  # whole path: basenames may repeat
    plot_spectrogram(record, envs[rid], row["sample_rate_hz"], n, rid, spectrogram_png)
    return f"figures written; spectrogram of {rid}"
