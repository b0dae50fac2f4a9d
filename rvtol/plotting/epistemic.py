"""Plot of an epistemic band: per output, the designs at nominal tolerances beside the tolerance band."""
from __future__ import annotations

import numpy as np

from . import COLORS, new_axes


def band_chart(res, ax=None):
    """One row per output, each scaled by the design as written (1 = the design's nominal prediction): every
    sampled design at nominal tolerances (dots), the epistemic band (thick bar), the tolerance band of the design as
    written (thin bar above) and the combined band of designs × units (thin bar below) where computed."""
    outs = [q.name for q in res.outputs]
    fig, ax = new_axes(ax, figsize=(6.4, 0.6 * max(len(outs), 2) + 1.2))
    ok = res.ok
    for i, q in enumerate(res.outputs):
        y = len(outs) - 1 - i
        b = res.band(q.name)
        ref = b["nominal design"] if b["nominal design"] not in (0.0,) and np.isfinite(b["nominal design"]) else 1.0
        v = res.Y[ok, i] / ref
        ax.plot(v, np.full(v.size, y), "o", ms=3, color=COLORS["data"], alpha=0.5,
                label="designs (nominal tolerances)" if i == 0 else None)
        ax.plot([b["epistemic low"] / ref, b["epistemic high"] / ref], [y, y], "-", lw=5, color=COLORS["data"],
                alpha=0.35, label="epistemic band" if i == 0 else None)
        if "tolerance low" in b:
            ax.plot([b["tolerance low"] / ref, b["tolerance high"] / ref], [y + 0.25, y + 0.25], "-", lw=2,
                    color=COLORS["fit"], label="tolerance band (design as written)" if i == 0 else None)
        if "combined low" in b:
            ax.plot([b["combined low"] / ref, b["combined high"] / ref], [y - 0.25, y - 0.25], "-", lw=2,
                    color=COLORS["ci"], label="designs × units" if i == 0 else None)
    ax.axvline(1.0, color="k", lw=0.8)
    ax.set_yticks(range(len(outs)), [f"{q.name} ({q.shown_unit})" for q in reversed(res.outputs)], fontsize=7)
    ax.set_ylim(-0.7, len(outs) - 0.3)
    ax.set_xlabel("prediction / the design as written at nominal tolerances")
    ax.legend(loc="lower center", bbox_to_anchor=(0.5, 1.0), fontsize=7, frameon=False, ncol=2)
    return fig
