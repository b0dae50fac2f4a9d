"""Baseline comparison, gates, JUnit and Markdown through the real CLI (``main``), and the intervals of a
change against independent references (SciPy's t-tests, Newcombe's published example, closed forms,
coverage by simulation).

The study: gap = a − b (µm), a normal with tolerance T (±T/2 at 3σ), b uniform ±5 µm.  Tightening or
loosening T keeps the seed, n and factors: the runs share their random numbers, so a_new = (T_new/T)·a
sample by sample and the change of σ is known in closed form: √((T_new/6)² + 100/12) − √((T/6)² + 100/12).
"""
import json
import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from scipy import stats

from rvtol.ci import differences as df
from rvtol.cli import main

from conftest import GAP_MODEL, gap_factors


STUDY = """
[study]
name = "gap"
spec = "spec_{tag}.toml"
{model}[sampling]
n = 4000
method = "lhs"
seed = 1
[[requirement]]
output = "gap"
upper = 20.0
unit = "um"
min_yield = 0.9
{gates}
"""

GATES = """
[[gate]]
kind = "requirements"
[[gate]]
kind = "output"
output = "gap"
statistic = "P99.865"
max_increase = 1.0
"""


def make(tmp_path, tag: str, T: float, gates: str = GATES, n: int | None = None):
    (tmp_path / f"spec_{tag}.toml").write_text(gap_factors(T))
    text = STUDY.format(tag=tag, gates=gates, model=GAP_MODEL)
    if n is not None:
        text = text.replace("n = 4000", f"n = {n}")
    p = tmp_path / f"study_{tag}.toml"
    p.write_text(text)
    return p


def run(tmp_path, study, out, *extra):
    return main(["run", str(study), "--out", str(tmp_path / out), "--no-pdf", "--executor", "serial", "--quiet", *extra])


def sigma(T):
    return math.sqrt((T / 6) ** 2 + 100 / 12)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("ci")
    for tag, T in (("base", 30.0), ("tight", 24.0), ("loose", 36.0)):
        assert run(tmp, make(tmp, tag, T), tag) == 0
    return tmp


def changes(c: dict) -> dict:
    return {ch["statistic"]: ch for ch in c["outputs"]["gap"]["changes"]}


@pytest.mark.parametrize("tag,T,sign,rc", [("tight", 24.0, -1, 0), ("loose", 36.0, +1, 1)])
def test_compare_gives_the_sign_of_the_change_with_a_paired_interval_narrower_than_the_unpaired(runs, tag, T, sign,
                                                                                                  rc, capsys):
    out = runs / f"cmp_{tag}.json"
    assert main(["compare", str(runs / "base"), str(runs / tag), "--out", str(out)]) == rc
    c = json.loads(out.read_text())
    assert c["paired"] is True and c["format"] == "rvtol-comparison/1"
    # numbers resolving the band (30 µm: 1 decimal) with four significant digits (rvtol.precision)
    assert c["spec_changes"] == [{"factor": "a", "change": "changed",
                                  "old": "normal(μ=0.0, σ=5.000) um; band [-15, 15] µm",
                                  "new": f"normal(μ=0.0, σ={T / 6:.3f}) um; band [{-T / 2:g}, {T / 2:g}] µm"}]
    ch = changes(c)
    for stat in ("std", "P99.865"):
        lo, hi = ch[stat]["ci"]
        assert sign * lo > 0 and sign * hi > 0, (stat, ch[stat])  # the change is demonstrated, with its sign
    for stat in ("mean", "std", "P99.865"):
        (lo, hi), (ulo, uhi) = ch[stat]["ci"], ch[stat]["unpaired_ci"]
        assert hi - lo < uhi - ulo and ch[stat]["gain"] == pytest.approx((uhi - ulo) / (hi - lo))
    assert ch["std"]["gain"] > 4  # common random numbers: the shared noise cancels
    # the closed-form change of σ lies in the paired interval (and in the unpaired one)
    true = sigma(T) - sigma(30.0)
    assert ch["std"]["ci"][0] <= true <= ch["std"]["ci"][1]
    assert ch["std"]["unpaired_ci"][0] <= true <= ch["std"]["unpaired_ci"][1]
    gates = {g["name"]: g for g in c["gates"]}
    p99 = gates["P99.865 of gap may not grow by more than 1 µm"]
    assert p99["passed"] is (sign < 0) and gates["no requirement may get worse"]["passed"] is True
    text = capsys.readouterr().out
    assert "paired on common random numbers" in text and "narrower than unpaired" in text
    assert f"gates: {'PASS' if rc == 0 else 'FAIL'}" in text


