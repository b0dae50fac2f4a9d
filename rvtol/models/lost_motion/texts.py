"""What the lost-motion breakdown says: its prose and the layout of a :class:`.breakdown.StageBreakdown`.

``layout(result, options) -> list of blocks`` (:mod:`rvtol.blocks`), named by
:mod:`rvtol.models.lost_motion.analyses`.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from ...blocks import Figure, Table, Text, figure_png

DOCUMENT = ("Lost motion of each contribution by the document's formulas as printed (doc 001, document mode): mean ± "
            "T/2 with T as written (means added, tolerances combined by RSS, involute stage divided by the ratio i), "
            "and mean ± 3σ of the same linear model with each factor's own distribution, beside the Monte Carlo of "
            "{n} samples. The involute stage is measured at the input shaft (÷ i = {ratio:g} at the output).")

CONSISTENT = ("Screening estimate of the geometric (zero-load) lost motion: doc 001's three contributions with every "
              "coefficient derived from the kinematics (consistent mode: flank-to-flank play, crank-bearing K = 1, "
              "√(1−K1²) at the first-contact pin, disc-to-output ratio i_b = {i_b:.4f}; "
              "rvtol.models.lost_motion.model). Mean ± 3σ of the linear model with each factor's own distribution "
              "beside the Monte Carlo of {n} samples. The involute stage is measured at the input shaft (÷ i = "
              "{ratio:g} at the output), the cycloid stage and the crank bearings at the disc (× i_b at the output). "
              "The maker's lost motion (hysteresis mid-points within ±3 % of rated torque) adds the elastic "
              "deflection: see the torsion curve.")

STAGES = ("Stage breakdown (arcmin; each stage at its own shaft, the total at the output). 'MC − analytic': the Monte "
          "Carlo mean and σ minus the analytic ones, in standard errors of the Monte Carlo estimate; |value| < 2 is "
          "ordinary sampling scatter, beyond 3 would point to a model or sampling error.")

INVOLUTE_T = ("The document's tolerance formula for the involute stage, T = √D(j)·K/d1, gives {T_doc:.3g}′, while the "
              "same factors give 6σ = {T_6sigma:.3g}′ ({ratio:.3g}×): the mean formula carries 2/d1 (backlash over "
              "the pitch radius) and the tolerance formula 1/d1, and √D(j) is one σ, not the ±3σ band that T means "
              "for the other stages. For the cycloid stage and the crank bearing the document's T equals 6σ.")

CORRELATED = "Note: the analytic columns ignore the spec's correlations; the Monte Carlo includes them."


def stage_table(res) -> pd.DataFrame:
    """The breakdown as the report shows it: each figure with its interval, in arcmin."""
    conf = f"{res.confidence:.0%}"
    rows = []
    for _, r in res.frame.iterrows():
        rows.append({
            "contribution": r["stage"],
            "× to output": f"{r['to_output']:.4g}",
            "document: mean ± T/2 [′]": f"{r['mean']:.4g} ± {r['T_doc'] / 2:.4g}" if np.isfinite(r["T_doc"]) else "—",
            "linear: mean ± 3σ [′]": f"{r['mean']:.4g} ± {3 * r['sigma']:.4g}",
            f"MC mean [{conf} CI] [′]": f"{r['mc_mean']:.4g} [{r['mc_mean_lo']:.4g}, {r['mc_mean_hi']:.4g}]",
            f"MC σ [{conf} CI] [′]": f"{r['mc_std']:.4g} [{r['mc_std_lo']:.4g}, {r['mc_std_hi']:.4g}]",
            "MC 95 % interval [′]": f"{r['mc_P2.5']:.4g} … {r['mc_P97.5']:.4g}",
            "MC P0.135 … P99.865 [′]": f"{r['mc_P0.135']:.4g} … {r['mc_P99.865']:.4g}",
            "MC − analytic (mean, σ) [s.e.]": f"{r['z_mean']:+.1f}, {r['z_sigma']:+.1f}",
        })
    return pd.DataFrame(rows)


def breakdown(res, o) -> list:
    document = res.mode == "document"
    intro = DOCUMENT.format(n=res.n, ratio=res.ratio) if document else \
        CONSISTENT.format(i_b=res.disc_to_output, n=res.n, ratio=res.ratio)
    blocks = [Text(intro), Table(res.geometry, "Geometry (from the design, or derived as shown)")]
    if res.extra is not None:
        blocks.append(Table(res.extra, "Further cycloid-stage factors ξ_i and their partial derivatives"))
    blocks.append(Table(stage_table(res), STAGES))
    inv = res.stage("involute_stage")
    if inv["sigma"] > 0 and document:
        blocks.append(Text(INVOLUTE_T.format(T_doc=inv["T_doc"], T_6sigma=inv["T_6sigma"],
                                             ratio=inv["T_6sigma"] / inv["T_doc"])))
    if res.correlated:
        blocks.append(Text(CORRELATED))
    hist = "Total geometric lost motion: Monte Carlo, analytic normal" + (", document band" if document else "") \
        + " and limit"
    return blocks + [Figure(figure_png(res.plot("total")), hist),
                     Figure(figure_png(res.plot("stages")), "Contributions at the output")]
