"""JUnit XML of a run (and of its baseline comparison): what CI systems show as test results.

One test suite per run, one test case per requirement (``classname`` ``rvtol.<study>.requirements``)
and per gate (``rvtol.<study>.gates``); a requirement that is not demonstrated — its state UNDECIDED or
FAIL (:func:`rvtol.verdict.requirement_state`) — or a gate that fails is a ``<failure>`` whose ``message``
is the state and the first reason and whose text holds the state, every reason and figure (a requirement
that passes: PASS and its figures as the case's output).  A run that checks no
requirement has one failing test case saying so (NO REQUIREMENTS), or a skipped one when the study is
exploratory: a CI dashboard never shows "0 tests, all green" for a study that proved nothing.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from ..safetext import visible
from ..verdict import state_of


def _fmt(v, f=".5g") -> str:
    return "—" if v is None else format(v, f)


def requirement_figures(r: dict) -> str:
    """A requirement's figures as text lines (JUnit failure text, Markdown details)."""
    if r.get("statistic"):
        lo, hi = r.get("statistic_interval") or [None, None]
        lines = [f"needs the {r['statistic']} within [{_fmt(r.get('lower'))}, {_fmt(r.get('upper'))}]",
                 f"{r['statistic']} {_fmt(r.get('statistic_estimate'))} [{_fmt(lo)}, {_fmt(hi)}] (each end a "
                 f"{100 * r.get('bound_level', r['confidence']):g} % one-sided bound)"]
        if r.get("n_to_demonstrate"):
            lines.append(f"n to decide: {r['n_to_demonstrate']}")
        return "\n".join(lines + list(r.get("reasons", [])))
    ci = r.get("yield_ci") or [None, None]
    lines = [f"yield {_fmt(r.get('yield'), '.6f')} [{_fmt(ci[0], '.6f')}, {_fmt(ci[1], '.6f')}] "
             f"(two-sided {100 * r['confidence']:g} %); judged on the {r.get('bound', 'two-sided')} lower bound "
             f"{_fmt(r.get('yield_bound'), '.6f')} at {100 * r.get('bound_level', r['confidence']):g} %",
             f"ppm {_fmt(r.get('ppm'), '.1f')} [{_fmt(r['ppm_ci'][0], '.1f')}, {_fmt(r['ppm_ci'][1], '.1f')}]"]
    if r.get("cpk") is not None:
        lines.append(f"Cpk {_fmt(r['cpk'], '.3f')} [{_fmt(r['cpk_ci'][0], '.3f')}, {_fmt(r['cpk_ci'][1], '.3f')}], "
                     f"bound {_fmt(r.get('cpk_bound'), '.3f')}")
    need = []
    if r.get("min_yield") is not None:
        need.append(f"yield ≥ {r['min_yield']:g}" + (" (rvtol's default)" if r.get("min_yield_default") else ""))
    if r.get("min_cpk") is not None:
        need.append(f"Cpk ≥ {r['min_cpk']:g}")
    lines.insert(0, f"needs {' and '.join(need)} on the {'estimate' if r['basis'] == 'estimate' else 'lower bound'}")
    if r.get("n_to_demonstrate"):
        lines.append(f"n to demonstrate: {r['n_to_demonstrate']}")
    return "\n".join(lines + list(r.get("reasons", [])))


def junit_tree(summary: dict, comparison=None) -> ET.ElementTree:
    study = summary["study"]
    suite = ET.Element("testsuite", name=f"rvtol {study}", timestamp=summary.get("created", ""))
    props = ET.SubElement(suite, "properties")
    for k in ("verdict", "n", "seed", "method", "rvtol_version"):
        ET.SubElement(props, "property", name=k, value=str(summary.get(k)))
    cases = failures = skipped = 0

    def case(classname: str, name: str, failure: str | None = None, text: str = "", skip: str | None = None):
        nonlocal cases, failures, skipped
        c = ET.SubElement(suite, "testcase", classname=f"rvtol.{study}.{classname}", name=name, time="0")
        cases += 1
        if failure is not None:
            f = ET.SubElement(c, "failure", message=failure, type="requirement" if classname == "requirements"
                              else "serial" if classname.startswith("serials.") else "gate")
            f.text = text
            failures += 1
        elif skip is not None:
            ET.SubElement(c, "skipped", message=skip)
            skipped += 1
        elif text:
            ET.SubElement(c, "system-out").text = text
        return c

    reqs = [r for o in summary["outputs"].values() for r in o.get("requirements", [])]
    for r in reqs:      # its state (PASS, UNDECIDED, FAIL) first: the word every output gives it
        state = state_of(r)
        text = f"{state}\n{requirement_figures(r)}"
        case("requirements", r["requirement"], None if r["passed"] else f"{state}: {(r['reasons'] or ['fails'])[0]}",
             text)
    if not reqs:
        if summary.get("verdict") == "EXPLORATORY":
            case("requirements", "requirements", skip="exploratory study: it checks no requirement by design")
        else:
            case("requirements", "requirements", "NO REQUIREMENTS: the study checks no requirement, nothing is "
                 "demonstrated", "Add [[requirement]] tables, or declare [study] exploratory = true.")
    for key, a in (summary.get("analyses") or {}).items():     # a verdict per serial (per-unit, per-serial analyses)
        for u in a.get("units", []) if isinstance(a, dict) else []:
            if "reducer" not in u or "verdict" not in u:
                continue
            reqs_u = "\n".join(f"{r['requirement']}: {r['verdict']} (P = {_fmt(r['P'], '.4f')})"
                                for r in u.get("requirements", []))
            text = f"{u['verdict']}\n{reqs_u}"
            case(f"serials.{key}", u["reducer"], None if u["verdict"] == "conforms" else u["verdict"], text)
    if comparison is not None:
        for g in comparison.gates:
            text = "\n".join(g.figures + g.reasons)
            case("gates", g.gate.name, None if g.passed else g.reasons[0], text)
    suite.set("tests", str(cases))
    suite.set("failures", str(failures))
    suite.set("errors", "0")
    suite.set("skipped", str(skipped))
    root = ET.Element("testsuites", name="rvtol", tests=str(cases), failures=str(failures), errors="0",
                      skipped=str(skipped))
    root.append(suite)
    for e in root.iter():       # XML 1.0 holds no control character: each shown as its escape (rvtol.safetext)
        e.attrib.update({k: visible(v) for k, v in e.attrib.items()})
        if e.text:
            e.text = visible(e.text)
    ET.indent(root)
    return ET.ElementTree(root)


def write_junit(path: str | Path, summary: dict, comparison=None) -> None:
    junit_tree(summary, comparison).write(path, encoding="utf-8", xml_declaration=True)
