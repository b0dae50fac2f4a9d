"""Plots of the engineers' inputs: the Q-Q plot of measured values against their distribution."""
from __future__ import annotations

import numpy as np

from ..units import label
from . import COLORS, new_axes


def qq_plot(qq, name: str, unit: str, what: str, ax=None):
    """Q-Q plot: ``qq`` has columns ``theoretical`` (quantiles of the distribution at the Hazen
    positions) and ``sample`` (the sorted values); the line is y = x."""
    fig, ax = new_axes(ax, figsize=(4.2, 3.6))
    t, s = np.asarray(qq["theoretical"], float), np.asarray(qq["sample"], float)
    ax.plot(t, s, "o", ms=3, color=COLORS["data"], alpha=0.8, label=f"measured (n={len(s)})")
    lo, hi = float(min(t.min(), s.min())), float(max(t.max(), s.max()))
    ax.plot([lo, hi], [lo, hi], color=COLORS["fit"], lw=1.2, label="y = x")
    u = label(unit)
    ax.set_xlabel(f"{what} quantile [{u}]")
    ax.set_ylabel(f"measured {name} [{u}]")
    ax.legend(loc="upper left")
    return fig
