"""The one pass/fail policy: how a requirement is judged from the measured yield and Cpk.

The Monte Carlo verdicts (:class:`rvtol.mc.MonteCarloResult`) and the
allocation's Monte Carlo constraint
(:class:`rvtol.allocation.problem.MonteCarloConstraint`) measure the yield
and Cpk of a sample (:mod:`rvtol.stats`) and hand them to :func:`judge`, so a
tolerance the optimiser calls feasible is one the sign-off passes:

* a requirement names a minimum yield and/or a minimum Cpk (a requirement
  with neither asks for the ±3σ yield, :attr:`rvtol.spec.Requirement.DEFAULT_MIN_YIELD`,
  and the report says so);
* ``basis = "lower_bound"`` (default) judges a lower confidence bound — the
  figure is *demonstrated* at the stated confidence; ``"estimate"`` judges
  the point estimate;
* the bound (:func:`bound_level`) is **one-sided** at the requirement's
  confidence by default: "yield ≥ 99.73 % at 95 % confidence" is a one-sided
  claim, and the 95 % one-sided lower bound (Clopper–Pearson / Wilson for the
  yield, Bissell for Cpk) is what makes it.  ``bound = "two-sided"`` judges
  the lower end of the two-sided interval instead — a one-sided bound at
  (1 + c)/2, i.e. 97.5 % for c = 95 %: rvtol's rule before the option
  existed (stricter than it said);
* ``cpk_method`` chooses the Cpk a minimum Cpk judges (:func:`cpk_figures`):
  ``"normal"`` (default) the normal-theory Cpk = min(USL − μ, μ − LSL)/3σ with
  Bissell's lower bound, or ``"percentile"`` the ISO 22514-2 Cpk from the
  0.135 %, 50 % and 99.865 % points (any distribution shape) with its
  bootstrap lower bound (at the same one-sided level);
* a requirement the estimate meets but the bound does not is *not
  demonstrated at this n*: :func:`judge` gives the sample size that would
  demonstrate it if the observed yield and Cpk held (:func:`rvtol.stats.n_for_yield`,
  :func:`rvtol.stats.n_for_cpk`);
* samples the model could not evaluate count as non-conforming in the
  yield, and while any sample fails a Cpk demonstrates nothing (it only
  describes the evaluated samples).

:func:`judge` also returns a *violation* ≥ 0, zero exactly when the
requirement passes, for optimisers (normalised shortfall of each figure).

A requirement on a **population statistic** (``statistic = "median"`` or ``"mean"``: a catalogue's typical
value, which a unit may miss by design) is judged by :func:`judge_statistic` on the statistic's confidence
interval (:func:`statistic_interval`, each end a one-sided bound at :func:`bound_level`): PASS when the
interval lies inside the band, FAIL when it lies wholly outside, UNDECIDED when it reaches both sides of a
limit (more samples decide; the sample size that would, if the estimate held, is given).  Both ends one-sided
at c make the PASS the two one-sided tests of an equivalence claim (Schuirmann, J. Pharmacokin. Biopharm. 15
(1987) 657: the (1 − 2α) interval inside the band; Berger's intersection–union principle keeps the level).

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

import numpy as np

from . import stats as st
from .spec import YIELD_INTERVALS, Requirement

#: violation charged for a Cpk that cannot be computed or demonstrated
CPK_UNAVAILABLE = 10.0


@dataclass
class Judgement:
    passed: bool
    reasons: list[str] = field(default_factory=list)
    violation: float = 0.0
    #: samples that would demonstrate a requirement the estimates meet but the bounds do not (else None)
    n_to_demonstrate: int | None = None
    #: a statistic's interval reaches both sides of a limit: neither PASS nor FAIL (:func:`judge_statistic`)
    undecided: bool = False


def bound_level(r: Requirement) -> float:
    """The one-sided confidence level of the bound that judges ``r``: c, or (1 + c)/2 for ``two-sided``."""
    return r.confidence if r.bound == "one-sided" else 0.5 * (1.0 + r.confidence)


def describe_bound(r: Requirement) -> str:
    """The bound in words, for reports: e.g. ``95 % one-sided lower bound``."""
    if r.statistic is not None:
        return f"the {r.statistic}'s interval, {describe_statistic_bound(r)}"
    if r.basis == "estimate":
        return "point estimate"
    if r.bound == "one-sided":
        return f"{_pct(r.confidence)} one-sided lower bound"
    return f"lower end of the two-sided {_pct(r.confidence)} interval ({_pct(bound_level(r))} one-sided)"


def yield_bound(r: Requirement, conforming: int, n: int) -> float:
    """The lower bound of the yield ``conforming/n`` that judges ``r`` (its interval method, :func:`bound_level`)."""
    return st.proportion_lower_bound(conforming, n, bound_level(r), YIELD_INTERVALS[r.interval])


def cpk_bound(r: Requirement, cpk: float | None, n: int) -> float | None:
    """Bissell's lower bound of Cpk (from ``n`` evaluated samples) that judges ``r``."""
    return st.cpk_lower_bound(cpk, n, bound_level(r))


