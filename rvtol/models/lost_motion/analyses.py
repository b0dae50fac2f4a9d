"""Study analysis of the lost-motion model: stage breakdown (analytic vs Monte Carlo).

``[[analysis]] kind = "lost_motion_breakdown"``: geometry, each stage's mean
± T/2 by the document's formulas and mean ± 3σ of the linear model beside the
Monte Carlo (mean and σ with CIs, 95 % and ±3σ-coverage intervals), the
histogram of the total against its limit and the contributions chart.
(Doc 001's printed figures are compared in :mod:`rvtol.reproduction.doc001_lost_motion`.)
"""
from __future__ import annotations


import numpy as np
import pandas as pd

from ...analysis import Analysis
from ... import stats as st
from ...report.sections import Section, frame_records
from ...units import convert
from .model import LostMotionModel, analytic, factor_moments


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
