"""The uniform baseline and the independent Monte Carlo check of an allocation.

* :func:`uniform_baseline` — every allocated tolerance scaled by one common
  factor s (the spec's tolerance pattern kept), the largest s that meets the
  constraint (bisection on log s; the constraints are monotone in s);
* :func:`verify` — a fresh Monte Carlo run (its own seed stream, plain
  random sampling) of the allocated spec through
  :func:`rvtol.mc.run_monte_carlo`, judged by the spine's verdicts.
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ..mc import run_monte_carlo
from .problem import AllocationProblem
from .results import AllocationResult, Verification


def uniform_baseline(problem: AllocationProblem, constraint, iterations: int = 40) -> AllocationResult:
    t0 = problem.t0
    lo, hi = problem.lower, problem.upper
    s_lo, s_hi = float(np.min(lo / t0)), float(np.max(hi / t0))
    at = lambda s: np.clip(s * t0, lo, hi)  # noqa: E731
    feasible = lambda s: bool(constraint.violation(at(s)[None, :])[0] <= 0.0)  # noqa: E731
    if not feasible(s_lo):
        why = constraint.binding(at(s_lo)) if hasattr(constraint, "binding") else []
        return AllocationResult("uniform", problem, at(s_lo), "infeasible", False, constraint.describe(),
                                notes=["no common scale of the spec's tolerances meets the requirements"
                                       + (", binding: " + "; ".join(why) if why else "")])
    if feasible(s_hi):
        return AllocationResult("uniform", problem, at(s_hi), "all at their upper bound", True, constraint.describe())
    a, b = math.log(s_lo), math.log(s_hi)
    for _ in range(iterations):
        mid = 0.5 * (a + b)
        if feasible(math.exp(mid)):
            a = mid
        else:
            b = mid
    return AllocationResult("uniform", problem, at(math.exp(a)), f"common scale {math.exp(a):.4g} × spec",
                            True, constraint.describe(), evaluations=getattr(constraint, "evaluations", 0))


def verify(result: AllocationResult, n: int, seed: int, executor=None) -> Verification:
    """Independent Monte Carlo run of the allocated spec; one row per requirement."""
    p = result.problem
    mc = run_monte_carlo(p.model, p.spec_at(result.t), n, "random", seed, p.requirements, executor,
                         progress=False)
    rows = []
    for v in mc.verdicts():
        d = v.to_dict()
        rows.append({"output": d["output"], "unit": d["unit"], "lower": d["lower"], "upper": d["upper"],
                     "yield": d["yield"], "yield_lo": d["yield_bound"],        # the bounds the verdict judges
                     "Cpk": d["cpk"], "Cpk_lo": d["cpk_bound"],
                     "required": (f"yield ≥ {d['min_yield']:g}" if d["min_yield"] is not None else "")
                     + (f"Cpk ≥ {d['min_cpk']:g}" if d["min_cpk"] is not None else "")
                     + (f"{d['statistic']} within the limits (its interval)" if d["statistic"] else f" ({d['basis']})"),
                     "passed": d["passed"]})
    return Verification(result.method, n, seed, pd.DataFrame(rows))
