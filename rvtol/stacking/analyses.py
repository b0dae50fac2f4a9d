"""Study analyses of the stack-up conventions (``[[analysis]] kind = ...``), for any model.

=====================  ==========================================================================
kind                   keys
=====================  ==========================================================================
stack_conventions      ``outputs`` (default: the outputs the requirements name, else the first),
                       ``sigma_levels`` ([3]: the ±zσ of the statistical rows), ``percentiles``
                       ([0.135, 99.865]: Monte Carlo percentiles with CIs), ``mrss_factor`` (a
                       given MRSS factor), ``six_sigma = {cp = 2.0, shift = 1.5}`` (or false),
                       ``true_worst_case`` (true), ``second_order`` (true: mean shift, skewness,
                       kurtosis by the method of moments and Pearson tails), ``starts`` (4),
                       ``max_evaluations`` (5000: model
                       evaluations of the search; an expensive model wants fewer),
                       ``gradient`` ("auto": the model's analytic one if it has it, else
                       "five_point"), ``percent`` (10, five-point)
tail_probability       ``outputs`` (default: every output a requirement names), ``samples`` (4000
                       model runs per sampling method and limit, 0: the approximations only),
                       ``methods`` (FORM, SORM, multi-FORM, importance sampling, subset,
                       directional), ``design_points`` (4, multi-FORM), ``seed``
=====================  ==========================================================================
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from .. import stats as st
from .. import units
from ..analysis import Analysis
from ..distributions import coverage
from ..report.sections import Section, frame_records
from ..sensitivity.common import model_gradient
from ..units import label
from .conventions import SIX_SIGMA_CP, SIX_SIGMA_SHIFT, stack_conventions
from .slopes import one_sided_slopes
from .tail import APPROXIMATIONS, METHODS, tail_probability
from .worst_case import true_worst_case


def _outputs(params, study, default_first: bool) -> list[str]:
    model = study.model
    outs = params.raw("outputs", None)
    if outs == "all":
        return list(model.output_names)
    if outs is None:
        req = list(dict.fromkeys(r.output for r in study.requirements))
        if req or not default_first:
            return req
        return [model.outputs[0].name]
    names = params.strs("outputs", min_length=1)
    for o in names:
        if o not in model.output_names:
            raise params.error("outputs", f"unknown output name {o!r} (model has: {', '.join(model.output_names)})")
    return names


def search_evaluator(ctx):
    """The evaluator for the many small sequential batches of a search (optimiser iterates, FORM steps):
    in this process when the model is cheap (a batch of 64 rows under ~20 ms: the executor's round trip
    would dominate), else the study's.  Models are row-deterministic, so the choice changes the time only."""
    import time

    from ..mc import Evaluator

    x0 = ctx.spec.nominal_base()
    serial = Evaluator()
    t0 = time.perf_counter()
    serial(ctx.model, np.repeat(x0[None], 64, axis=0), "timing")
    return serial if time.perf_counter() - t0 < 0.02 else ctx.evaluator


def _limits(mc, output: str) -> list[float]:
    return [v for r in mc.requirements if r.output == output for v in (r.lower, r.upper) if v is not None]


