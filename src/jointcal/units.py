"""Unit constants of jointcal's system (lbf, inch, second) and of the units records arrive in.

Every conversion in the package uses these names; no module writes the numbers again.
"""
from __future__ import annotations

__all__ = ["G", "G_SI", "LBF_N", "INCH_M", "FOOT_IN"]

G = 386.089  # in/s^2 per g (standard gravity, 9.80665 m/s^2, in inches)
G_SI = 9.80665  # m/s^2 per g (standard gravity, exact by definition)
LBF_N = 4.4482216152605  # N per lbf (exact by definition: 0.45359237 kg x 9.80665 m/s^2)
INCH_M = 0.0254  # m per inch (exact by definition)
FOOT_IN = 12.0  # inches per foot
