"""Convex allocation (cvxpy): the global optimum of the linearised problem.

``minimise Σ_i C_i(t_i)`` with convex decreasing cost curves, subject to

* RSS:        ``‖(c_j1 t_1, ..., c_jm t_m)‖₂ ≤ √budget_j`` for each requirement j (second-order cone), or
* worst case: ``Σ_i c_ji t_i ≤ budget_j`` (linear),

``t_min ≤ t ≤ t_max`` and tied factors at their lead's tolerance (one drawing callout), with the
coefficients of
:class:`rvtol.allocation.problem.LinearisedConstraint`.  The variables are
the tolerances in each cost curve's own unit, so the problem is well scaled.
"""
from __future__ import annotations

import numpy as np

from .. import units
from .problem import AllocationProblem, LinearisedConstraint
from .results import AllocationResult


def solve_convex(problem: AllocationProblem, constraint: LinearisedConstraint, solver: str | None = None
                 ) -> AllocationResult:
    import cvxpy as cp

    m = len(problem.factors)
    scale = np.array([units.factor(c.unit) for c in problem.curves])  # base per curve unit
    lo = np.array([c.t_min for c in problem.curves])
    hi = np.array([c.t_max for c in problem.curves])
    t = cp.Variable(m, name="t")
    cost = sum(c.expr(t[i]) for i, c in enumerate(problem.curves))
    cons = [t >= lo, t <= hi]
    for k in np.flatnonzero(problem.lead != np.arange(m)):      # tied: t_k = t_lead · t0_k / t0_lead (base)
        j = problem.lead[k]
        cons.append(t[k] == problem.ratio[k] * scale[j] / scale[k] * t[j])
    method = f"convex {constraint.mode}"
    if getattr(constraint, "unavailable", None):
        return AllocationResult(method, problem, None, "not available", False, constraint.describe(),
                                notes=["the model could not be evaluated on the five points of "
                                       f"{', '.join(constraint.unavailable)}: no linearisation"])
    if np.any(constraint.budget <= 0):
        return AllocationResult(method, problem, None, "infeasible", False, constraint.describe(),
                                notes=["infeasible, binding: " + "; ".join(constraint.binding())])
    for j in range(constraint.coef.shape[0]):
        a = constraint.coef[j] * scale  # per curve unit
        if constraint.mode == "rss":
            a = a / np.sqrt(constraint.budget[j])
            cons.append(cp.norm(cp.multiply(a, t), 2) <= 1.0)
        else:
            a = a / constraint.budget[j]
            cons.append(a @ t <= 1.0)
    prob = cp.Problem(cp.Minimize(cost), cons)
    solver = solver or "CLARABEL"
    # the optimum is flat (the cost's gradient vanishes along the constraint): t is accurate to about the
    # square root of the duality-gap tolerance, so the gap is closed to 1e-9 (t to a few 1e-5; tighter
    # settings make Clarabel report "inaccurate")
    opts = dict(tol_gap_abs=1e-9, tol_gap_rel=1e-9, tol_feas=1e-9) if solver == "CLARABEL" else {}
    try:
        prob.solve(solver=solver, **opts)
    except cp.SolverError as exc:
        return AllocationResult(method, problem, None, f"solver error: {exc}", False, constraint.describe())
    if prob.status not in ("optimal", "optimal_inaccurate") or t.value is None:
        why = constraint.binding(lo * scale)
        return AllocationResult(method, problem, None, prob.status, False, constraint.describe(),
                                notes=[("even the tightest tolerances cannot meet the requirements"
                                        + (", binding: " + "; ".join(why) if why else ""))
                                       if prob.status == "infeasible" else f"solver status {prob.status}"])
    tv = np.clip(np.asarray(t.value, float), lo, hi) * scale
    return AllocationResult(method, problem, tv, prob.status, True, constraint.describe())
