# Before the stages that call them: the numba kernels compiled once into numba's cache
# (jointcal.models.kernels), on the core the modal stage leaves idle (after ingest, and after envelopes,
# which takes both cores and has the higher priority). Without it, every job that starts before another
# has written the cache compiles the same kernels again (a fresh install's cache is empty).
# The stages that call kernels take its output as ancient(): it reruns when the kernels' code changes,
# and that alone reruns nothing downstream.


rule compile_kernels:
    input:
        INGEST / "runs.csv",
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
