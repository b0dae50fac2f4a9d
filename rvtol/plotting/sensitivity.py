"""Plots of sensitivity results: tornado charts, index bars with CI whiskers, Morris, S-versus-e curves."""
from __future__ import annotations

import numpy as np

from ..units import label
from . import COLORS, new_axes

_PALETTE = ["#4C72B0", "#DD8452", "#55A868", "#8172B3", "#937860", "#DA8BC3", "#8C8C8C", "#CCB974"]


def _tall(n: int) -> tuple[float, float]:
    return (6.4, max(2.2, 0.32 * n + 1.0))


def _tornado(ax, labels, low, high, xlabel: str, title: str, legend=("factor at low limit", "factor at high limit")):
    order = np.argsort(np.maximum(np.abs(low), np.abs(high)))  # largest on top
    ypos = np.arange(len(order))
    ax.barh(ypos, np.asarray(low)[order], color=COLORS["data"], alpha=0.85, label=legend[0])
    ax.barh(ypos, np.asarray(high)[order], color=COLORS["fit"], alpha=0.85, label=legend[1])
    ax.set_yticks(ypos, [labels[i] for i in order])
    ax.axvline(0.0, color="black", lw=0.8)
    ax.set_xlabel(xlabel)
    ax.set_title(title)
    ax.legend(loc="lower right")


def tornado(local, output: str, ax=None):
    """Linearised tornado: S_i × (limit − nominal) for each factor at its low and high tolerance limit."""
    d = local.for_output(output)
    fig, ax = new_axes(ax, _tall(len(d)))
    unit = d["output_unit"].iloc[0]
    _tornado(ax, list(d["factor"]), d["dy_low"].to_numpy(), d["dy_high"].to_numpy(),
             f"change of {output} [{label(unit)}] (five-point S × tolerance half-band)",
             f"Local sensitivity of {output} (±{local.percent:g} % five-point)")
    return fig


def swing_tornado(highlow, output: str, ax=None):
    """One-at-a-time tornado from model evaluations at each factor's low and high limit."""
    d = highlow.frame[highlow.frame["output"] == output]
    fig, ax = new_axes(ax, _tall(len(d)))
    unit = d["output_unit"].iloc[0]
    y0 = d["y_nominal"].to_numpy()
    _tornado(ax, list(d["factor"]), d["y_low"].to_numpy() - y0, d["y_high"].to_numpy() - y0,
             f"change of {output} from nominal [{label(unit)}]", f"High/low swing of {output} (model evaluated)")
    return fig


def contribution_bars(pred, ax=None):
    """Pareto of % contribution to variance (linearisation, (S_i σ_i)² / Σ)."""
    d = pred.frame.sort_values("variance_pct", ascending=True)
    fig, ax = new_axes(ax, _tall(len(d)))
    ax.barh(np.arange(len(d)), d["variance_pct"], color=COLORS["data"])
    ax.set_yticks(np.arange(len(d)), list(d["factor"]))
    for y, v in enumerate(d["variance_pct"]):
        ax.text(v, y, f" {v:.1f} %", va="center", fontsize=7)
    ax.set_xlabel("contribution to variance [%]")
    ax.set_title(f"{pred.output}: RSS σ = {pred.std:.3g} {label(pred.unit)} (linearised)")
    ax.set_xlim(0, max(100.0, float(d["variance_pct"].max()) * 1.15))
    return fig


def index_bars(result, output: str, ax=None):
    """Grouped bars of a method's indices for one output, with confidence-interval whiskers."""
    d = result.for_output(output)
    pairs = result.index_columns
    fig, ax = new_axes(ax, (6.4, 3.4) if len(d) <= 10 else (max(6.4, 0.45 * len(d)), 3.6))
    x = np.arange(len(d))
    w = 0.8 / len(pairs)
    for p, (col, conf) in enumerate(pairs):
        ax.bar(x + (p - (len(pairs) - 1) / 2) * w, d[col], w, yerr=d[conf], capsize=3,
               color=_PALETTE[p % len(_PALETTE)], label=col, error_kw={"lw": 0.9})
    ax.set_xticks(x, list(d["factor"]), rotation=30 if len(d) > 5 else 0, ha="right" if len(d) > 5 else "center")
    ax.axhline(0.0, color="black", lw=0.6)
    ax.set_ylabel("index [–]")
    ax.set_title(f"{result.title} of {output} (whiskers: {result.confidence:.0%} CI)")
    ax.legend()
    return fig


