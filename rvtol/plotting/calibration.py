"""Plots of a calibration: measured curve beside the calibrated model, and the residuals."""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from . import COLORS


def plot_overlay(x, measured, model, used, *, xlabel: str, ylabel: str, title: str = "",
                 split_at_zero: bool = False, unit: str = ""):
    """Two stacked axes: measured points (used ones filled, left-out ones grey) and the model at the
    measured abscissae (a line; broken at zero when ``split_at_zero``, where a frictionless torsion
    curve jumps across its clearances); below, the residuals model − measurement of the used points."""
    x, measured, model, used = (np.asarray(a) for a in (x, measured, model, used))
    fig, (ax, rax) = plt.subplots(2, 1, figsize=(6.4, 5.0), sharex=True, gridspec_kw={"height_ratios": [3, 1.3]})
    ax.plot(x[used], measured[used], "o", ms=2.5, color=COLORS["data"], label="measured")
    if (~used).any():
        ax.plot(x[~used], measured[~used], "o", ms=2.5, color=COLORS["ci"], mfc="none", label="measured, not fitted")
    parts = [x > 0, x < 0] if split_at_zero else [np.ones(x.size, bool)]
    for n, sel in enumerate(parts):
        sel = sel & np.isfinite(model)
        o = np.argsort(x[sel], kind="stable")
        ax.plot(x[sel][o], model[sel][o], "-", lw=1.2, color=COLORS["fit"], label="calibrated model" if n == 0 else None)
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title)
    ax.legend(loc="best")
    r = (model - measured)[used]
    rax.axhline(0.0, color="k", lw=0.6)
    rax.plot(x[used], r, "o", ms=2.2, color=COLORS["data"])
    rms = float(np.sqrt(np.mean(r ** 2))) if r.size else float("nan")
    rax.set_ylabel(f"model − measured{f' [{unit}]' if unit else ''}")
    rax.set_xlabel(xlabel)
    rax.set_title(f"residuals (RMS {rms:.3g}{f' {unit}' if unit else ''})", fontsize=8)
    fig.tight_layout()
    return fig


def plot_correlation(frame, ax=None):
    """The correlation matrix of the estimates as a heat map (``frame``: names × names)."""
    from . import new_axes

    fig, ax = new_axes(ax, figsize=(4.8, 4.0))
    v = frame.to_numpy(dtype=float)
    im = ax.imshow(v, vmin=-1, vmax=1, cmap="RdBu_r")
    ax.set_xticks(range(len(frame.columns)), frame.columns, rotation=45, ha="right", fontsize=7)
    ax.set_yticks(range(len(frame.index)), frame.index, fontsize=7)
    for i in range(v.shape[0]):
        for j in range(v.shape[1]):
            ax.text(j, i, "—" if not np.isfinite(v[i, j]) else f"{v[i, j]:+.2f}", ha="center", va="center", fontsize=7)
    ax.grid(False)
    fig.colorbar(im, ax=ax, fraction=0.046, pad=0.04, label="ρ")
    return fig
