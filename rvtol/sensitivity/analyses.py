"""Study analyses for sensitivity (``[[analysis]] kind = ...``), for any model.

Common keys: ``outputs`` (list of output names, or ``"all"``; default the
model's first output), ``factors`` (default all), ``title`` and ``key``
(section title / summary key, to run one kind twice), ``seed`` (default
the study seed) and ``confidence`` (default the report's).

=====================  ==========================================================================
kind                   keys
=====================  ==========================================================================
local_sensitivity      ``percent`` (10), ``abs_step`` ({factor = ± value in its unit}, for zero
                       nominals; default ±percent % of the tolerance half-band)
sensitivity_curve      ``factors`` (required), ``magnitudes`` (required), ``unit``, ``percent``,
                       ``together`` (set every listed factor to e at once)
contributions          ``percent``: % of variance (linearised), RSS and worst case beside the Monte
                       Carlo, high/low/median table (model evaluated one factor at a time)
sobol                  ``n`` (base samples, power of 2; 1024), ``second_order`` (true),
                       ``num_resamples`` (100)
morris                 ``trajectories`` (20), ``levels`` (4), ``num_resamples`` (1000)
fast                   ``method`` = "efast" (``n`` per factor, 1024; ``M`` 4) or "rbd" (RBD-FAST on
                       the Monte Carlo samples, or ``samples = "fresh"`` with ``n``; ``M`` 10)
delta                  ``samples`` = "monte_carlo" (default: reuse the study's sample, correlation
                       included) or "fresh" (``n``); ``num_resamples`` (50)
=====================  ==========================================================================
"""
from __future__ import annotations

import pandas as pd

from ..analysis import Analysis
from ..errors import did_you_mean
from ..report.sections import Section, frame_records
from ..units import label
from . import global_ as gs
from .linearisation import contributions, high_low_table
from .local import five_point, sensitivity_curve


class _Analysis(Analysis):
    """Parses the keys every sensitivity analysis shares; subclasses add theirs and ``run``."""

    kind = ""
    title = ""

    def setup(self, params, study):
        self.study = study
        model, spec = study.model, study.spec
        self.key = params.str("key", self.kind)
        self.title = params.str("title", self.title)
        outs = params.raw("outputs", None)
        if outs is None:
            self.outputs = [model.outputs[0].name]
        elif outs == "all":
            self.outputs = list(model.output_names)
        else:
            self.outputs = params.strs("outputs", min_length=1)
            for o in self.outputs:
                if o not in model.output_names:
                    raise params.error("outputs", f"unknown output name {o!r}{did_you_mean(o, model.output_names)} "
                                                  f"(model has: "
                                                  f"{', '.join(model.output_names)})")
        self.factors = params.strs("factors", None, min_length=1)
        for f in self.factors or ():
            if f not in spec.names:
                raise params.error("factors", f"unknown factor name {f!r}{did_you_mean(f, spec.names)} "
                                              f"(spec has: {', '.join(spec.names)})")
        self.seed = params.int("seed", None, min=0)
        self.confidence = params.float("confidence", None, min=0.5, max=0.999999)
        self.parse(params)
        params.finish()

    def parse(self, params) -> None:
        """Read the analysis' own keys (subclasses)."""

    # -- helpers for run --------------------------------------------------------
    def seed_of(self, ctx):
        return ctx.seed if self.seed is None else self.seed

    def confidence_of(self, ctx):
        return self.confidence or ctx.options.confidence

    def section(self) -> Section:
        return Section(self.key, self.title)


def _notes(sec: Section, notes) -> None:
    for n in notes:
        sec.add_text("Note: " + n)


# --------------------------------------------------------------------------- local
class LocalSensitivity(_Analysis):
    kind, title = "local_sensitivity", "Local sensitivity (five-point)"

    def parse(self, params):
        self.percent = params.float("percent", 10.0, positive=True)
        steps = params.sub("abs_step", {})
        self.abs_step = {k: steps.float(k, positive=True) for k in list(steps.keys())}
        for k in self.abs_step:
            if k not in self.study.spec.names:
                raise steps.error(k, f"unknown factor name {k!r}")
        steps.finish()

    def run(self, ctx):
        res = five_point(ctx.model, ctx.spec, self.factors, self.outputs, self.percent, self.abs_step or None,
                         ctx.evaluator)
        sec = self.section()
        sec.add_text(
            f"Each factor in turn takes five equally spaced values spanning ±{self.percent:g} % of its nominal "
            "(zero nominals: ±" + f"{self.percent:g} % of the tolerance half-band unless an absolute step is given"
            "), the others stay at nominal. S is the five-point central derivative at the nominal; the "
            "one-sided five-point stencils give S at the low and high end of the interval (their spread shows "
            "non-linearity). The tornado chart shows S × (tolerance limit − nominal) for each factor.")
        for o in self.outputs:
            sec.add_table(res.table(o), caption=f"Five-point sensitivities of {o} (sign: + the output grows "
                                                "with the factor)", float_format="{:.4g}")
            sec.add_figure(res.plot(o), caption=f"Tornado chart of {o} from the local sensitivities")
        _notes(sec, res.notes)
        sec.summary = {"percent": self.percent, "notes": res.notes,
                       "derivatives": frame_records(res.frame.drop(columns=["S_base"]))}
        return sec


