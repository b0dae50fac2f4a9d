"""Undecided yield requirements decided by tail estimators (rvtol.tail_decision), against the closed form.

The study: y = a − b, a and b normal with σ = 0.05/3 mm (±0.05 read as ±3σ), so y ~ N(6, σ_y²), σ_y = σ√2, and
P(y > U) = Φ(−(U − 6)/σ_y) exactly.  Limits are placed where the plain Monte Carlo of the study cannot decide.
"""
from __future__ import annotations

import json
import math

import pytest
from scipy import stats

from conftest import run_cli, write

SIGMA_Y = 0.05 / 3 * math.sqrt(2)


def _study(tmp_path, upper: float, min_yield: float, n: int, seed: int, tails: bool = True, extra: str = ""):
    text = f"""[study]
name = "td"
[[factor]]
name = "a"
unit = "mm"
nominal = 10
tolerance = "±0.05"
[[factor]]
name = "b"
unit = "mm"
nominal = 4
tolerance = "±0.05"
[model]
kind = "formula"
[[model.output]]
name = "y"
formula = "a - b"
unit = "mm"
[[requirement]]
name = "gap"
output = "y"
upper = {upper!r}
unit = "mm"
min_yield = {min_yield!r}
[sampling]
n = {n}
method = "random"
seed = {seed}
tails = {str(tails).lower()}
{extra}
[execution]
executor = "serial"
[report]
pdf = false
"""
    return write(tmp_path / f"s_{tails}.toml", text)


def _run(tmp_path, capsys, path):
    out = tmp_path / ("out_" + path.stem)
    rc, _ = run_cli(["run", path, "--out", out, "--quiet"], capsys)
    return rc, json.loads((out / "summary.json").read_text("utf-8"))


@pytest.mark.parametrize("p_true,min_yield,n,seed,state", [
    (1e-3, 0.9973, 1500, 7, "PASS"),        # the true yield 0.999 clears 0.9973; 1 of 1500 cannot show it
    (5e-3, 0.9973, 800, 5, "FAIL"),         # 0.995 misses 0.9973; 2 of 800 cannot show that either
    (1e-6, 0.99999, 2000, 1, "PASS"),       # a ppm requirement: 0 of 2000 bounds the yield at 0.9985 only
])
def test_the_tails_decide_what_the_monte_carlo_leaves_undecided(tmp_path, capsys, p_true, min_yield, n, seed, state):
    upper = 6.0 + float(stats.norm.isf(p_true)) * SIGMA_Y
    rc0, plain = _run(tmp_path, capsys, _study(tmp_path, upper, min_yield, n, seed, tails=False))
    assert plain["requirements"][0]["verdict"] == "UNDECIDED" and "tails" not in plain
    rc, summ = _run(tmp_path, capsys, _study(tmp_path, upper, min_yield, n, seed))
    d = summ["tails"]["gap"]
    req = summ["requirements"][0]
    assert d["state"] == req["verdict"] == state
    assert abs(d["nonconformance"] - p_true) < 4 * d["se"], d          # the exact tail within 4 standard errors
    lo, hi = d["interval"]
    assert lo <= d["nonconformance"] <= hi and req["yield_lower_bound"] == pytest.approx(1 - hi)
    # FORM, 2 000 importance samples, 2 000 per subset level (3 levels at 1e-3, 6 at 1e-6): the plain Monte Carlo
    # would need about 3/(1 − 0.99999) = 300 000 samples to show the ppm requirement
    assert d["evaluations"] < 20_000 and "decided by the tails" in d["why"] and "by both" in d["why"]
    assert (rc == 0) == (state == "PASS")


def test_a_tail_estimate_the_monte_carlo_contradicts_is_not_used(tmp_path, monkeypatch):
    import numpy as np

    from rvtol import tail_decision
    from rvtol.stacking.tail import Estimate, TailEstimate
    from rvtol.study import load_study, run_study

    def wrong(model, spec, output, limit, side, evaluate, **kw):       # an estimator that missed the failures
        est = TailEstimate(output, "mm", side, limit)
        est.estimates += [Estimate("subset", 1e-7, 1e-8, evaluations=3000),
                          Estimate("importance sampling", 1.1e-7, 1e-8, evaluations=1000)]
        est.reference = "subset"
        est.evaluations = 3000
        return est

    monkeypatch.setattr(tail_decision, "tail_probability", wrong)
    upper = 6.0 + float(stats.norm.isf(5e-3)) * SIGMA_Y        # 5 000 ppm: 2 of 800 in this run
    study = load_study(_study(tmp_path, upper, 0.9973, 800, 5), progress=False)
    mc = run_study(study).mc
    d = mc.tails["gap"]
    assert d.state == "UNDECIDED" and "disagree with the Monte Carlo's" in d.why
    assert mc.verdicts()[0].undecided and d.why in mc.verdicts()[0].reasons
    k = int(np.sum(mc.column("y") > upper))
    assert f"{k} of 800" in d.why


