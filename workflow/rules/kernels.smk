# Before the stages: the numba kernels compiled once into numba's cache (jointcal.models.kernels), on
# the core that ingest, envelopes and modal leave idle. Without it, every job that starts before another
# has written the cache compiles the same kernels again (a fresh install's cache is empty).
# The stages that call kernels take its output as ancient(): it reruns when the kernels' code changes,
# and that alone reruns nothing downstream.


rule compile_kernels:
    output:
        KERNELS,
    params:
        code=source_hash("kernels.py"),
    threads: 1
    benchmark:
        RESULTS / "benchmarks" / "compile_kernels.tsv"
    log:
        RESULTS / "logs" / "compile_kernels.log",
    script:
        "../scripts/kernels.py"
