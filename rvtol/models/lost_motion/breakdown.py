"""The stage breakdown of the lost-motion model: analytic mean ± T/2 and ±3σ beside the Monte Carlo.

:func:`stage_breakdown` returns a :class:`StageBreakdown`: per contribution (the three stages and
the total) the analytic figures of :func:`.model.analytic`, the Monte Carlo's mean and σ with their
intervals, the 95 % and ±3σ-coverage intervals, everything referred to the output, and the
difference between the two in standard errors of the Monte Carlo estimate.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ... import stats as st
from ...records import frame_records
from ...units import convert
from .model import LostMotionModel, analytic, factor_moments


def analytic_frame(model: LostMotionModel, spec) -> pd.DataFrame:
    """:func:`.model.analytic` of the model with the spec's factor moments (arcmin)."""
    return analytic(model.geometry, factor_moments(spec, model), model.extra)


def _mc_row(mc, name: str, confidence: float) -> dict:
    y = mc.column(name)
    y = np.sort(y[np.isfinite(y)])
    m, mlo, mhi = st.mean_ci(y, confidence)
    s, slo, shi = st.std_ci(y, confidence)
    out = {"mc_mean": m, "mc_mean_lo": mlo, "mc_mean_hi": mhi, "mc_std": s, "mc_std_lo": slo, "mc_std_hi": shi}
    for p in (2.5, 97.5, 0.135, 99.865):
        out[f"mc_P{p:g}"] = st.percentile_ci(y, p / 100, confidence)[0]
    return out


@dataclass
class StageBreakdown:
    """``frame``: one row per contribution (``stage``): the analytic columns, ``mc_*`` (Monte Carlo),
    ``*_out`` (referred to the output) and ``z_mean``, ``z_sigma`` (Monte Carlo − analytic, in standard
    errors); ``geometry``: the model's geometry table; ``extra``: the further cycloid-stage factors."""

    frame: pd.DataFrame
    geometry: pd.DataFrame
    extra: pd.DataFrame | None
    mode: str
    ratio: float
    disc_to_output: float
    n: int
    confidence: float
    correlated: bool
    mc: object = field(repr=False)

    def to_frame(self) -> pd.DataFrame:
        return self.frame

    def stage(self, name: str) -> pd.Series:
        return self.frame.set_index("stage").loc[name]

    def plot(self, which: str = "total"):
        """``"total"``: the Monte Carlo histogram of the total with the analytic normal (and the document's
        band) and the limit; ``"stages"``: each contribution at the output."""
        from ...plotting.lost_motion import stage_bars, total_histogram

        return total_histogram(self.mc, self.frame) if which == "total" else stage_bars(self.frame)

    def summary(self) -> dict:
        d = self.frame
        return {"mode": self.mode, "geometry": frame_records(self.geometry),
                "stages": frame_records(d.drop(columns=["z_mean", "z_sigma"])),
                "mc_minus_analytic_se": {r["stage"]: {"mean": float(r["z_mean"]), "sigma": float(r["z_sigma"])}
                                         for _, r in d.iterrows()}}


def stage_breakdown(model: LostMotionModel, spec, mc) -> StageBreakdown:
    """The analytic frame with the Monte Carlo ``mc`` beside it and everything referred to the output."""
    a = analytic_frame(model, spec)
    conf = mc.confidence
    mcf = pd.DataFrame([_mc_row(mc, s, conf) for s in a["stage"]])
    d = pd.concat([a, mcf], axis=1)
    for c in ("mean", "T_doc", "sigma", "mc_mean"):
        d[f"{c}_out"] = d[c] * d["to_output"]
    # MC − analytic in standard errors of the Monte Carlo estimate (normal theory for σ)
    n = int(mc.ok.sum())
    d["z_mean"] = (d["mc_mean"] - d["mean"]) / (d["mc_std"] / np.sqrt(n))
    d["z_sigma"] = (d["mc_std"] - d["sigma"]) / (d["sigma"] / np.sqrt(2.0 * (n - 1)))
    g = model.geometry
    extra = None
    if model.extra:
        extra = pd.DataFrame([{"factor ξ": n_, "∂Δφ34/∂ξ [arcmin/µm]": convert(v, "rad/mm", "arcmin/um"),
                               "source": model.extra_sources.get(n_, "")} for n_, v in model.extra.items()])
    return StageBreakdown(d, g.to_frame(), extra, g.mode, g.ratio, g.disc_to_output, mc.n, conf,
                          spec.correlation is not None, mc)
