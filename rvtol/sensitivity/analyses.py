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
delta                  ``samples`` = "monte_carlo" (default: a random subsample of the study's sample,
                       correlation included, ``n`` = 2000 rows, 0 = all of them) or "fresh" (``n`` new
                       runs, 2048); ``num_resamples`` (50)
given_data             first-order indices from the Monte Carlo sample, no model run: ``classes``
                       (⌊√n⌋ in [8, 200]), ``num_resamples`` (200)
pce                    S1, ST, S2 from a polynomial chaos surrogate fitted on the Monte Carlo sample, no
                       model run, with its validation (Q² leave-one-out and hold-out): ``min_q2``
                       (0.95: below it the indices are withheld), ``on_poor_fit`` ("withhold" |
                       "warn" | "raise"), ``n`` (fit on a subsample; 0 = all), ``holdout`` (0.2),
                       ``germs`` ("auto"), ``ci`` ("bootstrap" | "asymptotic"), ``num_resamples``
                       (100), ``second_order`` (true), ``max_degree``, ``q``, ``max_interaction``,
                       ``method`` ("lars": OpenTURNS' functional chaos, the default | "omp" | "ols")
sensitivity_matrix     drawing tolerance × output (default outputs: every output a requirement names):
                       five-point linearised variance shares of every tolerance, Sobol total indices
                       of the ``top`` (10) tolerances (the others as one group; ``n`` = 64 base
                       samples, power of 2), ``percent`` (10); two heat maps
=====================  ==========================================================================
"""
from __future__ import annotations

import pandas as pd

from ..analysis import Analysis
from ..errors import did_you_mean
from ..report.sections import Section, Table, frame_records
from ..units import label
from . import global_ as gs
from ._given import CorrelatedInputsWarning
from .given_data import DELTA_DEFAULT_N, delta_given, delta_subsample, given_data
from .linearisation import contributions, high_low_table
from .local import five_point, sensitivity_curve
from .surrogate import CI_METHODS, MIN_Q2, POOR_FIT, PoorSurrogateWarning, pce
from .surrogate import METHODS as FIT_METHODS


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
        given = self.samples == "monte_carlo"
        # on the Monte Carlo sample: a random subsample of n rows (its kernel density estimates cost ~n² per
        # factor); n = 0 keeps every sample.  Fresh: n new model runs.
        self.n = params.int("n", DELTA_DEFAULT_N if given else 2048, min=0 if given else 100)
        if given and 0 < self.n < 100:
            raise params.error("n", f"must be 0 (every sample) or >= 100, got {self.n}")
        self.num_resamples = params.int("num_resamples", 50, min=10)

    def run(self, ctx):
        args = dict(factors=self.factors, outputs=self.outputs, seed=self.seed_of(ctx),
                    num_resamples=self.num_resamples, confidence=self.confidence_of(ctx), evaluate=ctx.evaluator,
                    executor=ctx.executor)
        if self.samples == "fresh":
            return self.report(gs.delta(ctx.model, ctx.spec, self.n, **args))
        return self.report(delta_given(ctx.model, ctx.spec, ctx.mc.samples, ctx.mc.Y, self.n or None, **args))


class GivenData(_GlobalAnalysis):
    kind, title = "given_data", "Global sensitivity: first-order indices from the Monte Carlo sample"
    explain = ("First-order indices S1 = V[E(Y|X_i)]/V[Y] from the Monte Carlo samples themselves, with no further "
               "model run: the correlation ratio of the output on each factor over equal-count classes of the "
               "factor, with Kelley's correction of its noise bias (Plischke, Borgonovo & Smith 2013); CIs by "
               "bootstrap of the samples. Total indices cannot be read from given data: the pce analysis (a "
               "surrogate fitted on the same samples) or the Saltelli route (sobol) gives them.")

    def parse(self, params):
        self.classes = params.int("classes", None, min=2)
        self.num_resamples = params.int("num_resamples", 200, min=10)

    def run(self, ctx):
        return self.report(given_data(ctx.model, ctx.spec, ctx.mc.samples, ctx.mc.Y, self.factors, self.outputs,
                                      self.seed_of(ctx), self.classes, self.num_resamples, self.confidence_of(ctx)))


class PCE(_GlobalAnalysis):
    kind, title = "pce", "Global sensitivity: Sobol indices from a polynomial chaos surrogate"
    explain = ("Sobol indices S1, ST (and S2) read from the coefficients of a sparse polynomial chaos expansion "
               "fitted on the Monte Carlo samples (no further model run; Sudret 2008, Blatman & Sudret 2011). The "
               "expansion is validated by leave-one-out and on held-out samples: below the stated Q² its indices "
               "are withheld (their error could exceed their interval by up to 1 − Q²). CIs by bootstrap of the "
               "samples, given the selected terms.")

    def parse(self, params):
        self.germs = params.str("germs", "auto", choices=("auto", "legendre", "hermite"))
        self.holdout = params.float("holdout", 0.2, min=0.0, max=0.49)
        self.ci = params.str("ci", "bootstrap", choices=CI_METHODS)
        self.num_resamples = params.int("num_resamples", 100, min=10)
        self.min_q2 = params.float("min_q2", MIN_Q2, min=0.0, max=1.0)
        self.on_poor_fit = params.str("on_poor_fit", "withhold", choices=POOR_FIT)
        self.second_order = params.bool("second_order", True)
        self.n = params.int("n", 0, min=0)          # fit on a random subsample of n Monte Carlo rows (0: all)
        if 0 < self.n < 100:
            raise params.error("n", f"must be 0 (every sample) or >= 100, got {self.n}")
        self.fit = {}
        if "max_degree" in params:
            self.fit["max_degree"] = params.int("max_degree", min=1)
        if "q" in params:
            self.fit["q"] = params.float("q", positive=True, max=1.0)
        if "max_interaction" in params:
            self.fit["max_interaction"] = params.int("max_interaction", min=1)
        if "method" in params:
            self.fit["method"] = params.str("method", choices=FIT_METHODS)
        if "max_interaction" in self.fit and self.fit.get("method", "lars") == "lars":
            raise params.error("max_interaction", "capping the interaction order needs method = \"omp\" or \"ols\" "
                                                  "(OpenTURNS' LARS enumerates by hyperbolic norm only)")

    def run(self, ctx):
        import warnings

        samples, Y, note = delta_subsample(ctx.mc.samples, ctx.mc.Y, self.n or None, self.seed_of(ctx),
                                           "pce_subsample", "the surrogate fit")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PoorSurrogateWarning)   # said in the section's notes
            warnings.simplefilter("ignore", CorrelatedInputsWarning)
            res = pce(ctx.model, ctx.spec, samples, Y, self.factors, self.outputs, self.seed_of(ctx), germs=self.germs,
                      holdout=self.holdout, ci=self.ci, num_resamples=self.num_resamples,
                      confidence=self.confidence_of(ctx), min_q2=self.min_q2, on_poor_fit=self.on_poor_fit,
                      second_order=self.second_order, **self.fit)
        res.notes.insert(0, note[0].upper() + note[1:] + ".")
        sec = self.report(res)
        v = res.validation.copy()
        cols = [c for c in ("output", "reliable", "Q2_loo", "Q2_holdout", "rel_rmse_holdout", "bias_bound", "degree",
                            "n_terms", "n_candidates", "n_samples", "n_holdout") if c in v.columns]
        sec.blocks.insert(1, Table(v[cols], f"Validation of the surrogate (indices withheld below Q² = {self.min_q2:g})"))
        return sec


# --------------------------------------------------------------------------- cross-model matrix
class SensitivityMatrix(_Analysis):
    """Drawing tolerance × output: five-point variance shares of all, Sobol total indices of the top ones.

    A drawing tolerance is a factor, or the factors that stand for one callout (the end-point
    coordinates of a position zone, the copies of a per-pin family): :func:`rvtol.signoff.drawing_tolerance`.
    Five-point: each factor's linearised variance contribution ``(S_i σ_i)²`` as a share of the
    output's linearised variance (correlation ignored), summed per tolerance.  Sobol: ``top``
    tolerances, taken from every output in turn (:meth:`top_tolerances`), are groups of their own,
    every other factor is one group ("all other tolerances"), so n·(top + 3) model runs give a total index per
    tolerance that includes its interactions — the two maps side by side show where the
    linearisation misses.
    """

    kind, title = "sensitivity_matrix", "Sensitivity matrix: drawing tolerances × outputs"

    def parse(self, params):
        if "outputs" not in params.data:
            req = [r.output for r in self.study.requirements]
            self.outputs = list(dict.fromkeys(req)) or list(self.study.model.output_names)
        self.percent = params.float("percent", 10.0, positive=True)
        self.top = params.int("top", 10, min=1)
        self.n = params.int("n", 64, min=2)
        gs._check_power_of_two(self.n)
        self.num_resamples = params.int("num_resamples", 100, min=10)

    def run(self, ctx):
        import numpy as np

        from ..plotting.sensitivity import heatmap
        from ..signoff import drawing_tolerance

        spec, model = ctx.spec, ctx.model
        idx = [spec.index(f) for f in self.factors] if self.factors else list(range(len(spec)))
        names = [spec.names[i] for i in idx]
        tol = {spec.names[i]: drawing_tolerance(spec.factors[i]) for i in idx}
        order = list(dict.fromkeys(tol[n] for n in names))
        fp = five_point(model, spec, names, self.outputs, self.percent, None, ctx.evaluator)
        sd = spec.std_base()[idx]
        share = pd.DataFrame(0.0, index=order, columns=self.outputs)
        for o in self.outputs:
            c = (np.asarray(fp.gradient(o, names), dtype=float) * sd) ** 2
            total = np.nansum(c)
            for n, v in zip(names, c):
                share.loc[tol[n], o] += (v / total) if total > 0 and np.isfinite(v) else np.nan
        rank = share.max(axis=1, skipna=True).sort_values(ascending=False)
        top, by_mc = self.top_tolerances(share, ctx, order)
        rest = "all other tolerances"
        groups = [tol[n] if tol[n] in top else rest for n in names]
        res = gs.sobol(model, spec, self.n, names, self.outputs, second_order=False, seed=self.seed_of(ctx),
                       num_resamples=self.num_resamples, confidence=self.confidence_of(ctx), evaluate=ctx.evaluator,
                       groups=groups)
        rows = top + ([rest] if rest in groups else [])
        st = pd.DataFrame(np.nan, index=rows, columns=self.outputs)
        conf = st.copy()
        for _, r in res.frame.iterrows():
            st.loc[r["factor"], r["output"]] = r["ST"]
            conf.loc[r["factor"], r["output"]] = r["ST_conf"]
        shown = list(rank.index[:max(self.top, 20)])
        sec = self.section()
        sec.add_text(
            f"Rows: drawing tolerances (the coordinates of one callout and the copies of a per-part family are one "
            f"tolerance); columns: outputs. Left: the five-point (±{self.percent:g} %) linearised share of each "
            "output's variance, (S_i σ_i)² / Σ (correlation ignored), for every tolerance — "
            f"{4 * len(names) + 1} model runs. Right: Sobol "
            f"total indices (Saltelli, n = {self.n}, {res.n_evaluations} model runs) of {len(top)} tolerances — each "
            "output's largest in turn (its largest five-point share; for an output the linearisation cannot see, "
            "a magnitude whose derivative vanishes at the nominal"
            + (f" ({', '.join(by_mc)})" if by_mc else "") + ", its largest first-order index from the Monte "
            "Carlo samples) — the others as one group: the total index includes interactions and the "
            "non-linearity the linear share misses.")
        sec.add_figure(heatmap(share.loc[shown], "Five-point linearised share of variance", "share", "{:.2f}", vmax=1.0),
                       caption="Cross-model sensitivity: five-point linearised variance share (drawing tolerance × "
                               "output)")
        sec.add_figure(heatmap(st, f"Sobol total index (n = {self.n})", "ST", "{:.2f}", vmax=1.0),
                       caption="Cross-model sensitivity: Sobol total index of the top tolerances (their interactions "
                               "included)")
        table = st.copy()
        for o in self.outputs:
            table[o] = [f"{v:.2f} ± {c:.2f}" if np.isfinite(v) else "—" for v, c in zip(st[o], conf[o])]
        sec.add_table(table.reset_index(names="drawing tolerance"),
                      caption=f"Sobol total indices with their {100 * self.confidence_of(ctx):.0f} % bootstrap half-widths")
        sec.add_table(share.loc[shown].reset_index(names="drawing tolerance"), float_format="{:.3f}",
                      caption="Five-point linearised variance shares (the largest tolerances)")
        _notes(sec, fp.notes + res.notes)
        sec.summary = {"outputs": self.outputs, "percent": self.percent, "n_sobol": self.n,
                       "five_point_share": {t: {o: _num(share.loc[t, o]) for o in self.outputs} for t in order},
                       "sobol_total": {t: {o: {"ST": _num(st.loc[t, o]), "conf": _num(conf.loc[t, o])}
                                           for o in self.outputs} for t in rows},
                       "model_runs": {"five_point": 4 * len(names) + 1, "sobol": res.n_evaluations}}
        return sec

    def top_tolerances(self, share, ctx, order) -> tuple[list[str], list[str]]:
        """``top`` drawing tolerances taken from every output in turn (its first, then its second, ...): by
        five-point share, or — where the share is undefined (a magnitude with zero derivative at the
        nominal) — by the first-order index the Monte Carlo samples give (:func:`rvtol.signoff.first_order_drivers`).
        Returns the tolerances and the outputs ranked from the Monte Carlo."""
        from ..signoff import first_order_drivers

        ranking, by_mc = {}, []
        for o in self.outputs:
            col = share[o].dropna()
            if len(col) and col.max() > 0:
                ranking[o] = [t for t in col.sort_values(ascending=False).index if col[t] > 0]
            else:
                by_mc.append(o)
        if by_mc and ctx.mc is not None:
            drivers = first_order_drivers(ctx.mc, ctx.model, ctx.spec, by_mc, self.seed_of(ctx))
            for o in by_mc:
                ranking[o] = [d.tolerance for d in drivers.get(o, []) if d.tolerance in order and d.s1 > 0]
        top, level = [], 0
        while len(top) < self.top and any(level < len(r) for r in ranking.values()):
            for o in self.outputs:
                r = ranking.get(o, [])
                if level < len(r) and r[level] not in top and len(top) < self.top:
                    top.append(r[level])
            level += 1
        return top, [o for o in by_mc if ranking.get(o)]


def _num(v):
    import math

    v = float(v)
    return v if math.isfinite(v) else None
