"""Plots of the stack-up conventions: each convention's interval beside the requirement limits."""
from __future__ import annotations

import numpy as np

from ..units import label
from . import COLORS, new_axes


def convention_intervals(frame, output: str, unit: str, limits=(), ax=None):
    """One horizontal bar per convention (``frame``: convention, low, high), the limits as dashed lines."""
    n = len(frame)
    fig, ax = new_axes(ax, figsize=(6.4, 0.32 * n + 1.2))
    ys = np.arange(n)[::-1]
    for y, (_, r) in zip(ys, frame.iterrows()):
        mc = str(r["convention"]).startswith("Monte Carlo")
        ax.plot([r["low"], r["high"]], [y, y], lw=5, solid_capstyle="butt",
                color=COLORS["fit"] if mc else COLORS["data"])
    for v in limits:
        ax.axvline(v, color=COLORS["limit"], ls="--", lw=1.2)
    ax.set_yticks(ys)
    ax.set_yticklabels(frame["convention"], fontsize=7)
    ax.set_xlabel(f"{output} [{label(unit)}]")
    ax.grid(axis="y", alpha=0)
    fig.tight_layout()
    return fig
