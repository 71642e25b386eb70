"""Benchmark: one emcee step of the posterior, the numba kernel against the numpy path it replaced.

Run:  python tests/benchmarks/bench_posterior_step.py
Prints, measured in this one run (the machine is shared: read the ratios, not the times):
the log-probability per call (16 walkers) and the chain per step (32 walkers) of the old path
(`OldLogPosterior`: the likelihood as it was, on the whole-array numpy model
`amplitude._harmonic_balance_numpy`) and of the new (`LogPosterior` on `models._amplitude_kernel`),
alternated three times, with the best of each; the GA objective for a population of 200 the same way.
Equality: both log-probabilities on 4000 random points (relative to the sum of the magnitudes of
their terms, 1e-12), and the two chains from the same start and seed (equal bit for bit when no
accept/reject decision falls within the round-off).
Data: a synthetic modal table of the first Table 3.2 assembly at 96 amplitudes (0.3-10 g).
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from tests._support.modal_tables import TABLE_3_2, modal_tables  # noqa: E402

from jointcal.calibrate import CalibrateSettings, objective, select_modal  # noqa: E402
from jointcal.calibrate.space import PARAMS  # noqa: E402
from jointcal.models import amplitude  # noqa: E402
from jointcal.posterior import LogPosterior, PosteriorSettings, run_chain, start_ball  # noqa: E402
from jointcal.posterior.coords import log_det_dy_dx  # noqa: E402

CAL = CalibrateSettings()
STEPS = 1000


class OldLogPosterior(LogPosterior):
    """`LogPosterior` as it was before the kernel: the same expressions, on the numpy model."""

    def residuals(self, x):
        x = np.atleast_2d(np.asarray(x, dtype=float))
        theta = self.space.joint(np.where(self.space.is_log, 10.0 ** x[:, :self.space.ndim], x[:, :self.space.ndim]))
        v = dict(zip(PARAMS, np.split(theta, len(PARAMS), axis=1)))
        with np.errstate(all="ignore"):
            f_m, z_m = amplitude._harmonic_balance_numpy(self.data.q, v["Fs"], v["KT"], v["chi"], v["beta"], v["k"],
                                                         self.m, v["zeta_v"], viscous=self.viscous)
        return (self.data.f - f_m) / self.data.f, (self.data.zeta - z_m) / self.data.zeta

    def __call__(self, y):
        y = np.atleast_2d(np.asarray(y, dtype=float))
        x = self.to_x(y)
        out = np.full(y.shape[0], -np.inf)
        ok = np.all(np.isfinite(x) & (x >= self.lower) & (x <= self.upper), axis=1)
        if not ok.any():
            return out
        r_f, r_z = self.residuals(x[ok])
        s_f, s_z = 10.0 ** x[ok, -2], 10.0 ** x[ok, -1]
        n = self.data.q.size
        if self.data.weight is not None:
            w, n = self.data.w, self.data.n_readouts
            r_f, r_z = r_f * np.sqrt(w), r_z * np.sqrt(w)
        with np.errstate(all="ignore"):
            lp = (-0.5 * np.sum(r_f**2, axis=1) / s_f**2 - n * np.log(s_f)
                  - 0.5 * np.sum(r_z**2, axis=1) / s_z**2 - n * np.log(s_z)
                  - log_det_dy_dx(y[ok][:, self.joint]))
        out[ok] = np.where(np.isfinite(lp), lp, -np.inf)
        return out


def _data():
    modal, scatter = modal_tables({"first": TABLE_3_2["first"]}, seed=1, levels=np.geomspace(0.3, 10.0, 96))
    return select_modal(modal, "first", scatter=scatter)


def _best(fn, repeats=3):
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main() -> None:
    d = _data()
    ps = PosteriorSettings()
    theta = np.array([TABLE_3_2["first"][p] for p in PARAMS])
    args = (d, CAL.space, CAL.m, CAL.model, CAL.viscous, (0.05, 0.5))
    new, old = LogPosterior(*args), OldLogPosterior(*args)
    x0 = start_ball(old, theta, ps)
    rng = np.random.default_rng(0)
    y = x0[rng.integers(0, len(x0), 4000)] + 0.05 * rng.uniform(0, 1, (4000, 1)) * rng.standard_normal((4000, 8))
    lp_new, lp_old = new(y), old(y)
    fin = np.isfinite(lp_old)
    scale = np.maximum(np.abs(lp_old), 10.0 * d.q.size)  # the magnitude of the likelihood's terms, nats
    err = np.max(np.abs(lp_new[fin] - lp_old[fin]) / scale[fin])
    print(f"== {d.q.size} amplitudes; log-probability on 4000 random points: finite at the same points "
          f"{np.array_equal(fin, np.isfinite(lp_new))}, max |difference| / scale {err:.1e} (limit 1e-12)")

    w16 = x0[:16]
    new(w16), old(w16)
    t_old = min(_best(lambda: [old(w16) for _ in range(300)]) for _ in range(3)) / 300
    t_new = min(_best(lambda: [new(w16) for _ in range(300)]) for _ in range(3)) / 300
    print(f"  log-probability, 16 walkers: old {t_old * 1e6:6.0f} us, new {t_new * 1e6:6.0f} us -> {t_old / t_new:.1f}x")

    chains, times = {}, {"old": np.inf, "new": np.inf}
    for _ in range(3):
        for label, lp in (("old", old), ("new", new)):
            t0 = time.perf_counter()
            chains[label] = run_chain(lp, x0, seed=ps.seed, max_steps=STEPS, chunk=STEPS).chain
            times[label] = min(times[label], (time.perf_counter() - t0) / STEPS)
    print(f"  emcee step, {ps.n_walkers} walkers: old {times['old'] * 1e3:.2f} ms, new {times['new'] * 1e3:.2f} ms "
          f"-> {times['old'] / times['new']:.1f}x; chains equal from the same start: "
          f"{np.array_equal(chains['old'], chains['new'])} ({STEPS} steps)")

    pop = CAL.space.to_physical(np.random.default_rng(0).random((200, 6)))

    def ga_old():  # the old predict: the numpy model on (P, 1) columns
        v = dict(zip(PARAMS, np.split(pop, 6, axis=1)))
        with np.errstate(all="ignore"):
            amplitude._harmonic_balance_numpy(d.q, v["Fs"], v["KT"], v["chi"], v["beta"], v["k"], CAL.m, v["zeta_v"])

    t_ga_old = _best(lambda: [ga_old() for _ in range(20)]) / 20
    t_ga_new = _best(lambda: [objective(pop, d.q, d.f, d.zeta, m=CAL.m) for _ in range(20)]) / 20
    print(f"  GA, population of 200 (random within the bounds): old model call {t_ga_old * 1e3:.2f} ms, "
          f"new objective (model and eq. 3.9) {t_ga_new * 1e3:.2f} ms -> {t_ga_old / t_ga_new:.1f}x")


if __name__ == "__main__":
    main()
