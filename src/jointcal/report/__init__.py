"""Figures and tables of the workflow report (matplotlib imported inside the plotting functions)."""
