"""Study analysis of the lost-motion model: stage breakdown (analytic vs Monte Carlo).

``[[analysis]] kind = "lost_motion_breakdown"``: geometry, each stage's mean
± T/2 by the document's formulas (document mode) and mean ± 3σ of the linear
model beside the Monte Carlo (mean and σ with CIs, 95 % and ±3σ-coverage
intervals), the histogram of the total against its limit and the
contributions chart.

``[[analysis]] kind = "lost_motion_screening"``: the screening estimate beside
the maker's lost motion on the 20-DOF torsion curve (:class:`LostMotionScreening`).
(Doc 001's printed figures are compared in :mod:`rvtol.reproduction.doc001_lost_motion`.)
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ...analysis import Analysis
from ... import stats as st
from ... import units
from ...errors import InputError
from ...report.sections import Section, frame_records
from ...units import convert
from .model import FACTORS, LostMotionModel, analytic, factor_moments


def check_model(params, study) -> None:
    if not isinstance(study.model, LostMotionModel):
        raise params.error("kind", "this analysis needs the lost-motion model ([model] kind = \"lost_motion\")")


def analytic_frame(ctx) -> pd.DataFrame:
    m = ctx.model
    return analytic(m.geometry, factor_moments(ctx.spec, m), m.extra)


def _mc_row(mc, name: str, confidence: float) -> dict:
    y = mc.column(name)
    y = np.sort(y[np.isfinite(y)])
    m, mlo, mhi = st.mean_ci(y, confidence)
    s, slo, shi = st.std_ci(y, confidence)
    out = {"mc_mean": m, "mc_mean_lo": mlo, "mc_mean_hi": mhi, "mc_std": s, "mc_std_lo": slo, "mc_std_hi": shi}
    for p in (2.5, 97.5, 0.135, 99.865):
        out[f"mc_P{p:g}"] = st.percentile_ci(y, p / 100, confidence)[0]
    return out


def breakdown_frame(ctx) -> pd.DataFrame:
    """The analytic frame with the Monte Carlo beside it and everything referred to the output."""
    a = analytic_frame(ctx)
    conf = ctx.mc.confidence
    mc = pd.DataFrame([_mc_row(ctx.mc, s, conf) for s in a["stage"]])
    d = pd.concat([a, mc], axis=1)
    for c in ("mean", "T_doc", "sigma", "mc_mean"):
        d[f"{c}_out"] = d[c] * d["to_output"]
    # MC − analytic in standard errors of the Monte Carlo estimate (normal theory for σ)
    n = int(ctx.mc.ok.sum())
    d["z_mean"] = (d["mc_mean"] - d["mean"]) / (d["mc_std"] / np.sqrt(n))
    d["z_sigma"] = (d["mc_std"] - d["sigma"]) / (d["sigma"] / np.sqrt(2.0 * (n - 1)))
    return d


class LostMotionBreakdown(Analysis):
    def setup(self, params, study):
        check_model(params, study)
        self.key = params.str("key", "lost_motion_breakdown")
        self.title = params.str("title", "Geometric lost motion: stages, analytic and Monte Carlo")
        params.finish()

    def run(self, ctx):
        d = breakdown_frame(ctx)
        g = ctx.model.geometry
        sec = Section(self.key, self.title)
        if g.mode == "document":
            sec.add_text(
                "Lost motion of each contribution by the document's formulas as printed (doc 001, document "
                "mode): mean ± T/2 with T as written (means added, tolerances combined by RSS, involute stage "
                "divided by the ratio i), and mean ± 3σ of the same linear model with each factor's own "
                f"distribution, beside the Monte Carlo of {ctx.mc.n} samples. The involute stage is measured at "
                f"the input shaft (÷ i = {g.ratio:g} at the output).")
        else:
            sec.add_text(
                "Screening estimate of the geometric (zero-load) lost motion: doc 001's three contributions with "
                "every coefficient derived from the kinematics (consistent mode: flank-to-flank play, crank-"
                f"bearing K = 1, √(1−K1²) at the first-contact pin, disc-to-output ratio i_b = "
                f"{g.disc_to_output:.4f}; rvtol.models.lost_motion.model). Mean ± 3σ of the linear model with "
                f"each factor's own distribution beside the Monte Carlo of {ctx.mc.n} samples. The involute stage "
                f"is measured at the input shaft (÷ i = {g.ratio:g} at the output), the cycloid stage and the "
                f"crank bearings at the disc (× i_b at the output). The maker's lost motion (hysteresis "
                "mid-points within ±3 % of rated torque) adds the elastic deflection: see the torsion curve.")
        geo = g.to_frame()
        sec.add_table(geo, caption="Geometry (from the design, or derived as shown)")
        if ctx.model.extra:
            sec.add_table(pd.DataFrame([
                {"factor ξ": n, "∂Δφ34/∂ξ [arcmin/µm]": convert(v, "rad/mm", "arcmin/um"),
                 "source": ctx.model.extra_sources.get(n, "")} for n, v in ctx.model.extra.items()]),
                caption="Further cycloid-stage factors ξ_i and their partial derivatives")
        conf = f"{ctx.mc.confidence:.0%}"
        rows = []
        for _, r in d.iterrows():
            rows.append({
                "contribution": r["stage"],
                "× to output": f"{r['to_output']:.4g}",
                "document: mean ± T/2 [′]": f"{r['mean']:.4g} ± {r['T_doc'] / 2:.4g}" if np.isfinite(r["T_doc"])
                else "—",
                "linear: mean ± 3σ [′]": f"{r['mean']:.4g} ± {3 * r['sigma']:.4g}",
                f"MC mean [{conf} CI] [′]": f"{r['mc_mean']:.4g} [{r['mc_mean_lo']:.4g}, {r['mc_mean_hi']:.4g}]",
                f"MC σ [{conf} CI] [′]": f"{r['mc_std']:.4g} [{r['mc_std_lo']:.4g}, {r['mc_std_hi']:.4g}]",
                "MC 95 % interval [′]": f"{r['mc_P2.5']:.4g} … {r['mc_P97.5']:.4g}",
                "MC P0.135 … P99.865 [′]": f"{r['mc_P0.135']:.4g} … {r['mc_P99.865']:.4g}",
                "MC − analytic (mean, σ) [s.e.]": f"{r['z_mean']:+.1f}, {r['z_sigma']:+.1f}",
            })
        sec.add_table(pd.DataFrame(rows), caption="Stage breakdown (arcmin; each stage at its own shaft, the "
                                                  "total at the output). 'MC − analytic': the Monte Carlo mean and "
                                                  "σ minus the analytic ones, in standard errors of the Monte Carlo "
                                                  "estimate; |value| < 2 is ordinary sampling scatter, beyond 3 "
                                                  "would point to a model or sampling error.")
        inv = d.set_index("stage").loc["involute_stage"]
        if inv["sigma"] > 0 and g.mode == "document":
            sec.add_text(
                f"The document's tolerance formula for the involute stage, T = √D(j)·K/d1, gives "
                f"{inv['T_doc']:.3g}′, while the same factors give 6σ = {inv['T_6sigma']:.3g}′ "
                f"({inv['T_6sigma'] / inv['T_doc']:.3g}×): the mean formula carries 2/d1 (backlash over the "
                "pitch radius) and the tolerance formula 1/d1, and √D(j) is one σ, not the ±3σ band that T "
                "means for the other stages. For the cycloid stage and the crank bearing the document's T "
                "equals 6σ.")
        if ctx.spec.correlation is not None:
            sec.add_text("Note: the analytic columns ignore the spec's correlations; the Monte Carlo includes them.")
        from ...plotting.lost_motion import stage_bars, total_histogram

        sec.add_figure(total_histogram(ctx.mc, d), caption="Total geometric lost motion: Monte Carlo, analytic "
                                                           "normal" + (", document band" if g.mode == "document"
                                                                       else "") + " and limit")
        sec.add_figure(stage_bars(d), caption="Contributions at the output")
        sec.summary = {"mode": g.mode, "geometry": frame_records(geo),
                       "stages": frame_records(d.drop(columns=["z_mean", "z_sigma"])),
                       "mc_minus_analytic_se": {r["stage"]: {"mean": float(r["z_mean"]), "sigma": float(r["z_sigma"])}
                                                for _, r in d.iterrows()}}
        return sec


# --------------------------------------------------------------------------- screening beside the torsion curve
class LostMotionScreening(Analysis):
    """``[[analysis]] kind = "lost_motion_screening"``: doc 001's screening estimate beside the maker's figures.

    ::

        [[analysis]]
        kind = "lost_motion_screening"
        samples = 1000      # torsion curves on a random subsample of the Monte Carlo (all if fewer)
        percent = 3.0       # lost motion within ±percent % of rated torque (REFERENCE; others use 5)
        design = "..."      # 20-DOF design of the torsion curve (default: the study's design)
        limit = 1.0         # arcmin (default: the study's requirement on lost_motion, else the
                            # design's reducer.lost_motion_limit)
        model = "torsion"   # composed study: the torsion-curve stage (default: the only one)
        screening = "screening"   # composed study: the lost-motion stage (default: the only one)

    Works on a study whose model is the lost-motion model (the torsion curve is evaluated on a
    subsample, sub-stream ``screening_subsample``), the torsion-curve model (its Monte Carlo outputs
    are the maker's figures; the screening estimate is computed for every sample), a composed study
    with a torsion-curve and a lost-motion stage (keys ``model`` and ``screening`` name them when there
    are several; both stages' Monte Carlo results on every sample, the screening in both modes on the
    screening stage's mapped inputs) or any model with
    ``screening_inputs(X)`` (:mod:`rvtol.models.torsion_curve.screening`, which also gives the factor
    bridge between the two vocabularies).  Sections: per-factor rates (document, consistent, 20-DOF
    finite differences), the two screening modes beside the torsion-curve lost motion, backlash and
    elastic part on the same reducers, samples at quantiles of the screening estimate, a scatter plot.
    """

    def setup(self, params, study):
        from ...design import load_design
        from ..torsion_curve.model import TorsionCurveModel
        from ..transmission.geometry import geometry_from_design
        from .model import LostMotionGeometry

        self.key = params.str("key", "lost_motion_screening")
        self.title = params.str("title", "Screening estimate (doc 001) beside the maker's lost motion (torsion curve)")
        m = study.model
        if getattr(m, "stages", None):                 # a composed study: its torsion-curve and screening stages
            from ...analysis import target_model

            self.source = "composed"
            self.tc = target_model(params, study, TorsionCurveModel, "torsion_curve")
            self.lm = target_model(params, study, LostMotionModel, "lost_motion", key="screening")
        elif isinstance(m, LostMotionModel):
            self.source = "lost_motion"
        elif isinstance(m, TorsionCurveModel):
            self.source = "torsion_curve"
        elif hasattr(m, "screening_inputs"):
            self.source = "own"
        else:
            raise params.error("kind", "this analysis needs the lost-motion or the torsion-curve model, or a model "
                                       "with screening_inputs(X) (rvtol.models.torsion_curve.screening)")
        path = params.path_value("design", study.base_dir, None)
        design20 = load_design(path) if path is not None else study.design
        if design20 is None:
            raise params.error("design", "the torsion curve needs a 20-DOF design ([study] design or design = ...)")
        self.g20 = self.tc.model.geometry if self.source == "composed" and path is None else \
            geometry_from_design(design20)
        if self.source == "lost_motion":
            self.lm_geometry = m.geometry
        elif self.source == "composed":
            self.lm_geometry = self.lm.model.geometry
        else:
            d = study.design if study.design is not None else design20
            try:
                self.lm_geometry = LostMotionGeometry.from_design(d, "document")
            except (InputError, KeyError):
                self.lm_geometry = LostMotionGeometry.from_design(d, "consistent")
        lg, g20 = self.lm_geometry, self.g20
        same = (lg.cycloid_teeth == g20.z_c and math.isclose(lg.eccentricity, g20.ecc, rel_tol=1e-9)
                and math.isclose(lg.ratio, g20.ratio, rel_tol=1e-9) and math.isclose(lg.K1, g20.K1, rel_tol=1e-9))
        if not same:
            raise params.error("design", "the torsion curve's design is not the reducer of the screening estimate "
                                         "(cycloid teeth, eccentricity, ratio or K1 differ)")
        if self.source in ("torsion_curve", "composed"):
            tcm = self.tc.model if self.source == "composed" else m
            self.percent = params.float("percent", tcm.percent, min=0.01, max=50.0)
            if self.percent != tcm.percent:
                raise params.error("percent", f"the study's torsion-curve model reads lost motion at ±{m.percent:g} %"
                                              " (its Monte Carlo outputs are used): give the same percent")
        else:
            self.percent = params.float("percent", 3.0, min=0.01, max=50.0)
        self.samples = params.int("samples", 1000, min=10)
        limit = params.quantity("limit", "arcmin", None, positive=True)
        if limit is None:
            out = self.tc.output("lost_motion") if self.source == "composed" else "lost_motion"
            req = [r for r in study.requirements if r.output == out and r.upper is not None]
            if req:
                q = next(q for q in m.outputs if q.name == out)
                limit = float(units.to_base(req[0].upper, req[0].unit or q.shown_unit))
            elif "reducer.lost_motion_limit" in design20:
                limit = float(design20["reducer.lost_motion_limit"])
        self.limit = None if limit is None else float(units.from_base(limit, "arcmin"))
        params.finish()

    # ------------------------------------------------------------------
    def _composed_inputs(self, ctx, rows):
        """Both stages' vocabularies in a composed study: the screening stage's mapped inputs of every row;
        the drawing tolerances one stage depends on and the other does not (by part)."""
        from ..torsion_curve.screening import ScreeningInputs

        lm = self.lm.model
        X_lm = self.lm.inputs(ctx.mc.samples.values[rows])
        deps = ctx.model.depends_on()
        d_tc, d_lm = deps.get(self.tc.output("lost_motion"), set()), deps.get(self.lm.output("lost_motion"), set())

        def by_part(names):
            parts = {}
            for n in names:
                g = ctx.spec.factor(n).group or n
                parts[g] = parts.get(g, 0) + 1
            return tuple(f"{g} ({k} factor{'s' if k > 1 else ''})" for g, k in sorted(parts.items()))

        return ScreeningInputs(lm.inputs, X_lm, self.tc.model.inputs, None, by_part(d_lm - d_tc),
                               by_part(d_tc - d_lm), dict(lm.extra), dict(lm.extra_like))

    def _rows(self, ctx):
        from ...sampling import substream

        n = ctx.mc.n
        if self.source in ("torsion_curve", "composed") or self.samples >= n:
            return np.arange(n)
        return np.sort(substream(ctx.seed, "screening_subsample").choice(n, self.samples, replace=False))

    def run(self, ctx):
        from ...plotting.lost_motion import screening_scatter
        from ...stats import proportion_ci
        from ..torsion_curve.model import TorsionCurveModel
        from ..torsion_curve.screening import backlash_rates, screening_inputs, screening_models

        ev = ctx.evaluator
        amin = lambda v: np.asarray(units.from_base(v, "arcmin"), dtype=float)  # noqa: E731
        per_um = lambda v: float(convert(v, "rad/mm", "arcmin/um"))  # noqa: E731
        rows = self._rows(ctx)
        if self.source == "composed":
            inputs = self._composed_inputs(ctx, rows)
        else:
            inputs = screening_inputs(ctx.model, ctx.mc.samples.values[rows], self.g20.z_b)
        if self.source in ("torsion_curve", "composed"):
            out = self.tc.output if self.source == "composed" else str
            ok = ctx.mc.ok[rows]
            tc_lm, tc_bl = ctx.mc.column(out("lost_motion"))[rows], ctx.mc.column(out("backlash"))[rows]   # arcmin
        else:
            tcm = TorsionCurveModel(self.g20, inputs.tc_names, percent=self.percent)
            e = ev(tcm, inputs.X_tc, "torsion curves (screening)")
            ok = e.ok
            tc_lm, tc_bl = amin(e.Y[:, 0]), amin(e.Y[:, 2])
        models = screening_models(self.lm_geometry, inputs)
        doc = ev(models["document"], inputs.X_lm, "screening (document)")
        con = ev(models["consistent"], inputs.X_lm, "screening (consistent)")
        ok = ok & doc.ok & con.ok
        g = models["consistent"].geometry
        inv = amin(con.Y[:, 1]) / g.ratio                      # involute play at the output, in series
        d = pd.DataFrame({"document": amin(doc.Y[:, 0]), "consistent": amin(con.Y[:, 0]), "involute": inv,
                          "backlash": tc_bl + inv, "lost_motion": tc_lm + inv, "elastic": tc_lm - tc_bl})[ok]
        d["gap"] = d["lost_motion"] - d["consistent"]
        p = self.percent
        labels = {
            "document": "doc 001 as printed (document mode)",
            "consistent": "screening estimate: doc 001, consistent mode",
            "backlash": "torsion curve: backlash at zero torque",
            "lost_motion": f"torsion curve: lost motion ±{p:g} % rated (maker's definition)",
            "elastic": f"lost motion − backlash: elastic part within ±{p:g} % (and play taken up only under load)",
            "involute": "involute-stage play at the output (Δφ12/i, in series)",
            "gap": "torsion-curve lost motion − screening estimate",
        }
        stats_rows = []
        for c, label in labels.items():
            y = np.sort(d[c].to_numpy())
            row = {"quantity": label, "mean [′]": y.mean(), "σ [′]": y.std(ddof=1) if len(y) > 1 else math.nan,
                   "P50 [′]": np.quantile(y, 0.5), "P99 [′]": np.quantile(y, 0.99), "max [′]": y[-1]}
            if self.limit is not None and c in ("document", "consistent", "backlash", "lost_motion"):
                k = int((y > self.limit).sum())
                lo, hi = proportion_ci(k, len(y), ctx.mc.confidence)
                row[f"share > {self.limit:g}′ [{ctx.mc.confidence:.0%} CI]"] = f"{k / len(y):.4f} [{lo:.4f}, {hi:.4f}]"
            stats_rows.append(row)
        stats_frame = pd.DataFrame(stats_rows)

        # per-factor rates at the output
        rates = backlash_rates(self.g20, percent=p, evaluate=lambda mdl, X: (lambda r: (r.Y, r.status))(
            ev(mdl, X, "20-DOF backlash rates")))
        cd, cc = models["document"].geometry.output_coefficients(models["document"].extra), \
            g.output_coefficients(models["consistent"].extra)
        rate_rows = []
        for f in [n for n in (*FACTORS, *inputs.extra) if n in cd]:
            like = f if f in rates else inputs.extra_like.get(f)
            r20 = rates.get(like) if like else None
            rate_rows.append({
                "factor": f, "document [′/µm]": per_um(cd[f]), "consistent [′/µm]": per_um(cc[f]),
                "20-DOF backlash [′/µm]": per_um(r20["backlash"]) if r20 else math.nan,
                f"20-DOF lost motion ±{p:g} % [′/µm]": per_um(r20["lost_motion"]) if r20 else math.nan,
                "document / 20-DOF": cd[f] / r20["backlash"] if r20 else math.nan,
                "consistent / 20-DOF": cc[f] / r20["backlash"] if r20 else math.nan,
                "20-DOF factor": {"Delta_b": "δ_b = Δ/2, all six bearings", "Delta_r_c": "delta_pin (every pin)",
                                  "Delta_r_p": "R_pin[k] (every pin)"}.get(like, "— (bilateral mesh: played in "
                                                                                 "series, ÷ i)"
                                                                           if f in ("E_w", "Delta_a", "Delta_F_r")
                                                                           else "—"),
            })
        rate_frame = pd.DataFrame(rate_rows)

        # reducers at quantiles of the screening estimate
        q_rows = []
        order = d.sort_values("consistent")
        for q in (0.5, 0.9, 0.99, 1.0):
            r = order.iloc[min(len(order) - 1, int(round(q * (len(order) - 1))))]
            q_rows.append({"screening quantile": f"P{100 * q:g}" if q < 1 else "max",
                           "document [′]": r["document"], "consistent [′]": r["consistent"],
                           "torsion-curve backlash [′]": r["backlash"],
                           f"torsion-curve lost motion ±{p:g} % [′]": r["lost_motion"],
                           "elastic part [′]": r["elastic"]})
        q_frame = pd.DataFrame(q_rows)

        sec = Section(self.key, self.title)
        m = d.mean()
        where = ("every Monte Carlo sample (the study's torsion-curve outputs)"
                 if self.source in ("torsion_curve", "composed")
                 else f"{len(rows)} reducers drawn from the Monte Carlo sample (sub-stream screening_subsample)")
        sec.add_text(
            "What a sign-off judges is the maker's lost motion: the angle between the mid-points of the hysteresis "
            f"width at ±{p:g} % of rated torque, input locked, elastic deflection included (REFERENCE), here from "
            "the 20-DOF torsion curve. Doc 001's formula is a screening estimate of the geometric (zero-load) part "
            "only. Both on the same reducers — " + where + f": screening estimate (consistent mode) mean "
            f"{m['consistent']:.3f}′, doc 001 as printed {m['document']:.3f}′; torsion curve backlash "
            f"{m['backlash']:.3f}′ and lost motion {m['lost_motion']:.3f}′, of which {m['elastic']:.3f}′ is elastic "
            f"deflection within ±{p:g} %. The 20-DOF sun–planet mesh has no backlash, so the involute-stage play "
            f"(Δφ12/i, mean {m['involute']:.4f}′) is added to the torsion-curve figures in series (exact at zero "
            "load: plays in series add).")
        if self.source == "composed":
            sec.add_text(f"One drawing sample drives both: the screening stage {self.lm.stage!r} reads its seven "
                         f"inputs through the declared mapping, the torsion stage {self.tc.stage!r} the full 20-DOF "
                         "error state. The screening sums its stages' plays; the 20-DOF finds the smallest play of "
                         "the disc's three degrees of freedom together (a disc that translates within its needle "
                         "clearances closes its pins sooner), so with clearances in the pins AND the needle sets "
                         "the screening's sum lies above the torsion curve's backlash — a conservative screen.")
        if inputs.unseen_by_tc:
            sec.add_text("Not seen by the torsion curve (no 20-DOF counterpart): " + ", ".join(inputs.unseen_by_tc) + ".")
        if inputs.unseen_by_lm:
            sec.add_text("Not in doc 001's formula (the screening estimate ignores them; the torsion curve sees them): "
                         + ", ".join(inputs.unseen_by_lm) + ".")
        nbad = int((~ok).sum())
        if nbad:
            sec.add_text(f"{nbad} of {len(ok)} reducers could not be evaluated (e.g. a negative clearance) and are "
                         "left out of the comparison.")
        sec.add_table(stats_frame, f"Screening estimate and maker's figures on the same {len(d)} reducers (arcmin)")
        sec.add_table(rate_frame, "Rates at the output per factor: doc 001 as printed, consistent mode, and the "
                                  "20-DOF torsion curve (central differences of the backlash and of the lost motion "
                                  "around 2 µm of clearance on the crank bearings and pins)")
        sec.add_table(q_frame, "Reducers at quantiles of the screening estimate")
        sec.add_figure(screening_scatter(d["consistent"].to_numpy(), d["lost_motion"].to_numpy(), self.limit, p),
                       "Per reducer: screening estimate against the torsion-curve lost motion")
        sec.summary = {"n": int(len(d)), "failed": nbad, "percent": p, "limit_arcmin": self.limit,
                       "mean_arcmin": {c: float(m[c]) for c in labels},
                       "statistics": frame_records(stats_frame), "rates": frame_records(rate_frame),
                       "quantiles": frame_records(q_frame),
                       "unseen_by_torsion_curve": list(inputs.unseen_by_tc),
                       "unseen_by_screening": list(inputs.unseen_by_lm)}
        return sec
