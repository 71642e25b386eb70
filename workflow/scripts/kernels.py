"""Snakemake script of rule ``compile_kernels``: compile the numba kernels into numba's cache.

Writes a line naming the numba version (the output the kernel-calling stages wait for) and
the seconds taken to the log. (No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
from pathlib import Path

import numba

from jointcal.io import write_bytes_atomic
from jointcal.models.kernels import compile_kernels


def main(smk) -> None:
    seconds = compile_kernels()
    Path(smk.log[0]).parent.mkdir(parents=True, exist_ok=True)
    Path(smk.log[0]).write_text(f"jointcal: numba kernels compiled or loaded from the cache in {seconds:.1f} s\n")
    write_bytes_atomic(f"numba {numba.__version__}: the jointcal kernels are in numba's cache\n".encode(),
                       smk.output[0])


main(snakemake)  # noqa: F821 (provided by Snakemake)
