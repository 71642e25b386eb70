"""Snakemake script of rule ``ingest``: validate the campaign, write runs.csv.

On a contract violation the one-sentence message goes to the log and to stderr and
the script exits non-zero, so Snakemake fails with the message visible and no
runs.csv is written. (No ``from __future__`` import: Snakemake prepends a preamble
to scripts, after which such an import is a SyntaxError.)
"""
import sys
import warnings
from pathlib import Path

from jointcal.io import CampaignError, ingest_campaign, write_csv_atomic


def main(smk) -> None:
    """Run the rule with Snakemake's ``snakemake`` object."""
    log = Path(smk.log[0])
    campaign = Path(smk.input.manifest).parent
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            runs = ingest_campaign(campaign, on_data_problem=smk.params.ingest["on_data_problem"])
        except CampaignError as exc:
            error = exc
        else:
            error = None
    notes = [f"jointcal: warning: {w.message}" for w in caught]  # every warning, also before an error
    for note in notes:
        print(note, file=sys.stderr)
    if error is not None:
        log.write_text("\n".join([*notes, f"jointcal: {error}"]) + "\n")
        sys.exit(f"jointcal: {error}")
    write_csv_atomic(runs, smk.output.runs)
    flagged = int((runs["flags"] != "").sum())
    notes.append(f"jointcal: ingested {len(runs)} runs ({flagged} flagged) from {campaign}")
    log.write_text("\n".join(notes) + "\n")


main(snakemake)  # noqa: F821 (provided by Snakemake)
