"""How far the calibration's optimum misses the read-outs, against their noise scales: the chi-square test.

The noise scales are the repeat scatter, or where the campaign has no repeats the
read-outs' own scatter about a smooth backbone (`jointcal.posterior.noise`). The verdict
(`jointcal.report.verdict`) shows this test beside the validation's E.
"""
from __future__ import annotations

import numpy as np

from .likelihood import LogPosterior
from .noise import scale_words

__all__ = ["P_REJECT", "goodness_of_fit", "fit_test"]

P_REJECT = 1e-3  # chi-square probability below which the data reject the model


def goodness_of_fit(lp: LogPosterior, theta: np.ndarray, p_reject: float = P_REJECT,
                    sources: tuple[str, str] = ("repeats", "repeats")) -> tuple[list[float], str]:
    """How far the GA optimum misses the data, against the noise scales (the repeat scatter, or the read-outs'
    own scatter where the campaign has no repeats: `jointcal.posterior.noise`).

    Parameters
    ----------
    lp : LogPosterior
        Data and noise floors (``lp.data.rel_noise``: relative scatter of f and zeta).
    theta : ndarray, shape (n,)
        The optimum in `lp.space` (Fs lbf, KT lbf/in, chi, beta, k lbf/in, zeta_v, and any grown parameter).
    p_reject : float
        Chi-square probability below which the sentence says the data reject the model.
    sources : (str, str)
        Where the frequency's and the damping's scales came from (`jointcal.posterior.noise.SOURCE_WORDS`).

    Returns
    -------
    ratios : list of float
        rms relative residual of f and of zeta divided by its noise scale.
    sentence : str
    """
    x = lp.space.to_unit(theta) * (lp.space.x_hi - lp.space.x_lo) + lp.space.x_lo
    r_f, r_z = lp.residuals(x[None])
    s_f, s_z = lp.data.rel_noise
    rms = [float(np.sqrt(np.mean(r_f**2))), float(np.sqrt(np.mean(r_z**2)))]
    if lp.data.weight is not None:  # over read-outs (a ring-down's windows 1/k each)
        rms = [float(np.sqrt(np.sum(lp.data.w * r**2) / lp.data.n_readouts)) for r in (r_f, r_z)]
    ratios = [rms[0] / s_f, rms[1] / s_z]
    test = fit_test(lp, theta)
    stat, dof, p = test["fit_chi2"], int(test["fit_dof"]), test["fit_p"]
    scale = scale_words(sources)
    precision = "the repeats" if tuple(sources) == ("repeats", "repeats") else scale
    verdict = (f"the data reject the model at the precision of {precision} (model error, not noise, sets the "
               "noise scales, which widen the intervals)" if p < p_reject else f"consistent with {scale}")
    return ratios, (f"Fit of the GA optimum: rms relative residuals {rms[0]:.2g} (frequency) and {rms[1]:.2g} "
                    f"(damping) = {ratios[0]:.1f} and {ratios[1]:.1f} x {scale}; chi-square {stat:.0f} "
                    f"for {dof} degrees of freedom (p = {p:.1g}): {verdict}.")



def fit_test(lp: LogPosterior, theta: np.ndarray) -> dict[str, float]:
    """The chi-square test of `goodness_of_fit` as numbers: fit_chi2, fit_dof, fit_p (stored in chain.npz)."""
    from scipy.stats import chi2

    x = lp.space.to_unit(theta) * (lp.space.x_hi - lp.space.x_lo) + lp.space.x_lo
    r_f, r_z = lp.residuals(x[None])
    s_f, s_z = lp.data.rel_noise
    stat = float(np.sum((r_f / s_f) ** 2) + np.sum((r_z / s_z) ** 2))
    dof = max(2 * r_f.size - len(theta), 1)
    if lp.data.weight is not None:  # read-outs, not points: a ring-down's windows share one degree of freedom
        w = lp.data.w
        stat = float(np.sum(w * (r_f / s_f) ** 2) + np.sum(w * (r_z / s_z) ** 2))
        dof = max(2 * lp.data.n_readouts - len(theta), 1)
    return {"fit_chi2": stat, "fit_dof": float(dof), "fit_p": float(chi2.sf(stat, dof))}
