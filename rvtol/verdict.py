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
  describes the evaluated samples);
* a **constant** output (σ = 0 over every evaluated sample: no factor of the spec moves it) has no Cpk —
  (USL − μ)/3σ is 0/0 or ∞ — so a minimum Cpk is not demonstrated, and the reason says where the
  constant lies against the limits (a ``min_yield`` requirement states that; a Cpk cannot);
* a normal-theory Cpk describes a tail only when the output is normal: its ppm is Φ(−3·Cpk).  When the
  output is **demonstrably not normal** (Anderson–Darling test of normality rejected at 1 %,
  :class:`Shape`) and the two Cpk values — normal theory and ISO 22514-2 percentile — disagree on
  the verdict, the requirement passes only if both pass: a skewed output (skewness 1.5) whose
  normal-theory Cpk 1.4 passes while 3 400 ppm lie beyond the limit and its percentile Cpk is
  0.86 is *not* demonstrated (the percentile Cpk is the one ISO 22514-2 gives for a non-normal
  process; the normal one is kept as a second condition because the requirement asked for it).
  A disagreement is always stated in the requirement's notes; with a normal-looking output it
  changes nothing (the percentile bound is merely the less efficient one);
* a yield or Cpk measured on factors **fitted to measured parts** carries the fit's own uncertainty
  (:mod:`rvtol.fit_uncertainty`): the bound judged combines the Monte Carlo's bound with the
  spread of the figure under the laws the measured data allow, and a requirement that the fit's
  uncertainty alone keeps from being demonstrated gets the number of measured parts that would (more
  Monte Carlo samples cannot);
* a requirement not demonstrated whose estimate meets it is *undecided* (:attr:`Judgement.undecided`:
  more samples or more measured parts would decide); one whose estimate misses is not.

:func:`judge` also returns a *violation* ≥ 0, zero exactly when the
requirement passes, for optimisers (normalised shortfall of each figure).

