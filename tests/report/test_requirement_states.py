"""Issue 37, item 11: one word for a requirement's state — PASS, UNDECIDED (more samples would decide) or FAIL — in the
CLI, summary.json, JUnit, Markdown, the report (HTML, and so its PDF) and the one-page summary (summary.pdf's HTML).

Before, the CLI, summary.json, JUnit, Markdown and the report's verdict section said FAIL where the first page said
UNDECIDED."""
import math
import re
import xml.etree.ElementTree as ET

import pytest
from scipy import stats

from conftest import ab_study

REQUIREMENTS = """[[requirement]]
name = "passes"
output = "y"
lower = 5.8
upper = 6.2
unit = "mm"
min_yield = 0.9
[[requirement]]
name = "undecided"
output = "y"
lower = 5.8
upper = 6.2
unit = "mm"
[[requirement]]
name = "fails"
output = "y"
upper = 6.0
unit = "mm"
"""
STUDY = ab_study("states", requirements=REQUIREMENTS, n=300, seed=1)
N = 300


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    from rvtol.study import load_study, run_study

    p = tmp_path_factory.mktemp("states") / "states.toml"
    p.write_text(STUDY, encoding="utf-8")
    return run_study(load_study(p, progress=False))


def test_the_three_states_follow_from_the_one_sided_bound(result):
    """The reference: ±0.05 mm at ±3σ on both factors puts y = a − b within 6 ± 0.2 mm for every sample (σ_y =
    0.0236 mm, 8.5 σ), so k = n = 300: the Clopper–Pearson one-sided 95 % lower bound is 0.05^(1/300) = 0.99006 —
    above 0.9 (PASS), below 0.9973 which the estimate 1 meets (UNDECIDED: n = ln 0.05 / ln 0.9973 = 1109 would
    demonstrate it) —; y ≤ 6.0 holds for about half (FAIL: the estimate misses)."""
    bound = stats.beta.ppf(0.05, N, 1)
    assert bound == pytest.approx(0.05 ** (1 / N)) and 0.9 < bound < 0.9973
    v = {x.requirement.label: x for x in result.mc.verdicts()}
    assert v["undecided"].n_to_demonstrate == math.ceil(math.log(0.05) / math.log(0.9973)) == 1109
    assert {k: x.state for k, x in v.items()} == {"passes": "PASS", "undecided": "UNDECIDED", "fails": "FAIL"}


EXPECTED = {"passes": "PASS", "undecided": "UNDECIDED", "fails": "FAIL"}


def test_every_output_gives_each_requirement_the_same_word(result, capsys):
    from rvtol.ci.junit import junit_tree
    from rvtol.ci.markdown import render_markdown
    from rvtol.cli import _print_result
    from rvtol.report.render import render_html, render_summary_html

    said: dict[str, dict[str, str]] = {}

    _print_result(result)                                                        # the CLI
    said["cli"] = {m[2]: m[1] for m in re.finditer(r"^  (PASS|UNDECIDED|FAIL) +(\w+) \(needs", capsys.readouterr().out,
                                                   re.M)}
    summary = result.summary()                                                   # summary.json
    said["json outputs"] = {r["requirement"]: r["state"] for r in summary["outputs"]["y"]["requirements"]}
    said["json requirements"] = {r["requirement"]: r["verdict"] for r in summary["requirements"]}
    said["junit"] = {}                                                           # JUnit
    for case in ET.fromstring(ET.tostring(junit_tree(summary).getroot())).iter("testcase"):
        f = case.find("failure")
        text = f.get("message") if f is not None else case.find("system-out").text
        said["junit"][case.get("name")] = re.match(r"(PASS|UNDECIDED|FAIL)\b", text)[1]
        assert (f is None) == (said["junit"][case.get("name")] == "PASS")     # not demonstrated: a CI failure
    said["markdown"] = {m[1]: m[2] for m in re.finditer(r"^\| (\w+) \|.*\| \S+ (PASS|UNDECIDED|FAIL)(?: — [^|]*)? \|$",
                                                       render_markdown(summary), re.M)}
    html = render_html(result)                                                   # report.html (and report.pdf)
    said["report first page"] = dict((m[2], m[1]) for m in re.finditer(
        r'● (PASS|UNDECIDED|FAIL)</td>\s*<td>(\w+)</td>', html))
    verdict = html[html.index('id="verdict"'):]
    said["report verdict section"] = {m[1]: m[2] for m in re.finditer(
        r"<tr>\s*<t[hd]>(passes|undecided|fails)</t[hd]>(?:\s*<td>[^<]*</td>)*?\s*<td>(PASS|UNDECIDED|FAIL)</td>",
        verdict)}
    said["summary.pdf"] = dict((m[2], m[1]) for m in re.finditer(                # the one-page summary's HTML
        r'● (PASS|UNDECIDED|FAIL)</td>\s*<td>(\w+)</td>', render_summary_html(result)))
    for where, words in said.items():
        assert words == EXPECTED, where
