"""The sign-off: per requirement its verdict, the drawing tolerances that drive it, what to change — the digest
and the report's first page that lays it out.

The digest (:func:`digest`) is computed from the Monte Carlo alone (no further model run), for the first page of
the report and ``summary.json``'s ``requirements`` list:

* **drivers** — the first-order index S1 of every factor on the requirement's output, estimated
  from the Monte Carlo samples themselves (:func:`rvtol.sensitivity.given_data.given_data`, the
  correlation ratio with Kelley's bias correction).  Factors that stand for one drawing tolerance
  (the x1, y1, x2, y2 end points of one position zone, the copies of a per-pin family) are summed
  into that tolerance (:func:`rvtol.callouts.callout_of`): the share of the output's variance the
  tolerance explains on its own (first order; interactions are in a study's Sobol section).  The
  estimates are summed unclipped (each is unbiased; clipped at 0 the 40 copies of a family would
  add 40 positive halves of their noise) and only over the factors the output can depend on where
  the model knows its structure (:func:`rvtol.model.dependencies`);
* **what to change** — for a requirement that is not demonstrated: the spread the output must
  reach and the tightening of its largest driver that would give it, to first order
  (``σ² → σ² (1 − S1 (1 − f²))`` when that tolerance is scaled by ``f``); labelled an estimate —
  the allocation analysis gives cost-optimal tolerances that are checked by Monte Carlo;
* **a traffic light** — the requirement's state (:func:`rvtol.verdict.requirement_state`, the word every output
  gives it): green PASS, demonstrated; amber UNDECIDED, not demonstrated, but the estimate meets the
  requirement (more samples, or more measured parts of a fitted factor, would decide:
  :attr:`rvtol.verdict.Judgement.undecided`); red FAIL, the estimate itself misses it (or, for a constant output,
  a Cpk cannot be defined);
* **fixes by kind**, cheapest first (:data:`FIX_KINDS`): more samples (amber), re-centre (a two-sided
  band the present spread fits when the mean sits in its middle: a nominal moves, no tolerance
  changes), tighten (the first-order scaling above), redesign (the mean on or beyond a limit: no
  tolerance can help).  Analyses add checked fixes of their own (the allocation's verified
  tolerances and its design levers checked by Monte Carlo): :attr:`rvtol.blocks.Section.fixes`.

The sentences the digest writes (recorded in summary.json) are templates it fills with its numbers (``str.format``
fields named after them).  :func:`signoff_section` is the first page a quality manager reads: per requirement a
traffic light with its yield and Cpk, the tolerances that matter, the cheapest fix by kind, and — when there is
one — the comparison with the accepted baseline; it lays out what the run computed (the digests, the analyses'
fixes, the comparison), and the same section opens report.html, report.pdf and the one-page summary.pdf.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy import stats

from .blocks import Links, Section
from .callouts import short_label
from .mc import MonteCarloResult
from .model import Model
from .precision import Scaled, output_scale, shown
from .sensitivity.drivers import Driver, first_order_drivers
from .spec import ToleranceSpec
from .units import label
from .verdict import FAIL, PASS, REQUIREMENT_STATES, STATE_UNDECIDED


#: the kinds of fix, cheapest first: what a quality engineer tries in this order
FIX_KINDS = ("more samples", "re-centre", "tighten", "redesign")
#: the colour of a requirement's state (:data:`rvtol.verdict.REQUIREMENT_STATES`) on the first page
LIGHTS = {PASS: "green", STATE_UNDECIDED: "amber", FAIL: "red"}


# --------------------------------------------------------------------------- the digest's sentences
# what_to_change: one sentence per case of the first-order tightening (rvtol.signoff.tightening)
NOTHING_EVALUATED = "No sample could be evaluated: nothing to estimate from."
MEAN_BEYOND = ("The mean {mean:.4g} {unit} itself lies at or beyond the limit: tightening tolerances cannot fix it — "
               "the nominal design (or a mean shift of its largest drivers) must change.")
CONSTANT = ("The output is constant ({mean:.6g} {unit} in every evaluated sample, σ = 0): no tolerance of the spec "
            "moves it, so no tightening changes it.")
CONSTANT_CPK = " Its Cpk is undefined (σ = 0): state the requirement as a min_yield."
NO_DRIVER = "The spread must fall from σ = {sigma:.3g} to {target:.3g} {unit}; no driver could be estimated."
ONLY_CONFIDENCE = ("The point estimate already meets the requirement: the confidence bound does not — more samples "
                   "(a larger n) would demonstrate it, or a small tightening of the drivers below.")
SEVERAL = ("The spread must fall from σ = {sigma:.3g} to {target:.3g} {unit} ({need:.0f} % of the variance), more than "
           "the largest drivers explain to first order ({names}: {explained:.0f} %): tighten several tolerances (an "
           "allocation analysis finds which, at the least cost).")
SCALE = ("The spread must fall from σ = {sigma:.3g} to {target:.3g} {unit}: scaling {names} to {f:.0f} % of {their} "
         "present tolerance would do it to first order (S1 = {explained:.2f}). An estimate: an allocation analysis "
         "gives cost-optimal tolerances checked by Monte Carlo.")

# first_order_fixes: (action, reason) of each kind of fix
MORE_SAMPLES = ("run n = {n:,} samples",
                "the estimate already meets the requirement; this n would demonstrate it if the figures hold")
MORE_PARTS = ("measure about {parts}",
              "the fitted laws of the measured factors are too uncertain to demonstrate it — more Monte Carlo samples "
              "cannot; these would, if the fitted laws held (the fit's deviation shrinks as 1/√parts)")
FAILURES = ("find what makes {share:.3g} % of the samples fail to evaluate — {why} — and tighten or re-centre the "
            "factors that drive it (each sample's status is in samples.parquet)",
            "they count as failing the requirement, which allows {allowed:.3g} %; the evaluated units are a selection "
            "(those that could be evaluated), so no fix is read from their mean and σ alone — a nominal inside the "
            "limits is not ruled out")
FAILURES_ALONE = ("{share:.3g} % of the samples could not be evaluated — {why} — and count as failing: more than the "
                  "{allowed:.3g} % the requirement allows; the evaluated units meet it ({outside:.3g} % of all samples "
                  "outside the limits).")
FAILURES_AND_SPREAD = ("{share:.3g} % of the samples could not be evaluated — {why} — and count as failing, beside "
                       "{outside:.3g} % of all samples evaluated outside the limits (the requirement allows "
                       "{allowed:.3g} %): together they fail it.")
REDESIGN = ("move the mean ({mean:.4g} {unit}) {side} the limit {limit:g} {unit}: a nominal of the design",
            "tightening cannot help: as tolerances shrink, every unit approaches the nominal one")
RECENTRE = ("move the mean from {mean:.4g} to {mid:.4g} {unit} (shift {shift:+.3g} {unit}: a nominal, no tolerance "
            "changes)",
            "the present spread σ = {sigma:.3g} {unit} fits the band when centred (needs σ ≤ {centred:.3g}); to first "
            "order, at the point estimate")
TIGHTEN = ("scale {names} to {f:.0f} % of {their} present tolerance",
           "σ from {sigma:.3g} to {target:.3g} {unit}: to first order, at the point estimate (S1 = {explained:.2f} "
           "from the Monte Carlo samples)")
TIGHTEN_SEVERAL = ("tighten several tolerances",
                   "σ from {sigma:.3g} to {target:.3g} {unit}: more than the largest drivers explain to first order "
                   "({explained:.0f} %)")


# a population statistic's band (rvtol.verdict.judge_statistic): tolerances do not move a central value
STATISTIC_OUTSIDE = ("The {statistic} {value:.4g} {unit} lies outside the band [{lower}, {upper}] {unit}: a central "
                     "value is the nominal design's (and the model's), not the tolerances' — tightening cannot move it.")
STATISTIC_UNDECIDED = ("The {statistic}'s interval reaches both sides of a limit of the band: more samples decide it; "
                       "tolerances do not move a central value.")
MORE_SAMPLES_STATISTIC = ("run n = {n:,} samples",
                          "the {statistic}'s interval straddles a limit; this n would decide it if the estimate held")
REDESIGN_STATISTIC = ("move the {statistic} ({value:.4g} {unit}) into the band [{lower}, {upper}] {unit}: the nominal "
                      "design, or the model, must change",
                      "a central value: tightening tolerances narrows the units about it, it does not move it")


def their(n: int) -> str:
    """The possessive for ``n`` tolerances."""
    return "its" if n == 1 else "their"


# --------------------------------------------------------------------------- the digest
@dataclass
class Fix:
    """One way to make a requirement pass: its kind (:data:`FIX_KINDS`), what to do, what it gives, where the report
    shows it (a section key; '' for the digest's own first-order estimate) and whether a Monte Carlo run checked it."""

    requirement: str
    kind: str
    action: str
    effect: str
    source: str = ""
    checked: bool = False

    def to_dict(self) -> dict:
        return {"kind": self.kind, "action": self.action, "effect": self.effect, "source": self.source,
                "checked": self.checked}


@dataclass
class RequirementDigest:
    label: str
    output: str
    model: str                       # the stage of a composed study ('' for a one-model study)
    unit: str
    passed: bool
    mean: float | None
    p99865: float | None
    p00135: float | None
    yield_lo: float | None
    cpk_lo: float | None
    reasons: list[str]
    drivers: list[Driver] = field(default_factory=list)
    change: str = ""
    overlaps: list[str] = field(default_factory=list)   # pairs of drivers correlated in the spec
    state: str = PASS                                    # :func:`rvtol.verdict.requirement_state`
    yield_: float | None = None                          # the yield estimate
    cpk: float | None = None                             # the Cpk estimate (the one the requirement is judged on)
    fixes: list[Fix] = field(default_factory=list)       # the digest's own, first-order (analyses add theirs)
    notes: list[str] = field(default_factory=list)       # what the verdict rests on (rvtol.verdict.Judgement.notes)
    #: a statistic requirement's (estimate, lower bound, upper bound), else None
    statistic: tuple[float, float | None, float | None] | None = None
    reading: str = ""
    source: str = ""
    status: str = ""

    @property
    def light(self) -> str:
        """green, amber or red: the colour of its state (:data:`LIGHTS`)."""
        return LIGHTS[self.state]

    def to_dict(self) -> dict:
        return {"requirement": self.label, "output": self.output, "model": self.model, "unit": self.unit,
                "reading": self.reading, "source": self.source, "status": self.status,
                **({"statistic": {"estimate": self.statistic[0], "interval": list(self.statistic[1:])}}
                   if self.statistic is not None else {}),
                "verdict": self.state, "mean": self.mean, "P99.865": self.p99865,
                "P0.135": self.p00135, "yield_lower_bound": self.yield_lo, "cpk_lower_bound": self.cpk_lo,
                "reasons": self.reasons,
                "drivers": [{"tolerance": d.tolerance, "S1": d.s1, "factors": d.factors} for d in self.drivers],
                "what_to_change": self.change, "correlated_drivers": self.overlaps, "light": self.light,
                "yield": self.yield_, "cpk": self.cpk, "fixes": [f.to_dict() for f in self.fixes],
                "notes": self.notes}


def digest(mc: MonteCarloResult, model: Model, spec: ToleranceSpec, seed: int | None = None,
           top: int = 3) -> list[RequirementDigest]:
    """One :class:`RequirementDigest` per requirement of the Monte Carlo result."""
    verdicts = mc.verdicts()
    if not verdicts:
        return []
    outputs = list(dict.fromkeys(v.requirement.output for v in verdicts))
    s1 = first_order_drivers(mc, model, spec, outputs, seed)
    stats_df = mc.statistics()
    out = []
    for v in verdicts:
        r = v.requirement
        row = stats_df.loc[r.output]
        stage = r.output.split(".", 1)[0] if "." in r.output and hasattr(model, "stages") else ""
        d = RequirementDigest(r.label, r.output, stage, r.unit or mc.unit_of(r.output), v.passed,
                              _f(row.get("mean")), _f(row.get("P99.865")), _f(row.get("P0.135")),
                              _f(v.yield_bound), _f(v.cpk_bound), list(v.reasons), notes=list(v.notes),
                              reading=r.reading, source=r.source, status=r.status)
        d.drivers = s1.get(r.output, [])[:top]
        d.overlaps = correlated_drivers(d.drivers, spec)
        d.yield_, d.cpk = _f(v.yield_.estimate), _f(v.judged_cpk[0])
        d.state = v.state
        if v.statistic is not None:
            d.statistic = v.statistic
            d.yield_ = d.yield_lo = None          # the units' share in the band is not what is judged
        if not v.passed:
            if v.statistic is not None:
                d.change, d.fixes = statistic_fixes(r, v, d)
            else:
                d.change = what_to_change(r, row, d.drivers, mc)
                failures = _failures_matter(r, row, mc)
                d.fixes = first_order_fixes(r, row, d, v.n_to_demonstrate, _evaluated(mc, r.output),
                                            v.parts_to_demonstrate) if failures is None else [
                    Fix(r.label, "model failures", *(t.format(**failures) for t in FAILURES))]
        out.append(d)
    return out


def statistic_fixes(r, v, d: RequirementDigest) -> tuple[str, list[Fix]]:
    """What to change, and the fix, of a statistic requirement not passed: more samples where its interval straddles
    a limit (and a sample size would decide it), else the nominal design (a central value)."""
    est = v.statistic[0]
    numbers = dict(statistic=r.statistic, value=est, unit=r.unit or "",
                   lower="−∞" if r.lower is None else f"{r.lower:g}", upper="+∞" if r.upper is None else f"{r.upper:g}")
    if v.undecided:
        fixes = ([Fix(r.label, "more samples", *(t.format(n=v.n_to_demonstrate, **numbers)
                                                 for t in MORE_SAMPLES_STATISTIC))] if v.n_to_demonstrate else [])
        return STATISTIC_UNDECIDED.format(**numbers), fixes
    return (STATISTIC_OUTSIDE.format(**numbers),
            [Fix(r.label, "redesign", *(t.format(**numbers) for t in REDESIGN_STATISTIC))])


def correlated_drivers(drivers: list[Driver], spec: ToleranceSpec, threshold: float = 0.1) -> list[str]:
    """The pairs of drivers whose factors the spec correlates (|ρ| > ``threshold``, normal scores): their
    first-order shares overlap — each includes what its partner explains through the correlation — so they
    are not to be added, and a driver's share overstates what tightening it alone would gain."""
    from .sensitivity._given import correlated_pairs

    owner = {n: d.tolerance for d in drivers for n in d.factors}
    rho: dict[tuple[str, str], float] = {}
    for a, b, r, _ in correlated_pairs(spec.names, correlation=spec.correlation):
        ta, tb = owner.get(a), owner.get(b)
        if ta and tb and ta != tb and abs(r) > threshold:
            key = tuple(sorted((ta, tb)))
            rho[key] = max(rho.get(key, 0.0), abs(r))
    return [f"{a} and {b} (|ρ| = {r:.2g})" for (a, b), r in rho.items()]


def required_sigma(r, mean: float, sigma: float, y=None) -> float | None:
    """The standard deviation the output may have for ``r`` to pass at its point estimate.

    A minimum Cpk is normal theory (3·Cpk standard deviations to the nearer limit).  A minimum yield is read from
    the evaluated samples ``y`` when given — the deviations from the mean scaled by the largest s in (0, 1] whose
    scaled sample still meets the yield (:func:`spread_scale`): s·σ — so a skewed output (a magnitude, a clipped
    clearance) is sized by its own tail; without ``y``, normal theory (z of the yield, two-sided halves it)."""
    dists = [d for d in ((r.upper - mean) if r.upper is not None else None,
                         (mean - r.lower) if r.lower is not None else None) if d is not None]
    if not dists or min(dists) <= 0:
        return None
    targets = []
    if r.min_cpk is not None:
        targets.append(min(dists) / (3.0 * r.min_cpk))
    if r.min_yield is not None:
        if y is not None and len(y):
            s = spread_scale(r, mean, y)
            targets.append(s * sigma if s is not None else 0.0)
        else:
            two = r.lower is not None and r.upper is not None
            targets.append(min(dists) / float(stats.norm.ppf(1.0 - (1.0 - r.min_yield) / (2.0 if two else 1.0))))
    return min(targets) if targets else None


def spread_scale(r, mean: float, y, tol: float = 1e-4) -> float | None:
    """The largest s in (0, 1] such that ``mean + s (y − mean)`` meets ``r.min_yield`` within its limits (None: no s
    does). The fraction inside grows as s shrinks (the mean lies inside the limits), so bisection finds it."""
    import numpy as np

    y = np.asarray(y, dtype=float)

    def inside(s):
        z = mean + s * (y - mean)
        ok = np.ones(len(z), dtype=bool)
        if r.lower is not None:
            ok &= z >= r.lower
        if r.upper is not None:
            ok &= z <= r.upper
        return ok.mean() >= r.min_yield

    if inside(1.0):
        return 1.0
    lo, hi = 0.0, 1.0
    if not inside(tol):
        return None
    lo = tol
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if inside(mid) else (lo, mid)
    return lo


@dataclass
class Tightening:
    """What the spread of an output must become, and the drivers whose joint scaling by ``f`` gives it (first order)."""

    sigma: float
    target: float | None               # the σ the output may have (None: the mean lies at or beyond a limit)
    need: float = 0.0                  # the share of the variance that must go
    used: list[Driver] = field(default_factory=list)
    explained: float = 0.0             # Σ S1 of the drivers used
    f: float | None = None             # their common scale (None: they do not explain enough)


def tightening(r, mean: float, sigma: float, drivers: list[Driver], y=None) -> Tightening:
    """``σ² → σ² (1 − Σ S1 (1 − f²))`` solved for the scale ``f`` of the fewest largest drivers that can reach the
    target σ of :func:`required_sigma` (``y``: the evaluated samples, for a yield)."""
    t = Tightening(sigma, required_sigma(r, mean, sigma, y))
    if t.target is None or not drivers or not sigma > 0:     # a constant output: no tolerance moves it
        return t
    t.need = 1.0 - (t.target / sigma) ** 2
    if t.need <= 0:
        return t
    for d in drivers:
        t.explained += d.s1
        t.used.append(d)
        if t.explained >= t.need:
            t.f = math.sqrt(max(0.0, 1.0 - t.need / t.explained))
            break
    return t


def _failures_matter(r, row, mc) -> dict | None:
    """Where the samples the model could not evaluate (each a failure of every requirement on the output) are a
    sizeable part of what the requirement lets fail — more than half of it: their share, the allowed one (percent),
    the reasons, and whether the evaluated units alone would meet it (``alone``: the failures are what fails it).
    The evaluated units' mean and σ are then those of the units that could be evaluated (a selection), so no advice
    is read from them alone."""
    failed = int(row.get("failed") or 0)
    n = int(row.get("n") or 0) + failed
    if r.min_yield is not None:
        allowed = 1.0 - r.min_yield
    elif r.min_cpk is not None:          # a Cpk requirement: the share a centred normal process at that Cpk leaves out
        allowed = 2.0 * float(stats.norm.sf(3.0 * r.min_cpk))
    else:
        return None
    if not failed or failed / n <= 0.5 * allowed:
        return None
    y = _evaluated(mc, r.output)
    lo, hi = (-np.inf if r.lower is None else r.lower), (np.inf if r.upper is None else r.upper)
    outside = np.count_nonzero((y < lo) | (y > hi))
    codes = [int(c) for c in np.unique(mc.status[~mc.ok])]
    why = "; ".join(mc.status_reasons.get(c, f"status {c}") for c in codes[:3])
    return {"share": 100 * failed / n, "allowed": 100 * allowed, "why": why, "outside": 100 * outside / n,
            "alone": failed / n > allowed and outside / n <= allowed}


def what_to_change(r, row, drivers: list[Driver], mc) -> str:
    """A first-order estimate of the tightening that would make ``r`` pass (one of the digest's sentences)."""
    mean, sigma = _f(row.get("mean")), _f(row.get("std"))
    failures = _failures_matter(r, row, mc)
    if failures is not None:
        return (FAILURES_ALONE if failures["alone"] else FAILURES_AND_SPREAD).format(**failures)
    if mean is None or sigma is None:
        return NOTHING_EVALUATED
    unit = r.unit or ""
    if sigma == 0:
        return CONSTANT.format(mean=mean, unit=unit) + (CONSTANT_CPK if r.min_cpk is not None else "")
    t = tightening(r, mean, sigma, drivers, _evaluated(mc, r.output))
    mean, sigma, t.target = _in_unit(r, sigma, mean, sigma, t.target)
    if t.target is None:
        return MEAN_BEYOND.format(mean=mean, unit=unit)
    if not drivers:
        return NO_DRIVER.format(sigma=sigma, target=t.target, unit=unit)
    if t.need <= 0:
        return ONLY_CONFIDENCE
    names = (", " if t.f is None else " and ").join(d.tolerance for d in t.used)
    if t.f is None:
        return SEVERAL.format(sigma=sigma, target=t.target, unit=unit, need=100 * t.need, names=names,
                                explained=100 * t.explained)
    return SCALE.format(sigma=sigma, target=t.target, unit=unit, names=names, f=100 * t.f, their=their(len(t.used)),
                          explained=t.explained)


def _in_unit(r, sigma: float | None, *values) -> list:
    """``values`` in ``r``'s unit as numbers that show the decimals resolving its limit interval, else the output's
    σ (:class:`rvtol.precision.Scaled`: the sentences' ``{mean:.4g}`` resolve the band)."""
    scale = output_scale([(r.lower, r.upper)], sigma)
    return [None if v is None else Scaled(v, scale) for v in values]


def _evaluated(mc, output: str):
    """The output's evaluated samples, in the requirement's unit (the Monte Carlo's display unit)."""
    return mc.column(output)[mc.ok]


def first_order_fixes(r, row, d: RequirementDigest, n_to_demonstrate: int | None, y=None,
                      parts: dict[str, int] | None = None) -> list[Fix]:
    """The digest's own fixes of a requirement that is not demonstrated, by kind (estimates, not checked; the
    sentences above); ``parts``: the measured parts per fitted factor that would demonstrate it."""
    mean, sigma, unit = _f(row.get("mean")), _f(row.get("std")), r.unit or ""

    def fix(kind, template, **numbers):
        names = [k for k in numbers if k in ("mean", "sigma", "target", "mid", "shift", "centred")]   # not a limit:
        # it reads as the requirement writes it
        numbers.update(zip(names, _in_unit(r, sigma, *(numbers[k] for k in names))))
        return Fix(r.label, kind, *(part.format(**numbers) for part in template))

    if n_to_demonstrate or parts:
        out = [fix("more samples", MORE_SAMPLES, n=n_to_demonstrate)] if n_to_demonstrate else []
        if parts:
            out.append(fix("more samples", MORE_PARTS,
                           parts=", ".join(f"{m:,} parts of {f}" for f, m in parts.items())))
        return out
    if mean is None or sigma is None:
        return []
    out = []
    if required_sigma(r, mean, sigma, y) is None:
        beyond = [(lim, side) for lim, side in ((r.upper, "below"), (r.lower, "above"))
                  if lim is not None and (mean >= lim if side == "below" else mean <= lim)]
        lim, side = beyond[0] if beyond else (r.upper if r.upper is not None else r.lower, "inside")
        out.append(fix("redesign", REDESIGN, mean=mean, unit=unit, side=side, limit=lim))
        return out
    if not sigma > 0:                   # a constant output inside the limits: no tolerance moves it
        return out
    if r.lower is not None and r.upper is not None:
        mid = 0.5 * (r.lower + r.upper)
        centred = required_sigma(r, mid, sigma, None if y is None else y - mean + mid)
        if centred is not None and sigma <= centred and abs(mean - mid) > 0.05 * (r.upper - r.lower):
            out.append(fix("re-centre", RECENTRE, mean=mean, mid=mid, unit=unit, shift=mid - mean, sigma=sigma,
                           centred=centred))
    t = tightening(r, mean, sigma, d.drivers, y)
    if t.f is not None:
        names = " and ".join(short_label(x.tolerance) for x in t.used)
        out.append(fix("tighten", TIGHTEN, names=names, f=100 * t.f, their=their(len(t.used)), sigma=sigma,
                       target=t.target, unit=unit, explained=t.explained))
    elif t.used:
        out.append(fix("tighten", TIGHTEN_SEVERAL, sigma=sigma, target=t.target, unit=unit,
                       explained=100 * t.explained))
    return out


def _f(v):
    try:
        v = float(v)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


# --------------------------------------------------------------------------- the first page
#: a driver below this first-order share is not listed (it would read as 0 %)
MIN_SHARE = 0.005
#: drivers listed per requirement on the first page (summary.json holds the digest's three)
FIRST_PAGE_DRIVERS = 2


def _num(v, fmt="{:.4g}") -> str:
    return "—" if v is None else fmt.format(v)


def _need(bound, need, fmt) -> str:
    return f"{_num(bound, fmt)} (needs ≥ {need:g})" if need is not None else "—"


def signoff_section(result) -> Section:
    sec = Section("signoff", "Sign-off")
    digests = result.signoff
    if not digests:
        sec.add_text("This study states no requirements: nothing is signed off.")
        return sec
    reqs = {v.requirement.label: v.requirement for v in result.mc.verdicts()}
    counts = {k: sum(d.state == k for d in digests) for k in REQUIREMENT_STATES}
    head = (f"FAIL — {len(digests) - counts[PASS]} of {len(digests)} requirements are not demonstrated at their "
            "stated confidence" if counts[PASS] < len(digests) else
            f"PASS — all {len(digests)} requirements are demonstrated at their stated confidence")
    sec.add_text(head + f" ({counts[PASS]} PASS, {counts[STATE_UNDECIDED]} UNDECIDED, {counts[FAIL]} FAIL). "
                 + " ".join(f"{k}: {v}." for k, v in REQUIREMENT_STATES.items()))
    rows, staged = [], any(d.model for d in digests)
    cpk_asked = any(reqs[d.label].min_cpk is not None for d in digests)
    stat_asked = any(d.statistic is not None for d in digests)
    stt = result.mc.statistics()
    for d in digests:
        r = reqs[d.label]
        scale = output_scale([(r.lower, r.upper)], stt.loc[d.output].get("std"))   # the decimals resolve its band
        needs = " and ".join(x for x in (f"yield ≥ {r.min_yield:g}" if r.min_yield is not None else "",
                                         f"Cpk ≥ {r.min_cpk:g}" if r.min_cpk is not None else "") if x)
        if r.statistic is not None:
            needs = f"{r.statistic} in [{_num(r.lower, '{:g}')}, {_num(r.upper, '{:g}')}]"
        row = {"": f"● {d.state}", "requirement": short_label(d.label, 90)}
        if staged:
            row["model"] = d.model or "—"
        row.update({"needs": needs, "yield": _num(d.yield_, "{:.5f}"), "yield bound": _num(d.yield_lo, "{:.5f}"),
                    "Cpk": _num(d.cpk, "{:.2f}")})
        if cpk_asked:
            row["Cpk bound"] = _num(d.cpk_lo, "{:.2f}")
        if stat_asked:
            row["statistic [interval]"] = ("—" if d.statistic is None else " ".join(
                (shown(d.statistic[0], scale), f"[{shown(d.statistic[1], scale)}, {shown(d.statistic[2], scale)}]")))
        if any(x.status for x in digests):
            row["status"] = d.status or "—"
        row.update({"mean": shown(d.mean, scale), "P0.135 … P99.865": f"{shown(d.p00135, scale)} … "
                                                                       f"{shown(d.p99865, scale)}",
                    "unit": label(d.unit)})
        rows.append(row)
    sec.add_table(pd.DataFrame(rows), caption="Every requirement (its full name, intervals, reading, source and "
                                              "reasons in the requirements section): the bound — one-sided, at the "
                                              "requirement's confidence — is what is judged against what it needs; a "
                                              "statistic requirement (a catalogue's central value) judges the "
                                              "statistic's interval against its band. Status: how firmly the limit is "
                                              "known (confirmed: read in its source; recalled: remembered, not read; "
                                              "assumed: an engineering assumption)", text=True)
    drows = []
    watched = [d for d in digests if d.state != PASS] or digests    # the failures' drivers; all when all pass
    for d in watched:
        listed = [x for x in d.drivers if x.s1 >= MIN_SHARE and x.significant][:FIRST_PAGE_DRIVERS]
        for drv in listed:
            drows.append({"requirement": d.label, "drawing tolerance": short_label(drv.tolerance),
                          "share of variance (S1)": f"{100 * drv.s1:.0f} %",
                          "factors": ", ".join(drv.factors[:2]) + (f" (+{len(drv.factors) - 2})"
                                                                    if len(drv.factors) > 2 else "")})
    if drows:
        sec.add_table(pd.DataFrame(drows), text=True, caption=f"The (up to {FIRST_PAGE_DRIVERS}) tolerances that matter "
                      "most for each requirement not demonstrated (for every requirement when all pass): first-order "
                      "share of its variance, estimated from the "
                      "Monte Carlo samples (the coordinates of one drawing tolerance summed); listed when at least "
                      f"{100 * MIN_SHARE:g} % and more than three standard errors of its estimate")
    overlaps = [f"{d.label}: " + "; ".join(d.overlaps) for d in digests if d.overlaps]
    if overlaps:
        sec.add_text("Correlated in the spec, so their shares overlap (each includes what the other explains through "
                     "the correlation; do not add them, and tightening one alone gains less than its share says) — "
                     + " · ".join(overlaps) + ".")
    _fixes(sec, result, digests)
    if result.comparison is not None:
        _baseline(sec, result.comparison)
    return sec


def _fixes(sec: Section, result, digests) -> None:
    """The cheapest fix of each kind for every requirement that is not demonstrated, checked ones first."""
    titles = {s.key: s.title for s in result.sections}
    extra = [f for s in result.sections for f in s.fixes]
    rows, sources = [], []
    for d in digests:
        if d.state == PASS:
            continue
        fixes = [f for f in extra if f.requirement == d.label] + list(d.fixes)
        for kind in FIX_KINDS:
            of_kind = sorted((f for f in fixes if f.kind == kind), key=lambda f: not f.checked)
            if not of_kind:
                continue
            f = of_kind[0]
            where = titles.get(f.source)
            rows.append({"requirement": d.label, "fix": kind, "what to do": f.action, "what it gives": f.effect,
                         "evidence": (("checked by a Monte Carlo run" if f.checked else "estimate")
                                      + (f" — {where}" if where else " (first order)"))})
            if f.source in titles:
                sources.append(f.source)
    if not rows:
        return
    rows = _one_more_samples_row(rows)
    sec.add_table(pd.DataFrame(rows), caption="What to change, cheapest kind first (more samples, re-centre a "
                  "nominal, tighten tolerances, redesign)", text=True)
    if sources:
        sec.blocks.append(Links([(k, titles[k]) for k in dict.fromkeys(sources)], "Details"))


def _one_more_samples_row(rows: list[dict]) -> list[dict]:
    """The requirements more samples would decide, in one row: the largest n demonstrates each (the page stays one
    page when many requirements are undecided)."""
    more = [r for r in rows if r["fix"] == "more samples"]
    if len(more) < 2:
        return rows
    n = lambda r: int(re.sub(r"\D", "", r["what to do"]) or 0)  # noqa: E731  ("run n = 12,345 samples")
    top = max(more, key=n)
    one = {**top, "requirement": "; ".join(r["requirement"] for r in more),
           "what it gives": "the estimates already meet these requirements; this n would demonstrate each if the "
                            "figures hold"}
    first = rows.index(more[0])
    return [one if i == first else r for i, r in enumerate(rows) if r["fix"] != "more samples" or i == first]


def _baseline(sec: Section, cmp) -> None:
    """Against the accepted baseline: each requirement before and after, its ppm change, the gates."""
    rows = [{"requirement": r["requirement"], "baseline": r["base_verdict"], "this run": r["new_verdict"],
             "ppm out": f"{_num(r['ppm']['base'], '{:.0f}')} → {_num(r['ppm']['new'], '{:.0f}')}",
             "change [CI]": f"{_num(r['ppm']['change'], '{:+.0f}')} [{_ci(r['ppm']['ci'])}]"}
            for r in cmp.requirements]
    b = cmp.base
    sec.add_text(f"Against the accepted baseline {b['source']} (n {b['n']}, seed {b['seed']}; "
                 f"{'paired on common random numbers' if cmp.paired else 'unpaired'}): gates {cmp.verdict} — "
                 f"{cmp.one_line()}.")
    if rows:
        sec.add_table(pd.DataFrame(rows), caption=f"Requirements against the baseline (ppm non-conforming, change with "
                                                  f"its {100 * cmp.confidence:g} % interval)")
    if cmp.spec_changes:
        sec.add_table(pd.DataFrame(cmp.spec_changes), caption="What changed in the tolerance spec")


def _ci(ci) -> str:
    return "—" if not ci or None in ci else f"{ci[0]:+.0f}, {ci[1]:+.0f}"
