"""Snakemake script of rule ``compile_kernels``: compile the numba kernels into numba's cache.

Writes a line naming the numba version (the output the kernel-calling stages wait for) and
the seconds taken to the log. (No ``from __future__``: Snakemake prepends a preamble to scripts.)
"""
import numba

from jointcal._stage_job import stage_job
from jointcal.io import write_bytes_atomic
from jointcal.models.kernels import compile_kernels

with stage_job(snakemake) as job:  # noqa: F821 (provided by Snakemake)
    job.log(f"numba kernels compiled or loaded from the cache in {compile_kernels():.1f} s")
    write_bytes_atomic(f"numba {numba.__version__}: the jointcal kernels are in numba's cache\n".encode(),
                       job.smk.output[0])