class SensitivityCurve(_Analysis):
    kind, title = "sensitivity_curve", "Sensitivity against error magnitude"

    def parse(self, params):
        if self.factors is None:
            raise params.error("factors", "missing required key (the factors whose curve to draw)")
        self.magnitudes = params.floats("magnitudes", min_length=1)
        if any(m == 0 for m in self.magnitudes):
            raise params.error("magnitudes", "magnitudes must be non-zero (the points span ±percent % of e)")
        self.unit = params.unit("unit") if "unit" in params else None
        if self.unit is not None:
            from ..units import dimension

            for f in self.factors:
                fu = self.study.spec.factor(f).unit
                if dimension(fu) != dimension(self.unit):
                    raise params.error("unit", f"unit {self.unit!r} does not fit factor {f!r} ({fu})")
        self.percent = params.float("percent", 10.0, positive=True)
        self.together = params.bool("together", False)

    def run(self, ctx):
        res = sensitivity_curve(ctx.model, ctx.spec, self.factors, self.magnitudes, self.unit, self.outputs,
                                self.percent, self.together, ctx.evaluator)
        sec = self.section()
        how = "every listed factor set to e at once" if self.together else "one factor at a time set to e"
        sec.add_text(f"Five-point central derivative at magnitude e ({how}, the others at nominal; the five "
                     f"points span ±{self.percent:g} % of e). The shaded band spans the one-sided derivatives "
                     "at the interval ends.")
        for o in self.outputs:
            d = res.frame[res.frame["output"] == o]
            table = d.pivot_table(index="magnitude", columns="factor", values="S", sort=False).reset_index()
            mu = d["magnitude_unit"].iloc[0]
            table = table.rename(columns={"magnitude": f"e [{label(mu)}]"})
            table.columns = [c if i == 0 else f"S {c} [{d[d['factor'] == c]['S_unit'].iloc[0]}]"
                             for i, c in enumerate(table.columns)]
            sec.add_table(table, caption=f"Sensitivity of {o} against the magnitude e")
            sec.add_figure(res.plot(o), caption=f"Sensitivity curves of {o}")
        _notes(sec, res.notes)
        sec.summary = {"percent": self.percent, "together": self.together, "curve": frame_records(res.frame)}
        return sec


