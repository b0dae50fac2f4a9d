"""All of rvtol's plots (matplotlib, Agg backend), one module per topic.

Functions take results (and an optional ``ax``) and return the matplotlib
Figure; physics modules never import matplotlib.
"""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402

STYLE = {
    "figure.figsize": (6.4, 3.6),
    "axes.grid": True,
    "grid.alpha": 0.3,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "font.size": 9,
    "axes.titlesize": 10,
    "legend.fontsize": 8,
}
plt.rcParams.update(STYLE)

COLORS = {"data": "#4C72B0", "fit": "#DD8452", "limit": "#C44E52", "ci": "#8C8C8C", "ok": "#55A868"}


def new_axes(ax=None, figsize=None):
    """``(fig, ax)``: the given axes and its figure, or a fresh figure."""
    if ax is not None:
        return ax.figure, ax
    fig, ax = plt.subplots(figsize=figsize or STYLE["figure.figsize"])
    return fig, ax