def test_tails_and_a_sequential_run_are_one_choice(tmp_path, capsys):
    p = _study(tmp_path, 6.07, 0.9973, 400, 3, extra="until_decided = true")
    rc, err = run_cli(["check", p], capsys)
    assert rc == 2 and len(err) == 1 and "sampling.tails" in err[0] and "choose one" in err[0]


def _hypot_study(tmp_path, seed: int):
    # r = hypot(x, y), x and y normal with σ = 0.01 mm: P(r > U) = exp(−U²/2σ²) = 3e-5 exactly, yield 0.99997,
    # short of 0.99998: FAIL. Every direction fails alike: importance sampling about one design point sees about a
    # fifth of it (before both estimators had to agree, 5 seeds of 10 gave a wrong PASS)
    upper = 0.01 * math.sqrt(-2 * math.log(3e-5))
    text = (f'[study]\nname = "hypot"\n[[factor]]\nname = "x"\nunit = "mm"\nnominal = 0\ntolerance = "±0.03"\n'
            f'[[factor]]\nname = "y"\nunit = "mm"\nnominal = 0\ntolerance = "±0.03"\n[model]\nkind = "formula"\n'
            f'[[model.output]]\nname = "r"\nformula = "hypot(x, y)"\nunit = "mm"\n[[requirement]]\nname = "r"\n'
            f'output = "r"\nupper = {upper!r}\nunit = "mm"\nmin_yield = 0.99998\n[sampling]\nn = 2000\n'
            f'method = "random"\nseed = {seed}\ntails = true\n[execution]\nexecutor = "serial"\n[report]\npdf = false\n')
    return write(tmp_path / f"hypot_{seed}.toml", text)


@pytest.mark.parametrize("seed", [1, 2, 4])
def test_a_failure_region_importance_sampling_cannot_see_gives_no_wrong_pass(tmp_path, capsys, seed):
    rc, summ = _run(tmp_path, capsys, _hypot_study(tmp_path, seed))
    d = summ["tails"]["r"]
    assert d["state"] != "PASS" and summ["requirements"][0]["verdict"] != "PASS" and rc != 0, d["why"]


def test_a_limit_out_of_the_supports_reach_counts_zero_and_the_other_decides(tmp_path, capsys):
    # a, b uniform ±0.05: y = a − b triangular on 6 ± 0.1; P(y > U) = (0.1 − (U − 6))²/(2·0.1²) = 1e-2, the lower
    # limit 5.85 beyond the supports' reach (P = 0): yield 0.99 ≥ 0.98 (before, the lower side blocked the decision)
    upper = 6.0 + 0.1 - math.sqrt(2 * 0.1 ** 2 * 1e-2)
    text = _study(tmp_path, upper, 0.98, 300, 3).read_text("utf-8")
    text = text.replace('tolerance = "±0.05"\n', 'tolerance = "±0.05"\ndist = "uniform"\n')
    text = text.replace('upper = ', 'lower = 5.85\nupper = ')
    p = write(tmp_path / "uniform.toml", text)
    rc, summ = _run(tmp_path, capsys, p)
    d = summ["tails"]["gap"]
    assert d["state"] == "PASS" and any("lower: out of reach" in m for m in d["estimators"]), d
    assert abs(d["nonconformance"] - 1e-2) < 4 * d["se"]


def test_tails_from_the_command_line_beside_a_study_that_says_false(tmp_path, capsys):
    p = _study(tmp_path, 6.0 + float(stats.norm.isf(1e-3)) * SIGMA_Y, 0.9973, 1500, 7, tails=False)
    out = tmp_path / "cli"
    rc, err = run_cli(["run", p, "--out", out, "--quiet", "--tails"], capsys)
    assert rc == 0, err
    assert json.loads((out / "summary.json").read_text("utf-8"))["tails"]["gap"]["state"] == "PASS"
