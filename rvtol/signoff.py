"""The sign-off digest: per requirement its verdict, the drawing tolerances that drive it, what to change.

Computed from the Monte Carlo alone (no further model run), for the first page of the report and
``summary.json``'s ``requirements`` list:

* **drivers** — the first-order index S1 of every factor on the requirement's output, estimated
  from the Monte Carlo samples themselves (:func:`rvtol.sensitivity.given_data.given_data`, the
  correlation ratio with Kelley's bias correction).  Factors that stand for one drawing tolerance
  (the x1, y1, x2, y2 end points of one position zone, the copies of a per-pin family) are summed
  into that tolerance (:func:`rvtol.callouts.drawing_tolerance`): the share of the output's variance the
  tolerance explains on its own (first order; interactions are in a study's Sobol section).  The
  estimates are summed unclipped (each is unbiased; clipped at 0 the 40 copies of a family would
  add 40 positive halves of their noise) and only over the factors the output can depend on where
  the model knows its structure (:func:`rvtol.model.dependencies`);
* **what to change** — for a requirement that is not demonstrated: the spread the output must
  reach and the tightening of its largest driver that would give it, to first order
  (``σ² → σ² (1 − S1 (1 − f²))`` when that tolerance is scaled by ``f``); labelled an estimate —
  the allocation analysis gives cost-optimal tolerances that are checked by Monte Carlo.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from scipy import stats

from .mc import MonteCarloResult
from .model import Model
from .sensitivity.drivers import Driver, first_order_drivers
from .spec import ToleranceSpec


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

    def to_dict(self) -> dict:
        return {"requirement": self.label, "output": self.output, "model": self.model, "unit": self.unit,
                "verdict": "PASS" if self.passed else "FAIL", "mean": self.mean, "P99.865": self.p99865,
                "P0.135": self.p00135, "yield_lower_bound": self.yield_lo, "cpk_lower_bound": self.cpk_lo,
                "reasons": self.reasons,
                "drivers": [{"tolerance": d.tolerance, "S1": d.s1, "factors": d.factors} for d in self.drivers],
                "what_to_change": self.change, "correlated_drivers": self.overlaps}


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
                              _f(v.yield_bound), _f(v.cpk_bound), list(v.reasons))
        d.drivers = s1.get(r.output, [])[:top]
        d.overlaps = correlated_drivers(d.drivers, spec)
        if not v.passed:
            d.change = what_to_change(r, row, d.drivers, mc)
        out.append(d)
    return out


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


def required_sigma(r, mean: float, sigma: float) -> float | None:
    """The standard deviation the output may have for ``r`` to pass at its point estimate (normal theory)."""
    dists = [d for d in ((r.upper - mean) if r.upper is not None else None,
                         (mean - r.lower) if r.lower is not None else None) if d is not None]
    if not dists or min(dists) <= 0:
        return None
    z = 0.0
    if r.min_cpk is not None:
        z = max(z, 3.0 * r.min_cpk)
    if r.min_yield is not None:
        two = r.lower is not None and r.upper is not None
        p = 1.0 - (1.0 - r.min_yield) / (2.0 if two else 1.0)
        z = max(z, float(stats.norm.ppf(p)))
    return min(dists) / z if z > 0 else None


def what_to_change(r, row, drivers: list[Driver], mc) -> str:
    """A first-order estimate of the tightening that would make ``r`` pass (text)."""
    mean, sigma = _f(row.get("mean")), _f(row.get("std"))
    if mean is None or sigma is None:
        return "No sample could be evaluated: nothing to estimate from."
    target = required_sigma(r, mean, sigma)
    unit = r.unit or ""
    if target is None:
        return (f"The mean {mean:.4g} {unit} itself lies at or beyond the limit: tightening tolerances cannot fix "
                "it — the nominal design (or a mean shift of its largest drivers) must change.")
    if not drivers:
        return f"The spread must fall from σ = {sigma:.3g} to {target:.3g} {unit}; no driver could be estimated."
    need = 1.0 - (target / sigma) ** 2        # share of the variance that must go
    if need <= 0:
        return ("The point estimate already meets the requirement: the confidence bound does not — more samples "
                "(a larger n) would demonstrate it, or a small tightening of the drivers below.")
    total = 0.0
    used = []
    for d in drivers:
        total += d.s1
        used.append(d)
        if total >= need:
            break
    if total < need:
        names = ", ".join(d.tolerance for d in used)
        return (f"The spread must fall from σ = {sigma:.3g} to {target:.3g} {unit} ({100 * need:.0f} % of the "
                f"variance), more than the largest drivers explain to first order ({names}: {100 * total:.0f} %): "
                "tighten several tolerances — see the allocation and Sobol sections.")
    f = math.sqrt(max(0.0, 1.0 - need / total))
    names = " and ".join(d.tolerance for d in used)
    return (f"The spread must fall from σ = {sigma:.3g} to {target:.3g} {unit}: scaling {names} to "
            f"{100 * f:.0f} % of {'its' if len(used) == 1 else 'their'} present tolerance would do it to first "
            f"order (S1 = {total:.2f}). An estimate; the allocation section gives cost-optimal tolerances checked by "
            "Monte Carlo.")


def _f(v):
    try:
        v = float(v)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None