A requirement on a **population statistic** (``statistic = "median"`` or ``"mean"``: a catalogue's typical
value, which a unit may miss by design) is judged by :func:`judge_statistic` on the statistic's confidence
interval (:func:`statistic_interval`, each end a one-sided bound at :func:`bound_level`): PASS when the
interval lies inside the band, FAIL when it lies wholly outside, UNDECIDED when it reaches both sides of a
limit (more samples decide; the sample size that would, if the estimate held, is given).  Both ends one-sided
at c make the PASS the two one-sided tests of an equivalence claim (Schuirmann, J. Pharmacokin. Biopharm. 15
(1987) 657: the (1 − 2α) interval inside the band; Berger's intersection–union principle keeps the level).

A **sequential run** (``rvtol run --until-decided``) judges yields, medians and means after every batch by the anytime-valid
rule of :mod:`rvtol.sequential` instead (the fixed-n bounds here hold for one look); its verdicts replace these
(:meth:`rvtol.mc.MonteCarloResult._sequential_verdict`).

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
from .stats import Shape
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
    #: what the verdict rests on, whatever it is (a fitted law's uncertainty, an extrapolation, a disagreement)
    notes: list[str] = field(default_factory=list)
    #: per measured factor, the parts that would demonstrate a requirement its fit's uncertainty keeps undecided
    parts_to_demonstrate: dict[str, int] | None = None
    #: not demonstrated, but the estimate meets it: more samples (or measured parts) would decide; for a statistic's
    #: band, its interval reaches both sides of a limit (:func:`judge_statistic`)
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


def other_cpk(r: Requirement, good, capability: dict, judged: tuple | None = None):
    """``(shape, (estimate, bound))`` for :func:`judge`'s non-normal rule: the :class:`rvtol.stats.Shape` of the
    evaluated output ``good`` and the Cpk ``r`` is *not* judged on — the percentile one (its bootstrap bound at
    :func:`bound_level`) for normal theory, Bissell's for a percentile requirement; ``(None, None)`` below 100
    evaluated samples (no percentile bound).  Given the ``judged`` ``(Cpk, bound)`` (an optimiser's many
    candidates, which need the verdict, not its notes), only what can refute a pass is computed: the shape when
    the judged normal-theory Cpk passes, the percentile bound when the output is demonstrably not normal."""
    import numpy as np

    if len(good) < 100:
        return None, None
    i = 1 if r.basis == "lower_bound" else 0
    shape = None
    if judged is not None:
        if r.cpk_method != "normal" or judged[i] is None or not judged[i] >= r.min_cpk:
            return None, None
        shape = st.normality(good)
        if shape is None or not shape.non_normal:
            return None, None
    if r.cpk_method == "normal":
        lo = st.percentile_cpk_ci(np.sort(good), r.lower, r.upper, percentile_cpk_confidence(r))[0]
        other = (capability.get("cpk_percentile"), lo)
    else:
        other = (capability.get("cpk"), st.cpk_lower_bound(capability.get("cpk"), len(good), bound_level(r)))
    return shape or st.normality(good), other


def percentile_cpk_confidence(r: Requirement) -> float:
    """The two-sided bootstrap confidence whose lower end is the one-sided bound :func:`bound_level` of ``r``."""
    return 2.0 * bound_level(r) - 1.0


def cpk_name(r: Requirement) -> str:
    """How the report names the Cpk that judges ``r``."""
    return "percentile Cpk" if r.cpk_method == "percentile" else "Cpk"


def judge(r: Requirement, *, yield_: float | None = None, yield_lo: float | None = None,
          cpk: float | None = None, cpk_lo: float | None = None, n_failed: int = 0,
          n: int | None = None, constant: float | None = None, other_cpk: tuple | None = None,
          shape: Shape | None = None, fit=None) -> Judgement:
    """Pass/fail, reasons and violation of requirement ``r`` from its measured figures.

    ``yield_lo`` and ``cpk_lo`` are the bounds of :func:`yield_bound` and :func:`cpk_bound` (with a ``fit``,
    combined with the fit's uncertainty: :func:`rvtol.stats.combined_lower_bound`).  Given the sample size
    ``n``, a requirement that fails only on its bounds gets the sample size (or the measured parts) that would
    demonstrate it (``n_to_demonstrate``, ``parts_to_demonstrate`` and a reason).  ``constant``: the output's
    value when every evaluated sample has it (σ = 0); ``other_cpk``: ``(estimate, bound)`` of the Cpk the
    requirement is *not* judged on (percentile for ``cpk_method = "normal"``, normal theory for
    ``"percentile"``) and ``shape`` the output's :class:`Shape` — together the non-normal rule of the module
    docstring; ``fit``: the measured factors' fit uncertainty of this requirement
    (:class:`rvtol.fit_uncertainty.FitEffect`: ``yield_dev``, ``cpk_dev``, ``parts``, ``notes``).
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
    plan_cpk = cpk
    if r.min_cpk is not None:
        c = cpk_lo if lb else cpk
        if constant is not None:
            j.passed = False
            j.reasons.append(_constant(r, constant))
        elif c is None or not c >= r.min_cpk:
            j.passed = False
            j.reasons.append(f"{cpk_name(r)} {what}{_f(c, '.3f')} < required {r.min_cpk:g}")
        if c is None or not math.isfinite(c) or n_failed:
            j.violation += CPK_UNAVAILABLE
        else:
            j.violation += max(0.0, r.min_cpk - c) / r.min_cpk
        if other_cpk is not None and shape is not None and constant is None and _non_normal_rule(
                r, j, (cpk, cpk_lo), other_cpk, shape):
            plan_cpk = min(x for x in (cpk, other_cpk[0]) if x is not None) if other_cpk[0] is not None else None
    if n_failed:
        j.reasons.append(f"{n_failed} sample(s) could not be evaluated and count as non-conforming")
        if r.min_cpk is not None:
            j.passed = False
            j.reasons.append("Cpk is not demonstrated while samples fail (it only describes the evaluated ones)")
    if fit is not None:
        j.notes.extend(fit.notes)
        for name, why in fit.unavailable:
            j.passed = False
            j.reasons.append(f"the uncertainty of {name}'s fitted law could not be estimated ({why}): nothing that "
                             "depends on it is demonstrated")
    unplannable = (constant is not None and r.min_cpk is not None) or (fit is not None and fit.unavailable)
    if not j.passed and lb and n is not None and not unplannable:
        _plan(r, j, yield_, plan_cpk, n, n_failed, fit)
    return j


def _constant(r: Requirement, value: float) -> str:
    """Why a minimum Cpk is not demonstrated on an output that does not vary."""
    inside = (r.lower is None or value >= r.lower) and (r.upper is None or value <= r.upper)
    return (f"Cpk is undefined for a constant output: {r.output} = {value:.6g} in every evaluated sample (σ = 0: no "
            f"factor of the spec moves it), {'inside' if inside else 'outside'} the limits — a min_yield requirement "
            "can state that, a Cpk cannot")


def _non_normal_rule(r: Requirement, j: Judgement, judged: tuple, other: tuple, shape: Shape) -> bool:
    """The normal-theory and percentile Cpk against ``r.min_cpk`` (module docstring): a disagreement is noted, and on
    a demonstrably non-normal output a normal-theory pass the percentile Cpk refutes is not a pass.  True when the
    rule failed the requirement."""
    i = 1 if r.basis == "lower_bound" else 0
    what = "lower bound " if i else ""
    if judged[i] is None or other[i] is None:
        return False
    mine, theirs = judged[i] >= r.min_cpk, other[i] >= r.min_cpk
    if mine == theirs:
        return False
    normal = r.cpk_method == "normal"
    other_name = "percentile Cpk (ISO 22514-2)" if normal else "normal-theory Cpk"
    judged_name = "normal-theory Cpk" if normal else "percentile Cpk"
    if normal and mine and shape.non_normal:
        j.passed = False
        j.reasons.append(f"the output is not normal ({shape.describe()}): its normal-theory Cpk {what}"
                         f"{judged[i]:.3f} passes but its percentile Cpk (ISO 22514-2) {what}{other[i]:.3f} < required "
                         f"{r.min_cpk:g} — normal theory misstates the tail of this shape; not demonstrated unless "
                         'both pass (cpk_method = "percentile" judges on the percentile Cpk alone)')
        j.violation += max(0.0, r.min_cpk - other[i]) / r.min_cpk
        return True
    how = (f"the output is not normal ({shape.describe()})" if shape.non_normal else
           f"the output shows no departure from normality ({shape.describe()})")
    then = ('cpk_method = "percentile" judges a non-normal output by its own tails' if normal and shape.non_normal
            else "normal theory judges it (the percentile bound is the less efficient one)" if normal
            else "the percentile Cpk judges it")
    j.notes.append(f"the {other_name} {what}{other[i]:.3f} would {'pass' if theirs else 'fail'} where the "
                   f"{judged_name} {'passes' if mine else 'fails'}: {how}; {then}")
    return False


def _plan(r: Requirement, j: Judgement, yield_: float | None, cpk: float | None, n: int, n_failed: int,
          fit=None) -> None:
    """Say whether more samples — or, with factors fitted to measured parts, more measured parts — would demonstrate
    ``r``, and how many (the observed figures held).

    A figure's bound is the estimate less √(d_MC² + d_fit²) (:func:`rvtol.stats.combined_lower_bound`), d_MC the
    Monte Carlo's deviation (shrinking as 1/√n) and d_fit the fit's (as 1/√m, m measured parts: the MLE's
    standard errors).  With the margin M = estimate − required: d_fit < M — samples alone decide, the n whose d_MC
    reaches √(M² − d_fit²); d_fit ≥ M — no n does: the parts must grow by d_fit²/(M² − d_MC²) if the present
    d_MC < M, else both, each deviation brought to M/√2 (parts × 2 d_fit²/M²).
    """
    level = bound_level(r)
    needs, grow = [], []
    cases = []
    if r.min_yield is not None:
        mc_dev = None if yield_ is None else yield_ - yield_bound(r, yield_ * n, n)
        cases.append((yield_, r.min_yield, mc_dev, fit.yield_dev if fit is not None else 0.0,
                      lambda est, req: st.n_for_yield(est, req, level, YIELD_INTERVALS[r.interval])))
    if r.min_cpk is not None:
        b = cpk_bound(r, cpk, n) if n > 1 else -math.inf
        mc_dev = None if cpk is None or b is None or n_failed else cpk - b
        cases.append((None if n_failed else cpk, r.min_cpk, mc_dev, fit.cpk_dev if fit is not None else 0.0,
                      lambda est, req: st.n_for_cpk(est, req, level)))
    for est, req, mc_dev, fit_dev, n_for in cases:
        if est is not None and not math.isfinite(est):
            j.reasons.append(f"the estimate is {est}: no sample size can be planned from it")
            return
        if est is None or not est > req:
            j.reasons.append("the estimate itself misses the requirement: more samples will not demonstrate it")
            return
        margin = est - req
        if fit_dev < margin:
            needs.append(n_for(est, est - math.sqrt(margin * margin - fit_dev * fit_dev)))
        elif mc_dev is not None and mc_dev < margin:
            grow.append(fit_dev * fit_dev / (margin * margin - mc_dev * mc_dev))
        else:
            needs.append(n_for(est, est - margin / math.sqrt(2.0)))
            grow.append(2.0 * fit_dev * fit_dev / (margin * margin))
    if any(m is None for m in needs):
        j.reasons.append("the estimate itself misses the requirement: more samples will not demonstrate it")
        return
    j.undecided = True
    need = max(needs, default=0)
    if need > n:
        j.n_to_demonstrate = need
        j.reasons.append(f"not demonstrated at n = {n}: the estimate meets the requirement, and about "
                         f"n = {need} samples would demonstrate it if the observed "
                         f"{'yield' if r.min_cpk is None else 'Cpk' if r.min_yield is None else 'yield and Cpk'}"
                         f" held")
    elif not grow:     # e.g. a percentile Cpk whose bootstrap bound misses where Bissell's rule says n suffices
        j.reasons.append(f"not demonstrated at n = {n}: the estimates meet the requirement, their bounds do not — more "
                         "samples would decide")
    if grow:
        j.parts_to_demonstrate = {f: math.ceil(m * max(grow)) for f, m in fit.parts.items()}
        parts = ", ".join(f"{m:,} measured parts of {f} (now {fit.parts[f]:,})"
                          for f, m in j.parts_to_demonstrate.items())
        j.reasons.append("the fitted law of the measured factors is too uncertain to demonstrate it: more Monte Carlo "
                         f"samples cannot; about {parts} would, if the fitted law held")


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
    now straddles if the estimate held (the half-width shrinks as 1/√n), None when the estimate sits on it.

    ``violation`` (normalised as :func:`judge`'s, by the band's width, or by |limit| for a one-sided band): 0 inside,
    1 + the gap between the interval and the band when it lies wholly outside, the interval's larger reach beyond a
    limit when it straddles one (1 while it is unbounded: failed samples, or too few for a bound)."""
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
    if lo is None or hi is None:
        j.reasons.append(f"{n_failed} sample(s) could not be evaluated: the {r.statistic} is not bounded while they "
                         "fail" + (" (the median bounds them on either side)" if r.statistic == "mean" else "")
                         if n_failed else f"the {r.statistic} is not bounded at n = {n} (too few samples for a bound "
                         f"at {_pct(bound_level(r))}): more samples would bound it")
        j.violation = 1.0
        return j
    needs = []
    for lim, beyond in ((r.lower, lo), (r.upper, hi)):
        # a limit in question: the interval reaches beyond it and holds it (the band is closed: an end on the limit
        # from outside still holds a value of the band)
        if lim is None or not lo <= lim <= hi or beyond == lim:       # lo and hi are bounds here (returned above)
            continue
        d = abs(estimate - lim)
        half = (estimate - lo) if estimate > lim else (hi - estimate)
        # the half-width shrinks as 1/√n: n (half/d)² samples, and at least one more than now (undecided at n)
        needs.append(None if d == 0 else max(math.ceil(n * (half / d) ** 2), n + 1))
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


# --------------------------------------------------------------------------- a requirement's state
#: the state of a requirement more samples would decide (:func:`requirement_state`)
STATE_UNDECIDED = "UNDECIDED"
#: a requirement's state — the one word the CLI, summary.json, JUnit, Markdown, the report and the one-page summary
#: give it — and what it means; the run's verdict is PASS only when every requirement's state is PASS
REQUIREMENT_STATES = {PASS: "demonstrated at its confidence",
                      STATE_UNDECIDED: "not demonstrated: the estimate meets it, more samples (or more measured parts) "
                                       "would decide",
                      FAIL: "not demonstrated: the estimate itself misses it"}


def requirement_state(passed: bool, more_would_decide: bool = False) -> str:
    """PASS (demonstrated), UNDECIDED (not demonstrated, but the estimate meets it and more samples or more measured
    parts would decide: :attr:`Judgement.undecided`) or FAIL — :data:`REQUIREMENT_STATES`."""
    if passed:
        return PASS
    return STATE_UNDECIDED if more_would_decide else FAIL


def state_of(record: dict) -> str:
    """The state of a requirement as summary.json records it: its ``state`` (from ``passed`` and ``undecided``, or
    ``n_to_demonstrate``, in a summary written before it had one)."""
    more = record.get("undecided")
    return record.get("state") or requirement_state(bool(record.get("passed")),
                                                    bool(record.get("n_to_demonstrate") if more is None else more))