class StackConventionsAnalysis(Analysis):
    """Worst case, RSS, MRSS, 6σ and the true worst case beside the Monte Carlo (:mod:`rvtol.stacking`)."""

    def setup(self, params, study):
        self.study = study
        self.key = params.str("key", "stack_conventions")
        self.title = params.str("title", "Stack-up conventions beside the Monte Carlo")
        self.outputs = _outputs(params, study, default_first=True)
        self.sigma_levels = params.floats("sigma_levels", [3.0], min_length=1, positive=True)
        self.percentiles = params.floats("percentiles", [0.135, 99.865], min_length=1)
        for p in self.percentiles:
            if not 0.0 < p < 100.0:
                raise params.error("percentiles", f"percentiles lie in (0, 100), got {p:g}")
        self.mrss_factor = params.float("mrss_factor", None, positive=True)
        six = params.raw("six_sigma", {})
        if six is False:
            self.six_sigma = None
        else:
            t = params.sub("six_sigma", {})
            cp = t.float("cp", SIX_SIGMA_CP, positive=True)
            shift = t.float("shift", SIX_SIGMA_SHIFT, nonnegative=True)
            if not shift < 3.0 * cp:
                raise t.error("shift", f"a shift of {shift:g}σ leaves no Cpk at Cp {cp:g} (it must be < 3·Cp)")
            t.finish()
            self.six_sigma = (cp, shift)
        self.true_wc = params.bool("true_worst_case", True)
        self.second_order = params.bool("second_order", True)
        self.starts = params.int("starts", 4, min=2)
        self.max_evaluations = params.int("max_evaluations", 5000, min=100)
        self.gradient = params.str("gradient", "auto", choices=("auto", "five_point"))
        self.percent = params.float("percent", 10.0, positive=True)

    def _gradients(self, ctx):
        """Per output: (gradient in base units, y0 base, how)."""
        model, spec = ctx.model, ctx.spec
        x0 = spec.nominal_base()
        G = model_gradient(model, x0) if self.gradient == "auto" else None
        if G is not None:
            y0 = ctx.evaluator(model, x0[None], "nominal point").Y[0]
            return {o: (G[model.output_index(o)], float(y0[model.output_index(o)]), "analytic") for o in self.outputs}
        from ..sensitivity.local import five_point

        loc = five_point(model, spec, outputs=self.outputs, percent=self.percent, evaluate=ctx.evaluator)
        out = {}
        for o in self.outputs:
            q = model.output(o)
            yd = float(loc.for_output(o)["y0"].iloc[0])
            out[o] = (loc.gradient(o, spec.names), float(units.convert(yd, q.shown_unit, q.unit)),
                      f"five-point (±{self.percent:g} %)")
        return out

    def run(self, ctx):
        sec = Section(self.key, self.title)
        sec.add_text(
            "The conventions engineers and peer tools quote, beside this study's Monte Carlo. Linearised rows use "
            "the output's gradient at the nominal point and each factor's band (its drawing limits where written "
            "in drawing notation); the true worst case is the extreme of the model itself over the bands "
            "(bounded optimisation). RSS reads every band as ±3σ of a centred normal; MRSS inflates it (Bender's "
            "1.5; the handbook's C_f = 1 + ½(T_wc − T_rss)/(T_rss(√n − 1))); the statistical rows use each "
            "factor's own distribution; the 6σ rows treat mean shifts arithmetically (static) or as a wider σ "
            "(dynamic, σ/(1 − k)), and the 1.5σ-shift convention reads every band as a ±6σ process shifted 1.5σ. "
            "Only the Monte Carlo enters the verdict.")
        summary = {}
        for o, (g, y0, how) in self._gradients(ctx).items():
            q = ctx.model.output(o)
            sc = stack_conventions(ctx.spec, g, y0, output=o, out_unit=q.shown_unit, out_base_unit=q.unit,
                                   sigma_levels=self.sigma_levels, mrss_factor=self.mrss_factor,
                                   six_sigma=self.six_sigma,
                                   slopes=one_sided_slopes(ctx.model, ctx.spec, o, evaluate=search_evaluator(ctx)))
            wc = None
            if self.true_wc:
                wc = true_worst_case(ctx.model, ctx.spec, o, search_evaluator(ctx), starts=self.starts,
                                     max_evaluations=self.max_evaluations, gradient=g)
                sc.add("worst case (true extreme)", wc.low, wc.high, note=wc.how + ("; " + "; ".join(wc.notes)
                                                                                    if wc.notes else ""),
                       source="corners, differential evolution, L-BFGS-B (scipy)")
            if self.second_order:
                _second_order_rows(ctx, o, sc, self.sigma_levels, search_evaluator(ctx))
            pct = self._monte_carlo(ctx, o, sc)
            lims = _limits(ctx.mc, o)
            frame = sc.frame.copy()
            rq = [r for r in ctx.mc.requirements if r.output == o]
            if rq:
                lo = max((r.lower for r in rq if r.lower is not None), default=None)
                hi = min((r.upper for r in rq if r.upper is not None), default=None)
                frame["inside the limits"] = [("yes" if (lo is None or a >= lo) and (hi is None or b <= hi) else "no")
                                              for a, b in zip(frame["low"], frame["high"])]
            u = label(q.shown_unit)
            sec.add_table(frame.rename(columns={"low": f"low [{u}]", "high": f"high [{u}]",
                                                "half_width": f"± [{u}]", "centre": f"centre [{u}]",
                                                "sigma": f"σ [{u}]"}),
                          caption=f"{o}: stack-up conventions (gradient: {how}; y at the band centres "
                                  f"{sc.y_centre:.6g} {u})")
            sec.add_table(sc.factors, caption=f"{o}: contributors (a: sensitivity; k = |μ − band centre|/t; Cp, "
                                              "Cpk of each factor's distribution against its band; shares of the "
                                              "worst case and of the RSS)")
            sec.add_table(pct, caption=f"{o}: Monte Carlo percentiles of the study's choice with "
                                       f"{ctx.mc.confidence:.0%} order-statistic intervals")
            from ..plotting.stacking import convention_intervals

            sec.add_figure(convention_intervals(sc.frame, o, q.shown_unit, lims),
                           caption=f"{o}: each convention's interval (Monte Carlo rows in orange), limits dashed")
            for n in sc.notes:
                sec.add_text("Note: " + n)
            s = sc.summary()
            s["gradient"] = how
            s["percentiles"] = frame_records(pct)
            if wc is not None:
                s["true_worst_case"] = {"low": wc.low, "high": wc.high, "x_low": wc.x_low, "x_high": wc.x_high,
                                        "evaluations": wc.evaluations, "how": wc.how, "notes": wc.notes,
                                        "guaranteed": wc.guaranteed, "methods": wc.methods}
            summary[o] = s
        sec.summary = summary
        return sec

    def _monte_carlo(self, ctx, o: str, sc) -> pd.DataFrame:
        y = ctx.mc.column(o)
        y = np.sort(y[np.isfinite(y)])
        c = ctx.mc.confidence
        rows = []
        if len(y) < 2:
            return pd.DataFrame(rows)
        m, s = float(np.mean(y)), float(np.std(y, ddof=1))
        for z in self.sigma_levels:
            frac = float(np.mean((y >= m - z * s) & (y <= m + z * s)))
            sc.add(f"Monte Carlo mean ±{z:g}σ", m - z * s, m + z * s, centre=m, sigma=s,
                   note=f"{frac:.5f} of the samples inside (a normal: {coverage(z):.5f})", source="this study")
        sc.add("Monte Carlo range", float(y[0]), float(y[-1]), note=f"n = {len(y)}", source="this study")
        for p in self.percentiles:
            est, lo, hi = st.percentile_ci(y, p / 100.0, c)
            rows.append({"percentile": p, "value": est, "ci_low": lo, "ci_high": hi,
                         "note": "" if lo is not None and hi is not None else "too few samples for this tail"})
        return pd.DataFrame(rows)


