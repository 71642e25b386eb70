"""Test helpers (not jointcal code): modal-stage tables synthesised from a known truth.

`modal_tables` plays an ideal modal stage: each run's resonance is the harmonic-balance
steady state at its level (`resonance_amplitude`, what a slow sweep shows at phase
resonance), with seeded relative noise on f and zeta; `scatter.csv` is computed from
those values as the modal stage does (spread of repeats per level, pooled over levels). A
base-driven run's own damping read-out, zeta_res, is its phase-resonance damping.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from jointcal.calibrate import select_modal
from jointcal.models import G, resonance_amplitude

LEVELS = (1, 1, 1, 1, 1, 1, 2, 2, 5, 5, 10, 10)  # Table 3.1, g
TABLE_3_2 = {
    "first": dict(Fs=313.0, KT=1.02e6, chi=-0.65, beta=0.004, k=6.12e5, zeta_v=0.0015),
    "reassembly": dict(Fs=274.0, KT=0.90e6, chi=-0.61, beta=0.025, k=8.56e5, zeta_v=0.0017),
}
M = 2.65 / G
QUANTITIES = ("f_res_hz", "zeta_res", "zeta_phase_resonance", "zeta_half_power")


def modal_tables(truths: dict[str, dict], *, rel_noise: tuple[float, float] = (2e-4, 0.01), seed: int = 0,
                 levels=LEVELS, viscous: str = "dashpot",
                 model_noise_q: float = 0.0) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(modal_properties, scatter) tables for the given assemblies' truths."""
    rng = np.random.default_rng(seed)
    rows = []
    for assembly, t in truths.items():
        lv = np.asarray(levels, dtype=float)
        q, f, z = resonance_amplitude(lv, t["Fs"], t["KT"], t["chi"], t["beta"], t["k"], M, t["zeta_v"],
                                      viscous=viscous)
        f_meas = f * (1 + rel_noise[0] * rng.standard_normal(lv.size))
        z_meas = z * (1 + rel_noise[1] * rng.standard_normal(lv.size))
        z_hp = z * (1 + rel_noise[1] * rng.standard_normal(lv.size))
        q_meas = q * (1 + model_noise_q * rng.standard_normal(lv.size))
        for i, level in enumerate(lv):
            direction = "up" if i % 2 == 0 else "down"
            resp = q_meas[i] * (2 * np.pi * f_meas[i]) ** 2 / G
            rows.append(dict(run_id=f"{assembly}_{i + 1:02d}_{level:g}g_{direction}", assembly=assembly,
                             sequence=i + 1, level_g=level, direction=direction, f_res_hz=f_meas[i],
                             f_peak_hz=f_meas[i] * (1 + 2e-4), zeta_half_power=z_hp[i],
                             zeta_phase_resonance=z_meas[i], zeta_res=z_meas[i], q_in=q_meas[i], response_g=resp,
                             base_g=level,
                             eta=300.0 / (f_meas[i] * z_meas[i]) ** 2, flags=""))
    modal = pd.DataFrame(rows)
    return modal, scatter_table(modal)


def scatter_table(modal: pd.DataFrame) -> pd.DataFrame:
    """The modal stage's tidy scatter table from a modal-properties table."""
    out = []
    for assembly, quantity in ((a, qn) for a in modal["assembly"].unique() for qn in QUANTITIES):
        sub = modal[modal["assembly"] == assembly]
        ss, dof = 0.0, 0
        for level, g in sub.groupby("level_g"):
            x = g[quantity].to_numpy(float)
            mean = x.mean()
            std = x.std(ddof=1) if x.size > 1 else np.nan
            source = "repeats" if x.size > 2 else "up_down"
            out.append(dict(assembly=assembly, quantity=quantity, level_g=level, source=source, n=x.size,
                            mean=mean, std=std, rel_std=std / mean))
            if x.size > 1:
                ss += np.sum(((x - mean) / mean) ** 2)
                dof += x.size - 1
        rel = np.sqrt(ss / dof) if dof else np.nan
        out.append(dict(assembly=assembly, quantity=quantity, level_g=np.nan, source="pooled", n=dof,
                        mean=np.nan, std=np.nan, rel_std=rel))
    return pd.DataFrame(out)


def write_tables(folder, truths, **kw):
    """Write modal_properties.csv, scatter.csv and backbone.csv (each run's one point, as the modal stage writes
    for sweeps) into `folder`/modal; return the first two's paths."""
    from pathlib import Path

    from jointcal.measure.modes import with_modes
    from jointcal.measure.testkinds.read import backbone_table

    modal, scatter = modal_tables(truths, **kw)
    d = Path(folder) / "modal"
    d.mkdir(parents=True, exist_ok=True)
    modal.to_csv(d / "modal_properties.csv", index=False)
    scatter.to_csv(d / "scatter.csv", index=False)
    backbone_table(with_modes(modal), []).to_csv(d / "backbone.csv", index=False)
    return d / "modal_properties.csv", d / "scatter.csv"


def _data(truth=TABLE_3_2["first"], seed=1, noise=(2e-4, 0.01)):
    """The calibration's data (`select_modal`) of assembly 'first' from `modal_tables` of `truth`."""
    modal, scatter = modal_tables({"first": truth}, rel_noise=noise, seed=seed)
    return select_modal(modal, "first", scatter=scatter)