def cpk_figures(r: Requirement, capability: dict, n: int,
                percentile_ci=(None, None)) -> tuple[float | None, float | None]:
    """``(Cpk, its lower bound)`` that judge ``r``'s minimum Cpk: normal theory (Bissell's bound from the ``n``
    evaluated samples, :func:`cpk_bound`) or percentile (ISO 22514-2; ``percentile_ci`` a bootstrap interval
    whose lower end is the one-sided bound at :func:`bound_level`), by ``r.cpk_method``."""
    if r.cpk_method == "percentile":
        return capability.get("cpk_percentile"), percentile_ci[0]
    c = capability.get("cpk")
    return c, cpk_bound(r, c, n)


def percentile_cpk_confidence(r: Requirement) -> float:
    """The two-sided bootstrap confidence whose lower end is the one-sided bound :func:`bound_level` of ``r``."""
    return 2.0 * bound_level(r) - 1.0


def cpk_name(r: Requirement) -> str:
    """How the report names the Cpk that judges ``r``."""
    return "percentile Cpk" if r.cpk_method == "percentile" else "Cpk"


def judge(r: Requirement, *, yield_: float | None = None, yield_lo: float | None = None,
          cpk: float | None = None, cpk_lo: float | None = None, n_failed: int = 0,
          n: int | None = None) -> Judgement:
    """Pass/fail, reasons and violation of requirement ``r`` from its measured figures.

    ``yield_lo`` and ``cpk_lo`` are the bounds of :func:`yield_bound` and :func:`cpk_bound`.  Given
    the sample size ``n``, a requirement that fails only on its bounds gets the sample size that
    would demonstrate it (``n_to_demonstrate`` and a reason).
    """
    lb = r.basis == "lower_bound"
    j = Judgement(True)
    what = "lower bound " if lb else ""
    if r.min_yield is not None:
        v = yield_lo if lb else yield_
        if not (v is not None and v >= r.min_yield):
            j.passed = False
            j.reasons.append(f"yield {what}{_f(v, '.5f')} < required {r.min_yield:g}")
            short = r.min_yield - v if v is not None and math.isfinite(v) else 1.0
            j.violation += max(0.0, short) / max(1.0 - r.min_yield, 1e-6)
    if r.min_cpk is not None:
        c = cpk_lo if lb else cpk
        if c is None or not c >= r.min_cpk:
            j.passed = False
            j.reasons.append(f"{cpk_name(r)} {what}{_f(c, '.3f')} < required {r.min_cpk:g}")
        if c is None or not math.isfinite(c) or n_failed:
            j.violation += CPK_UNAVAILABLE
        else:
            j.violation += max(0.0, r.min_cpk - c) / r.min_cpk
    if n_failed:
        j.reasons.append(f"{n_failed} sample(s) could not be evaluated and count as non-conforming")
        if r.min_cpk is not None:
            j.passed = False
            j.reasons.append("Cpk is not demonstrated while samples fail (it only describes the evaluated ones)")
    if not j.passed and lb and n is not None:
        _plan(r, j, yield_, cpk, n, n_failed)
    return j


def _plan(r: Requirement, j: Judgement, yield_: float | None, cpk: float | None, n: int, n_failed: int) -> None:
    """Say whether more samples would demonstrate ``r``, and how many (the observed figures held)."""
    level = bound_level(r)
    needs = []
    if r.min_yield is not None:
        needs.append(st.n_for_yield(yield_, r.min_yield, level, YIELD_INTERVALS[r.interval])
                     if yield_ is not None else None)
    if r.min_cpk is not None:
        needs.append(st.n_for_cpk(cpk, r.min_cpk, level) if not n_failed else None)
    if any(m is None for m in needs):
        j.reasons.append("the estimate itself misses the requirement: more samples will not demonstrate it")
        return
    need = max(needs)
    if need > n:
        j.n_to_demonstrate = need
        j.reasons.append(f"not demonstrated at n = {n}: the estimate meets the requirement, and about "
                         f"n = {need} samples would demonstrate it if the observed "
                         f"{'yield' if r.min_cpk is None else 'Cpk' if r.min_yield is None else 'yield and Cpk'}"
                         f" held")