def _second_order_rows(ctx, o, sc, sigma_levels, evaluate) -> None:
    """The second-order rows (:mod:`rvtol.stacking.second_order`) beside the linearised ones, or a note why not."""
    from .second_order import curvature, second_order

    q = ctx.model.output(o)
    d = lambda v: float(q.to_display(np.array([v]))[0])  # noqa: E731
    if any("kink" in n for n in sc.notes):
        sc.notes.append("second order: the output has a kink at the nominal point (no second-order expansion)")
        return
    try:
        y0, g, H, _ = curvature(ctx.model, ctx.spec, o, evaluate=evaluate)
        so = second_order(ctx.spec, y0, g, H)
    except ValueError as exc:
        sc.notes.append(f"second order: {exc}")
        return
    for z in sigma_levels:
        sc.add(f"second order (moments) ±{z:g}σ", d(so.mean - z * so.sigma), d(so.mean + z * so.sigma),
               centre=d(so.mean), sigma=d(so.mean + so.sigma) - d(so.mean),
               note=f"mean shift {d(so.mean) - d(so.y_at_means):+.4g} from curvature, skewness {so.skewness:.3g}, "
                    f"kurtosis {so.kurtosis:.3g}", source="Glancy & Chase 1999 (method of moments)")
        lo, hi = so.interval(z)
        sc.add(f"second order, {so.law} tails ({z:g}σ coverage)", d(lo), d(hi), centre=d(so.mean),
               note="quantiles of the curve with the four moments" + ("; " + "; ".join(so.notes) if so.notes else ""),
               source="Pearson 1895 / Johnson 1949")


