"""Plot of a validation: predicted / measured per published figure, before and after a calibration."""
from __future__ import annotations

import numpy as np
from matplotlib import ticker

from . import COLORS, new_axes


def ratio_chart(frame, ax=None):
    """One row per published figure and stage: the predicted median / measured (dot) and the central predicted
    interval / measured (bar), log scale, 1 = agreement; a limit's row reads the prediction / the limit."""
    rows = frame[np.isfinite(frame["predicted / measured"].astype(float))].reset_index(drop=True)
    fig, ax = new_axes(ax, figsize=(6.4, 0.45 * max(len(rows), 2) + 1.2))
    stages = list(dict.fromkeys(rows["stage"]))
    colors = [COLORS["data"], COLORS["fit"], COLORS["ok"]]
    labelled: set[str] = set()
    ticks: list[tuple[int, str]] = []
    for i, r in rows.iterrows():
        c = colors[stages.index(r["stage"]) % len(colors)]
        y = len(rows) - 1 - i
        m = float(r["measured"])
        lo, hi = float(r["P low"]) / m, float(r["P high"]) / m
        ax.plot([lo, hi], [y, y], "-", lw=3, color=c, alpha=0.4)
        ax.plot([r["predicted / measured"]], [y], "o", color=c,
                label=None if r["stage"] in labelled else r["stage"].split(" fitted to ")[0].rstrip(")") + ")"
                if " fitted to " in r["stage"] else r["stage"])
        labelled.add(r["stage"])
        lim = "" if r["kind"] in ("value", "range") else f" ({r['kind'].replace('_', ' ')})"
        ticks.append((y, f"{r['source']}:{r['quantity']}{lim}"))
    ax.axvline(1.0, color="k", lw=0.8)
    ax.set_xscale("log")
    ax.xaxis.set_major_locator(ticker.LogLocator(subs=(1.0, 2.0, 5.0)))
    ax.xaxis.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
    ax.xaxis.set_minor_formatter(ticker.NullFormatter())
    ax.set_yticks([t for t, _ in ticks], [lab for _, lab in ticks], fontsize=7)
    ax.set_ylim(-0.7, len(rows) - 0.3)
    ax.set_xlabel("predicted / measured (median: dot; central interval: bar)")
    if labelled:
        ax.legend(loc="lower center", bbox_to_anchor=(0.5, 1.0), fontsize=7, frameon=False)
    fig.tight_layout()
    return fig
