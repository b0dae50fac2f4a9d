"""Plots of the transmission-error model: TE curve, order spectrum, sensitivity ranking, S-versus-e."""
from __future__ import annotations

import numpy as np

from . import COLORS, new_axes

_PALETTE = ["#4C72B0", "#DD8452", "#55A868", "#C44E52", "#8172B3", "#937860", "#DA8BC3", "#8C8C8C",
            "#CCB974", "#64B5CD", "#1B1B1B", "#A0522D"]


def te_curve(result, ax=None, label: str | None = None, color: str | None = None):
    """Δθ_ca (arcsec) against the output angle over one revolution."""
    fig, ax = new_axes(ax)
    ax.plot(np.degrees(result.theta_c), result.te, lw=0.9, color=color or COLORS["data"],
            label=label or f"{result.mode}: Δθ_er = {result.te_pp:.3g} arcsec")
    _mark_extremes(ax, result, color)
    ax.set_xlabel("output angle θ_c [deg]")
    ax.set_ylabel("transmission error Δθ_ca [arcsec]")
    ax.set_xlim(0, 360)
    ax.legend(loc="best")
    return fig


def _mark_extremes(ax, result, color=None, shift: float = 0.0):
    """The curve's largest and smallest TE refined between the positions (quasi-static results), as markers."""
    e = getattr(result, "extremes", None)
    if e is None:
        return
    arcsec = 180.0 * 3600.0 / np.pi
    ax.plot(np.degrees([e.theta_max, e.theta_min]), [e.te_max * arcsec - shift, e.te_min * arcsec - shift], "o",
            ms=4, mfc="none", color=color or COLORS["data"])


def te_curves(results: dict, ax=None):
    """Several TE curves (``{label: TEResult}``) on one axis, each shifted to zero mean."""
    fig, ax = new_axes(ax)
    for n, (lab, r) in enumerate(results.items()):
        ax.plot(np.degrees(r.theta_c), r.te - r.te.mean(), lw=1.2 if n == 0 else 0.8, ls="-" if n == 0 else "--",
                color=_PALETTE[n % len(_PALETTE)], label=f"{lab}: Δθ_er = {r.te_pp:.3g} arcsec")
        _mark_extremes(ax, r, _PALETTE[n % len(_PALETTE)], shift=r.te.mean())
    ax.set_xlabel("output angle θ_c [deg]")
    ax.set_ylabel("Δθ_ca − mean [arcsec]")
    ax.set_xlim(0, 360)
    ax.legend(loc="best", fontsize=7)
    return fig


def spectrum(result, ax=None, max_order: int | None = None, label: str | None = None):
    """Order spectrum of the TE (amplitude per order, orders per output revolution)."""
    fig, ax = new_axes(ax)
    s = result.spectrum()
    k = s["order [1/rev]"].to_numpy()[1:]
    a = s["amplitude [arcsec]"].to_numpy()[1:]
    if max_order is None:
        big = np.flatnonzero(a > 1e-3 * max(a.max(), 1e-300))
        max_order = int(min(k[-1], max(50, 1.1 * k[big[-1]]))) if big.size else int(k[-1])
    m = k <= max_order
    ax.vlines(k[m], 0, a[m], color=COLORS["data"], lw=1.2, label=label)
    ax.set_xlabel("order [1/output revolution]")
    ax.set_ylabel("TE amplitude [arcsec]")
    ax.set_xlim(0, max_order)
    ax.set_ylim(bottom=0)
    if label:
        ax.legend(loc="best")
    return fig


def ranking(frame, ax=None):
    """Mean sensitivity |S| over e per factor (arcsec/µm), log scale, coloured by the document's class
    (rvtol's class when no document is compared)."""
    d = frame.sort_values("mean |S|", ascending=True)
    fig, ax = new_axes(ax, (6.4, max(2.4, 0.3 * len(d) + 1.0)))
    cls_color = {"high": COLORS["limit"], "low": COLORS["data"], "negligible": COLORS["ci"]}
    y = np.arange(len(d))
    by = "document class" if "document class" in d else "rvtol class"
    ax.barh(y, d["mean |S|"], color=[cls_color.get(c, COLORS["fit"]) for c in d[by]])
    ax.errorbar(d["mean |S|"], y, xerr=[d["mean |S|"] - d["min |S|"], d["max |S|"] - d["mean |S|"]],
                fmt="none", ecolor="black", lw=0.8, capsize=2)
    ax.set_yticks(y, list(d["factor"]))
    ax.set_xscale("log")
    low = d["mean |S|"][d["mean |S|"] > 0].min() if (d["mean |S|"] > 0).any() else 1.0
    for yy, v in zip(y, d["mean |S|"]):
        if v <= 0:
            ax.text(low, yy, " 0 (no effect)", va="center", fontsize=7)
    ax.set_xlabel(f"sensitivity of Δθ_er [{d['unit'].iloc[0]}] (mean over e; bars: min–max)")
    for c, col in cls_color.items():
        ax.barh([np.nan], [np.nan], color=col, label=f"{by.split()[0]}: {c}")
    ax.legend(loc="lower right", fontsize=7)
    return fig


def te_vs_magnitude(frame, ax=None):
    """Δθ_er against the magnitude e of each factor (at the centre of each five-point stencil)."""
    fig, ax = new_axes(ax)
    for n, (name, g) in enumerate(frame.groupby("factor", sort=False)):
        ax.plot(g["magnitude"], g["y"], "o-", ms=3, lw=1, color=_PALETTE[n % len(_PALETTE)], label=name)
    ax.set_xlabel(f"magnitude e [{frame['magnitude_unit'].iloc[0]}]")
    ax.set_ylabel(f"Δθ_er [{frame['output_unit'].iloc[0]}]")
    ax.set_yscale("symlog", linthresh=0.01)
    ax.legend(fontsize=7, ncol=1, loc="center left", bbox_to_anchor=(1.01, 0.5))
    return fig