def test_run_with_baseline_writes_junit_markdown_and_the_step_summary(runs, tmp_path, monkeypatch, capsys):
    step = tmp_path / "step_summary.md"
    step.write_text("earlier step\n")
    monkeypatch.setenv("GITHUB_STEP_SUMMARY", str(step))
    junit, md = tmp_path / "ci" / "junit.xml", tmp_path / "ci" / "summary.md"
    study = make(tmp_path, "loose", 36.0)
    rc = run(tmp_path, study, "new", "--baseline", str(runs / "base"), "--junit", str(junit), "--markdown", str(md))
    assert rc == 1  # the requirement passes; the P99.865 gate fails against the baseline
    assert "gates: FAIL" in capsys.readouterr().out
    assert (tmp_path / "new" / "comparison.json").exists()

    root = ET.parse(junit).getroot()
    assert root.tag == "testsuites" and root.get("tests") == "3" and root.get("failures") == "1"
    cases = {(c.get("classname"), c.get("name")): c for c in root.iter("testcase")}
    assert set(cases) == {("rvtol.gap.requirements", "gap ≤ 20 µm"), ("rvtol.gap.gates", "no requirement may get worse"),
                          ("rvtol.gap.gates", "P99.865 of gap may not grow by more than 1 µm")}
    assert cases[("rvtol.gap.requirements", "gap ≤ 20 µm")].find("failure") is None
    fail = cases[("rvtol.gap.gates", "P99.865 of gap may not grow by more than 1 µm")].find("failure")
    assert "exceeds the allowed increase 1" in fail.get("message") and "P99.865 of gap:" in fail.text

    text = md.read_text()
    assert text.startswith("### ✅ rvtol · gap: **PASS**")
    assert "#### ❌ Against the baseline: gates **FAIL**" in text and "| a | changed |" in text
    assert step.read_text() == "earlier step\n" + text + "\n"


def test_junit_of_a_failing_requirement_and_of_a_study_that_checks_nothing(tmp_path):
    study = make(tmp_path, "fail", 30.0, gates="")
    study.write_text(study.read_text().replace("upper = 20.0", "upper = 6.0"))
    assert run(tmp_path, study, "f", "--junit", str(tmp_path / "f.xml")) == 1
    case = ET.parse(tmp_path / "f.xml").getroot().find("testsuite/testcase")
    assert case.get("name") == "gap ≤ 6 µm"
    assert case.find("failure").get("message").startswith("FAIL: yield lower bound ") and "ppm" in case.find("failure").text

    bare = make(tmp_path, "bare", 30.0, gates="")
    bare.write_text(bare.read_text().split("[[requirement]]")[0])
    assert run(tmp_path, bare, "b", "--junit", str(tmp_path / "b.xml")) == 4
    case = ET.parse(tmp_path / "b.xml").getroot().find("testsuite/testcase")
    assert case.find("failure").get("message").startswith("NO REQUIREMENTS")
    bare.write_text(bare.read_text().replace('name = "gap"', 'name = "gap"\nexploratory = true', 1))
    assert run(tmp_path, bare, "e", "--junit", str(tmp_path / "e.xml")) == 0
    case = ET.parse(tmp_path / "e.xml").getroot().find("testsuite/testcase")
    assert case.find("skipped") is not None and case.find("failure") is None


def test_a_requirement_that_gets_worse_fails_the_default_gate(runs, tmp_path):
    """No [[gate]] declared: compare applies "no requirement may get worse"; a PASS → FAIL is caught."""
    study = make(tmp_path, "worse", 30.0, gates="")
    study.write_text(study.read_text().replace("min_yield = 0.9", "min_yield = 0.9995"))  # 500 ppm > 0.05 %: FAIL
    assert run(tmp_path, study, "w") == 1
    assert run(tmp_path, make(tmp_path, "b2", 30.0, gates=""), "b2") == 0
    # the same requirement (its label: "gap ≤ 20 µm"), asked for a higher yield: PASS → FAIL
    out = tmp_path / "c.json"
    assert main(["compare", str(tmp_path / "b2"), str(tmp_path / "w"), "--out", str(out)]) == 1
    g = json.loads(out.read_text())["gates"]
    assert [x["name"] for x in g] == ["no requirement may get worse"]
    assert g[0]["reasons"] == ["gap ≤ 20 µm: PASS → FAIL"]


