"""The first page a quality manager reads: per requirement a traffic light with its yield and Cpk, the tolerances
that matter, the cheapest fix by kind, and — when there is one — the comparison with the accepted baseline.

Everything here lays out what the run computed (:mod:`rvtol.signoff`, the analyses' fixes, the comparison);
the same section opens report.html, report.pdf and the one-page summary.pdf.
"""
from __future__ import annotations

import re

import pandas as pd

from ..callouts import short_label
from ..precision import output_scale, shown
from ..signoff import FIX_KINDS
from ..units import label
from ..blocks import Links, Section
from ..verdict import FAIL, PASS, REQUIREMENT_STATES, STATE_UNDECIDED
#: a driver below this first-order share is not listed (it would read as 0 %)
MIN_SHARE = 0.005
#: drivers listed per requirement on the first page (summary.json holds the digest's three)
FIRST_PAGE_DRIVERS = 2


def _num(v, fmt="{:.4g}") -> str:
    return "—" if v is None else fmt.format(v)


def _need(bound, need, fmt) -> str:
    return f"{_num(bound, fmt)} (needs ≥ {need:g})" if need is not None else "—"


def signoff_section(result) -> Section:
    sec = Section("signoff", "Sign-off")
    digests = result.signoff
    if not digests:
        sec.add_text("This study states no requirements: nothing is signed off.")
        return sec
    reqs = {v.requirement.label: v.requirement for v in result.mc.verdicts()}
    counts = {k: sum(d.state == k for d in digests) for k in REQUIREMENT_STATES}
    head = (f"FAIL — {len(digests) - counts[PASS]} of {len(digests)} requirements are not demonstrated at their "
            "stated confidence" if counts[PASS] < len(digests) else
            f"PASS — all {len(digests)} requirements are demonstrated at their stated confidence")
    sec.add_text(head + f" ({counts[PASS]} PASS, {counts[STATE_UNDECIDED]} UNDECIDED, {counts[FAIL]} FAIL). "
                 + " ".join(f"{k}: {v}." for k, v in REQUIREMENT_STATES.items()))
    rows, staged = [], any(d.model for d in digests)
    cpk_asked = any(reqs[d.label].min_cpk is not None for d in digests)
    stt = result.mc.statistics()
    for d in digests:
        r = reqs[d.label]
        scale = output_scale([(r.lower, r.upper)], stt.loc[d.output].get("std"))   # the decimals resolve its band
        needs = " and ".join(x for x in (f"yield ≥ {r.min_yield:g}" if r.min_yield is not None else "",
                                         f"Cpk ≥ {r.min_cpk:g}" if r.min_cpk is not None else "") if x)
        row = {"": f"● {d.state}", "requirement": short_label(d.label, 90)}
        if staged:
            row["model"] = d.model or "—"
        row.update({"needs": needs, "yield": _num(d.yield_, "{:.5f}"), "yield bound": _num(d.yield_lo, "{:.5f}"),
                    "Cpk": _num(d.cpk, "{:.2f}")})
        if cpk_asked:
            row["Cpk bound"] = _num(d.cpk_lo, "{:.2f}")
        row.update({"mean": shown(d.mean, scale), "P0.135 … P99.865": f"{shown(d.p00135, scale)} … "
                                                                       f"{shown(d.p99865, scale)}",
                    "unit": label(d.unit)})
        rows.append(row)
    sec.add_table(pd.DataFrame(rows), caption="Every requirement (its full name, intervals and reasons in the "
                                              "requirements section): the bound — one-sided, at the requirement's "
                                              "confidence — is what is judged against what it needs", text=True)
    drows = []
    watched = [d for d in digests if d.state != PASS] or digests    # the failures' drivers; all when all pass
    for d in watched:
        listed = [x for x in d.drivers if x.s1 >= MIN_SHARE and x.significant][:FIRST_PAGE_DRIVERS]
        for drv in listed:
            drows.append({"requirement": d.label, "drawing tolerance": short_label(drv.tolerance),
                          "share of variance (S1)": f"{100 * drv.s1:.0f} %",
                          "factors": ", ".join(drv.factors[:2]) + (f" (+{len(drv.factors) - 2})"
                                                                    if len(drv.factors) > 2 else "")})
    if drows:
        sec.add_table(pd.DataFrame(drows), text=True, caption=f"The (up to {FIRST_PAGE_DRIVERS}) tolerances that matter "
                      "most for each requirement not demonstrated (for every requirement when all pass): first-order "
                      "share of its variance, estimated from the "
                      "Monte Carlo samples (the coordinates of one drawing tolerance summed); listed when at least "
                      f"{100 * MIN_SHARE:g} % and more than three standard errors of its estimate")
    overlaps = [f"{d.label}: " + "; ".join(d.overlaps) for d in digests if d.overlaps]
    if overlaps:
        sec.add_text("Correlated in the spec, so their shares overlap (each includes what the other explains through "
                     "the correlation; do not add them, and tightening one alone gains less than its share says) — "
                     + " · ".join(overlaps) + ".")
    _fixes(sec, result, digests)
    if result.comparison is not None:
        _baseline(sec, result.comparison)
    return sec