def morris_scatter(result, output: str, ax=None):
    """Morris μ* against σ, with μ* confidence whiskers; labels name the factors."""
    d = result.for_output(output)
    fig, ax = new_axes(ax)
    unit = label(d["unit"].iloc[0])
    ax.errorbar(d["mu_star"], d["sigma"], xerr=d["mu_star_conf"], fmt="o", color=COLORS["data"], capsize=3)
    for k, (_, r) in enumerate(d.sort_values("mu_star").iterrows()):  # staggered labels: linear models sit on σ = 0
        ax.annotate(r["factor"], (r["mu_star"], r["sigma"]), textcoords="offset points", xytext=(3, 4 + 9 * (k % 3)),
                    fontsize=7)
    hi = float(np.nanmax(np.r_[d["mu_star"] + d["mu_star_conf"], d["sigma"], 0.0])) * 1.1 or 1.0
    ax.plot([0, hi], [0, hi], color=COLORS["ci"], ls=":", lw=0.8, label="σ = μ*")
    ax.set_xlim(0, hi)
    ax.set_ylim(0, hi)
    ax.set_xlabel(f"μ* [{unit}] (mean |elementary effect|)")
    ax.set_ylabel(f"σ [{unit}] (non-linearity / interaction)")
    ax.set_title(f"Morris screening of {output}")
    ax.legend(loc="upper left")
    return fig


def curves(curve, output: str, ax=None):
    """Sensitivity S against the magnitude e, one line per factor (central derivative, end-stencil band)."""
    d = curve.frame[curve.frame["output"] == output]
    fig, ax = new_axes(ax)
    for p, (name, g) in enumerate(d.groupby("factor", sort=False)):
        c = _PALETTE[p % len(_PALETTE)]
        ax.plot(g["magnitude"], g["S"], "o-", color=c, ms=3, label=f"{name} [{g['S_unit'].iloc[0]}]")
        lo = np.minimum(g["S_low_end"], g["S_high_end"])
        hi = np.maximum(g["S_low_end"], g["S_high_end"])
        ax.fill_between(g["magnitude"], lo, hi, color=c, alpha=0.15, lw=0)
    ax.set_xlabel(f"magnitude e [{label(d['magnitude_unit'].iloc[0])}]")
    ax.set_ylabel(f"sensitivity S of {output}")
    ax.set_title(f"Five-point sensitivity of {output} against e (±{curve.percent:g} %; band: end stencils)")
    ax.legend(fontsize=7)
    return fig


def heatmap(matrix, title: str, cbar: str, fmt: str = "{:.2f}", ax=None, vmax: float | None = None):
    """A matrix (pandas DataFrame: rows = tolerances, columns = outputs) as an annotated heat map."""
    data = matrix.to_numpy(dtype=float)
    nr, nc = data.shape
    fig, ax = new_axes(ax, (max(5.0, 1.1 * nc + 3.5), max(2.4, 0.32 * nr + 1.4)))
    ax.grid(False)
    top = vmax if vmax is not None else (np.nanmax(data) if np.isfinite(data).any() else 1.0)
    im = ax.imshow(np.nan_to_num(data, nan=0.0), cmap="Reds", vmin=0.0, vmax=max(top, 1e-12), aspect="auto")
    ax.set_xticks(np.arange(nc), [str(c) for c in matrix.columns], rotation=30, ha="right")
    ax.set_yticks(np.arange(nr), [str(r) for r in matrix.index])
    for i in range(nr):
        for j in range(nc):
            v = data[i, j]
            if np.isfinite(v):
                ax.text(j, i, fmt.format(v), ha="center", va="center", fontsize=7,
                        color="white" if v > 0.6 * top else "black")
    ax.set_title(title)
    fig.colorbar(im, ax=ax, label=cbar, shrink=0.8)
    return fig
