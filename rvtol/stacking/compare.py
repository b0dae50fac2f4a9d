"""The stack-up conventions and the tail estimates of a study, beside its Monte Carlo — one result each.

:func:`compare_conventions` gives, per output, every convention of :mod:`rvtol.stacking.conventions`
from the output's gradient at the nominal point (the model's own, else five-point), the true worst
case (:mod:`rvtol.stacking.worst_case`) and the Monte Carlo's own rows and percentiles with their
order-statistic intervals; :func:`tail_probabilities` gives, per requirement limit, FORM and
importance sampling (:mod:`rvtol.stacking.tail`) beside the Monte Carlo's count.  Only the Monte
Carlo enters a verdict.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from .. import stats as st
from .. import units
from ..distributions import coverage
from ..mc import Evaluator
from ..records import frame_records
from ..sensitivity.common import model_gradient
from ..units import label
from .conventions import StackConventions, stack_conventions
from .tail import TailEstimate, form, importance_sampling
from .worst_case import WorstCase, true_worst_case


def search_evaluator(model, spec, evaluator):
    """The evaluator for the many small sequential batches of a search (optimiser iterates, FORM steps):
    in this process when the model is cheap (a batch of 64 rows under ~20 ms: the executor's round trip
    would dominate), else ``evaluator``.  Models are row-deterministic, so the choice changes the time only."""
    x0 = spec.nominal_base()
    serial = Evaluator()
    t0 = time.perf_counter()
    serial(model, np.repeat(x0[None], 64, axis=0), "timing")
    return serial if time.perf_counter() - t0 < 0.02 else evaluator


def limits_of(mc, output: str) -> list[float]:
    """The requirement limits on ``output`` (display units)."""
    return [v for r in mc.requirements if r.output == output for v in (r.lower, r.upper) if v is not None]


# --------------------------------------------------------------------------- conventions
@dataclass
class OutputConventions:
    """One output's conventions (with the Monte Carlo rows), its percentiles, the true worst case."""

    conventions: StackConventions
    gradient: str                        # how the gradient was found
    percentiles: pd.DataFrame
    worst_case: WorstCase | None
    limits: list[float]
    inside: list[str] | None             # per convention: inside every requirement limit ("yes"/"no")

    def table(self) -> pd.DataFrame:
        frame = self.conventions.frame.copy()
        if self.inside is not None:
            frame["inside the limits"] = self.inside
        return frame

    def summary(self) -> dict:
        s = self.conventions.summary()
        s["gradient"] = self.gradient
        s["percentiles"] = frame_records(self.percentiles)
        wc = self.worst_case
        if wc is not None:
            s["true_worst_case"] = {"low": wc.low, "high": wc.high, "x_low": wc.x_low, "x_high": wc.x_high,
                                    "evaluations": wc.evaluations, "how": wc.how, "notes": wc.notes}
        return s


@dataclass
class ConventionsComparison:
    """Per output (display units), the conventions engineers quote beside the study's Monte Carlo."""

    outputs: dict[str, OutputConventions]
    confidence: float

    def to_frame(self) -> pd.DataFrame:
        return pd.concat([o.table().assign(output=name) for name, o in self.outputs.items()], ignore_index=True)

    def plot(self, output: str):
        from ..plotting.stacking import convention_intervals

        o = self.outputs[output]
        return convention_intervals(o.conventions.frame, output, o.conventions.unit, o.limits)

    def summary(self) -> dict:
        return {name: o.summary() for name, o in self.outputs.items()}


def compare_conventions(model, spec, outputs, mc, evaluator, *, sigma_levels=(3.0,), percentiles=(0.135, 99.865),
                        mrss_factor: float | None = None, six_sigma: tuple[float, float] | None = None,
                        true_wc: bool = True, starts: int = 4, max_evaluations: int = 5000, gradient: str = "auto",
                        percent: float = 10.0) -> ConventionsComparison:
    """The conventions of each output (module docstring); ``gradient``: ``auto`` (the model's own where it has
    one) or ``five_point`` (±``percent`` % of the nominals)."""
    out = {}
    for o, (g, y0, how) in _gradients(model, spec, outputs, evaluator, gradient, percent).items():
        q = model.output(o)
        sc = stack_conventions(spec, g, y0, output=o, out_unit=q.shown_unit, out_base_unit=q.unit,
                               sigma_levels=sigma_levels, mrss_factor=mrss_factor, six_sigma=six_sigma)
        wc = None
        if true_wc:
            wc = true_worst_case(model, spec, o, search_evaluator(model, spec, evaluator), starts=starts,
                                 max_evaluations=max_evaluations, gradient=g)
            sc.add("worst case (true extreme)", wc.low, wc.high, note=wc.how + ("; " + "; ".join(wc.notes)
                                                                                if wc.notes else ""),
                   source="bounded optimisation (scipy L-BFGS-B)")
        pct = _monte_carlo(mc, o, sc, sigma_levels, percentiles)
        rq = [r for r in mc.requirements if r.output == o]
        inside = None
        if rq:
            lo = max((r.lower for r in rq if r.lower is not None), default=None)
            hi = min((r.upper for r in rq if r.upper is not None), default=None)
            inside = [("yes" if (lo is None or a >= lo) and (hi is None or b <= hi) else "no")
                      for a, b in zip(sc.frame["low"], sc.frame["high"])]
        out[o] = OutputConventions(sc, how, pct, wc, limits_of(mc, o), inside)
    return ConventionsComparison(out, mc.confidence)


