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

One serial reducer (:mod:`rvtol.production.per_unit`) is judged by :func:`judge_unit` with the same
figures read the other way round: its measured parts and the unmeasured factors give a probability
``P`` that *this* unit meets the requirement; the unit **conforms** when ``P`` reaches the yield
the requirement demands of the population (its lower confidence bound, or the estimate with
``basis = "estimate"`` — :func:`judge` decides), **does not conform** when even the upper bound
stays below it, and is **undecided** in between (measure more, or evaluate more samples) — the
decision rules of ISO 14253-1 with the prediction's spread as the guard band.
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


#: the three states of a unit's verdict (:func:`judge_unit`)
CONFORMS, DOES_NOT_CONFORM, UNDECIDED = "conforms", "does not conform", "undecided"


def unit_probability_required(r: Requirement) -> float:
    """The probability of conformance one unit must show: the requirement's ``min_yield``; for a
    Cpk-only requirement the yield that Cpk guarantees of a normal process, Φ(3·Cpk) one-sided or
    2Φ(3·Cpk) − 1 two-sided (a Cpk describes a population, not a unit)."""
    if r.min_yield is not None:
        return float(r.min_yield)
    from scipy.stats import norm

    p = float(norm.cdf(3.0 * r.min_cpk))
    return 2.0 * p - 1.0 if r.lower is not None and r.upper is not None else p


@dataclass
class UnitJudgement:
    state: str
    required: float
    reasons: list[str] = field(default_factory=list)


def judge_unit(r: Requirement, *, p: float, p_lo: float, p_hi: float, n_failed: int = 0,
               required: float | None = None) -> UnitJudgement:
    """The verdict of one unit on requirement ``r`` from its probability of conformance ``p`` and
    that probability's confidence interval ``[p_lo, p_hi]`` (module docstring); ``required``: the
    probability a unit must show, instead of :func:`unit_probability_required` (e.g. 0.95, the
    coverage of ISO 14253-1's decision rule for one workpiece)."""
    req = unit_probability_required(r) if required is None else float(required)
    lb = r.basis == "lower_bound"
    yr = r if r.min_yield == req and r.min_cpk is None else _as_yield(r, req)
    ok = judge(yr, yield_=p, yield_lo=p_lo, n_failed=n_failed)
    if ok.passed:
        return UnitJudgement(CONFORMS, req, [])
    reasons = [f"P(conforms) {'upper bound ' if lb else ''}{_f(p_hi if lb else p, '.5f')} < required {req:g}"]
    if not (lb and p_hi >= req):
        return UnitJudgement(DOES_NOT_CONFORM, req, reasons + ok.reasons[1:])
    return UnitJudgement(UNDECIDED, req, ok.reasons[:1] + [f"upper bound {_f(p_hi, '.5f')} ≥ {req:g}: more "
                                                             "samples or a smaller measurement uncertainty decide"]
                         + ok.reasons[1:])


def _as_yield(r: Requirement, p: float) -> Requirement:
    from dataclasses import replace

    return replace(r, min_yield=p, min_cpk=None)


def _f(v, fmt: str) -> str:
    return "n/a" if v is None else format(v, fmt)
