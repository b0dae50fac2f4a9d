"""Plots of the torsional-stiffness model (doc 004) and of torsion (hysteresis) curves."""
from __future__ import annotations

import numpy as np

from . import COLORS, new_axes


def _legend_both(ax, ax2, loc="best"):
    """One legend for an axes and its twin."""
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, loc=loc)


def plot_pin_forces(contact, row: int = 0, ax=None):
    """Pin forces F_k (bars) and initial clearances Δ(φ_k) (line) against the pin angle."""
    fig, ax = new_axes(ax)
    deg = np.degrees(contact.phi)
    side = contact.arm > 0
    ax.bar(deg[side], contact.force[row][side], width=4.0, color=COLORS["data"], label="pin force F_k")
    ax.set_xlabel("pin angle φ_k [deg]")
    ax.set_ylabel("pin force [N]")
    ax2 = ax.twinx()
    ax2.plot(deg[side], contact.gap[row][side] * 1e3, "o-", color=COLORS["fit"], ms=3, label="clearance Δ(φ_k)")
    ax2.set_ylabel("initial clearance [µm]")
    ax2.grid(False)
    _legend_both(ax, ax2, "upper right")
    return fig


def plot_breakdown(frame, ax=None):
    """Horizontal bars of the torsion-angle components (a ``TorsionAngles.to_frame()``)."""
    fig, ax = new_axes(ax)
    parts = frame[frame["component"] != "Total θ_Σ"]
    ax.barh(parts["component"], parts["θ (arcsec)"], color=COLORS["data"])
    for y, v in enumerate(parts["θ (arcsec)"]):
        ax.text(v, y, f" {v:.2f}", va="center")
    ax.invert_yaxis()
    total = float(frame["θ (arcsec)"].iloc[-1])
    ax.set_xlabel("torsion angle at the output [arcsec]")
    ax.set_title(f"θ_Σ = {total:.2f} arcsec")
    return fig


def plot_sweep(df, x: str, ys, ax=None, ylabel: str = "", secondary=None, secondary_label: str = ""):
    """Lines of columns ``ys`` against ``x``; optional ``secondary`` column on a right axis (markers)."""
    fig, ax = new_axes(ax)
    for i, y in enumerate(ys):
        ax.plot(df[x], df[y], "o-", ms=3, label=y)
    ax.set_xlabel(x.replace("um", "µm"))
    ax.set_ylabel(ylabel)
    if secondary is not None:
        ax2 = ax.twinx()
        if "pairs" in secondary:      # counts: steps
            ax2.step(df[x], df[secondary], where="mid", color=COLORS["ci"], label=secondary)
        else:
            ax2.plot(df[x], df[secondary], "s--", ms=3, color=COLORS["ci"], label=secondary)
        ax2.set_ylabel(secondary_label or secondary)
        ax2.grid(False)
        _legend_both(ax, ax2)
    else:
        ax.legend(loc="best")
    return fig


def plot_torsion_curve(curve, ax=None, percent: float | None = None):
    """Hysteresis (torsion) curve: output angle [arcmin] against output torque [N·m]."""
    fig, ax = new_axes(ax)
    ax.plot(curve.torque_Nm, curve.angle_arcmin, "-", color=COLORS["data"], lw=1.2, label="torsion curve")
    if percent is not None and curve.rated_Nm:
        lim = percent / 100.0 * curve.rated_Nm
        ax.axvspan(-lim, lim, color=COLORS["ci"], alpha=0.2, label=f"±{percent:g} % rated")
    ax.axhline(0, color="k", lw=0.5)
    ax.axvline(0, color="k", lw=0.5)
    ax.set_xlabel("output torque [N·m]")
    ax.set_ylabel("output torsion angle [arcmin]")
    ax.legend(loc="best")
    return fig


def plot_compliance_breakdown(labels, series: dict, ax=None, xlabel: str = "output torsion angle [arcsec]"):
    """Grouped horizontal bars: one group per element (``labels``), one bar per model (``series``: name ->
    values, NaN = the model has no such element), values printed at the bar ends."""
    n, m = len(labels), max(len(series), 1)
    fig, ax = new_axes(ax, figsize=(6.4, 0.42 * n * max(m, 2) / 2 + 1.2))
    height = 0.8 / m
    palette = [COLORS["data"], COLORS["fit"], COLORS["ok"], COLORS["ci"], COLORS["limit"]]
    y = np.arange(n)
    for k, (name, vals) in enumerate(series.items()):
        v = np.asarray(vals, dtype=float)
        pos = y - 0.4 + height * (k + 0.5)
        ok = np.isfinite(v)
        ax.barh(pos[ok], v[ok], height=height, color=palette[k % len(palette)], label=name)
        for p, val in zip(pos[ok], v[ok]):
            ax.text(val, p, f" {val:.1f}", va="center", fontsize=7)
    ax.set_yticks(y)
    ax.set_yticklabels(labels)
    ax.invert_yaxis()
    ax.set_xlabel(xlabel)
    ax.legend(loc="lower right")
    return fig


def plot_torsion_curves(curves, percent: float, rated_Nm: float, zoom: bool = False):
    """Torsion curves (``curves``: (label, curve) pairs) over the whole cycle, or (``zoom``) within ±10 % of
    rated torque, with the ±``percent`` % band of the maker's lost motion."""
    fig, ax = new_axes(None, figsize=(6.4, 3.2 if zoom else 4.0))
    for label, c in curves:
        if zoom:
            sel = np.abs(c.torque) <= 0.1 * c.rated
            ax.plot(c.torque_Nm[sel], c.angle_arcmin[sel], "o-", ms=2, lw=1, label=label)
        else:
            ax.plot(c.torque_Nm, c.angle_arcmin, "-o", ms=2, lw=1, label=label)
    lim = percent / 100.0 * rated_Nm
    if zoom:
        ax.axvspan(-lim, lim, color="0.6", alpha=0.2)
    else:
        ax.axvspan(-lim, lim, color="0.6", alpha=0.2, label=f"±{percent:g} % rated")
    ax.set_xlabel("output torque [N·m]")
    ax.set_ylabel("torsion angle [arcmin]" if zoom else "output torsion angle [arcmin]")
    ax.legend(loc="best")
    return fig