def _pct(c: float) -> str:
    return f"{100 * c:.4g} %"


# --------------------------------------------------------------------------- population statistics
def statistic_interval(r: Requirement, y, n_failed: int = 0) -> tuple[float, float | None, float | None]:
    """``(estimate, lower, upper)`` of ``r.statistic`` from the evaluated values ``y``, each end a one-sided bound
    at :func:`bound_level` (None: no bound at this n).

    * median — distribution-free, from order statistics: the number B of the n values below the population
      median is Binomial(n, ½), so P(y_(l) ≤ m) = P(B ≥ l) ≥ level for l = F⁻¹(1 − level) and P(y_(u) ≥ m) =
      P(B ≤ u − 1) ≥ level for u = F⁻¹(level) + 1 (F⁻¹ the binomial quantile; e.g. Hahn & Meeker, Statistical
      Intervals, 1991, §5.2).  The ``n_failed`` samples the model could not evaluate may lie anywhere: they are
      placed below the evaluated ones for the lower bound and above them for the upper (the ranks count all n);
    * mean — Student's t: ȳ ∓ t(level, n − 1) s/√n; unbounded while samples fail (a failed sample's value
      could move the mean by any amount).
    """
    from scipy import stats as sps

    y = np.sort(np.asarray(y, dtype=float))
    k, level = int(n_failed), bound_level(r)
    if y.size == 0:
        return math.nan, None, None
    if r.statistic == "mean":
        m = float(y.mean())
        if k or y.size < 2:
            return m, None, None
        h = float(sps.t.ppf(level, y.size - 1)) * float(y.std(ddof=1)) / math.sqrt(y.size)
        return m, m - h, m + h
    n = y.size + k
    lo_rank = int(sps.binom.ppf(1.0 - level, n, 0.5))          # 1-based rank of the lower bound in all n
    hi_rank = int(sps.binom.ppf(level, n, 0.5)) + 1
    lo = float(y[lo_rank - k - 1]) if lo_rank - k >= 1 else None   # the k failed below the evaluated
    hi = float(y[hi_rank - 1]) if hi_rank <= y.size else None       # ... and above them
    return float(np.median(y)), lo, hi


def judge_statistic(r: Requirement, estimate: float, lo: float | None, hi: float | None, n: int,
                    n_failed: int = 0) -> Judgement:
    """PASS / UNDECIDED / FAIL of a statistic requirement from its interval ``[lo, hi]`` (module docstring).

    UNDECIDED gives ``n_to_demonstrate``: the samples whose interval would clear the nearer limit the interval
    now straddles if the estimate held (the half-width shrinks as 1/√n), None when the estimate sits on it."""
    name = f"{r.statistic} {_f(estimate, '.5g')}"
    band = f"[{'−∞' if r.lower is None else format(r.lower, 'g')}, {'+∞' if r.upper is None else format(r.upper, 'g')}]"
    ci = f"its interval [{_f(lo, '.5g')}, {_f(hi, '.5g')}] ({describe_statistic_bound(r)})"
    above = r.upper is not None and lo is not None and lo > r.upper
    below = r.lower is not None and hi is not None and hi < r.lower
    inside = ((r.lower is None or (lo is not None and lo >= r.lower))
              and (r.upper is None or (hi is not None and hi <= r.upper)))
    scale = (r.upper - r.lower) if r.lower is not None and r.upper is not None else abs(r.lower or r.upper or 1.0)
    if inside:
        return Judgement(True)
    if above or below:
        gap = (lo - r.upper) if above else (r.lower - hi)
        return Judgement(False, [f"{name}: {ci} lies wholly {'above' if above else 'below'} the band {band}"],
                         violation=1.0 + gap / scale)
    j = Judgement(False, [f"{name}: {ci} reaches both sides of a limit of the band {band}"], undecided=True)
    if n_failed and (lo is None or hi is None):
        j.reasons.append(f"{n_failed} sample(s) could not be evaluated: the {r.statistic} is not bounded while they "
                         "fail" + (" (the median bounds them on either side)" if r.statistic == "mean" else ""))
        j.violation = 1.0
        return j
    needs = []
    for lim in (r.lower, r.upper):
        if lim is None or lo is None or hi is None or not lo < lim < hi:
            continue
        d = abs(estimate - lim)
        half = (estimate - lo) if estimate > lim else (hi - estimate)
        needs.append(None if d == 0 else math.ceil(n * (half / d) ** 2))
    j.violation = max([0.0] + [(r.lower - lo) / scale if r.lower is not None and lo is not None else 0.0,
                               (hi - r.upper) / scale if r.upper is not None and hi is not None else 0.0])
    if needs and None not in needs:
        j.n_to_demonstrate = max(needs)
        held = (r.lower is None or estimate >= r.lower) and (r.upper is None or estimate <= r.upper)
        verdict = "PASS" if held else "FAIL"
        j.reasons.append(f"about n = {j.n_to_demonstrate} samples would decide it ({verdict}, if the estimate held)")
    else:
        j.reasons.append("the estimate sits on a limit: more samples will not decide it")
    return j


