"""Genetic algorithm (DEAP) over the unit cube, with batch evaluation, stall stop and checkpoints.

The generation loop is DEAP's `eaMuPlusLambda` written out (`algorithms.varOr`, then
selection from parents + offspring) so that it can stop on stall and checkpoint:

* genes: `list` individuals of floats in [0, 1] (see `space.ParamSpace`);
* crossover: `tools.cxSimulatedBinaryBounded` (SBX, bounded to [0, 1]);
* mutation: `tools.mutGaussian`, clipped to [0, 1]; the per-gene sigma follows the
  population's spread (sigma_j = scale * std_j, within [sigma_min, sigma_max]), so the
  search narrows as the population converges -- a fixed sigma cannot resolve the
  0.01%-level frequency differences the objective is made of;
* selection: `tools.selTournament` over parents + offspring, plus `elite` copies of
  the best (mu + lambda with tournaments alone is not elitist);
* every individual with an invalid fitness is evaluated in ONE call of the batch
  objective (a vectorised model), not individually through `toolbox.map`;
* `tools.HallOfFame`, `tools.Statistics` and `tools.Logbook` record the run.

DEAP's operators draw from the `random` module, so `run_ga` seeds it (and a numpy
Generator for the initial population) from `seed`, and the checkpoint holds both
states: an interrupted run resumed from its last checkpoint ends exactly as an
uninterrupted one.
"""
from __future__ import annotations

import random
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from deap import algorithms, base, creator, tools
from numpy.typing import NDArray

__all__ = ["GAOptions", "GAResult", "run_ga"]

# DEAP's creator warns when a class is created twice (an error under -W error): guard it.
if not hasattr(creator, "JointcalFitness"):
    creator.create("JointcalFitness", base.Fitness, weights=(-1.0,))
if not hasattr(creator, "JointcalIndividual"):
    creator.create("JointcalIndividual", list, fitness=creator.JointcalFitness)

BatchObjective = Callable[[NDArray[np.float64]], NDArray[np.float64]]


@dataclass(frozen=True)
class GAOptions:
    """GA settings (the config's ``calibrate`` section; probabilities in [0, 1]).

    population (mu) and offspring (lambda) per generation; generations: the cap;
    cxpb / mutpb: probability that an offspring comes from SBX crossover / Gaussian
    mutation (else it is a copy); sbx_eta: SBX distribution index (larger keeps children
    nearer their parents); sigma_max, sigma_min, sigma_scale: the mutation's per-gene
    standard deviation in the unit cube (see module notes); indpb: per-gene mutation
    probability; tournament: tournament size; elite: best individuals always kept;
    stall_generations, stall_rtol: stop when the best objective has not improved by a
    relative stall_rtol for that many generations; checkpoint_every: generations
    between checkpoints; seed: seeds `random` and numpy.
    """

    population: int = 200
    offspring: int = 200
    generations: int = 100
    cxpb: float = 0.6
    mutpb: float = 0.3
    sbx_eta: float = 10.0
    sigma_max: float = 0.1
    sigma_min: float = 1.0e-5
    sigma_scale: float = 1.0
    indpb: float = 0.5
    tournament: int = 3
    elite: int = 2
    stall_generations: int = 20
    stall_rtol: float = 1.0e-4
    checkpoint_every: int = 5
    seed: int = 2017

    def __post_init__(self) -> None:
        if self.population < 2 or self.offspring < 1 or self.generations < 0:
            raise ValueError(f"need population >= 2, offspring >= 1, generations >= 0; got {self.population}, "
                             f"{self.offspring}, {self.generations}")
        if not (0 <= self.cxpb and 0 <= self.mutpb and self.cxpb + self.mutpb <= 1):
            raise ValueError(f"cxpb + mutpb must lie in [0, 1], got {self.cxpb} + {self.mutpb}")
        if not 0 <= self.elite < self.population:
            raise ValueError(f"elite must lie in [0, population), got {self.elite}")


