"""The first page a manager acts on: traffic lights, the drivers that matter, the cheapest fix by kind (checked against
hand computations), links that exist, the baseline comparison, and the one-page summary.pdf."""
import math
import re

import pytest
from scipy.stats import norm

from rvtol.executors import make_executor
from rvtol.mc import run_monte_carlo
from rvtol.model import LinearModel, Quantity
from rvtol.signoff import FIX_KINDS, Fix, digest, first_order_fixes, required_sigma
from rvtol.spec import Factor, Requirement, ToleranceSpec
from rvtol.distributions import Distribution

from conftest import ROOT


def _row(mean, std):
    return {"mean": mean, "std": std}


def test_re_centring_is_offered_when_the_centred_band_holds_the_spread():
    """Band [0, 0.075] mm, yield 0.9973 two-sided: z = Φ⁻¹(1 − 0.0027/2) = 3.0; centred, σ may reach 0.0375/3 = 0.0125.
    A mean of 0.05 with σ = 0.0108 fails (0.025/3 = 0.00833 < σ) but fits when centred: re-centre by −0.0125 mm."""
    r = Requirement("gap", lower=0.0, upper=0.075, unit="mm", min_yield=0.9973)
    z = norm.ppf(1 - 0.0027 / 2)
    assert required_sigma(r, 0.0375, 0.0108) == pytest.approx(0.0375 / z)
    d = type("D", (), {"drivers": [], "change": ""})()
    fixes = first_order_fixes(r, _row(0.05, 0.0108), d, None)
    rc = [f for f in fixes if f.kind == "re-centre"]
    assert len(rc) == 1 and "shift -0.0125 mm" in rc[0].action


def test_no_re_centring_when_the_spread_is_too_wide_even_centred():
    r = Requirement("gap", lower=0.0, upper=0.075, unit="mm", min_yield=0.9973)
    d = type("D", (), {"drivers": [], "change": ""})()
    assert not [f for f in first_order_fixes(r, _row(0.05, 0.013), d, None) if f.kind == "re-centre"]


def test_a_mean_beyond_its_limit_asks_for_a_redesign_only():
    r = Requirement("sum", upper=9.94, unit="mm")
    d = type("D", (), {"drivers": [], "change": "x"})()
    fixes = first_order_fixes(r, _row(9.95, 0.0076), d, None)
    assert [f.kind for f in fixes] == ["redesign"] and "below the limit 9.94 mm" in fixes[0].action


def test_an_undecided_requirement_asks_for_more_samples_first():
    r = Requirement("y", upper=1.0, unit="mm")
    d = type("D", (), {"drivers": [], "change": ""})()
    fixes = first_order_fixes(r, _row(0.0, 0.2), d, 5000)
    assert [f.kind for f in fixes] == ["more samples"] and "5,000" in fixes[0].action
    assert FIX_KINDS.index("more samples") < FIX_KINDS.index("re-centre") < FIX_KINDS.index("tighten") \
        < FIX_KINDS.index("redesign")


def _mc(n, reqs, seed=1):
    """y = a + b with a ~ N(0, 1), b ~ N(0, 0.5): var 1.25, S1(a) = 0.8, S1(b) = 0.2."""
    fs = (Factor("a", "mm", Distribution.make("normal", mean=0.0, sigma=1.0), part="p", feature="a"),
          Factor("b", "mm", Distribution.make("normal", mean=0.0, sigma=0.5), part="p", feature="b"))
    spec = ToleranceSpec("lights", fs)
    model = LinearModel(spec.names, spec.units, [Quantity("y", "mm")], [[1.0, 1.0]])
    with make_executor("serial") as ex:
        return run_monte_carlo(model, spec, n, "random", seed, reqs, ex, progress=False), model, spec


def test_lights_green_amber_red_and_the_tightening_fix():
    """σ_y = √1.25 = 1.118. Green: |y| ≤ 5 (4.5σ). Amber: yield ≥ 0.99 on |y| ≤ 3.5 (3.13σ: true yield 0.9983) with
    n = 2000 — the estimate meets it, the 95 % bound cannot demonstrate 0.99 with the expected ~3.5 failures? it can
    not when the bound falls below: decided by the run's own n_to_demonstrate. Red: |y| ≤ 1 (0.89σ)."""
    reqs = [Requirement("y", lower=-5, upper=5, unit="mm"), Requirement("y", lower=-1, upper=1, unit="mm", name="tight")]
    mc, model, spec = _mc(2000, reqs)
    d = digest(mc, model, spec, seed=1)
    assert [x.light for x in d] == ["green", "red"]
    red = d[1]
    tighten = [f for f in red.fixes if f.kind == "tighten"]
    # the target σ is 1/3 (two-sided 0.9973 → z = 3): need = 1 − (1/3)²/1.25 = 0.911 > S1(a) ≈ 0.8 → both drivers,
    # Σ S1 ≈ 1 → f = √(1 − 0.911/1) ≈ 0.30
    assert tighten and "tolerance" in tighten[0].action
    f = float(re.search(r"to (\d+) %", tighten[0].action).group(1)) / 100
    assert f == pytest.approx(math.sqrt(1 - (1 - (1 / 3) ** 2 / 1.25)), abs=0.06)


