"""Plots of Monte Carlo results: histograms with spec limits and fitted normal, convergence."""
from __future__ import annotations

import numpy as np
from scipy import stats

from ..units import label
from . import COLORS, new_axes


def histogram(result, output: str, ax=None, bins: int = 60):
    """Histogram of one output (display units) with spec limits and the fitted normal."""
    fig, ax = new_axes(ax)
    y = result.column(output)
    y = y[np.isfinite(y)]
    unit = label(result.unit_of(output))
    if len(y) == 0:
        ax.text(0.5, 0.5, "no successful samples", ha="center", transform=ax.transAxes)
        return fig
    lo_lim = [r.lower for r in result.requirements if r.output == output and r.lower is not None]
    hi_lim = [r.upper for r in result.requirements if r.output == output and r.upper is not None]
    span_lo, span_hi = float(y.min()), float(y.max())
    if span_hi == span_lo:
        span_hi = span_lo + 1e-12
    hist_range = None
    if span_hi - span_lo <= 1e-9 * max(1.0, abs(span_lo), abs(span_hi)):   # (numerically) constant output
        pad = 1e-6 * max(1.0, abs(span_lo))
        hist_range = (span_lo - pad, span_hi + pad)
    ax.hist(y, bins=bins, range=hist_range, density=True, color=COLORS["data"], alpha=0.75,
            label=f"Monte Carlo (n={len(y)})")
    mu, s = float(np.mean(y)), float(np.std(y, ddof=1)) if len(y) > 1 else 0.0
    if s > 0:
        xs = np.linspace(min([span_lo] + lo_lim), max([span_hi] + hi_lim), 400)
        ax.plot(xs, stats.norm.pdf(xs, mu, s), color=COLORS["fit"], lw=1.5,
                label=f"normal fit μ={mu:.4g}, σ={s:.3g}")
    for v in lo_lim:
        ax.axvline(v, color=COLORS["limit"], ls="--", lw=1.5, label=f"LSL {v:g}")
    for v in hi_lim:
        ax.axvline(v, color=COLORS["limit"], ls="--", lw=1.5, label=f"USL {v:g}")
    ax.set_xlabel(f"{output} [{unit}]")
    ax.set_ylabel(f"density [1/{unit}]")
    ax.legend(loc="best")
    return fig


def convergence(result, output: str, ax=None):
    """Running mean with its confidence band, and running yield(s), against n (log scale)."""
    fig, ax = new_axes(ax, figsize=(6.4, 3.2))
    df = result.convergence()
    df = df[df["output"] == output]
    unit = label(result.unit_of(output))
    ax.fill_between(df["n"], df["mean_lo"], df["mean_hi"], color=COLORS["ci"], alpha=0.3,
                    label=f"{result.confidence:.0%} CI of the mean")
    ax.plot(df["n"], df["mean"], color=COLORS["data"], label="running mean")
    ax.set_xscale("log")
    ax.set_xlabel("samples n")
    ax.set_ylabel(f"mean {output} [{unit}]")
    ycols = [c for c in df.columns if c.startswith("yield_") and df[c].notna().any()]
    if ycols:
        ax2 = ax.twinx()
        for c in ycols:
            ax2.plot(df["n"], df[c] * 100, color=COLORS["ok"], ls="-", lw=1, label="running yield")
        ax2.set_ylabel("yield [%]")
        ax2.grid(False)
        h1, l1 = ax.get_legend_handles_labels()
        h2, l2 = ax2.get_legend_handles_labels()
        ax.legend(h1 + h2, l1 + l2, loc="lower right")
    else:
        ax.legend(loc="best")
    return fig


def factor_histograms(samples, max_factors: int = 12):
    """Small-multiple histograms of the sampled factors (display units)."""
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    k = min(len(samples.names), max_factors)
    cols = 4
    rows = int(np.ceil(k / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(8, 1.7 * rows), squeeze=False)
    vals = samples.display_values()
    for j in range(rows * cols):
        ax = axes[j // cols][j % cols]
        if j >= k:
            ax.axis("off")
            continue
        ax.hist(vals[:, j], bins=40, color=COLORS["data"], alpha=0.75)
        ax.set_title(f"{samples.names[j]} [{label(samples.units[j])}]", fontsize=7)
        ax.ticklabel_format(axis="x", useOffset=False, style="plain")
        ax.xaxis.set_major_locator(MaxNLocator(3))
        ax.tick_params(labelsize=6)
        ax.set_yticks([])
    fig.tight_layout()
    return fig