@dataclass
class GAResult:
    """Outcome of `run_ga`.

    best : ndarray, shape (ndim,) -- the hall of fame's best individual (unit cube);
    best_value : float -- its objective; generations : int -- generations run;
    stop_reason : 'generations' or 'stall'; logbook : deap.tools.Logbook (gen, nevals,
    min, median, max of the population, best so far, mean sigma); history : ndarray,
    shape (n_evals, 2 + ndim) -- generation, objective, then the genes of every
    evaluated individual.
    """

    best: NDArray[np.float64]
    best_value: float
    generations: int
    stop_reason: str
    logbook: tools.Logbook
    history: NDArray[np.float64]

    @property
    def evaluated(self) -> NDArray[np.float64]:
        """Genes of every evaluated individual (unit cube), shape (n_evals, ndim)."""
        return self.history[:, 2:]

    @property
    def objectives(self) -> NDArray[np.float64]:
        """Objective of every evaluated individual, shape (n_evals,)."""
        return self.history[:, 1]

    @property
    def generation_of(self) -> NDArray[np.int_]:
        """Generation in which each individual was evaluated, shape (n_evals,)."""
        return self.history[:, 0].astype(int)


def _mutate(ind: list, sigma: list[float], indpb: float) -> tuple[list]:
    (ind,) = tools.mutGaussian(ind, mu=0.0, sigma=sigma, indpb=indpb)
    ind[:] = [min(1.0, max(0.0, g)) for g in ind]
    return (ind,)


def _clone(ind: list) -> list:
    """The copy `copy.deepcopy` makes of an individual (its genes, floats, shared as deepcopy shares them; a new
    fitness holding the same weighted values, as `deap.base.Fitness.__deepcopy__` makes it), without deepcopy's
    walk over each gene: the toolbox's default clone took a third of a generation's Python time."""
    new = creator.JointcalIndividual(ind)
    new.fitness.wvalues = ind.fitness.wvalues
    return new


def _toolbox(opt: GAOptions) -> base.Toolbox:
    tb = base.Toolbox()
    tb.register("clone", _clone)
    tb.register("mate", tools.cxSimulatedBinaryBounded, eta=opt.sbx_eta, low=0.0, up=1.0)
    tb.register("select", tools.selTournament, tournsize=opt.tournament)
    return tb


def _sigma(pop: list, opt: GAOptions) -> list[float]:
    """Per-gene mutation sigma from the population's spread (unit cube)."""
    spread = np.std(np.asarray(pop, dtype=float), axis=0)
    return np.clip(opt.sigma_scale * spread, opt.sigma_min, opt.sigma_max).tolist()


def _evaluate(individuals: list, batch: BatchObjective, gen: int, history: list) -> int:
    """Evaluate all invalid individuals in one batch call; append them to `history`."""
    todo = [ind for ind in individuals if not ind.fitness.valid]
    if not todo:
        return 0
    genes = np.asarray(todo, dtype=float)
    values = np.asarray(batch(genes), dtype=float)
    values = np.where(np.isfinite(values), values, np.inf)
    for ind, v in zip(todo, values):
        ind.fitness.values = (float(v),)
    history.append(np.column_stack([np.full(len(todo), gen), values, genes]))
    return len(todo)


def _stats() -> tools.Statistics:
    st = tools.Statistics(key=lambda ind: ind.fitness.values[0])
    st.register("min", np.min)
    st.register("median", np.median)
    st.register("max", np.max)
    return st