def test_amber_when_the_estimate_meets_but_the_bound_does_not():
    """|y| ≤ 3.5: true yield 2Φ(3.5/1.118) − 1 = 0.99826 ≥ 0.99; with n = 300 the one-sided 95 % Clopper–Pearson
    bound of ~299/300 is ≈ 0.984 < 0.99: undecided — more samples."""
    reqs = [Requirement("y", lower=-3.5, upper=3.5, unit="mm", min_yield=0.99)]
    mc, model, spec = _mc(300, reqs, seed=2)
    (d,) = digest(mc, model, spec, seed=1)
    v = mc.verdicts()[0]
    assert v.yield_.estimate >= 0.99 and not v.passed
    assert d.light == "amber" and d.fixes[0].kind == "more samples"


def _run(tmp_path, text, *args):
    from rvtol.cli import main

    study = tmp_path / "s.toml"
    study.write_text(text)
    out = tmp_path / "out"
    rc = main(["run", str(study), "--out", str(out), "--quiet", *args])
    return rc, out


STUDY = '''
[study]
name = "fp"
title = "first page"
[[factor]]
name = "a"
unit = "mm"
dist = "normal"
mean = 0.05
tolerance = 0.05
[[factor]]
name = "z"
unit = "mm"
dist = "normal"
mean = 0.0
tolerance = 1e-9
[model]
kind = "formula"
[[model.output]]
name = "gap"
formula = "a + 0 * z"
unit = "mm"
[sampling]
n = 400
seed = 3
[[requirement]]
output = "gap"
lower = 0.0
upper = 0.075
'''


def test_report_first_page_has_no_zero_share_driver_and_only_existing_links(tmp_path):
    """z carries no variance: it must not be listed as a driver; the fixes name no section the report lacks."""
    rc, out = _run(tmp_path, STUDY, "--no-pdf")
    assert rc == 1
    html = (out / "report.html").read_text()
    first = html[html.index('id="signoff"'):html.index('id="verdict"')]
    assert "<td>z</td>" not in first and ">a</td>" in first
    assert "re-centre" in first
    for key in re.findall(r'href="#([\w-]+)"', first):
        assert f'id="{key}"' in html
    assert "allocation section" not in html


def test_summary_pdf_is_one_page(tmp_path):
    rc, out = _run(tmp_path, STUDY)
    from pypdf import PdfReader

    assert len(PdfReader(str(out / "summary.pdf")).pages) == 1
    assert len(PdfReader(str(out / "report.pdf")).pages) > 1


def test_report_html_carries_the_baseline_comparison(tmp_path):
    rc, base = _run(tmp_path, STUDY, "--no-pdf")
    study = tmp_path / "s.toml"
    out2 = tmp_path / "out2"
    from rvtol.cli import main

    rc2 = main(["run", str(study), "--out", str(out2), "--quiet", "--no-pdf", "--baseline", str(base)])
    html = (out2 / "report.html").read_text()
    first = html[html.index('id="signoff"'):html.index('id="verdict"')]
    assert "Against the accepted baseline" in first and "Requirements against the baseline" in first
    assert rc2 == 1


def test_study_and_data_files_carry_no_development_references():
    """A customer-facing report shows the study's title and description and the data's sources and reasons: no
    'Issue 11.'-style references to the tracker in any value of a study or data file (comments may keep them)."""
    import tomllib

    def strings(v, path):
        if isinstance(v, dict):
            for k, x in v.items():
                yield from strings(x, f"{path}.{k}")
        elif isinstance(v, list):
            for i, x in enumerate(v):
                yield from strings(x, f"{path}[{i}]")
        elif isinstance(v, str):
            yield path, v

    files = [*(ROOT / "studies").rglob("*.toml"), *(ROOT / "data").rglob("*.toml")]
    bad = [(f"{p.relative_to(ROOT)}{where}", v[:60]) for p in files if p.name != "pyproject.toml"
           for where, v in strings(tomllib.loads(p.read_text(encoding="utf-8")), "")
           if re.search(r"\b[Ii]ssues? \d+", v)]
    assert bad == []


