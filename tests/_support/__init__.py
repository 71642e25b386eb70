"""Helpers shared by the tests and the benchmark scripts (not jointcal code): campaigns, tables and records made from a
known truth, and the Snakemake run of a workflow copy."""