class Contributions(_Analysis):
    kind, title = "contributions", "Contributions to variance (linearisation) and high/low table"

    def parse(self, params):
        self.percent = params.float("percent", 10.0, positive=True)

    def run(self, ctx):
        ev = ctx.evaluator
        local = five_point(ctx.model, ctx.spec, None, self.outputs, self.percent, None, ev)
        hl = high_low_table(ctx.model, ctx.spec, self.factors, self.outputs, ev)
        stats = ctx.mc.statistics()
        sec = self.section()
        sec.add_text("Linearisation at the nominal point with the five-point gradient: % contribution to "
                     "variance = (S_i σ_i)² / Σ (S_j σ_j)²; RSS σ = √(Sᵀ C S); worst case = every factor at the "
                     "tolerance limit that pushes the output the same way. Beside it, the Monte Carlo figures, "
                     "and the one-at-a-time table with the model evaluated at each factor's low limit, median "
                     "and high limit.")
        summary = {}
        for o in self.outputs:
            pred = contributions(ctx.model, ctx.spec, o, local)
            unit = pred.unit
            s = stats.loc[o]
            comp = pd.DataFrame([
                {"figure": "mean", "linearised": pred.mean, "Monte Carlo": s.get("mean")},
                {"figure": "standard deviation", "linearised": pred.std, "Monte Carlo": s.get("std")},
                {"figure": "low end (RSS: mean − 3σ; MC: P0.135)", "linearised": pred.mean - 3 * pred.std,
                 "Monte Carlo": s.get("P0.135")},
                {"figure": "high end (RSS: mean + 3σ; MC: P99.865)", "linearised": pred.mean + 3 * pred.std,
                 "Monte Carlo": s.get("P99.865")},
                {"figure": "worst case low", "linearised": pred.worst_low, "Monte Carlo": s.get("min")},
                {"figure": "worst case high", "linearised": pred.worst_high, "Monte Carlo": s.get("max")},
            ])
            comp.columns = ["figure", f"linearised [{label(unit)}]", f"Monte Carlo [{label(unit)}]"]
            sec.add_table(comp, caption=f"{o}: linearised predictions beside the Monte Carlo "
                                        "(MC worst-case rows: sample min/max)")
            f = pred.frame
            contrib = pd.DataFrame({
                "factor": f["factor"], "S": f["S"], "unit of S": f["S_unit"],
                "σ": [f"{v:.4g} {label(u)}" for v, u in zip(f["sigma"], f["factor_unit"])],
                f"S·σ [{label(unit)}]": f["S_sigma"], "% of variance": f["variance_pct"],
                f"Δ at low limit [{label(unit)}]": f["dy_low"], f"Δ at high limit [{label(unit)}]": f["dy_high"],
            }).sort_values("% of variance", ascending=False)
            sec.add_table(contrib, caption=f"{o}: linearised contributions")
            sec.add_figure(pred.plot(), caption=f"{o}: % contribution to variance")
            h = hl.frame[hl.frame["output"] == o]
            ht = pd.DataFrame({
                "factor": h["factor"],
                "low / median / high": [f"{a:.4g} / {b:.4g} / {c:.4g} {label(u)}"
                                        for a, b, c, u in zip(h["low"], h["median"], h["high"], h["factor_unit"])],
                f"{o} at low [{label(unit)}]": h["y_low"], f"at median [{label(unit)}]": h["y_median"],
                f"at high [{label(unit)}]": h["y_high"], f"swing [{label(unit)}]": h["swing"],
            }).sort_values(f"swing [{label(unit)}]", ascending=False)
            sec.add_table(ht, caption=f"{o}: high/low/median (one factor at a time, the others at nominal = "
                                      f"{h['y_nominal'].iloc[0]:.4g} {label(unit)})")
            sec.add_figure(hl.plot(o), caption=f"{o}: high/low swing (model evaluated)")
            _notes(sec, pred.notes)
            summary[o] = {"prediction": pred.summary(), "contributions": frame_records(f),
                          "high_low": frame_records(h)}
        sec.summary = summary
        return sec


# --------------------------------------------------------------------------- global
def _index_table(res, output: str) -> pd.DataFrame:
    d = res.for_output(output)
    out = pd.DataFrame({"factor": d["factor"]})
    if res.method == "morris":
        u = label(d["unit"].iloc[0])
        out[f"μ* [{u}]"] = d["mu_star"]
        out[f"μ* CI ± [{u}]"] = d["mu_star_conf"]
        out[f"μ [{u}]"] = d["mu"]
        out[f"σ [{u}]"] = d["sigma"]
        return out.sort_values(f"μ* [{u}]", ascending=False)
    for col, conf in gs.INDEX_COLUMNS[res.method]:
        out[col] = d[col]
        out[f"{col} CI ±"] = d[conf]
    return out.sort_values(gs.INDEX_COLUMNS[res.method][-1][0], ascending=False)


class _GlobalAnalysis(_Analysis):
    method = ""
    explain = ""

    def report(self, res) -> Section:
        sec = self.section()
        sec.add_text(self.explain + f" {res.n_evaluations} model evaluations"
                     + (f" ({res.n_failed} failed)" if res.n_failed else "") + ".")
        for o in self.outputs:
            sec.add_table(_index_table(res, o), caption=f"{gs.TITLES[res.method]} of {o} "
                                                        f"(CI: {res.confidence:.0%})")
            if res.second_order is not None:
                s2 = res.second_order[res.second_order["output"] == o].drop(columns="output")
                s2 = s2.reindex(s2["S2"].abs().sort_values(ascending=False).index).head(15)
                sec.add_table(s2.rename(columns={"S2_conf": "S2 CI ±"}),
                              caption=f"Second-order Sobol indices of {o} (largest 15 pairs)")
            sec.add_figure(res.plot(o), caption=f"{gs.TITLES[res.method]} of {o}")
        _notes(sec, res.notes)
        sec.summary = res.summary()
        return sec