def _gradients(model, spec, outputs, evaluator, gradient: str, percent: float) -> dict:
    """Per output: (gradient in base units, y0 base, how)."""
    x0 = spec.nominal_base()
    G = model_gradient(model, x0) if gradient == "auto" else None
    if G is not None:
        y0 = evaluator(model, x0[None], "nominal point").Y[0]
        return {o: (G[model.output_index(o)], float(y0[model.output_index(o)]), "analytic") for o in outputs}
    from ..sensitivity.local import five_point

    loc = five_point(model, spec, outputs=outputs, percent=percent, evaluate=evaluator)
    out = {}
    for o in outputs:
        q = model.output(o)
        yd = float(loc.for_output(o)["y0"].iloc[0])
        out[o] = (loc.gradient(o, spec.names), float(units.convert(yd, q.shown_unit, q.unit)),
                  f"five-point (±{percent:g} %)")
    return out


def _monte_carlo(mc, o: str, sc: StackConventions, sigma_levels, percentiles) -> pd.DataFrame:
    """The Monte Carlo rows of the conventions table (mean ± zσ, range) and its percentiles with intervals."""
    y = mc.column(o)
    y = np.sort(y[np.isfinite(y)])
    rows = []
    if len(y) < 2:
        return pd.DataFrame(rows)
    m, s = float(np.mean(y)), float(np.std(y, ddof=1))
    for z in sigma_levels:
        frac = float(np.mean((y >= m - z * s) & (y <= m + z * s)))
        sc.add(f"Monte Carlo mean ±{z:g}σ", m - z * s, m + z * s, centre=m, sigma=s,
               note=f"{frac:.5f} of the samples inside (a normal: {coverage(z):.5f})", source="this study")
    sc.add("Monte Carlo range", float(y[0]), float(y[-1]), note=f"n = {len(y)}", source="this study")
    for p in percentiles:
        est, lo, hi = st.percentile_ci(y, p / 100.0, mc.confidence)
        rows.append({"percentile": p, "value": est, "ci_low": lo, "ci_high": hi,
                     "note": "" if lo is not None and hi is not None else "too few samples for this tail"})
    return pd.DataFrame(rows)


# --------------------------------------------------------------------------- tails
@dataclass
class LimitTail:
    """One requirement limit: FORM (and importance sampling) beside the Monte Carlo's count."""

    requirement: object
    side: str
    limit: float
    estimate: TailEstimate
    k: int                      # Monte Carlo samples beyond the limit (failed evaluations included)
    n: int
    ci: tuple[float, float]

    def row(self) -> dict:
        r, est, (lo, hi) = self.requirement, self.estimate, self.ci
        k, n = self.k, self.n
        return {"requirement": r.label,
                "limit": f"{'≥' if self.side == 'lower' else '≤'} {self.limit:g} {label(r.unit)}",
                "Monte Carlo ppm [CI]": f"{1e6 * k / n:.3g} [{1e6 * lo:.3g}, {1e6 * hi:.3g}] (n = {n})",
                "FORM β": est.beta, "FORM ppm": est.ppm_form,
                "IS ppm ± s.e.": (f"{est.ppm_is:.3g} ± {1e6 * est.pf_is_se:.2g} (N = {est.n_is})"
                                  if est.pf_is is not None else "—"),
                "converged": "yes" if est.converged else ("n/a" if est.beta in (None, math.inf) else "no"),
                "evaluations": est.evaluations, "notes": "; ".join(est.notes)}

    def record(self) -> dict:
        d = self.estimate.to_dict()
        lo, hi = self.ci
        d.update(requirement=self.requirement.label, mc_ppm=1e6 * self.k / self.n, mc_ppm_ci=[1e6 * lo, 1e6 * hi],
                 mc_n=self.n)
        return d


@dataclass
class TailProbabilities:
    """Every requirement limit's tail estimates, and the Monte Carlo's confidence level."""

    limits: list[LimitTail]
    confidence: float
    notes: list[str] = field(default_factory=list)

    def to_frame(self) -> pd.DataFrame:
        return pd.DataFrame([t.row() for t in self.limits])

    def failure_points(self) -> pd.DataFrame:
        """The most probable failure points (each factor in its unit), where FORM found one."""
        recs = [t.record() for t in self.limits]
        return pd.DataFrame([{"limit": f"{d['requirement']} ({d['side']})", **d["most_probable_failure_point"]}
                             for d in recs if d["most_probable_failure_point"]])

    def summary(self) -> dict:
        return {"estimates": [t.record() for t in self.limits]}


def tail_probabilities(model, spec, mc, outputs, evaluator, *, samples: int = 4000, max_iterations: int = 60,
                       seed: int | None = None) -> TailProbabilities:
    """FORM and (``samples`` > 0) importance sampling beyond each limit of the requirements on ``outputs``."""
    search = search_evaluator(model, spec, evaluator)
    out, key = [], 0
    for r in mc.requirements:
        if r.output not in outputs:
            continue
        y = mc.column(r.output)
        for side, lim in (("lower", r.lower), ("upper", r.upper)):
            if lim is None:
                continue
            est, z = form(model, spec, r.output, lim, side, search, max_iterations=max_iterations)
            if z is not None and samples:
                importance_sampling(model, spec, est, z, samples, seed, key, evaluator)
            key += 1
            beyond = (~np.isfinite(y)) | ((y < lim) if side == "lower" else (y > lim))
            k, n = int(beyond.sum()), len(y)
            out.append(LimitTail(r, side, lim, est, k, n, st.proportion_ci(k, n, mc.confidence)))
    return TailProbabilities(out, mc.confidence)
