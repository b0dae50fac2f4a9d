"""Plots of the assembly adjustment: KC errors per step, final error and effort against Q."""
from __future__ import annotations

import math

import numpy as np

from .. import units
from . import COLORS, new_axes, plt


def _steps_axis(ax, n_steps: int):
    ax.set_xticks(range(n_steps + 1))
    ax.set_xticklabels(["datum"] + [f"step {k}" for k in range(1, n_steps + 1)])


def kc_steps(run, row: int = 0, ax=None, unit: str = "mrad", unadjusted=None, title: str = ""):
    """One assembly: each KC's error after every step, adjusted (solid) and unadjusted (dashed)."""
    fig, ax = new_axes(ax)
    N, nx = run.x_adjusted.shape[1], run.x_adjusted.shape[2]
    names = run.state_names or [f"x{i}" for i in range(nx)]
    cmap = plt.get_cmap("tab10")
    steps = np.arange(N + 1)
    for i in range(nx):
        c = cmap(i % 10)
        adj = np.concatenate([[0.0], units.from_base(run.x_adjusted[row, :, i], unit)])
        ax.plot(steps, adj, "-o", color=c, ms=3, label=f"{names[i]} adjusted")
        if unadjusted is not None:
            free = np.concatenate([[0.0], units.from_base(unadjusted.x_installed[row, :, i], unit)])
            ax.plot(steps, free, "--", color=c, alpha=0.6, lw=1, label=f"{names[i]} unadjusted")
    _steps_axis(ax, N)
    ax.axhline(0, color="k", lw=0.6)
    ax.set_ylabel(f"KC error [{unit}]")
    if title:
        ax.set_title(title)
    return fig


def example_steps(example, fig=None):
    """One panel per accuracy weight Q: the example assembly's KC errors per step, with and without adjustment."""
    n = len(example.weights)
    cols = 2 if n > 1 else 1
    rows = math.ceil(n / cols)
    if fig is None:
        fig, axes = plt.subplots(rows, cols, figsize=(6.8, 2.6 * rows), sharey=True, squeeze=False)
    else:
        axes = np.array(fig.subplots(rows, cols, sharey=True, squeeze=False))
    for ax, q, run in zip(axes.flat, example.weights, example.runs):
        kc_steps(run, ax=ax, unit=example.unit, unadjusted=example.unadjusted, title=f"Q = {units.number_label(q)}")
        ax.tick_params(axis="x", labelsize=7)
    for ax in list(axes.flat)[n:]:
        ax.set_visible(False)
    h, lab = axes.flat[0].get_legend_handles_labels()
    fig.legend(h, lab, loc="lower center", ncol=4, fontsize=7, bbox_to_anchor=(0.5, -0.02 - 0.04 * (len(lab) > 8)))
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    return fig


def accuracy_sweep(sweep, fig=None):
    """Final error and adjustment effort against the accuracy weight Q (log axis)."""
    u = sweep.unit
    if fig is None:
        fig, (a1, a2) = plt.subplots(1, 2, figsize=(7.2, 3.2))
    else:
        a1, a2 = fig.subplots(1, 2)
    Q = sweep.Q
    a1.plot(Q, units.from_base(sweep.final_error, u), color=COLORS["data"], label="example assembly")
    a2.plot(Q, units.from_base(sweep.effort, u), color=COLORS["data"], label="example assembly")
    if not math.isnan(sweep.unadjusted_final):
        a1.axhline(units.from_base(sweep.unadjusted_final, u), color=COLORS["data"], ls=":", lw=1,
                   label="example, no adjustment")
    if sweep.batch_rms_final is not None:
        lab = f"Monte Carlo RMS (n={sweep.batch_n})"
        a1.plot(Q, units.from_base(sweep.batch_rms_final, u), color=COLORS["fit"], label=lab)
        a2.plot(Q, units.from_base(sweep.batch_mean_effort, u), color=COLORS["fit"],
                label=f"Monte Carlo mean (n={sweep.batch_n})")
        if not math.isnan(sweep.unadjusted_batch_rms):
            a1.axhline(units.from_base(sweep.unadjusted_batch_rms, u), color=COLORS["fit"], ls=":", lw=1,
                       label="MC, no adjustment")
    for a in (a1, a2):
        a.set_xscale("log")
        a.set_xlabel("accuracy weight Q [1]")
        a.legend(fontsize=7)
    a1.set_yscale("log")
    a1.set_ylabel(f"final KC error (RSS) [{u}]")
    a2.set_ylabel(f"adjustment effort sqrt(Σ|u|²) [{u}]")
    fig.tight_layout()
    return fig


def step_statistics(stats, ax=None):
    """Monte Carlo batch: RMS of each KC's error after every step, adjusted (solid) and unadjusted (dashed)."""
    fig, ax = new_axes(ax)
    N, nx = stats.adjusted.shape
    cmap = plt.get_cmap("tab10")
    steps = np.arange(N + 1)
    for i, nm in enumerate(stats.state_names):
        c = cmap(i % 10)
        ax.plot(steps, np.concatenate([[0.0], units.from_base(stats.adjusted[:, i], stats.unit)]), "-o", ms=3,
                color=c, label=f"{nm} adjusted")
        ax.plot(steps, np.concatenate([[0.0], units.from_base(stats.unadjusted[:, i], stats.unit)]), "--",
                color=c, alpha=0.6, lw=1, label=f"{nm} unadjusted")
    _steps_axis(ax, N)
    ax.set_ylabel(f"RMS KC error [{stats.unit}]")
    ax.set_title(f"Monte Carlo batch (n={stats.n}), Q = {units.number_label(stats.accuracy)}")
    ax.legend(fontsize=7, ncol=2 if nx <= 6 else 3)
    return fig
