"""Plots of the geometric lost-motion analyses: total histogram against the limit, stage breakdown."""
from __future__ import annotations

import numpy as np
from scipy import stats

from . import COLORS, new_axes
from .mc import histogram


def total_histogram(mc, analytic, output: str = "lost_motion", ax=None):
    """Monte Carlo histogram of the total with its limit(s), the linear-model normal and the document's band.

    ``analytic`` is the :func:`rvtol.models.lost_motion.model.analytic` frame (arcmin).
    """
    fig = histogram(mc, output, ax=ax)
    ax = ax or fig.axes[0]
    row = analytic.set_index("stage").loc[output]
    lo, hi = ax.get_xlim()
    xs = np.linspace(lo, hi, 400)
    if row["sigma"] > 0:
        ax.plot(xs, stats.norm.pdf(xs, row["mean"], row["sigma"]), color="black", lw=1, ls=":",
                label=f"analytic μ={row['mean']:.3g}, σ={row['sigma']:.3g}")
    half = 0.5 * row["T_doc"]
    if np.isfinite(half):     # the document's band (document mode only)
        ax.axvspan(row["mean"] - half, row["mean"] + half, color=COLORS["ci"], alpha=0.15,
                   label=f"document mean ± T/2 = {row['mean']:.3g} ± {half:.3g}")
    ax.legend(loc="best")
    return fig


def stage_bars(breakdown, ax=None):
    """Each stage's contribution at the output: mean with ±3σ (linear model) and the document's ±T/2."""
    fig, ax = new_axes(ax)
    d = breakdown
    x = np.arange(len(d))
    ax.bar(x, d["mean_out"], color=COLORS["data"], alpha=0.8, label="mean (at the output)")
    ax.errorbar(x - 0.12, d["mean_out"], yerr=3 * d["sigma_out"], fmt="none", ecolor="black", capsize=4,
                label="± 3σ (linear model)")
    if np.all(np.isfinite(d["T_doc_out"])):     # document mode only
        ax.errorbar(x + 0.12, d["mean_out"], yerr=0.5 * d["T_doc_out"], fmt="none", ecolor=COLORS["fit"],
                    capsize=4, label="± T/2 (document formula)")
    if "mc_mean_out" in d:
        ax.plot(x, d["mc_mean_out"], "D", color=COLORS["ok"], ms=5, label="Monte Carlo mean")
    ax.set_xticks(x, list(d["stage"]))
    ax.set_ylabel("lost motion at the output [arcmin]")
    ax.set_title("Geometric lost motion by contribution")
    ax.legend(fontsize=7)
    return fig


def screening_scatter(screening, maker, limit=None, percent: float = 3.0, ax=None):
    """Per reducer: doc 001's screening estimate (x) against the maker's lost motion on the torsion curve (y)."""
    fig, ax = new_axes(ax, figsize=(5.6, 4.6))
    ax.plot(screening, maker, ".", ms=3, alpha=0.5, color=COLORS["data"], label="reducer (Monte Carlo sample)")
    lo = float(min(np.nanmin(screening), np.nanmin(maker), 0.0))
    hi = float(max(np.nanmax(screening), np.nanmax(maker), limit or 0.0)) * 1.05
    ax.plot([lo, hi], [lo, hi], color="black", lw=0.8, ls=":", label="y = x")
    if limit is not None:
        ax.axhline(limit, color=COLORS["limit"], lw=1, label=f"limit {limit:g}′")
        ax.axvline(limit, color=COLORS["limit"], lw=1, ls="--")
    ax.set_xlim(lo, hi)
    ax.set_ylim(lo, hi)
    ax.set_xlabel("screening estimate, doc 001 consistent mode [arcmin]")
    ax.set_ylabel(f"lost motion at ±{percent:g} % rated, torsion curve [arcmin]")
    ax.legend(loc="upper left", fontsize=7)
    return fig
