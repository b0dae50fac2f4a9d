"""Genetic-algorithm allocation (pygad) for any constraint, in particular Monte Carlo yield / Cpk.

Genes are ``g_i ∈ [0, 1]`` with ``t_i = t_min,i · (t_max,i / t_min,i)^g_i`` (log
scale: a tolerance ratio is what matters).  The whole population is
evaluated in one batch (``fitness_batch_size``), so a Monte Carlo constraint
sends one large array through :func:`rvtol.mc.evaluate` per generation.

Constraint handling (pygad maximises the fitness):

* ``feasibility`` (Deb's rules): a feasible candidate scores ``−cost``; an
  infeasible one ``−(C_max + C_ref · violation)`` with ``C_max`` the cost of the
  tightest tolerances — every feasible candidate beats every infeasible one,
  and among infeasible ones the smaller violation wins;
* ``penalty``: ``−(cost + μ · C_ref · violation)``.

Reproducible: pygad is seeded (``random_seed``) and the initial population is
drawn from :func:`rvtol.sampling.rng`; the Monte Carlo constraint uses a fixed
design, so the fitness is a deterministic function of the genes.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..sampling import substream
from .problem import AllocationProblem
from .results import AllocationResult

HANDLING = ("feasibility", "penalty")


@dataclass(frozen=True)
class GASettings:
    population: int = 40
    generations: int = 150
    parents: int = 20
    elitism: int = 2
    mutation_probability: float = 0.15
    crossover_eta: float = 15.0  # SBX distribution index (larger: children closer to the parents)
    mutation_eta: float = 20.0  # polynomial mutation distribution index (larger: smaller steps)
    handling: str = "feasibility"
    penalty: float = 10.0
    seed: int = 1

    def __post_init__(self):
        if self.handling not in HANDLING:
            raise InputError(f"unknown constraint handling {self.handling!r} ({' | '.join(HANDLING)})",
                             key="handling")
        if not 2 <= self.parents <= self.population:
            raise InputError(f"parents must lie in [2, population={self.population}], got {self.parents}",
                             key="parents")
        if not 0 <= self.elitism < self.population:
            raise InputError(f"elitism must lie in [0, population), got {self.elitism}", key="elitism")


def genes_to_t(problem: AllocationProblem, G: np.ndarray) -> np.ndarray:
    """One gene per free tolerance (a tied group's lead, or an untied factor), log-scaled on its bounds."""
    f = problem.free
    lo, hi = problem.lower[f], problem.upper[f]
    G = np.asarray(G, float)
    T = np.empty(G.shape[:-1] + (len(problem.factors),))
    T[..., f] = lo * (hi / lo) ** np.clip(G, 0.0, 1.0)
    return problem.tie(T)


def t_to_genes(problem: AllocationProblem, T: np.ndarray) -> np.ndarray:
    f = problem.free
    lo, hi = problem.lower[f], problem.upper[f]
    return np.log(np.clip(np.asarray(T, float)[..., f], lo, hi) / lo) / np.log(hi / lo)


def solve_ga(problem: AllocationProblem, constraint, settings: GASettings = GASettings(),
             initial: np.ndarray | None = None, confirm=None, confirm_batches: int = 3) -> AllocationResult:
    """Minimise the cost subject to ``constraint.violation(T) == 0`` with pygad.

    ``initial``: optional tolerance vectors (base units) to seed part of the population.
    ``confirm``: a second constraint of the same kind on a fresh sample (a Monte Carlo constraint with
    its own design). The GA's cheapest feasible candidate is the one the optimisation's own sample
    flatters most (it is chosen BY that sample: the winner's curse of a fixed-design constraint), so the
    feasible candidates are taken cheapest first, in batches of the population size (at most
    ``confirm_batches``), and the cheapest that also meets ``confirm`` is returned.
    """
    import pygad

    s = settings
    m = len(problem.free)
    c_max = float(problem.cost(problem.lower))
    c_ref = max(float(problem.cost(problem.upper)), 1e-300)
    history: list[float] = []
    best = {"cost": np.inf, "t": None}
    pool: dict[bytes, tuple[float, np.ndarray]] = {}        # every feasible candidate (for the confirmation)

    def fitness(ga, solutions, indices):
        G = np.atleast_2d(np.asarray(solutions, float))
        T = genes_to_t(problem, G)
        cost = problem.cost(T)
        viol = constraint.violation(T)
        ok = viol <= 0.0
        if s.handling == "feasibility":
            fit = np.where(ok, -cost, -(c_max + c_ref * (1.0 + viol)))
        else:
            fit = -(cost + s.penalty * c_ref * viol)
        for i in np.flatnonzero(ok):
            if cost[i] < best["cost"]:
                best["cost"], best["t"] = float(cost[i]), T[i].copy()
            if confirm is not None:
                pool.setdefault(T[i].tobytes(), (float(cost[i]), T[i].copy()))
        return list(fit / c_ref)

    def on_generation(ga):
        history.append(best["cost"])

    pop0 = substream(s.seed, "ga_population").random((s.population, m))
    if initial is not None:
        init = t_to_genes(problem, np.atleast_2d(initial))[: s.population]
        pop0[: len(init)] = init
    ga = pygad.GA(num_generations=s.generations, num_parents_mating=s.parents, fitness_func=fitness,
                  fitness_batch_size=s.population, initial_population=pop0, gene_type=float,
                  gene_space={"low": 0.0, "high": 1.0}, init_range_low=0.0, init_range_high=1.0,
                  parent_selection_type="tournament", K_tournament=3, crossover_type="sbx",
                  sbx_crossover_eta=s.crossover_eta, mutation_type="polynomial",
                  mutation_probability=s.mutation_probability, polynomial_mutation_eta=s.mutation_eta,
                  keep_elitism=s.elitism, on_generation=on_generation, random_seed=s.seed, suppress_warnings=True,
                  save_solutions=False)
    ga.run()
    evals = getattr(constraint, "evaluations", 0)
    what = constraint.describe()
    method = "GA"
    if best["t"] is None:
        G, _, _ = ga.best_solution(ga.last_generation_fitness)
        return AllocationResult(method, problem, genes_to_t(problem, np.asarray(G, float)), "no feasible candidate",
                                False, what, history, evals,
                                ["the GA found no candidate that meets the requirement; shown: the least violating"])
    if confirm is None:
        return AllocationResult(method, problem, best["t"], f"best feasible of {s.generations} generations", True,
                                what, history, evals)
    ranked = sorted(pool.values(), key=lambda ct: ct[0])
    for b in range(confirm_batches):
        batch = ranked[b * s.population:(b + 1) * s.population]
        if not batch:
            break
        ok = np.flatnonzero(confirm.violation(np.array([t for _, t in batch])) <= 0.0)
        if len(ok):
            k = b * s.population + int(ok[0])
            return AllocationResult(method, problem, ranked[k][1], f"best feasible of {s.generations} generations, "
                                    "confirmed on a second sample", True, what, history, evals,
                                    [f"confirmed: the cheapest of the GA's {len(ranked)} feasible candidates that "
                                     f"also meets the requirements on a fresh sample ({confirm.describe()}) — "
                                     f"rank {k + 1} by cost, {100 * (ranked[k][0] / ranked[0][0] - 1):.1f} % above "
                                     "the cheapest on the optimisation's own sample"])
    n_tried = min(len(ranked), confirm_batches * s.population)
    return AllocationResult(method, problem, best["t"], f"best feasible of {s.generations} generations, NOT "
                            "confirmed", True, what, history, evals,
                            [f"none of the {n_tried} cheapest feasible candidates met the requirements on a fresh "
                             "sample: the best on the optimisation's own sample is shown"])
