"""The stack-up conventions and the tail estimates of a study, beside its Monte Carlo — one result each.

:func:`compare_conventions` gives, per output, every convention of :mod:`rvtol.stacking.conventions`
from the output's gradient at the nominal point (the model's own, else five-point), the true worst
case (:mod:`rvtol.stacking.worst_case`) and the Monte Carlo's own rows and percentiles with their
order-statistic intervals, and (``second_order``) the second-order moments of
:mod:`rvtol.stacking.second_order`; :func:`tail_probabilities` gives, per requirement limit, OpenTURNS'
reliability estimates (:mod:`rvtol.stacking.tail`: FORM, SORM, multi-FORM, importance, subset and
directional sampling) beside the Monte Carlo's count.  Only the Monte Carlo enters a verdict.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from .. import stats as st
from .. import units
from ..distributions import coverage
from ..mc import Evaluator
from ..envelopes import envelopes, extreme, violations
from ..patterns import frame_extreme, patterns
from ..records import frame_records
from ..sensitivity.common import model_gradient
from ..units import label
from . import notes as N
from .conventions import StackConventions, stack_conventions
from .slopes import one_sided_slopes
from .tail import METHODS, TailEstimate, tail_probability
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
    return [v for r in mc.requirements if r.output == output and r.per_unit for v in (r.lower, r.upper)
            if v is not None]


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
                                    "evaluations": wc.evaluations, "how": wc.how, "notes": wc.notes,
                                    "guaranteed": wc.guaranteed, "methods": wc.methods}
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
                        true_wc: bool = True, second_order: bool = True, starts: int = 4,
                        max_evaluations: int = 5000, gradient: str = "auto",
                        percent: float = 10.0) -> ConventionsComparison:
    """The conventions of each output (module docstring); ``gradient``: ``auto`` (the model's own where it has
    one) or ``five_point`` (±``percent`` % of the nominals)."""
    out = {}
    for o, (g, y0, how) in _gradients(model, spec, outputs, evaluator, gradient, percent).items():
        q = model.output(o)
        search = search_evaluator(model, spec, evaluator)
        sc = stack_conventions(spec, g, y0, output=o, out_unit=q.shown_unit, out_base_unit=q.unit,
                               sigma_levels=sigma_levels, mrss_factor=mrss_factor, six_sigma=six_sigma,
                               slopes=one_sided_slopes(model, spec, o, evaluate=search))
        _domain_row(spec, g, q, sc, mc)
        linearised = len(sc.frame)   # the rows so far read the output by its gradient at the nominal point
        wc = None
        if true_wc:
            wc = true_worst_case(model, spec, o, search, starts=starts, max_evaluations=max_evaluations, gradient=g)
            sc.add("worst case (true extreme)", wc.low, wc.high, note=wc.how + ("; " + "; ".join(wc.notes)
                                                                                if wc.notes else ""),
                   source="corners, differential evolution, L-BFGS-B (scipy)")
        if second_order:
            _second_order_rows(model, spec, o, sc, sigma_levels, search, linearised)
        pct = _monte_carlo(mc, o, sc, sigma_levels, percentiles)
        rq = [r for r in mc.requirements if r.output == o and r.per_unit]
        inside = None
        if rq:
            lo = max((r.lower for r in rq if r.lower is not None), default=None)
            hi = min((r.upper for r in rq if r.upper is not None), default=None)
            inside = [("yes" if (lo is None or a >= lo) and (hi is None or b <= hi) else "no")
                      for a, b in zip(sc.frame["low"], sc.frame["high"])]
        out[o] = OutputConventions(sc, how, pct, wc, limits_of(mc, o), inside)
    return ConventionsComparison(out, mc.confidence)


def _domain_row(spec, g, q, sc, mc) -> None:
    """Where the output depends on a GD&T domain that is not the box of its factors' bands — a composite frame
    (:mod:`rvtol.patterns`: the frame admits more than its decomposition) or a form bound by its size's envelope
    (:mod:`rvtol.envelopes`: the polygon admits less than the box) — the arithmetic worst case over those domains,
    beside the first row; the envelopes' violations among the sampled parts in the notes.  A domain whose factors
    also take a bonus or a datum shift, or whose gradient is not finite, is left to the first row (said)."""
    g = np.asarray(g, dtype=float)
    low = high = 0.0
    parts, skipped = [], []
    d = lambda v: float(units.convert(v, q.unit, q.shown_unit))  # noqa: E731   base → display, a difference
    for p in patterns(spec.factors):
        cols = [spec.index(f.name) for z in p.zones for f in spec.factors if f.zone == z]
        if not g[cols].any():
            continue
        skip = not np.isfinite(g[cols]).all() or any(spec.factors[i].modifier or spec.factors[i].datum_size
                                                      for i in cols)
        if p.may_rotate:      # turned in this row only where the features' basic positions are given
            sc.notes.append((N.FRAMEWORK_ROTATION_IN_ROW if p.basic is not None and not skip else N.FRAMEWORK_ROTATES)
                            .format(pattern=p.name, datums=" ".join(p.datums) or "no datum"))
        if skip:
            skipped.append(f"pattern {p.name}")
            continue
        frame, decomposition = frame_extreme(p, g[cols])
        low, high = low - (frame - decomposition), high + (frame - decomposition)
        parts.append(f"pattern {p.name} over its frame ±{d(frame):.4g} (decomposed ±{d(decomposition):.4g})")
    coupled = {n for f in spec.factors for n in (f.size, f.datum_size) if n}
    for e in envelopes(spec):
        a = g[[e.size, e.form]]
        size, form = spec.factors[e.size], spec.factors[e.form]
        if not a.any():
            continue
        if not np.isfinite(a).all() or size.name in coupled:
            skipped.append(f"{form.name}'s envelope")
            continue
        dl, dh = extreme(e, a[0], a[1], (0.5 * sum(e.size_limits), 0.5 * e.form_limit))
        low, high = low + dl, high + dh
        bad = violations(e, mc.samples.values) if mc is not None else 0
        parts.append(f"{form.name} within {size.name}'s envelope: low {d(dl):+.4g}, high {d(dh):+.4g}")
        if bad:
            sc.notes.append(N.ENVELOPE_VIOLATED.format(n=bad, total=mc.n, form=form.name, size=size.name))
    if skipped:
        sc.notes.append(N.DOMAIN_SKIPPED.format(domains=", ".join(skipped)))
    if not parts:
        return
    wc = sc.row("worst case (arithmetic)")
    sc.add("worst case (GD&T domains)", wc["low"] + d(low), wc["high"] + d(high),
           note=N.DOMAIN_ROW.format(parts="; ".join(parts)),
           source="ASME Y14.5-2018 §5.8, §10.5.1 (corners; SOCP, cvxpy)")


def _second_order_rows(model, spec, o, sc, sigma_levels, evaluate, linearised: int) -> None:
    """The second-order rows (:mod:`rvtol.stacking.second_order`) beside the linearised ones, or a note why not; where
    the output is curved, each of the first ``linearised`` rows says that it leaves the curvature out."""
    from .second_order import curvature, second_order

    q = model.output(o)
    d = lambda v: float(q.to_display(np.array([v]))[0])  # noqa: E731
    if any("kink" in n for n in sc.notes):
        sc.notes.append("second order: the output has a kink at the nominal point (no second-order expansion)")
        return
    try:
        y0, g, H, _ = curvature(model, spec, o, evaluate=evaluate)
        so = second_order(spec, y0, g, H)
    except ValueError as exc:
        sc.notes.append(f"second order: {exc}")
        return
    if so.curved:
        rows = sc.frame.index[:linearised]
        sc.frame.loc[rows, "note"] = sc.frame.loc[rows, "note"] + N.LINEARISED.format(
            shift=d(so.mean) - d(so.y_at_means))
    for z in sigma_levels:
        sc.add(f"second order (moments) ±{z:g}σ", d(so.mean - z * so.sigma), d(so.mean + z * so.sigma),
               centre=d(so.mean), sigma=d(so.mean + so.sigma) - d(so.mean),
               note=f"mean shift {d(so.mean) - d(so.y_at_means):+.4g} from curvature, skewness {so.skewness:.3g}, "
                    f"kurtosis {so.kurtosis:.3g}" + "".join("; " + n for n in so.notes),
               source="Glancy & Chase 1999 (method of moments)")
        lo, hi = so.interval(z)
        sc.add(f"second order, {so.law} tails ({z:g}σ coverage)", d(lo), d(hi), centre=d(so.mean),
               note="quantiles of the curve with the four moments" + "".join("; " + n for n in so.notes + so.tail_notes),
               source="Pearson 1895 / Johnson 1949")


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
    """One requirement limit: OpenTURNS' estimates beside the Monte Carlo's count."""

    requirement: object
    side: str
    limit: float
    estimate: TailEstimate
    k: int                      # Monte Carlo samples beyond the limit (failed evaluations included)
    n: int
    ci: tuple[float, float]

    @property
    def where(self) -> str:
        r = self.requirement
        return f"{r.label} ({self.side}: {'≥' if self.side == 'lower' else '≤'} {self.limit:g} {label(r.unit)})"

    def rows(self) -> list[dict]:
        """The Monte Carlo's row, then one per method (the reference marked)."""
        est, (lo, hi), k, n = self.estimate, self.ci, self.k, self.n
        rows = [{"limit": self.where, "method": f"Monte Carlo (the verdict's, n = {n})",
                 "ppm": 1e6 * k / n, "± s.e. / [CI]": f"[{1e6 * lo:.3g}, {1e6 * hi:.3g}]",
                 "evaluations": n, "note": "counted, Clopper–Pearson interval"}]
        for e in est.estimates:
            rows.append({"limit": self.where, "method": e.method + (" (reference)" if e.method == est.reference else ""),
                         "ppm": None if e.pf is None else 1e6 * e.pf,
                         "± s.e. / [CI]": "" if e.se is None else f"± {1e6 * e.se:.2g}",
                         "evaluations": e.evaluations, "note": e.note})
        return rows

    def disagreements(self) -> list[str]:
        return [f"{self.where}: {d}" for d in self.estimate.disagreements]

    def record(self) -> dict:
        d = self.estimate.to_dict()
        lo, hi = self.ci
        d.update(requirement=self.requirement.label, mc_ppm=1e6 * self.k / self.n, mc_ppm_ci=[1e6 * lo, 1e6 * hi],
                 mc_n=self.n, verdict_uses="Monte Carlo")
        return d