def _fixes(sec: Section, result, digests) -> None:
    """The cheapest fix of each kind for every requirement that is not demonstrated, checked ones first."""
    titles = {s.key: s.title for s in result.sections}
    extra = [f for s in result.sections for f in s.fixes]
    rows, sources = [], []
    for d in digests:
        if d.state == PASS:
            continue
        fixes = [f for f in extra if f.requirement == d.label] + list(d.fixes)
        for kind in FIX_KINDS:
            of_kind = sorted((f for f in fixes if f.kind == kind), key=lambda f: not f.checked)
            if not of_kind:
                continue
            f = of_kind[0]
            where = titles.get(f.source)
            rows.append({"requirement": d.label, "fix": kind, "what to do": f.action, "what it gives": f.effect,
                         "evidence": (("checked by a Monte Carlo run" if f.checked else "estimate")
                                      + (f" — {where}" if where else " (first order)"))})
            if f.source in titles:
                sources.append(f.source)
    if not rows:
        return
    rows = _one_more_samples_row(rows)
    sec.add_table(pd.DataFrame(rows), caption="What to change, cheapest kind first (more samples, re-centre a "
                  "nominal, tighten tolerances, redesign)", text=True)
    if sources:
        sec.blocks.append(Links([(k, titles[k]) for k in dict.fromkeys(sources)], "Details"))


def _one_more_samples_row(rows: list[dict]) -> list[dict]:
    """The requirements more samples would decide, in one row: the largest n demonstrates each (the page stays one
    page when many requirements are undecided)."""
    more = [r for r in rows if r["fix"] == "more samples"]
    if len(more) < 2:
        return rows
    n = lambda r: int(re.sub(r"\D", "", r["what to do"]) or 0)  # noqa: E731  ("run n = 12,345 samples")
    top = max(more, key=n)
    one = {**top, "requirement": "; ".join(r["requirement"] for r in more),
           "what it gives": "the estimates already meet these requirements; this n would demonstrate each if the "
                            "figures hold"}
    first = rows.index(more[0])
    return [one if i == first else r for i, r in enumerate(rows) if r["fix"] != "more samples" or i == first]


def _baseline(sec: Section, cmp) -> None:
    """Against the accepted baseline: each requirement before and after, its ppm change, the gates."""
    rows = [{"requirement": r["requirement"], "baseline": r["base_verdict"], "this run": r["new_verdict"],
             "ppm out": f"{_num(r['ppm']['base'], '{:.0f}')} → {_num(r['ppm']['new'], '{:.0f}')}",
             "change [CI]": f"{_num(r['ppm']['change'], '{:+.0f}')} [{_ci(r['ppm']['ci'])}]"}
            for r in cmp.requirements]
    b = cmp.base
    sec.add_text(f"Against the accepted baseline {b['source']} (n {b['n']}, seed {b['seed']}; "
                 f"{'paired on common random numbers' if cmp.paired else 'unpaired'}): gates {cmp.verdict} — "
                 f"{cmp.one_line()}.")
    if rows:
        sec.add_table(pd.DataFrame(rows), caption=f"Requirements against the baseline (ppm non-conforming, change with "
                                                  f"its {100 * cmp.confidence:g} % interval)")
    if cmp.spec_changes:
        sec.add_table(pd.DataFrame(cmp.spec_changes), caption="What changed in the tolerance spec")


def _ci(ci) -> str:
    return "—" if not ci or None in ci else f"{ci[0]:+.0f}, {ci[1]:+.0f}"
