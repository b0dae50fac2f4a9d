"""Plots of production analyses: per-unit prediction intervals, selective assembly (distributions with
and without grading, yield against the number of classes, stock balance)."""
from __future__ import annotations

import numpy as np

from ..units import label
from . import COLORS, new_axes

#: colour of each per-unit verdict
VERDICT_COLORS = {"conforms": COLORS["ok"], "undecided": "#E1A33B", "does not conform": COLORS["limit"]}


def plot_unit_intervals(units, median, lo, hi, verdicts, *, output: str, unit: str, lower=None, upper=None,
                        interval: float = 0.95, ax=None):
    """One row per reducer: the median (dot) and the prediction interval (bar), coloured by the unit's
    verdict on this output's requirement(s); the limits as dashed lines."""
    n = len(units)
    fig, ax = new_axes(ax, figsize=(6.4, max(2.0, 0.32 * n + 1.0)))
    yy = np.arange(n)[::-1]
    for y, m, a, b, v in zip(yy, median, lo, hi, verdicts):
        c = VERDICT_COLORS.get(v, COLORS["data"])
        if np.isfinite(a) and np.isfinite(b):
            ax.plot([a, b], [y, y], color=c, lw=2.2, solid_capstyle="butt")
        if np.isfinite(m):
            ax.plot(m, y, "o", color=c, ms=4.5)
    for v, name in ((lower, "LSL"), (upper, "USL")):
        if v is not None:
            ax.axvline(v, color=COLORS["limit"], ls="--", lw=1.2, label=f"{name} {v:g}")
    for v, c in VERDICT_COLORS.items():
        if v in verdicts:
            ax.plot([], [], color=c, lw=2.2, label=v)
    ax.set_yticks(yy, units, fontsize=7)
    ax.set_xlabel(f"{output} [{label(unit)}] — median and {interval:.0%} prediction interval")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7)
    ax.grid(axis="y", visible=False)
    return fig


def plot_graded_distributions(series: dict, *, output: str, unit: str, lower=None, upper=None, ax=None,
                              bins: int = 50):
    """Histograms (step outlines, common bins) of one output for several assembly cases
    (``series``: case label -> values), with the limits."""
    fig, ax = new_axes(ax)
    vals = [np.asarray(v, float)[np.isfinite(v)] for v in series.values()]
    allv = np.concatenate(vals) if vals else np.array([])
    if allv.size == 0:
        ax.text(0.5, 0.5, "no successful samples", ha="center", transform=ax.transAxes)
        return fig
    lo, hi = float(allv.min()), float(allv.max())
    if hi <= lo:
        hi = lo + 1e-9 * max(1.0, abs(lo))
    edges = np.linspace(lo, hi, bins + 1)
    colors = [COLORS["ci"], COLORS["data"], COLORS["fit"], COLORS["ok"], "#8172B3"]
    for (name, _), v, c in zip(series.items(), vals, colors * 3):
        ax.hist(v, bins=edges, density=True, histtype="step", lw=1.6, color=c, label=f"{name} (n={v.size})")
    for v, name in ((lower, "LSL"), (upper, "USL")):
        if v is not None:
            ax.axvline(v, color=COLORS["limit"], ls="--", lw=1.2, label=f"{name} {v:g}")
    ax.set_xlabel(f"{output} [{label(unit)}]")
    ax.set_ylabel(f"density [1/{label(unit)}]")
    ax.legend(loc="best", fontsize=7)
    return fig


def plot_yield_against_classes(k, estimate, lo, hi, *, title: str = "", optimised=None, ax=None):
    """Yield (with its confidence interval) against the number of classes; ``optimised``: an optional
    ``(k, estimate, lo, hi)`` of optimised limits, drawn as a star."""
    fig, ax = new_axes(ax, figsize=(5.6, 3.4))
    k, e, a, b = (np.asarray(v, float) for v in (k, estimate, lo, hi))
    ax.errorbar(k, 100 * e, yerr=[100 * (e - a), 100 * (b - e)], fmt="o-", color=COLORS["data"], capsize=3,
                label="equal-probability classes")
    if optimised is not None:
        ko, eo, ao, bo = optimised
        ax.errorbar([ko], [100 * eo], yerr=[[100 * (eo - ao)], [100 * (bo - eo)]], fmt="*", ms=11,
                    color=COLORS["fit"], capsize=3, label="optimised limits")
    ax.set_xlabel("number of classes (1 = no grading)")
    ax.set_ylabel("yield [%]")
    ax.set_xticks(sorted(set(k.astype(int).tolist() + ([int(optimised[0])] if optimised is not None else []))))
    if title:
        ax.set_title(title)
    ax.legend(loc="best")
    return fig


def plot_stock_balance(classes, made, used, leftover, *, ax=None):
    """Per class: parts made (graded batch), used and left over."""
    fig, ax = new_axes(ax, figsize=(5.6, 3.2))
    x = np.arange(len(classes))
    w = 0.28
    ax.bar(x - w, made, w, color=COLORS["ci"], label="made")
    ax.bar(x, used, w, color=COLORS["data"], label="used")
    ax.bar(x + w, leftover, w, color=COLORS["fit"], label="left over")
    ax.set_xticks(x, [str(c) for c in classes])
    ax.set_xlabel("class")
    ax.set_ylabel("parts")
    ax.legend(loc="best")
    return fig


def plot_prior_posterior(units, frame, *, output: str, unit: str, lower=None, upper=None, interval: float = 0.95,
                         ax=None):
    """One row per reducer: the prior interval (light bar), the posterior interval after its end-of-line test
    (dark bar, median dot) and the reading itself (cross); ``frame``: per reducer ``lo/median/hi prior``,
    ``… posterior`` and ``measured``."""
    n = len(units)
    fig, ax = new_axes(ax, figsize=(6.4, max(2.0, 0.36 * n + 1.0)))
    yy = np.arange(n)[::-1]
    for y, (_, r) in zip(yy, frame.iterrows()):
        ax.plot([r["lo prior"], r["hi prior"]], [y + 0.15] * 2, color=COLORS["ci"], lw=2.2, solid_capstyle="butt")
        ax.plot([r["lo posterior"], r["hi posterior"]], [y - 0.15] * 2, color=COLORS["data"], lw=2.2,
                solid_capstyle="butt")
        ax.plot(r["median posterior"], y - 0.15, "o", color=COLORS["data"], ms=4)
        if np.isfinite(r["measured"]):
            ax.plot(r["measured"], y, "x", color=COLORS["fit"], ms=6, mew=1.6)
    for v, name in ((lower, "LSL"), (upper, "USL")):
        if v is not None:
            ax.axvline(v, color=COLORS["limit"], ls="--", lw=1.2, label=f"{name} {v:g}")
    ax.plot([], [], color=COLORS["ci"], lw=2.2, label="prior (measured parts)")
    ax.plot([], [], color=COLORS["data"], lw=2.2, label="after the end-of-line test")
    ax.plot([], [], "x", color=COLORS["fit"], label="end-of-line reading")
    ax.set_yticks(yy, units, fontsize=7)
    ax.set_xlabel(f"{output} [{label(unit)}] — {interval:.0%} prediction interval")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7)
    ax.grid(axis="y", visible=False)
    return fig