def test_compare_from_summaries_alone_is_unpaired(runs, tmp_path):
    for tag in ("base", "loose"):
        (tmp_path / f"{tag}.json").write_text((runs / tag / "summary.json").read_text())
    out, ref = tmp_path / "c.json", tmp_path / "paired.json"
    main(["compare", str(tmp_path / "base.json"), str(tmp_path / "loose.json"), "--out", str(out)])
    main(["compare", str(runs / "base"), str(runs / "loose"), "--out", str(ref)])
    c = json.loads(out.read_text())
    assert c["paired"] is False and "samples.parquet missing" in c["pairing"]
    ch, paired = changes(c), changes(json.loads(ref.read_text()))
    true = sigma(36.0) - sigma(30.0)
    assert ch["std"]["ci"][0] <= true <= ch["std"]["ci"][1]
    for stat in ("mean", "std"):  # from the summaries: the unpaired interval of the samples, to a few %
        assert ch[stat]["ci"] == pytest.approx(paired[stat]["unpaired_ci"], rel=0.05, abs=0.01)


def test_different_seeds_are_compared_unpaired(runs, tmp_path):
    study = make(tmp_path, "s2", 36.0)
    study.write_text(study.read_text().replace("seed = 1", "seed = 2"))
    run(tmp_path, study, "s2")
    out = tmp_path / "c.json"
    main(["compare", str(runs / "base"), str(tmp_path / "s2"), "--out", str(out)])
    c = json.loads(out.read_text())
    assert c["paired"] is False and c["pairing"].startswith("different seed (1 → 2)")
    assert all(ch["unpaired_ci"] is None for ch in c["outputs"]["gap"]["changes"])


