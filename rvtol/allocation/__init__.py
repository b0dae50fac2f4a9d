"""Cost-optimal tolerance allocation (doc 002), for any :class:`rvtol.model.Model`.

* :mod:`.cost` — cost–tolerance models (reciprocal power ``a + b/t^c``,
  exponential), fitted to (tolerance, cost) data with scipy; ``data/costs/*.toml``;
* :mod:`.problem` — :class:`AllocationProblem` (model, spec, allocated factors
  with their cost curves, requirements) and its two constraints:
  :class:`LinearisedConstraint` (RSS or worst case from the five-point
  gradient) and :class:`MonteCarloConstraint` (yield and/or Cpk from a fixed
  Monte Carlo design, common random numbers);
* :mod:`.convex` — :func:`solve_convex` (cvxpy; the global optimum of the
  linearised problem, a cross-check);
* :mod:`.ga` — :func:`solve_ga` (pygad; seeded, any constraint);
* :mod:`.baseline` — uniform-tolerance baseline and the independent Monte
  Carlo :func:`verify`;
* :mod:`.allocate` — :func:`allocate`: what a study asks for, one :class:`Allocation` result;
* :mod:`.analyses` — the ``allocation`` study analysis (``ANALYSES["allocation"]``), :mod:`.texts` its report.
"""
from .baseline import uniform_baseline, verify
from .convex import solve_convex
from .cost import CostModel, CostTable, fit_cost_model, load_costs
from .ga import GASettings, solve_ga
from .problem import AllocationProblem, LinearisedConstraint, MonteCarloConstraint

__all__ = ["AllocationProblem", "LinearisedConstraint", "MonteCarloConstraint", "solve_convex", "solve_ga",
           "GASettings", "uniform_baseline", "verify", "CostModel", "CostTable", "fit_cost_model", "load_costs"]