def run_ga(batch: BatchObjective, ndim: int, options: GAOptions = GAOptions(), *,
           resume: dict[str, Any] | None = None,
           on_checkpoint: Callable[[dict[str, Any]], None] | None = None,
           init: NDArray[np.float64] | None = None) -> GAResult:
    """Minimise a batch objective over [0, 1]^ndim with DEAP.

    Parameters
    ----------
    batch : callable
        ``batch(U) -> values``: U of shape (n, ndim) in the unit cube, values of shape
        (n,), finite (large for invalid points).
    ndim : int
        Number of genes.
    options : GAOptions
        Settings and seed.
    resume : dict, optional
        A state passed earlier to `on_checkpoint`; the run continues from it (its
        options must equal `options` except ``generations`` and ``checkpoint_every``).
    on_checkpoint : callable, optional
        Called with a picklable state dict every ``checkpoint_every`` generations and
        at the end.
    init : ndarray (k, ndim), optional
        Known good points of the unit cube (e.g. earlier optima) that replace the first k
        members of the seeded random initial population (clipped to [0, 1]).

    Returns
    -------
    GAResult
    """
    opt = options
    tb = _toolbox(opt)
    hof = tools.HallOfFame(1)
    stats = _stats()
    if resume is None:
        random.seed(opt.seed)
        rng = np.random.default_rng(opt.seed)
        start = rng.random((opt.population, ndim))
        if init is not None and len(init):
            k = min(len(init), opt.population)
            start[:k] = np.clip(np.asarray(init, dtype=float).reshape(-1, ndim)[:k], 0.0, 1.0)
        pop = [creator.JointcalIndividual(row) for row in start.tolist()]
        logbook = tools.Logbook()
        logbook.header = ["gen", "nevals", "min", "median", "max", "best", "sigma"]
        history: list = []
        nevals = _evaluate(pop, batch, 0, history)
        hof.update(pop)
        gen, stall, ref = 0, 0, hof[0].fitness.values[0]
        logbook.record(gen=0, nevals=nevals, best=ref, sigma=float(np.mean(_sigma(pop, opt))), **stats.compile(pop))
    else:
        _check_resume(resume, opt, ndim)
        random.setstate(resume["random_state"])
        rng = np.random.default_rng()
        rng.bit_generator.state = resume["numpy_state"]
        pop, hof, logbook, history = resume["population"], resume["hof"], resume["logbook"], resume["history"]
        gen, stall, ref = resume["generation"], resume["stall"], resume["ref"]

    def state() -> dict[str, Any]:
        return dict(options=asdict(opt), ndim=ndim, generation=gen, stall=stall, ref=ref, population=pop, hof=hof,
                    logbook=logbook, history=history, random_state=random.getstate(),
                    numpy_state=rng.bit_generator.state)

    while gen < opt.generations and stall < opt.stall_generations:
        gen += 1
        sigma = _sigma(pop, opt)
        tb.register("mutate", _mutate, sigma=sigma, indpb=opt.indpb)
        offspring = algorithms.varOr(pop, tb, opt.offspring, opt.cxpb, opt.mutpb)
        nevals = _evaluate(offspring, batch, gen, history)
        hof.update(offspring)
        pool = pop + offspring
        elite = [tb.clone(i) for i in tools.selBest(pool, opt.elite)]
        pop[:] = elite + tb.select(pool, opt.population - opt.elite)
        best = hof[0].fitness.values[0]
        if best < ref * (1.0 - opt.stall_rtol):
            ref, stall = best, 0
        else:
            stall += 1
        logbook.record(gen=gen, nevals=nevals, best=best, sigma=float(np.mean(sigma)), **stats.compile(pop))
        if on_checkpoint is not None and gen % max(1, opt.checkpoint_every) == 0:
            on_checkpoint(state())
    reason = "stall" if stall >= opt.stall_generations else "generations"
    if on_checkpoint is not None:
        on_checkpoint(state())
    hist = np.concatenate(history) if history else np.zeros((0, 2 + ndim))
    return GAResult(best=np.asarray(hof[0], dtype=float), best_value=float(hof[0].fitness.values[0]),
                    generations=gen, stop_reason=reason, logbook=logbook, history=hist)


def _check_resume(resume: dict[str, Any], opt: GAOptions, ndim: int) -> None:
    free = {"generations", "checkpoint_every"}
    saved = {k: v for k, v in resume["options"].items() if k not in free}
    now = {k: v for k, v in asdict(opt).items() if k not in free}
    if saved != now or resume["ndim"] != ndim:
        raise ValueError("the GA checkpoint was made with other settings; delete it or restore the settings")
