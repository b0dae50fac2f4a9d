"""Plots of the deviation stack-up: contribution bars, the assembly graph, sequence and domain views."""
from __future__ import annotations

import numpy as np

from ..units import label
from . import COLORS, new_axes

SIGN_COLORS = {"+": "#C44E52", "−": "#4C72B0", "0": "#8C8C8C"}
FLOW_STYLE = {  # colour, line style
    "f1": ("#8C8C8C", "-"),
    "f3": ("#4C72B0", "-"),
    "f4": ("#DD8452", "-"),
    "closes": ("#C44E52", "--"),
}


def contribution_bars(lin, top: int = 12, ax=None):
    """Shares of variance (bars) and of worst case (dots) of the largest contributors, coloured by loop sign."""
    d = lin.contributions.sort_values("variance share %", ascending=False).head(top).iloc[::-1]
    fig, ax = new_axes(ax, (6.4, 0.9 + 0.28 * len(d)))
    y = np.arange(len(d))
    signs = [s if s in SIGN_COLORS else "0" for s in d["sign"]]
    colors = [SIGN_COLORS[s] if lin.form == "dof" else COLORS["data"] for s in signs]
    ax.barh(y, d["variance share %"], color=colors, alpha=0.85, label="share of variance (RSS)")
    ax.plot(d["worst-case share %"], y, "k|", ms=10, mew=2, label="share of worst case")
    ax.set_yticks(y, [f"{f} ({s})" if lin.form == "dof" else f for f, s in zip(d["factor"], d["sign"])],
                  fontsize=7)
    ax.set_xlabel("contribution [%]")
    ax.set_xlim(0, max(5.0, float(max(d["variance share %"].max(), d["worst-case share %"].max())) * 1.1))
    title = f"{lin.output} [{label(lin.unit)}]"
    if lin.form == "dof":
        title += ": red + positive / blue − negative accumulator"
    ax.set_title(title, fontsize=9)
    ax.legend(loc="lower right", fontsize=7)
    return fig


def assembly_graph(assembly, sequence=None, ax=None):
    """The assembly graph: parts (boxes, in placing order), features, fits and deviation flows.

    Within a part, grey arrows run from the datum to each deviating feature
    (f1; ×n marks several deviation terms, f5; ◇ a form deviation, f2).  Fits
    join features of two parts (f3, blue, numbered as listed beside the
    graph); clearance fits are orange (f4); fits that close the loop instead
    of locating a part are dashed red.
    """
    seq = sequence or assembly.sequence(None)
    order = [assembly.ground] + [p for p, _ in seq.steps]
    feats = {p: [f for f in assembly.features.values() if f.part == p] for p in order}
    rows = max(len(v) for v in feats.values())
    fig, ax = new_axes(ax, (max(6.4, 1.9 * len(order) + 2.2), 1.6 + 1.0 * rows))
    pos = {}
    for i, part in enumerate(order):
        n = len(feats[part])
        ax.add_patch(_box(i - 0.42, -0.6, 0.84, rows + 0.1))
        ax.text(i, rows - 0.25, part, ha="center", va="bottom", fontsize=9, weight="bold")
        for j, f in enumerate(feats[part]):
            yy = rows - 1 - j * (rows - 1) / max(n - 1, 1) if n > 1 else (rows - 1) / 2
            pos[f.id] = (i, yy - 0.35)
            mark = "s" if f.datum else "o"
            ax.plot(*pos[f.id], mark, color="k" if f.datum else COLORS["data"], ms=7, zorder=3)
            tag = f.name + (f" ×{len(f.terms)}" if len(f.terms) > 1 else "") + (" ◇" if f.form else "")
            ax.text(pos[f.id][0], pos[f.id][1] - 0.16, tag, ha="center", va="top", fontsize=7, zorder=4,
                    bbox=dict(boxstyle="round,pad=0.1", fc="white", ec="none", alpha=0.85))
    for f in assembly.features.values():
        if f.terms and f.part in feats:
            datum = next((g for g in feats[f.part] if g.datum), None)
            if datum is not None:
                _arrow(ax, pos[datum.id], pos[f.id], *FLOW_STYLE["f1"], rad=0.35, lw=0.8)
    ax.set_xlim(-0.6, len(order) - 0.4)
    ax.set_ylim(-0.8, rows + 0.3)
    fit_lines = []
    for i, fit in enumerate(assembly.fits.values()):
        closes = fit.name not in seq.locating
        key = "closes" if closes else ("f4" if fit.is_clearance else "f3")
        color, ls = FLOW_STYLE[key]
        a, b = pos[fit.base], pos[fit.mate]
        rad = 0.0 if abs(b[0] - a[0]) <= 1.01 else 0.12  # long fits bow, to pass beside the parts between
        _arrow(ax, a, b, color, ls, rad=rad, lw=1.6)
        ax.text(*_arc_middle(ax, a, b, rad), str(i + 1), fontsize=7, ha="center", va="center",
                color=color, zorder=5, weight="bold",
                bbox=dict(boxstyle="circle,pad=0.2", fc="white", ec=color, lw=0.8))
        fit_lines.append(f"{i + 1}  {fit.name} ({fit.type}{', clearance' if fit.is_clearance else ''}; "
                         f"{'closes' if closes else 'locates'})")
    ax.text(1.01, 0.98, "fits\n" + "\n".join(fit_lines), transform=ax.transAxes, fontsize=7, va="top",
            ha="left", family="monospace")
    ax.axis("off")
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color=FLOW_STYLE["f1"][0], label="f1 datum → feature (×n: f5, ◇: f2 form)"),
               Line2D([], [], color=FLOW_STYLE["f3"][0], lw=1.6, label="f3 fit, locates"),
               Line2D([], [], color=FLOW_STYLE["f4"][0], lw=1.6, label="f3+f4 clearance fit, locates (float)"),
               Line2D([], [], color=FLOW_STYLE["closes"][0], ls="--", lw=1.6, label="fit closing the loop (misfit KC)"),
               Line2D([], [], marker="s", color="k", ls="", label="datum feature (D)"),
               Line2D([], [], marker="o", color=COLORS["data"], ls="", label="deviation-prone feature (g)")]
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.02), ncol=3, fontsize=7, frameon=False)
    ax.set_title(f"{assembly.name}: sequence {seq.name} ({' → '.join(order)})", fontsize=9)
    return fig


