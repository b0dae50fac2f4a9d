"""The first page a quality manager reads: the verdict per requirement, the tolerances that matter, what to change."""
from __future__ import annotations

import pandas as pd

from ..units import label
from .sections import Section


def _num(v, fmt="{:.4g}") -> str:
    return "—" if v is None else fmt.format(v)


def signoff_section(result) -> Section:
    sec = Section("signoff", "Sign-off")
    digests = result.signoff
    if not digests:
        sec.add_text("This study states no requirements: nothing is signed off.")
        return sec
    failed = [d for d in digests if not d.passed]
    if failed:
        sec.add_text(f"FAIL — {len(failed)} of {len(digests)} requirements are not demonstrated at their stated "
                     "confidence: " + "; ".join(d.label for d in failed) + ".")
    else:
        sec.add_text(f"PASS — all {len(digests)} requirements are demonstrated at their stated confidence.")
    rows = []
    for d in digests:
        rows.append({"requirement": d.label, "model": d.model or "—", "verdict": "PASS" if d.passed else "FAIL",
                     "mean": _num(d.mean), "P0.135 … P99.865": f"{_num(d.p00135)} … {_num(d.p99865)}",
                     "unit": label(d.unit), "yield (lower bound)": _num(d.yield_lo, "{:.5f}"),
                     "Cpk (lower bound)": _num(d.cpk_lo, "{:.2f}")})
    sec.add_table(pd.DataFrame(rows), caption="Every requirement: PASS means demonstrated at the stated confidence "
                                              "(details, intervals and reasons in the requirements section)")
    drows = []
    for d in digests:
        for rank, drv in enumerate(d.drivers, start=1):
            drows.append({"requirement": d.label, "rank": rank, "drawing tolerance": drv.tolerance,
                          "share of variance (S1)": f"{100 * drv.s1:.0f} %",
                          "factors": ", ".join(drv.factors[:4]) + (" …" if len(drv.factors) > 4 else "")})
    if drows:
        sec.add_table(pd.DataFrame(drows), caption="The tolerances that matter most for each requirement: first-order "
                                                   "share of the output's variance, estimated from the Monte Carlo "
                                                   "samples (coordinates of one drawing tolerance summed)")
    overlaps = [f"{d.label}: " + "; ".join(d.overlaps) for d in digests if d.overlaps]
    if overlaps:
        sec.add_text("Correlated in the spec, so their shares overlap (each includes what the other explains through "
                     "the correlation; do not add them, and tightening one alone gains less than its share says; "
                     "the Sobol total indices of the sensitivity matrix treat the factors as independent and need "
                     "not agree) — " + " · ".join(overlaps) + ".")
    for d in failed:
        if d.change:
            sec.add_text(f"What to change — {d.label}: {d.change}")
    return sec
