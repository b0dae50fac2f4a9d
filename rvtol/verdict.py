"""The one pass/fail policy: how a requirement is judged from the measured yield and Cpk.

The Monte Carlo verdicts (:class:`rvtol.mc.MonteCarloResult`) and the
allocation's Monte Carlo constraint
(:class:`rvtol.allocation.problem.MonteCarloConstraint`) measure the yield
and Cpk of a sample (:mod:`rvtol.stats`) and hand them to :func:`judge`, so a
tolerance the optimiser calls feasible is one the sign-off passes:

* a requirement names a minimum yield and/or a minimum Cpk (a requirement
  with neither asks for the ±3σ yield, :attr:`rvtol.spec.Requirement.DEFAULT_MIN_YIELD`);
* ``basis = "lower_bound"`` (default) judges the lower end of the
  confidence interval — the figure is *demonstrated* at the stated
  confidence; ``"estimate"`` judges the point estimate;
* ``cpk_method`` chooses the Cpk a minimum Cpk judges (:func:`cpk_figures`):
  ``"normal"`` (default) the normal-theory Cpk = min(USL − μ, μ − LSL)/3σ with
  Bissell's lower bound, or ``"percentile"`` the ISO 22514-2 Cpk from the
  0.135 %, 50 % and 99.865 % points (any distribution shape) with its
  bootstrap lower bound;
* samples the model could not evaluate count as non-conforming in the
  yield, and while any sample fails a Cpk demonstrates nothing (it only
  describes the evaluated samples).

:func:`judge` also returns a *violation* ≥ 0, zero exactly when the
requirement passes, for optimisers (normalised shortfall of each figure).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from .spec import Requirement

#: violation charged for a Cpk that cannot be computed or demonstrated
CPK_UNAVAILABLE = 10.0


@dataclass
class Judgement:
    passed: bool
    reasons: list[str] = field(default_factory=list)
    violation: float = 0.0


def cpk_figures(r: Requirement, capability: dict, percentile_ci=(None, None)) -> tuple[float | None, float | None]:
    """``(Cpk, its lower bound)`` that judge ``r``'s minimum Cpk: normal theory (Bissell) or percentile
    (ISO 22514-2, bootstrap), by ``r.cpk_method``; ``capability`` is :func:`rvtol.stats.capability`'s dict."""
    if r.cpk_method == "percentile":
        return capability.get("cpk_percentile"), percentile_ci[0]
    return capability.get("cpk"), capability.get("cpk_lo")


def cpk_name(r: Requirement) -> str:
    """How the report names the Cpk that judges ``r``."""
    return "percentile Cpk" if r.cpk_method == "percentile" else "Cpk"


def judge(r: Requirement, *, yield_: float | None = None, yield_lo: float | None = None,
          cpk: float | None = None, cpk_lo: float | None = None, n_failed: int = 0) -> Judgement:
    """Pass/fail, reasons and violation of requirement ``r`` from its measured figures."""
    lb = r.basis == "lower_bound"
    j = Judgement(True)
    if r.min_yield is not None:
        v = yield_lo if lb else yield_
        if not (v is not None and v >= r.min_yield):
            j.passed = False
            j.reasons.append(f"yield {'lower bound ' if lb else ''}{_f(v, '.5f')} < required {r.min_yield:g}")
            short = r.min_yield - v if v is not None and math.isfinite(v) else 1.0
            j.violation += max(0.0, short) / max(1.0 - r.min_yield, 1e-6)
    if r.min_cpk is not None:
        c = cpk_lo if lb else cpk
        if c is None or not c >= r.min_cpk:
            j.passed = False
            j.reasons.append(f"{cpk_name(r)} {'lower bound ' if lb else ''}{_f(c, '.3f')} < required {r.min_cpk:g}")
        if c is None or not math.isfinite(c) or n_failed:
            j.violation += CPK_UNAVAILABLE
        else:
            j.violation += max(0.0, r.min_cpk - c) / r.min_cpk
    if n_failed:
        j.reasons.append(f"{n_failed} sample(s) could not be evaluated and count as non-conforming")
        if r.min_cpk is not None:
            j.passed = False
            j.reasons.append("Cpk is not demonstrated while samples fail (it only describes the evaluated ones)")
    return j


def _f(v, fmt: str) -> str:
    return "n/a" if v is None else format(v, fmt)
