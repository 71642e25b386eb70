"""Test helpers (not jointcal code): posterior-like draws along the microslip null manifold, by hand.

Below macroslip the harmonic-balance frequency and damping depend on the joint only through
K0 = k + KT, R (eq. 3.5), chi and zeta_v (k_df = K0 - R q^(chi+1) J, D = 4R q^(chi+3)/((chi+2)(chi+3))).
With K0, R, chi and zeta_v held, the KT/k split and beta are free, and eqs. 3.5 and 3.7 give Fs:

    R = (1 + chi) KT^(chi+2) c^(chi+1) / (Fs^(chi+1) (1 + beta)^(chi+2)),   c = beta + (chi+1)/(chi+2),

so Fs = ((1 + chi) KT^(chi+2) c^(chi+1) / (R (1 + beta)^(chi+2)))^(1/(chi+1)). Every such draw fits
read-outs below its macroslip onset exactly: an oracle of which directions the data leave free that
does not go through the Fisher information it tests.
"""
import numpy as np

from jointcal.models import G, derived, harmonic_balance, resonance_amplitude

M = 2.65 / G
TRUTH = {"Fs": 313.0, "KT": 1.02e6, "chi": -0.65, "beta": 0.004, "k": 6.12e5, "zeta_v": 0.0015}
PARAMS = ("Fs", "KT", "chi", "beta", "k", "zeta_v")


def readouts(levels=(1, 1, 2, 5, 10), truth=TRUTH):
    """Exact phase-resonance read-outs (q in, f Hz, zeta) of the truth at base levels (g)."""
    t = truth
    q, f, z = resonance_amplitude(np.asarray(levels, float), t["Fs"], t["KT"], t["chi"], t["beta"], t["k"], M,
                                  t["zeta_v"])
    return q, f, z


def null_draws(n=400, split=(-0.3, 1.5), log_beta=(-3.5, -1.0), truth=TRUTH, q_max=None, seed=0,
               sigma=(1e-4, 0.01)):
    """Draws (n', 8) of (Fs, KT, chi, beta, k, zeta_v, sigma_f, sigma_zeta) with K0, R, chi, zeta_v of the truth,
    log10(KT/k) and log10(beta) uniform in the given ranges, kept where macroslip starts above 1.2 q_max."""
    rng = np.random.default_rng(seed)
    t = truth
    K0 = t["KT"] + t["k"]
    chi = t["chi"]
    R = derived(t["Fs"], t["KT"], chi, t["beta"])[1]
    a = rng.uniform(*split, n)
    beta = 10 ** rng.uniform(*log_beta, n)
    k = K0 / (1 + 10**a)
    KT = K0 - k
    c = beta + (chi + 1) / (chi + 2)
    Fs = ((1 + chi) * KT ** (chi + 2) * c ** (chi + 1) / (R * (1 + beta) ** (chi + 2))) ** (1 / (chi + 1))
    S = np.column_stack([Fs, KT, np.full(n, chi), beta, k, np.full(n, t["zeta_v"]), np.full(n, sigma[0]),
                         np.full(n, sigma[1])])
    if q_max is not None:
        S = S[derived(Fs, KT, chi, beta)[0] > 1.2 * q_max]
    return S


def model_readouts(S, q):
    """The draws' harmonic-balance f and zeta at amplitudes q, shape (n, N) each."""
    return harmonic_balance(np.asarray(q)[None, :], *(S[:, i:i + 1] for i in range(5)), M, S[:, 5:6])