def describe_statistic_bound(r: Requirement) -> str:
    """A statistic's interval in words: each end a one-sided bound at c, or the two-sided interval."""
    if r.bound == "one-sided":
        return f"each end a {_pct(r.confidence)} one-sided bound"
    return f"two-sided {_pct(r.confidence)}"


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
    """One unit on one requirement: its verdict, the probability it had to show, the probability it
    shows (estimate) with the lower and upper bounds at the requirement's bound level, and why."""

    state: str
    required: float
    p: float
    p_lo: float
    p_hi: float
    reasons: list[str] = field(default_factory=list)


def judge_unit(r: Requirement, *, conforming: int, n: int, n_failed: int = 0,
               required: float | None = None) -> UnitJudgement:
    """The verdict of one unit on requirement ``r`` from ``conforming`` of its ``n`` predicted samples
    (module docstring): ``P = conforming/n`` with its one-sided lower and upper bounds at
    :func:`bound_level` (the requirement's interval method); ``required``: the probability a unit must
    show, instead of :func:`unit_probability_required` (e.g. 0.95, the coverage of ISO 14253-1's
    decision rule for one workpiece)."""
    from dataclasses import replace

    req = unit_probability_required(r) if required is None else float(required)
    ry = replace(r, min_yield=req, min_cpk=None)
    p = conforming / n
    p_lo = yield_bound(ry, conforming, n)
    p_hi = 1.0 - st.proportion_lower_bound(n - conforming, n, bound_level(ry), YIELD_INTERVALS[r.interval])
    ok = judge(ry, yield_=p, yield_lo=p_lo, n_failed=n_failed, n=n)
    if ok.passed:
        return UnitJudgement(CONFORMS, req, p, p_lo, p_hi, [])
    lb = r.basis == "lower_bound"
    if not lb or p_hi < req:
        why = f"P(conforms) {'upper bound ' if lb else ''}{_f(p_hi if lb else p, '.5f')} < required {req:g}"
        return UnitJudgement(DOES_NOT_CONFORM, req, p, p_lo, p_hi, [why] + ok.reasons[1:])
    return UnitJudgement(UNDECIDED, req, p, p_lo, p_hi, ok.reasons[:1] + [
        f"upper bound {_f(p_hi, '.5f')} ≥ {req:g}: more samples or a smaller measurement uncertainty decide"]
        + ok.reasons[1:])


def samples_for_unit(r: Requirement, required: float | None = None) -> int | None:
    """The fewest samples with which a unit whose every sample conforms is judged to conform on ``r``
    (:func:`rvtol.stats.n_for_yield` at P = 1: the success-run size, e.g. 1109 for 0.9973 at a 95 %
    one-sided bound, 59 for 0.95); 1 with ``basis = "estimate"``, None when no sample size can."""
    req = unit_probability_required(r) if required is None else float(required)
    if r.basis == "estimate":
        return 1
    return st.n_for_yield(1.0, req, bound_level(r), YIELD_INTERVALS[r.interval])


def _f(v, fmt: str) -> str:
    return "n/a" if v is None else format(v, fmt)


# --------------------------------------------------------------------------- the study's verdict
#: the verdict of a run: every requirement demonstrated / one fails / none was checked / none by design
PASS, FAIL, NO_REQUIREMENTS, EXPLORATORY = "PASS", "FAIL", "NO REQUIREMENTS", "EXPLORATORY"
VERDICTS = (PASS, FAIL, NO_REQUIREMENTS, EXPLORATORY)


def study_verdict(passed: list[bool], exploratory: bool = False) -> str:
    """The run's verdict from its requirements' results: a run that checks nothing never says PASS.

    With no requirement the verdict is ``NO REQUIREMENTS`` (a CI gate must not read "nothing
    checked" as "proven"), or ``EXPLORATORY`` when the study declares itself so
    (``[study] exploratory = true``: a study that only describes, e.g. a document reproduction).
    """
    if not passed:
        return EXPLORATORY if exploratory else NO_REQUIREMENTS
    return PASS if all(passed) else FAIL
