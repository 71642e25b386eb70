"""A run's flags in modal_properties.csv: the ingest stage's and the modal stage's, merged, each with
its sentence for the log (`FLAG_WORDS`)."""
from __future__ import annotations

from ..io import UNUSABLE_FLAGS
from ..io.contract import UNUSABLE
from .modal import FLAG_WORDS

__all__ = ["run_flags"]


def run_flags(ingest_flags: str | None, stage_flags: str | None, run_id: str, *,
              sweep_note: str | None = None) -> tuple[str, list[str]]:
    """A run's flags in modal_properties.csv, and a sentence for each that the log shows.

    The ingest stage's flags come first, then this stage's, each once. A run that ingest
    flagged for wrong units, level, channels or clipping (``jointcal.io.UNUSABLE_FLAGS``)
    is also ``unusable``: no fit reads it.

    Parameters
    ----------
    ingest_flags : str or None
        runs.csv's ``flags`` cell (``;``-separated; empty, None or NaN for none).
    stage_flags : str or None
        The flags `modal_properties` gave the run (``;``-separated).
    run_id : str
        The run, named in the sentences.
    sweep_note : str, optional
        Why the whole-transient fit failed, added to a ``sweep_fit_failed`` sentence.

    Returns
    -------
    flags : str
        ``;``-separated.
    notes : list of str
        ``"<run_id>: <flag>: <what it means>."`` per flag of `FLAG_WORDS` (or with a detail after ``:``),
        after a sentence on a run made unusable by its ingest flags.
    """
    ingest = [f for f in str(ingest_flags or "").split(";") if f and f != "nan"]
    flags = list(dict.fromkeys(ingest + [f for f in str(stage_flags or "").split(";") if f]))
    notes = []
    wrong = [f for f in ingest if f.split(":")[0] in UNUSABLE_FLAGS]
    if wrong and UNUSABLE not in flags:  # wrong units, level, channels; clipped: no fit
        flags.append(UNUSABLE)
        notes.append(f"{run_id}: {UNUSABLE}: ingest flagged {', '.join(wrong)} (see the ingest log); "
                     "left out of the calibration")
    for flag in [f for f in flags if f.split(":")[0] in FLAG_WORDS or ":" in f]:
        why = f" ({sweep_note})" if flag == "sweep_fit_failed" and sweep_note else ""
        notes.append(f"{run_id}: {flag.split(':')[0]}: {FLAG_WORDS.get(flag.split(':')[0], flag)}{why}.")
    return ";".join(flags), notes