@pytest.mark.parametrize("gate,key,reason", [
    ('[[gate]]\nkind = "output"\noutput = "gpa"\nstatistic = "P99.865"\nmax_increase = 1.0\n', "gate[0].output",
     "did you mean 'gap'?"),
    ('[[gate]]\nkind = "output"\noutput = "gap"\nstatistic = "P99.865"\n', "gate[0].max_increase",
     "needs max_increase and/or max_decrease"),
    ('[[gate]]\nkind = "output"\noutput = "gap"\nstatistic = "P99.9"\nmax_increase = 1.0\n', "gate[0].statistic",
     "unknown value 'P99.9'"),
    ('[[gate]]\nkind = "output"\noutput = "gap"\nstatistic = "mean"\nmax_increase = 1.0\nunit = "arcmin"\n',
     "gate[0].unit", "does not fit output 'gap'"),
    ('[[gate]]\nkind = "requirement"\n', "gate[0].kind", "did you mean 'requirements'?"),
    ('[[gate]]\nkind = "requirements"\noutput = "gap"\n', "gate[0].output",
     "belongs to a kind = 'output' gate, not to a 'requirements' one"),
    ('[[gate]]\nkind = "output"\noutput = "gap"\nmax_ppm_increase = 5\nmax_increase = 1.0\n', "gate[0].max_ppm_increase",
     "belongs to a kind = 'requirements' gate"),
    ('[[gate]]\nkind = "output"\noutput = "gap"\nmax_increase = 1.0\n', "gate[0].statistic", "missing required key"),
    ('[[gate]]\nkind = "output"\noutput = "gap"\nstatistic = "mean"\nmax_increase = 1.0\nunit = "furlongz"\n',
     "gate[0].unit", "unknown unit"),
])
def test_bad_gates_are_reported_when_the_study_loads(tmp_path, capsys, gate, key, reason):
    study = make(tmp_path, "g", 30.0, gates=gate)
    assert main(["check", str(study)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"rvtol: error: {study}: {key}: ") and reason in err, err


def test_bad_baselines_are_exit_2_before_computing(runs, tmp_path, capsys):
    study = make(tmp_path, "x", 30.0)
    (tmp_path / "empty").mkdir()
    assert run(tmp_path, study, "o", "--baseline", str(tmp_path / "empty")) == 2
    assert "--baseline: no summary.json in this folder" in capsys.readouterr().err
    broken = tmp_path / "broken.json"
    broken.write_text(json.dumps({**json.loads((runs / "base" / "summary.json").read_text()), "verdict": "MAYBE"}))
    assert run(tmp_path, study, "o", "--baseline", str(broken)) == 2
    assert capsys.readouterr().err.startswith(f"rvtol: error: {broken}: verdict: not a valid rvtol summary: 'MAYBE'")
    assert not (tmp_path / "o").exists()


# --------------------------------------------------------------------------- the intervals of a change
def test_mean_change_is_scipys_paired_and_welch_t_interval():
    g = np.random.default_rng(5)
    a = g.normal(10, 2, 300)
    b = a + g.normal(0.3, 0.5, 300)
    d, lo, hi = df.mean_change(a, b, True, 0.95)
    ci = stats.ttest_rel(b, a).confidence_interval(0.95)
    assert (lo, hi) == pytest.approx((ci.low, ci.high)) and d == pytest.approx(np.mean(b - a))
    c = g.normal(10.5, 3, 200)
    d, lo, hi = df.mean_change(a, c, False, 0.95)
    ci = stats.ttest_ind(c, a, equal_var=False).confidence_interval(0.95)
    assert (lo, hi) == pytest.approx((ci.low, ci.high))


def test_proportion_change_reproduces_newcombes_example():
    """Newcombe (1998), Stat. Med. 17:873, Table II: 56/70 − 48/80, method 10: [0.0524, 0.3339]."""
    a = np.r_[np.ones(48), np.zeros(32)].astype(bool)
    b = np.r_[np.ones(56), np.zeros(14)].astype(bool)
    d, lo, hi = df.proportion_change(a, b, False)
    assert d == pytest.approx(0.2) and lo == pytest.approx(0.0524, abs=5e-5) and hi == pytest.approx(0.3339, abs=5e-5)


def _coverage(make_pair, fn, true, trials=400):
    hits = sum(lo <= true <= hi for lo, hi in (fn(*make_pair(i))[1:] for i in range(trials)))
    return hits / trials


@pytest.mark.parametrize("paired", [True, False])
def test_std_and_proportion_changes_cover_the_truth(paired):
    """Coverage by simulation, against 95 % − 3 binomial standard errors (400 trials)."""
    floor = 0.95 - 3 * math.sqrt(0.95 * 0.05 / 400)
    g = np.random.default_rng(11 if paired else 12)

    def pair(i, n=400):
        x = g.normal(size=n)
        y = 1.3 * x + 0.4 * g.normal(size=n) if paired else g.normal(0, math.sqrt(1.69 + 0.16), n)
        return x, y

    assert _coverage(pair, lambda a, b: df.std_change(a, b, paired), math.sqrt(1.69 + 0.16) - 1.0) >= floor

    def flags(i, n=2000):  # out of spec above 2σ: P = 2.28 %, and above 2σ of the wider variable
        x, y = pair(i, n)
        return x > 2.0, y > 2.0
    true = stats.norm.sf(2.0 / math.sqrt(1.85)) - stats.norm.sf(2.0)
    assert _coverage(flags, lambda a, b: df.proportion_change(a, b, paired), true) >= floor


def _table(n11, n10, n01, n00):
    a = np.r_[np.ones(n11 + n10), np.zeros(n01 + n00)].astype(bool)
    b = np.r_[np.ones(n11), np.zeros(n10), np.ones(n01), np.zeros(n00)].astype(bool)
    return a, b


def test_paired_proportion_interval_uses_the_correlation_of_the_pairs():
    # a 2×2 table with n11·n00 = n10·n01 has φ = 0: Newcombe's paired interval is then the independent one
    a, b = _table(1, 9, 19, 171)
    assert df.proportion_change(a, b, True) == pytest.approx(df.proportion_change(a, b, False))
    # nested out-of-spec sets (every sample out before is out after: a loosened tolerance): φ > 0, narrower
    a, b = _table(20, 0, 15, 965)
    d, lo, hi = df.proportion_change(a, b, True)
    _, ulo, uhi = df.proportion_change(a, b, False)
    assert d == pytest.approx(0.015) and hi - lo < uhi - ulo and lo > 0