def test_spread_scale_reads_the_tail_of_the_samples():
    """Uniform samples on [0, 1] (mean 0.5), upper limit 0.99, yield 0.9973: the scaled sample meets it when
    0.5 + s (0.9973 − 0.5) ≤ 0.99, s = 0.49 / 0.4973 = 0.98533 (bisection to 1e-4)."""
    import numpy as np

    from rvtol.signoff import spread_scale

    y = np.linspace(0.0, 1.0, 100_001)
    r = Requirement("y", upper=0.99, unit="mm", min_yield=0.9973)
    assert spread_scale(r, 0.5, y) == pytest.approx(0.49 / (np.quantile(y, 0.9973) - 0.5), abs=2e-4)


def test_a_skewed_output_normal_theory_would_pass_still_gets_a_tightening_fix():
    """Exponential output (mean 1, σ 1), upper limit 5.5, yield 0.9973: normal theory allows σ = 4.5 / 2.78 = 1.62 > 1
    (it would call the spread fine), but the exponential's own P99.73 is −ln 0.0027 = 5.91 > 5.5: the deviations must
    shrink by s = 4.5 / 4.91 = 0.916, σ to 0.916 — the fix says so."""
    import numpy as np
    from scipy.stats import expon

    from rvtol.sensitivity.drivers import Driver

    y = expon.ppf((np.arange(200_000) + 0.5) / 200_000)
    r = Requirement("y", upper=5.5, unit="mm", min_yield=0.9973)
    assert required_sigma(r, 1.0, 1.0) > 1.0                                   # normal theory: fine
    assert required_sigma(r, 1.0, 1.0, y) == pytest.approx(4.5 / (-math.log(0.0027) - 1.0), abs=2e-3)
    d = type("D", (), {"drivers": [Driver("x", 1.0, ["x"])], "change": ""})()
    fixes = first_order_fixes(r, _row(1.0, 1.0), d, None, y)
    assert [f.kind for f in fixes] == ["tighten"] and "σ from 1.00 to 0.91" in fixes[0].effect


def test_a_drawing_tolerance_reads_short_in_a_cell():
    from rvtol.callouts import short_label

    assert short_label("pin housing: pin-groove circle (40 semicircular grooves, centres on R 76.5): groove-centre "
                       "circle ø153 js3 (±4 µm on the diameter)") == "pin housing: pin-groove circle: groove-centre circle ø153 js3"
    assert short_label("a (b (c) d) e") == "a e"
    assert short_label("x" * 80, width=10) == "x" * 9 + "…"


def test_the_factors_of_one_callout_share_its_name():
    """A callout's name, by hand: the spec's feature (with its part), else the factor's name without its coordinate
    suffix and its family index — the x1 … y2 of one zone and the copies of a family are one callout."""
    from types import SimpleNamespace as F

    from rvtol.callouts import callout_of

    assert {callout_of(F(name=f"cam.{c}")) for c in ("x1", "y1", "x2", "y2")} == {"cam"}
    assert {callout_of(F(name=f"R_pin[{k}]")) for k in (1, 2, 40)} == {"R_pin[k]"}
    assert callout_of(F(name="hole[3].x")) == "hole[k]"
    assert callout_of(F(name="carrier.width")) == "carrier.width"          # not a coordinate: its own callout
    assert callout_of(F(name="c.x1", feature="bore", part="carrier")) == "carrier: bore"
    assert callout_of(F(name="c.x1", feature="bore", part="")) == "bore"


def test_requirements_more_samples_would_decide_share_one_row():
    """Eleven undecided requirements are one line of the first page, with the largest n (each is demonstrated by it
    if its figures hold), not eleven."""
    from rvtol.signoff import _one_more_samples_row

    rows = [{"requirement": "a", "fix": "more samples", "what to do": "run n = 2,000 samples", "what it gives": "",
             "evidence": "estimate"},
            {"requirement": "a", "fix": "tighten", "what to do": "scale x", "what it gives": "", "evidence": ""},
            {"requirement": "b", "fix": "more samples", "what to do": "run n = 12,345 samples", "what it gives": "",
             "evidence": "estimate"}]
    out = _one_more_samples_row(rows)
    assert [r["fix"] for r in out] == ["more samples", "tighten"]
    assert out[0]["requirement"] == "a; b" and out[0]["what to do"] == "run n = 12,345 samples"
    assert _one_more_samples_row(rows[:2]) == rows[:2]