class TailProbabilityAnalysis(Analysis):
    """Tail probabilities beyond each requirement limit by OpenTURNS' reliability methods (:mod:`rvtol.stacking.tail`)."""

    def setup(self, params, study):
        self.study = study
        self.key = params.str("key", "tail_probability")
        self.title = params.str("title", "Tail probabilities beyond the limits (FORM, SORM, importance, subset and "
                                         "directional sampling)")
        self.outputs = _outputs(params, study, default_first=False)
        if not self.outputs:
            raise params.error("outputs", "tail probabilities need requirement limits: this study has no "
                                          "[[requirement]]")
        for o in self.outputs:
            if not any(r.output == o for r in study.requirements):
                raise params.error("outputs", f"output {o!r} has no requirement (no limit to estimate a tail beyond)")
        self.samples = params.int("samples", 4000, min=0)
        if 0 < self.samples < 100:
            raise params.error("samples", f"the sampling methods need at least 100 samples, got {self.samples}")
        self.methods = tuple(params.strs("methods", list(METHODS), min_length=1))
        for m in self.methods:
            if m not in METHODS:
                raise params.error("methods", f"unknown method {m!r} (known: {', '.join(METHODS)})")
        if not self.samples:
            self.methods = tuple(m for m in self.methods if m in APPROXIMATIONS)
        self.design_points = params.int("design_points", 4, min=2)
        self.seed = params.int("seed", None, min=0)

    def run(self, ctx):
        seed = ctx.seed if self.seed is None else self.seed
        sec = Section(self.key, self.title)
        sec.add_text(
            "Estimates, not demonstrations, by OpenTURNS in the study's own standard-normal space: FORM (the most "
            "probable failure point u*, β = |u*|, P ≈ Φ(−β): exact for a linear output of normal factors), SORM "
            "(FORM corrected by the curvatures at u*), multi-FORM (several design points), importance sampling "
            "about u*, subset simulation and directional sampling (any shape of failure domain), each sampling "
            "estimate with its standard error. Estimates that disagree beyond three standard errors are flagged; "
            "the reference is the most precise sampling estimate not under suspicion (importance sampling about "
            "one point is blind to failure regions far from it). All rest on the factors' distributions (their "
            "tails extrapolated, not measured) and none enters the verdict, which is the Monte Carlo's: where it "
            "sees no failure it only bounds the ppm.")
        rows, records, flags = [], [], []
        key = 0
        search = search_evaluator(ctx)
        for r in ctx.mc.requirements:
            if r.output not in self.outputs:
                continue
            y = ctx.mc.column(r.output)
            for side, lim in (("lower", r.lower), ("upper", r.upper)):
                if lim is None:
                    continue
                est = tail_probability(ctx.model, ctx.spec, r.output, lim, side, search, samples=self.samples,
                                       seed=seed, key=key, methods=self.methods, design_points=self.design_points)
                key += 1
                beyond = (~np.isfinite(y)) | ((y < lim) if side == "lower" else (y > lim))
                k, n = int(beyond.sum()), len(y)
                lo, hi = st.proportion_ci(k, n, ctx.mc.confidence)
                where = f"{r.label} ({side}: {'≥' if side == 'lower' else '≤'} {lim:g} {label(r.unit)})"
                rows.append({"limit": where, "method": f"Monte Carlo (the verdict's, n = {n})",
                             "ppm": 1e6 * k / n, "± s.e. / [CI]": f"[{1e6 * lo:.3g}, {1e6 * hi:.3g}]",
                             "evaluations": n, "note": "counted, Clopper–Pearson interval"})
                for e in est.estimates:
                    rows.append({"limit": where, "method": e.method + (" (reference)" if e.method == est.reference
                                                                       else ""),
                                 "ppm": None if e.pf is None else 1e6 * e.pf,
                                 "± s.e. / [CI]": "" if e.se is None else f"± {1e6 * e.se:.2g}",
                                 "evaluations": e.evaluations, "note": e.note})
                flags += [f"{where}: {d}" for d in est.disagreements]
                d = est.to_dict()
                d.update(requirement=r.label, mc_ppm=1e6 * k / n, mc_ppm_ci=[1e6 * lo, 1e6 * hi], mc_n=n,
                         verdict_uses="Monte Carlo")
                records.append(d)
        sec.add_table(pd.DataFrame(rows), caption="Probability beyond each limit: the Monte Carlo (counted; the "
                                                  "verdict uses it) and OpenTURNS' estimates from the distributions, "
                                                  f"the reference marked ({ctx.mc.confidence:.0%} interval of the "
                                                  "Monte Carlo)")
        for f in flags:
            sec.add_text("Disagreement: " + f)
        pts = [{"limit": f"{d['requirement']} ({d['side']})", **d["most_probable_failure_point"]} for d in records
               if d["most_probable_failure_point"]]
        if pts:
            sec.add_table(pd.DataFrame(pts), caption="The most probable failure points (each factor in its unit): "
                                                     "the combination of deviations most likely to reach the limit")
        sec.summary = {"estimates": records, "disagreements": flags, "verdict_uses": "Monte Carlo"}
        return sec