def _arc_middle(ax, a, b, rad):
    """Middle of matplotlib's ``arc3`` curve from a to b (its control point is offset in display space)."""
    (x1, y1), (x2, y2) = ax.transData.transform([a, b])
    cx, cy = 0.5 * (x1 + x2) + rad * (y2 - y1), 0.5 * (y1 + y2) - rad * (x2 - x1)
    mx, my = 0.25 * x1 + 0.5 * cx + 0.25 * x2, 0.25 * y1 + 0.5 * cy + 0.25 * y2
    return ax.transData.inverted().transform((mx, my))


def _box(x, y, w, h):
    from matplotlib.patches import FancyBboxPatch

    return FancyBboxPatch((x, y), w, h, boxstyle="round,pad=0.02,rounding_size=0.08", fc="#F4F6FA", ec="#B0B8C8")


def _arrow(ax, a, b, color, ls, rad=0.1, lw=1.0):
    ax.annotate("", xy=b, xytext=a, arrowprops=dict(arrowstyle="-|>", color=color, ls=ls, lw=lw, shrinkA=5,
                                                    shrinkB=5, connectionstyle=f"arc3,rad={rad}"), zorder=2)


def sequence_histograms(comparison, outputs=None, bins: int = 50):
    """Overlaid histograms of the outputs two or more assembly sequences share."""
    import matplotlib.pyplot as plt

    names = outputs or comparison.common_outputs()
    ncol = 2
    nrow = max(1, (len(names) + ncol - 1) // ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(7.0, 2.3 * nrow), squeeze=False)
    palette = [COLORS["data"], COLORS["fit"], COLORS["ok"], COLORS["limit"]]
    for ax, name in zip(axes.flat, names):
        ys = {s: comparison.column(s, name) for s in comparison.sequences}
        allv = np.concatenate([v[np.isfinite(v)] for v in ys.values()])
        edges = np.histogram_bin_edges(allv, bins=bins) if len(allv) else bins
        for c, (s, v) in zip(palette, ys.items()):
            ax.hist(v[np.isfinite(v)], bins=edges, histtype="step", lw=1.4, color=c, density=True, label=s)
        ax.set_xlabel(f"{name} [{label(comparison.unit(name))}]", fontsize=8)
        ax.set_ylabel("density", fontsize=8)
        ax.legend(fontsize=7)
    for ax in axes.flat[len(names):]:
        ax.axis("off")
    fig.tight_layout()
    return fig


def planar_domain(zone, samples, ax=None):
    """Samples of a parallel-plane zone on (Δw, Δα·W/2): the exact domain and its bounding box."""
    fig, ax = new_axes(ax, (5.0, 3.6))
    s = np.asarray(samples)[:3000]
    h = 0.5 * zone.dt
    ax.plot((s[:, 2] - zone.centre) * 1e3, s[:, 3] * zone.W / 2 * 1e3, ".", ms=2, alpha=0.4,
            color=COLORS["data"], label="samples (all β)")
    ax.plot(np.array([h, 0, -h, 0, h]) * 1e3, np.array([0, h, 0, -h, 0]) * 1e3, color=COLORS["fit"],
            label="exact domain at Δβ = 0")
    ax.plot(np.array([h, -h, -h, h, h]) * 1e3, np.array([h, h, -h, -h, h]) * 1e3, color=COLORS["ci"], ls=":",
            label="bounding box")
    ax.set_xlabel("Δw − zone centre [µm]")
    ax.set_ylabel("Δα · W/2 [µm]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(fontsize=7, loc="upper right")
    return fig
