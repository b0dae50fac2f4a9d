"""What an epistemic-band section says: its prose and the layout of an :class:`.band.EpistemicResult` as report
blocks; the analysis (:mod:`.analyses`) names :func:`layout`."""
from __future__ import annotations

import numpy as np

from ..blocks import Figure, Table, Text, figure_png

INTRODUCTION = (
    "The tolerance Monte Carlo takes the design's numbers as exact. {k} of them are engineering estimates (no drawing "
    "of this reducer gives them), each with a plausible range and its basis in the design file. Here {n} designs are "
    "drawn over those ranges ({method}; a count or a standard size over its grid points); each is built into the "
    "study's whole model — the numbers computed from a sampled one follow it — and evaluated at nominal tolerances: "
    "the epistemic band of each prediction, the central {i:.0f} % of the designs beside their extremes. The tolerance "
    "band is the scatter of the units of the design as written (the study's Monte Carlo){tol}. Nothing is fitted: the "
    "ranges are the design file's, and the band is what they give. The first-order index S1 of each estimated "
    "number, estimated from the same designs ({sens}), says which of them could move each prediction.")


def requirement_lines(res) -> list[str]:
    """Per requirement on a banded output: its limit against the epistemic band (does any plausible design reach
    the limit?)."""
    lines = []
    for r in res.requirements:
        b = res.band(r.output)
        q = next(q for q in res.outputs if q.name == r.output)
        r = r.in_unit(q.shown_unit)
        lo, hi = b["epistemic min"], b["epistemic max"]
        for side, lim in (("lower", r.lower), ("upper", r.upper)):
            if lim is None:
                continue
            if side == "lower":
                where = ("every design lies above it" if lo >= lim else "no design reaches up to it" if hi < lim
                         else "the band crosses it")
            else:
                where = ("every design lies below it" if hi <= lim else "no design comes down to it" if lo > lim
                         else "the band crosses it")
            lines.append(f"{r.label}: {side} limit {lim:.4g} {q.shown_unit}; the designs give {lo:.4g} … {hi:.4g} "
                         f"{q.shown_unit} (the design as written {b['nominal design']:.4g}): {where}.")
    return lines


def layout(res, o) -> list:
    lo, hi = 50 * (1 - res.interval), 50 * (1 + res.interval)
    tol = (f"; with {res.settings['tolerance_samples']} units per design the designs × units band beside it"
           if res.settings.get("tolerance_samples") else "")
    blocks = [Text(INTRODUCTION.format(k=len(res.inputs), n=res.n, method=res.settings.get("method", ""),
                                       i=100 * res.interval, tol=tol, sens=res.settings.get("sensitivity", ""))),
              Table(res.inputs_frame(), "The estimated numbers sampled: their value as written, plausible range and "
                                        "basis (design file)")]
    names = {"epistemic low": f"epistemic P{lo:g}", "epistemic high": f"epistemic P{hi:g}",
             "tolerance low": f"tolerance P{lo:g}", "tolerance high": f"tolerance P{hi:g}",
             "combined low": f"designs × units P{lo:g}", "combined high": f"designs × units P{hi:g}"}
    blocks.append(Table(res.to_frame().rename(columns=names), "Each prediction: the design as written, its tolerance "
                                                              "band and the epistemic band"))
    lines = requirement_lines(res)
    if lines:
        blocks.append(Text("Against the requirements: " + " ".join(lines)))
    top = res.sensitivity.sort_values(["output", "S1"], ascending=[True, False]).groupby("output").head(o.top)
    blocks.append(Table(top.reset_index(drop=True), f"The {o.top} estimated numbers with the largest first-order index "
                                                    f"on each output (from the {int(res.ok.sum())} designs)"))
    if np.isfinite(res.Y[res.ok]).any():
        blocks.append(Figure(figure_png(res.plot()), "Each prediction over the designs, scaled by the design as "
                                                     "written"))
    if len(res.failures()):
        blocks.append(Table(res.failures(), "Designs that gave no prediction"))
    if res.notes:
        blocks.append(Text(" ".join(res.notes)))
    return blocks
