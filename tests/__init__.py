"""jointcal's tests, laid out as the package: ``tests/<package>/test_<module>.py`` for
``src/jointcal/<package>/<module>.py``, ``tests/test_<module>.py`` for the top-level modules,
``tests/workflow/`` for the Snakemake runs and ``tests/_support/`` for shared helpers (not jointcal
code). A package (as is each folder in it), so that two folders may hold test files of one name."""