class Sobol(_GlobalAnalysis):
    kind, title = "sobol", "Global sensitivity: Sobol indices"
    explain = ("Variance-based indices (Saltelli scheme on a scrambled Sobol' sequence, each factor sampled "
               "from its own distribution): S1 = share of the output variance due to the factor alone, "
               "ST = including its interactions, S2 = pair interactions; CIs by bootstrap.")

    def parse(self, params):
        self.n = params.int("n", 1024, min=2)
        if self.n & (self.n - 1):
            raise params.error("n", f"must be a power of 2 (Sobol' sequence balance), got {self.n}")
        self.second_order = params.bool("second_order", True)
        self.num_resamples = params.int("num_resamples", 100, min=10)

    def run(self, ctx):
        return self.report(gs.sobol(ctx.model, ctx.spec, self.n, self.factors, self.outputs, self.second_order,
                                    self.seed_of(ctx), self.num_resamples, self.confidence_of(ctx),
                                    ctx.evaluator))


class Morris(_GlobalAnalysis):
    kind, title = "morris", "Global screening: Morris elementary effects"
    explain = ("Morris trajectories on each factor's tolerance band in probability (P0.135…P99.865 for "
               "±3σ): μ* = mean |elementary effect| (importance), σ = their spread (non-linearity or "
               "interaction), in the output's unit.")

    def parse(self, params):
        self.trajectories = params.int("trajectories", 20, min=2)
        self.levels = params.int("levels", 4, min=2)
        if self.levels % 2:
            raise params.error("levels", f"must be even, got {self.levels}")
        self.num_resamples = params.int("num_resamples", 1000, min=10)

    def run(self, ctx):
        return self.report(gs.morris(ctx.model, ctx.spec, self.trajectories, self.levels, self.factors,
                                     self.outputs, self.seed_of(ctx), self.num_resamples,
                                     self.confidence_of(ctx), ctx.evaluator))


class Fast(_GlobalAnalysis):
    kind, title = "fast", "Global sensitivity: FAST"

    def parse(self, params):
        self.method = params.str("method", "efast", choices=("efast", "rbd"))
        self.samples = params.str("samples", "monte_carlo", choices=("monte_carlo", "fresh"))
        self.M = params.int("M", 4 if self.method == "efast" else 10, min=1)
        self.n = params.int("n", 1024 if self.method == "efast" else 2048, min=2)
        if self.method == "efast" and self.n <= 4 * self.M**2:
            raise params.error("n", f"must be > 4·M² = {4 * self.M ** 2}, got {self.n}")
        self.num_resamples = params.int("num_resamples", 100, min=10)
        self.explain = ("Extended FAST (search curves through each factor's distribution): S1 and ST."
                        if self.method == "efast" else
                        "RBD-FAST first-order indices from a random sample (no extra evaluations when it "
                        "reuses the Monte Carlo sample).")

    def run(self, ctx):
        ev, seed, conf = ctx.evaluator, self.seed_of(ctx), self.confidence_of(ctx)
        if self.method == "efast":
            res = gs.fast(ctx.model, ctx.spec, self.n, self.M, self.factors, self.outputs, seed,
                          self.num_resamples, conf, ev)
        else:
            given = self.samples == "monte_carlo"
            res = gs.rbd_fast(ctx.model, ctx.spec, self.n, self.M, self.factors, self.outputs, seed,
                              ctx.mc.samples if given else None, ctx.mc.Y if given else None,
                              self.num_resamples, conf, ev)
        return self.report(res)


class Delta(_GlobalAnalysis):
    kind, title = "delta", "Global sensitivity: delta (moment-independent)"
    explain = ("Borgonovo's δ: the expected shift of the whole output distribution when a factor is known "
               "(0: none, 1: all); valid with correlated inputs. S1 is estimated from the same data.")

    def parse(self, params):
        self.samples = params.str("samples", "monte_carlo", choices=("monte_carlo", "fresh"))
        self.n = params.int("n", 2048, min=100)
        self.num_resamples = params.int("num_resamples", 50, min=10)

    def run(self, ctx):
        given = self.samples == "monte_carlo"
        return self.report(gs.delta(ctx.model, ctx.spec, self.n, self.factors, self.outputs, self.seed_of(ctx),
                                    ctx.mc.samples if given else None, ctx.mc.Y if given else None,
                                    self.num_resamples, self.confidence_of(ctx), ctx.evaluator,
                                    ctx.executor))