@dataclass
class TailProbabilities:
    """Every requirement limit's tail estimates, and the Monte Carlo's confidence level."""

    limits: list[LimitTail]
    confidence: float
    notes: list[str] = field(default_factory=list)

    def to_frame(self) -> pd.DataFrame:
        return pd.DataFrame([row for t in self.limits for row in t.rows()])

    def disagreements(self) -> list[str]:
        return [f for t in self.limits for f in t.disagreements()]

    def failure_points(self) -> pd.DataFrame:
        """The most probable failure points (each factor in its unit), where FORM found one."""
        recs = [t.record() for t in self.limits]
        return pd.DataFrame([{"limit": f"{d['requirement']} ({d['side']})", **d["most_probable_failure_point"]}
                             for d in recs if d["most_probable_failure_point"]])

    def summary(self) -> dict:
        return {"estimates": [t.record() for t in self.limits], "disagreements": self.disagreements(),
                "verdict_uses": "Monte Carlo"}

    def plot(self):
        """No figure: a handful of probabilities per limit, each with its standard error, read best as the
        report's table (:meth:`to_frame`); calling this is an error that says so."""
        raise ValueError("tail probabilities have no figure: read to_frame() (one row per limit and method)")


def tail_probabilities(model, spec, mc, outputs, evaluator, *, samples: int = 4000, methods=None,
                       design_points: int = 4, seed: int | None = None) -> TailProbabilities:
    """OpenTURNS' estimates (``methods``; the sampling ones with ``samples`` model runs each) beyond each limit of
    the requirements on ``outputs``."""
    search = search_evaluator(model, spec, evaluator)
    out, key = [], 0
    for r in mc.requirements:
        if r.output not in outputs or not r.per_unit:
            continue
        y = mc.column(r.output)
        for side, lim in (("lower", r.lower), ("upper", r.upper)):
            if lim is None:
                continue
            est = tail_probability(model, spec, r.output, lim, side, search, samples=samples, seed=seed, key=key,
                                   methods=METHODS if methods is None else methods, design_points=design_points)
            key += 1
            beyond = (~np.isfinite(y)) | ((y < lim) if side == "lower" else (y > lim))
            k, n = int(beyond.sum()), len(y)
            out.append(LimitTail(r, side, lim, est, k, n, st.proportion_ci(k, n, mc.confidence)))
    return TailProbabilities(out, mc.confidence)
