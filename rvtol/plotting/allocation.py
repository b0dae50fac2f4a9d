"""Plots of the tolerance allocation: cost curves, allocated tolerances, GA convergence, Pareto curve."""
from __future__ import annotations

import numpy as np

from . import COLORS, new_axes, plt


def cost_curves(curves, cost_unit: str = "relative", ax=None):
    """Each cost–tolerance curve over its range, with the data it was fitted to."""
    fig, ax = new_axes(ax)
    cmap = plt.get_cmap("tab10")
    units_seen = set()
    for i, c in enumerate(curves):
        t = np.geomspace(c.t_min, c.t_max, 200)
        ax.plot(t, c(t), color=cmap(i % 10), label=f"{c.name}: {c.formula()}")
        if c.fit is not None:
            ax.plot(c.fit.tolerance, c.fit.cost, "o", ms=4, color=cmap(i % 10), alpha=0.7)
        units_seen.add(c.unit)
    ax.set_xlabel(f"tolerance ±t [{', '.join(sorted(units_seen))}]")
    ax.set_ylabel(f"cost [{cost_unit}]")
    ax.legend(fontsize=7)
    return fig


def tolerance_bars(results, ax=None):
    """Allocated tolerances per factor, one bar per method (factor units)."""
    p = results[0].problem
    fig, ax = new_axes(ax, figsize=(max(6.4, 0.45 * len(p.factors) * max(1, len(results)) / 2), 3.6))
    x = np.arange(len(p.factors))
    w = 0.8 / len(results)
    colors = [COLORS["ci"], COLORS["data"], COLORS["fit"], COLORS["ok"]]
    for i, r in enumerate(results):
        ax.bar(x + (i - (len(results) - 1) / 2) * w, r.display_t(), w, label=f"{r.method} (cost {r.total_cost:.4g})",
               color=colors[i % len(colors)])
    ax.set_xticks(x)
    ax.set_xticklabels(p.factors, rotation=60, ha="right", fontsize=7)
    us = sorted({p.spec.factor(n).unit for n in p.factors})
    ax.set_ylabel(f"tolerance ±t [{', '.join(us)}]")
    ax.legend(fontsize=7)
    return fig


def ga_history(result, reference=None, ax=None):
    """Best feasible cost per GA generation, with the convex optimum for reference."""
    fig, ax = new_axes(ax, figsize=(6.4, 3.0))
    h = np.asarray(result.history, float)
    ax.plot(np.arange(1, len(h) + 1), h, color=COLORS["data"], label="GA best feasible")
    if reference is not None and reference.t is not None:
        ax.axhline(reference.total_cost, color=COLORS["fit"], ls="--", label=f"{reference.method} optimum")
    ax.set_xlabel("generation")
    ax.set_ylabel("total cost")
    ax.legend(fontsize=7)
    return fig


def pareto(curve, ax=None):
    """Minimum total cost against the requirement scale (limits × f about the nominal output)."""
    fig, ax = new_axes(ax)
    df = curve.frame
    x = df.columns[0]
    styles = ["-o", "--s", ":^", "-.d"]
    for i, col in enumerate(df.columns[1:]):
        ax.plot(df[x], df[col], styles[i % len(styles)], ms=4, label=col)
    ax.set_xlabel("requirement scale f (limits × f) [1]")
    ax.set_ylabel(f"minimum total cost [{curve.cost_unit}]")
    ax.legend(fontsize=7)
    return fig
