"""emcee run in chunks until the chain is long compared with its autocorrelation time.

After each chunk the integrated autocorrelation time tau of every coordinate is read from
the whole chain so far with `emcee.autocorr.integrated_time(chain, tol=0)` (what
`EnsembleSampler.get_autocorr_time(tol=0)` computes, here over the chunks of earlier
processes too). The run stops when the chain is longer than ``tau_factor * max(tau)``
and every tau changed by less than ``tau_rtol`` since the previous chunk, or at
``max_steps``.

Early stop (``stop_projected``): a chain whose autocorrelation time keeps growing with
its length (walkers that do not mix, e.g. between separated modes) never reaches the
tau_factor rule. After ``min_chunks`` checks, the chain length in units of tau, r = N / tau,
is extrapolated linearly over the last three checks to the N where it reaches
``tau_factor`` (`projected_steps`). For a chain that mixes, tau settles and r grows at
1/tau per step, so the projection is about tau_factor * tau; for one that does not, r
stays flat and the projection runs off. When it exceeds ``stop_projected * max_steps``
at two checks in a row, the run stops there and says so (``stop_reason``).

Reproducible: emcee draws from its own ``numpy.random.RandomState``, set from `seed`
through the initial `emcee.State` (not from numpy's global state). Resumable: after
every chunk `on_chunk` receives the chain so far, the last log-probabilities and the
RandomState; passing that back as `resume` continues the chain exactly where it stopped,
so an interrupted run ends with the same chain as an uninterrupted one.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.fft
from numpy.typing import NDArray

__all__ = ["TAU_FACTOR", "ChainResult", "run_chain", "sample_ball", "projected_steps", "random_state_arrays", "random_state_tuple"]

TAU_FACTOR = 50.0  # chain length over the largest autocorrelation time that counts as converged (the config's default)


@dataclass
class ChainResult:
    """An emcee chain and its convergence record.

    chain : ndarray (steps, walkers, ndim); log_prob : ndarray (steps, walkers);
    tau : ndarray (ndim [+ k],) -- integrated autocorrelation time of each coordinate
    (and observed quantity), steps; tau_history : ndarray (chunks, 1 + len(tau)) -- chain
    length, then tau, after each chunk;
    converged : bool -- the tau_factor rule was met; stop_reason : str -- "converged",
    "max_steps" or "projected" (stopped early, see the module notes); projected_steps :
    float -- the last projection of the steps the tau_factor rule needs (inf: r not growing);
    acceptance : ndarray (walkers,) --
    acceptance fraction over the whole chain; random_state : tuple -- emcee's RandomState.
    """

    chain: NDArray[np.float64]
    log_prob: NDArray[np.float64]
    tau: NDArray[np.float64]
    tau_history: NDArray[np.float64]
    converged: bool
    acceptance: NDArray[np.float64]
    random_state: tuple
    stop_reason: str = "max_steps"
    projected_steps: float = float("nan")

    @property
    def steps(self) -> int:
        """Chain length, steps."""
        return int(self.chain.shape[0])


def random_state_arrays(state: tuple) -> dict[str, NDArray]:
    """A ``RandomState.get_state()`` tuple as plain arrays (for ``numpy.savez``)."""
    _, keys, pos, has_gauss, cached = state
    return {"rs_keys": np.asarray(keys, dtype=np.uint32), "rs_pos": np.asarray(pos, dtype=np.int64),
            "rs_has_gauss": np.asarray(has_gauss, dtype=np.int64), "rs_cached": np.asarray(cached, dtype=float)}


def random_state_tuple(arrays: dict[str, NDArray]) -> tuple:
    """Inverse of `random_state_arrays`."""
    return ("MT19937", np.asarray(arrays["rs_keys"], dtype=np.uint32), int(arrays["rs_pos"]),
            int(arrays["rs_has_gauss"]), float(arrays["rs_cached"]))


def integrated_time(x: NDArray[np.float64], c: float = 5.0) -> NDArray[np.float64]:
    """Integrated autocorrelation time of each quantity of a chain x (steps, walkers, quantities), steps.

    emcee's estimator (`emcee.autocorr.integrated_time` with ``tol=0``): each walker's series
    normalised autocorrelation by FFT (zero-padded past twice its length), averaged over the
    walkers; tau = 2 sum_{t <= M} rho(t) - 1 with Sokal's window, the smallest M >= c tau(M).
    Here the walkers' series of a quantity go through one real FFT of a fast length (emcee: a
    complex FFT of twice the next power of two per series); the result agrees with emcee's to
    rounding (tests/posterior/test_sampler.py).
    """
    x = np.asarray(x, dtype=float)
    n_t, _, n_d = x.shape
    n = scipy.fft.next_fast_len(2 * n_t - 1, real=True)  # zero-padded: no lag below n_t wraps around
    tau = np.empty(n_d)
    for d in range(n_d):
        series = np.ascontiguousarray(x[:, :, d].T)  # (walkers, steps)
        spec = scipy.fft.rfft(series - series.mean(axis=1, keepdims=True), n=n)
        acf = scipy.fft.irfft(spec.real**2 + spec.imag**2, n=n)[:, :n_t]
        taus = 2.0 * np.cumsum(np.mean(acf / acf[:, :1], axis=0)) - 1.0
        short = np.arange(n_t) < c * taus
        tau[d] = taus[np.argmin(short) if np.any(short) else n_t - 1]
    return tau


def _tau(chain: NDArray[np.float64], observe: Callable | None) -> NDArray[np.float64]:
    if observe is not None:
        chain = np.concatenate([chain, observe(chain)], axis=-1)
    return integrated_time(chain)


def projected_steps(hist: NDArray[np.float64] | list, tau_factor: float = 50.0, last: int = 3) -> float:
    """Chain length at which N / max(tau) reaches `tau_factor`, extrapolated linearly over the last checks.

    Parameters
    ----------
    hist : array_like, shape (checks, 1 + n)
        Chain length, then tau of each quantity, after each check (`ChainResult.tau_history`).
    tau_factor : float
        Target chain length in units of the largest tau.
    last : int
        Checks the linear fit uses.

    Returns
    -------
    float
        Steps; the current length when already there; inf when N / tau is not growing;
        NaN with fewer than `last` checks.
    """
    h = np.asarray(hist, dtype=float).reshape(len(hist), -1)
    if len(h) < last:
        return float("nan")
    n = h[-last:, 0]
    r = n / np.max(h[-last:, 1:], axis=1)
    if r[-1] >= tau_factor:
        return float(n[-1])
    slope = np.polyfit(n, r, 1)[0]
    return float(n[-1] + (tau_factor - r[-1]) / slope) if slope > 0 else float("inf")


def run_chain(log_prob: Callable[[NDArray[np.float64]], NDArray[np.float64]], x0: NDArray[np.float64], *,
              seed: int, max_steps: int, chunk: int = 1000, tau_factor: float = TAU_FACTOR, tau_rtol: float = 0.05,
              stop_projected: float = 0.0, min_chunks: int = 5,
              observe: Callable[[NDArray[np.float64]], NDArray[np.float64]] | None = None,
              resume: dict[str, Any] | None = None,
              on_chunk: Callable[[dict[str, Any]], None] | None = None) -> ChainResult:
    """Run an affine-invariant ensemble (emcee) with a vectorised log-probability.

    Parameters
    ----------
    log_prob : callable
        ``log_prob(X) -> (W,)`` for X of shape (W, ndim); -inf outside the prior.
    x0 : ndarray, shape (walkers, ndim)
        Starting positions (used only when not resuming).
    seed : int
        Seed of emcee's RandomState.
    max_steps : int
        Hard cap on the chain length, steps.
    chunk : int
        Steps between convergence checks and `on_chunk` calls.
    tau_factor, tau_rtol : float
        Stop when steps > tau_factor * max(tau) and max |delta tau / tau| < tau_rtol.
    stop_projected : float
        Stop early when `projected_steps` exceeds ``stop_projected * max_steps`` at two
        checks in a row, from check `min_chunks` on (0: never; the run goes to max_steps).
    min_chunks : int
        Checks before the early stop is considered (tau of a short chain is capped by its
        length, so N / tau starts flat even for a chain that mixes).
    observe : callable, optional
        ``observe(chain) -> (steps, walkers, k)``: further quantities (e.g. the
        physical parameters) whose tau also counts in the stopping rule; tau then has
        ndim + k entries.
    resume : dict, optional
        A dict given earlier to `on_chunk` (keys chain, log_prob, random_state,
        tau_history, accepted); the chain continues from its last step.
    on_chunk : callable, optional
        Called after each chunk with that dict.

    Returns
    -------
    ChainResult
    """
    import emcee  # here: it imports scipy.stats (~1 s), which the figure, report and design jobs never need

    if resume is not None and len(resume["chain"]):
        chain, lp = np.asarray(resume["chain"]), np.asarray(resume["log_prob"])
        hist = [np.asarray(h) for h in resume["tau_history"]]
        accepted = np.asarray(resume["accepted"], dtype=float)
        state = emcee.State(chain[-1], log_prob=lp[-1], random_state=resume["random_state"])
    else:
        x0 = np.asarray(x0, dtype=float)
        chain, lp = np.zeros((0, *x0.shape)), np.zeros((0, x0.shape[0]))
        hist, accepted = [], np.zeros(x0.shape[0])
        state = emcee.State(x0, random_state=np.random.RandomState(seed).get_state())
    nwalkers, ndim = chain.shape[1:] if chain.size else np.shape(state.coords)
    sampler = emcee.EnsembleSampler(nwalkers, ndim, log_prob, vectorize=True)
    tau = _tau(chain, observe) if len(chain) else np.full(ndim, np.inf)
    converged = _converged(hist, tau_factor, tau_rtol)

    def late(h: list) -> bool:
        return stop_projected > 0 and len(h) >= min_chunks and projected_steps(h, tau_factor) > stop_projected * max_steps

    hopeless = 0
    for k in range(1, len(hist) + 1):  # a resumed chain stops where the uninterrupted one would
        hopeless = hopeless + 1 if late(hist[:k]) else 0
    projected = projected_steps(hist, tau_factor) if hist else float("nan")
    while not converged and len(chain) < max_steps and hopeless < 2:
        n = int(min(chunk, max_steps - len(chain)))
        sampler.reset()
        state = sampler.run_mcmc(state, n, skip_initial_state_check=len(chain) > 0)
        chain = np.concatenate([chain, sampler.get_chain()])
        lp = np.concatenate([lp, sampler.get_log_prob()])
        accepted = accepted + sampler.backend.accepted
        tau = _tau(chain, observe)
        hist.append(np.r_[len(chain), tau])
        converged = _converged(hist, tau_factor, tau_rtol)
        projected = projected_steps(hist, tau_factor)
        hopeless = hopeless + 1 if late(hist) else 0
        if on_chunk is not None:
            on_chunk(dict(chain=chain, log_prob=lp, random_state=state.random_state, tau_history=hist,
                          accepted=accepted))
    rs = state.random_state if state.random_state is not None else sampler.random_state
    reason = "converged" if converged else ("projected" if hopeless >= 2 and len(chain) < max_steps else "max_steps")
    return ChainResult(chain=chain, log_prob=lp, tau=tau, tau_history=np.asarray(hist).reshape(len(hist), -1),
                       converged=converged, acceptance=accepted / max(len(chain), 1), random_state=rs,
                       stop_reason=reason, projected_steps=projected)


def _converged(hist: list[NDArray[np.float64]], tau_factor: float, tau_rtol: float) -> bool:
    """The tau_factor rule (with tau_rtol) on the last two convergence checks."""
    if len(hist) < 2:
        return False
    (n, *tau), (_, *prev) = hist[-1], hist[-2]
    tau, prev = np.asarray(tau), np.asarray(prev)
    return bool(np.all(np.isfinite(tau)) and n > tau_factor * tau.max()
                and np.all(np.abs(tau - prev) / tau < tau_rtol))


def sample_ball(log_prob: Callable[[NDArray[np.float64]], NDArray[np.float64]], centre: NDArray[np.float64],
                sd: NDArray[np.float64], *, walkers: int, steps: int, seed: int) -> ChainResult:
    """`run_chain` from a Gaussian ball in the unit cube (clipped to it), checked four times.

    Parameters
    ----------
    log_prob : callable
        ``log_prob(V) -> (W,)`` on unit-cube points V (W, d) (e.g. a `ResidualPosterior`).
    centre, sd : ndarray, shape (d,)
        Centre and per-coordinate width of the starting ball.
    walkers, steps, seed : int
        Ensemble size, the chain's length cap (steps; chunks of max(50, steps / 4)) and the
        seed of the ball and of emcee.
    """
    rng = np.random.default_rng(seed)
    x0 = np.clip(centre + rng.standard_normal((walkers, centre.size)) * sd, 0.0, 1.0)
    return run_chain(log_prob, x0, seed=seed, max_steps=steps, chunk=max(50, steps // 4), stop_projected=0.0)
