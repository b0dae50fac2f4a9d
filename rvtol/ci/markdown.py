"""The Markdown summary of a run (and of its baseline comparison): for a pull request or a job summary.

``rvtol run … --markdown FILE`` writes it; when ``GITHUB_STEP_SUMMARY`` is set (GitHub Actions)
the same text is appended there and shows on the run's page.
"""
from __future__ import annotations

import html
from functools import partial

from .. import units
from ..precision import shown
from ..safetext import visible
from ..verdict import state_of

_ICON = {"PASS": "✅", "FAIL": "❌", "UNDECIDED": "🟡", "NO REQUIREMENTS": "⚠️", "EXPLORATORY": "ℹ️"}


def _f(v, fmt: str = ".4g") -> str:
    return "—" if v is None else format(v, fmt)


def _ci(ci, fmt=".4g") -> str:
    """``[lo, hi]``; ``fmt`` a format spec or a function of the number."""
    if not ci or None in ci:
        return "—"
    form = fmt if callable(fmt) else (lambda v: format(v, fmt))
    return f"[{form(ci[0])}, {form(ci[1])}]"


def _cell(s: str) -> str:
    """Text from the study (names, titles, reasons) in a Markdown table or heading: raw HTML escaped (a
    ``<script>`` in a requirement's name shows as text), pipes escaped, one line."""
    return html.escape(visible(str(s)), quote=False).replace("|", "\\|").replace("\n", " ")


def _state(word: str) -> str:
    """A requirement's or a gate's state with its icon."""
    return f"{_ICON[word]} {word}"


def _code(s) -> str:
    """Text in a code span: backticks cannot close it early."""
    return "`" + visible(str(s)).replace("`", "'") + "`"


def _table(head: list[str], rows: list[list]) -> list[str]:
    out = ["| " + " | ".join(head) + " |", "|" + "|".join("---" for _ in head) + "|"]
    out += ["| " + " | ".join(_cell(c) for c in r) + " |" for r in rows]
    return out


def render_markdown(summary: dict, comparison=None) -> str:
    v = summary["verdict"]
    lines = [f"### {_ICON.get(v, '')} rvtol · {_cell(summary.get('title') or summary['study'])}: **{v}**", "",
             f"Study {_code(summary['study'])} · {summary['n']:,} samples ({summary['method']}, seed {summary['seed']}) · "
             f"rvtol {summary['rvtol_version']}", ""]
    reqs = [r for o in summary["outputs"].values() for r in o.get("requirements", [])]
    if reqs:
        rows = []
        for r in reqs:
            need = []
            if r.get("min_yield") is not None:
                need.append(f"yield ≥ {r['min_yield']:g}" + (" (default)" if r.get("min_yield_default") else ""))
            if r.get("min_cpk") is not None:
                need.append(f"Cpk ≥ {r['min_cpk']:g}")
            judged = ("estimate" if r["basis"] == "estimate" else
                      f"{r.get('bound', 'two-sided')} {100 * r.get('bound_level', r['confidence']):g} %")
            rows.append([r["requirement"], " and ".join(need), judged,
                         f"{_f(r['yield'], '.5f')} {_ci(r['yield_ci'], '.5f')}", _f(r.get("yield_bound"), ".5f"),
                         _f(r["ppm"], ".0f"),
                         f"{_f(r['cpk'], '.3f')} (bound {_f(r.get('cpk_bound'), '.3f')})" if r.get("cpk") is not None
                         else "—",
                         f"{r['n_to_demonstrate']:,}" if r.get("n_to_demonstrate") else "",
                         _state(state_of(r)) + ("" if r["passed"] else f" — {r['reasons'][0]}")])
        lines += _table(["requirement", "needs", "judged on (lower bound)", "yield [two-sided CI]", "yield bound",
                         "ppm", "Cpk", "n to demonstrate", "result"], rows)
        if any(r.get("min_yield_default") for r in reqs):
            lines += ["", "A requirement that names neither a yield nor a Cpk asks for yield ≥ 0.9973 (±3σ coverage, "
                      "rvtol's default)."]
    elif v == "EXPLORATORY":
        lines.append("Exploratory study: it checks no requirement by design.")
    else:
        lines.append("**No requirement is checked: nothing is demonstrated** (exit code 4). Add `[[requirement]]` "
                     "tables, or declare `[study] exploratory = true`.")
    if comparison is not None:
        lines += ["", *comparison_markdown(comparison)]
    return "\n".join(lines) + "\n"


def comparison_markdown(c) -> list[str]:
    pct = f"{100 * c.confidence:g} %"
    lines = [f"#### {_ICON[c.verdict]} Against the baseline: gates **{c.verdict}**", "",
             f"Baseline {_code(c.base['source'])} (n {c.base['n']:,}, seed {c.base['seed']}, verdict {c.base['verdict']}) · "
             + ("**paired** on common random numbers (" if c.paired else "unpaired (") + _cell(c.pairing) + ")", ""]
    if c.spec_changes:
        lines += _table(["factor", "change", "before", "after"],
                        [[s["factor"], s["change"], s.get("old") or "—", s.get("new") or "—"] for s in c.spec_changes])
        lines.append("")
    else:
        lines += ["No change of the tolerance spec.", ""]
    rows = []
    for name, o in c.outputs.items():       # in the output's unit: the decimals resolve its band (rvtol.precision)
        num = partial(shown, scale=o.get("scale"))
        for ch in o["changes"]:
            rows.append([name, ch.statistic, f"{num(ch.base)} → {num(ch.new)} {units.label(o['unit'])}",
                         num(ch.change), _ci(ch.ci, num), _ci(ch.unpaired_ci, num) if ch.unpaired_ci else "—",
                         f"{ch.gain:.3g}×" if ch.gain else "—"])
    if rows:
        lines += _table(["output", "statistic", "baseline → new", "change", f"{pct} interval",
                         "unpaired interval", "gain"], rows)
        lines.append("")
    if c.requirements:
        lines += _table(["requirement", "verdict", "ppm", "ppm change [interval]"],
                        [[r["requirement"], f"{r['base_verdict']} → {r['new_verdict']}",
                          f"{_f(r['ppm']['base'], '.0f')} → {_f(r['ppm']['new'], '.0f')}",
                          f"{_f(r['ppm']['change'], '.4g')} {_ci(r['ppm']['ci'])}"] for r in c.requirements])
        lines.append("")
    lines += _table(["gate", "result", "why"],
                    [[g.gate.name, _state("PASS" if g.passed else "FAIL"), "; ".join(g.reasons or g.figures)]
                     for g in c.gates])
    return lines
