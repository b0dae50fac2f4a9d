"""Selective assembly inside the Monte Carlo: closed-form yield of class-to-class matching, exact stock
counts by hand, the target rule, the class-limit optimiser against a brute-force search, the study analysis."""
import json
import math

import numpy as np
import pytest
from scipy import integrate, stats

from conftest import write
from rvtol.errors import InputError
from rvtol.mc import Evaluator
from rvtol.model import LinearModel, Quantity
from rvtol.production.selective import (Classes, ClassToClassRule, GradedPart, Supply, TargetRule, assemble,
                                        bandwidths, optimise_limits, smoothed_yield, stock_batch,
                                        take_from_stock, ungraded)
from rvtol.expressions import Expression
from rvtol.sampling import sample
from rvtol.spec import Requirement, spec_from_table
from rvtol.study import load_study, run_study, write_outputs

MU_H, MU_S, SIG = 10.0, 0.0, 1.0          # µm: hole and shaft sizes (deviations), both normal σ = 1
LOW, HIGH = 9.0, 11.0                     # clearance c = H − S within [9, 11] µm
FIT = spec_from_table({"factor": [
    {"name": "hole", "unit": "um", "dist": "normal", "mean": MU_H, "sigma": SIG},
    {"name": "shaft", "unit": "um", "dist": "normal", "mean": MU_S, "sigma": SIG}]})
CLEARANCE = LinearModel(FIT.names, ["mm", "mm"], [Quantity("clearance", "mm", "um")], [[1.0, -1.0]])


def yield_class_to_class(k: int) -> float:
    """Closed form: k equal-probability classes of H and S matched class to class; within class i, H and S
    are independent normals truncated to their class: P(L ≤ H − S ≤ U) = (1/k) Σ_i ∫ f_Hi(h) P(h − U ≤ S_i ≤ h − L) dh
    (a 1-D quadrature per class; k = 1 is the normal c ~ N(μH − μS, σ√2))."""
    qh = MU_H + SIG * stats.norm.ppf(np.arange(k + 1) / k)
    qs = MU_S + SIG * stats.norm.ppf(np.arange(k + 1) / k)
    total = 0.0
    for i in range(k):
        def inner(h):
            lo, hi = max(h - HIGH, qs[i]), min(h - LOW, qs[i + 1])
            ps = max(0.0, stats.norm.cdf(hi, MU_S, SIG) - stats.norm.cdf(lo, MU_S, SIG)) * k
            return stats.norm.pdf(h, MU_H, SIG) * k * ps
        total += integrate.quad(inner, qh[i], qh[i + 1], limit=200)[0] / k
    return total


def test_closed_form_reference_without_grading_is_the_normal_clearance():
    s = SIG * math.sqrt(2)
    ref = stats.norm.cdf(HIGH, MU_H - MU_S, s) - stats.norm.cdf(LOW, MU_H - MU_S, s)
    assert abs(yield_class_to_class(1) - ref) < 1e-9


@pytest.mark.parametrize("k", [1, 2, 4, 8])
def test_class_to_class_yield_matches_the_closed_form(k):
    n = 20000
    X = sample(FIT, n, "random", 17).values
    part = GradedPart(("shaft",), Supply(FIT.factor("shaft")), (ClassToClassRule("hole", Supply(FIT.factor("hole"))),))
    asm = assemble(X, FIT, part, Classes.equal_probability(part.supply, k), {"hole": X[:, 0], "shaft": X[:, 1]})
    c = Evaluator()(CLEARANCE, asm.X).Y[:, 0] * 1e3
    y = float(np.mean((c >= LOW) & (c <= HIGH)))
    ref = yield_class_to_class(k)
    assert abs(y - ref) < 4 * math.sqrt(ref * (1 - ref) / n), (k, y, ref)
    # the graded part lies in the class the rule wants, the hole is untouched
    np.testing.assert_array_equal(asm.X[:, 0], X[:, 0])
    assert np.array_equal(Classes.equal_probability(part.supply, k).of(asm.X[:, 1]), asm.wanted[:, 0])


def test_grading_gains_what_the_closed_form_says():
    """The gain of 4 classes over none, by the closed form: 0.52 → 0.93."""
    assert yield_class_to_class(1) == pytest.approx(0.5205, abs=1e-4)
    assert yield_class_to_class(4) > 0.92


def test_one_class_and_an_own_supply_give_back_the_samples_exactly():
    X = sample(FIT, 500, "lhs", 3).values
    part = GradedPart(("shaft",), Supply(FIT.factor("shaft")), (ClassToClassRule("hole", Supply(FIT.factor("hole"))),))
    asm = assemble(X, FIT, part, Classes.equal_probability(part.supply, 1), {"hole": X[:, 0]})
    np.testing.assert_allclose(asm.X, X, rtol=1e-12, atol=1e-15)
    assert np.array_equal(ungraded(X, FIT, part), X)


def test_leftover_parts_are_counted_exactly_by_hand():
    """Batch classes [0 0 0 1 2 2 2]; demands [2 2 2 2 0 1]:
    d1–d3 take parts 4, 5, 6 (class 2); d4 wants 2 (empty): nearest class with stock is 1 -> part 3;
    d5 takes part 0 (class 0); d6 wants 1 (empty): only class 0 left -> part 1. Left over: one part of class 0."""
    t = take_from_stock([0, 0, 0, 1, 2, 2, 2], 3, [2, 2, 2, 2, 0, 1])
    assert t.taken.tolist() == [4, 5, 6, 3, 0, 1]
    assert t.given.tolist() == [2, 2, 2, 1, 0, 0]
    assert t.leftover.tolist() == [1, 0, 0]
    # ties go to the lower class: wanted 1 (empty) with classes 0 and 2 in stock
    assert take_from_stock([0, 2], 3, [1]).given.tolist() == [0]
    with pytest.raises(ValueError, match="ran out"):
        take_from_stock([0], 2, [1, 1])


def test_stock_balance_of_an_assembly_by_hand():
    """Three classes with limits 0 and 1 µm; stock of five parts; four reducers whose targets want classes
    2, 2, 0, 2 (0-based): class 2 has two parts, so the third reducer wanting it gets the nearest centre."""
    spec = spec_from_table({"factor": [
        {"name": "t", "unit": "um", "dist": "normal", "mean": 0.0, "sigma": 1.0},
        {"name": "p", "unit": "um", "dist": "normal", "mean": 0.5, "sigma": 1.0}]})
    part = GradedPart(("p",), Supply(spec.factor("p")), (TargetRule(Expression.parse("t")),))
    classes = Classes.from_limits(np.array([0.0, 1.0]) * 1e-3)
    stock = np.array([-0.5, 1.5, 0.5, 2.0, -1.0]) * 1e-3           # classes 0, 2, 1, 2, 0
    t = np.array([3.0, 1.2, -2.0, 5.0]) * 1e-3                     # wants 2, 2, 0, 2
    X = np.column_stack([t, np.zeros(4)])
    asm = assemble(X, spec, part, classes, {"t": t, "p": X[:, 1]}, stock)
    assert asm.wanted[:, 0].tolist() == [2, 2, 0, 2]
    # reducer 1 takes part 1 (1.5), reducer 2 part 3 (2.0), reducer 3 part 0 (−0.5), reducer 4 (class 2 empty,
    # target 5 µm): nearest centre with stock is class 1 (part 2, 0.5 µm)
    np.testing.assert_allclose(asm.X[:, 1], np.array([1.5, 2.0, -0.5, 0.5]) * 1e-3)
    b = asm.stock
    assert b.made.tolist() == [2, 1, 2] and b.wanted.tolist() == [1, 0, 3]
    assert b.used.tolist() == [1, 1, 2] and b.leftover.tolist() == [1, 0, 0] and b.substituted == 1


def test_the_target_rule_brings_the_fit_to_its_target():
    """Pin size chosen from a measured clearance: the more classes, the closer the result to the target."""
    spec = spec_from_table({"factor": [
        {"name": "gap", "unit": "um", "dist": "normal", "mean": 6.0, "sigma": 1.0},
        {"name": "pin", "unit": "um", "dist": "uniform", "lower": 0.0, "upper": 6.0}]})
    part = GradedPart(("pin",), Supply(spec.factor("pin")), (TargetRule(Expression.parse("gap - 0.003")),))
    X = sample(spec, 4000, "lhs", 8).values
    env = {"gap": X[:, 0], "pin": X[:, 1]}
    spread = []
    for k in (1, 3, 6, 12):
        asm = assemble(X, spec, part, Classes.equal_probability(part.supply, k), env)
        spread.append(np.std((asm.X[:, 0] - asm.X[:, 1]) * 1e3))
    assert all(a > b for a, b in zip(spread, spread[1:]))
    # 12 classes of 0.5 µm: within a class the pin is uniform (σ = 0.5/√12) — plus the gap beyond the outer classes
    assert spread[-1] < 0.35


def test_a_stock_batch_is_reproducible_from_its_sub_stream():
    s = Supply(FIT.factor("shaft"))
    np.testing.assert_array_equal(stock_batch(s, 50, 7), stock_batch(s, 50, 7))
    assert not np.array_equal(stock_batch(s, 50, 7), stock_batch(s, 50, 8))


def test_the_optimiser_finds_the_brute_force_optimum_of_its_objective():
    """Target rule, 2 classes: the one limit that maximises the smoothed yield on a fixed design, found by
    Nelder–Mead, agrees with a grid search over the same objective."""
    spec = spec_from_table({"factor": [
        {"name": "gap", "unit": "um", "dist": "normal", "mean": 1.5, "sigma": 0.6},
        {"name": "pin", "unit": "um", "dist": "uniform", "lower": 0.0, "upper": 4.0}]})
    model = LinearModel(spec.names, ["mm", "mm"], [Quantity("play", "mm", "um")], [[1.0, -1.0]])
    part = GradedPart(("pin",), Supply(spec.factor("pin")), (TargetRule(Expression.parse("gap")),))
    X = sample(spec, 2000, "lhs", 21).values
    env = {"gap": X[:, 0], "pin": X[:, 1]}
    reqs = [Requirement("play", lower=-0.6, upper=0.6, unit="um")]
    base = Evaluator()(model, X).Y * 1e3
    h = bandwidths(base, np.ones(len(X), bool), reqs, ["play"])

    def objective(classes):
        y = Evaluator()(model, assemble(X, spec, part, classes, env).X).Y * 1e3
        return smoothed_yield(y, np.ones(len(X), bool), reqs, ["play"], h)

    opt = optimise_limits(objective, part.supply, 2, max_evaluations=60)
    grid = np.linspace(0.2, 3.8, 181)
    vals = [objective(Classes.from_limits([b * 1e-3])) for b in grid]
    b_best = grid[int(np.argmax(vals))]
    assert opt.best >= max(vals) - 2e-3
    assert abs(opt.classes.edges[1] * 1e3 - b_best) < 0.1
    assert opt.best > opt.start


def test_the_rv80e_pin_rule_weighs_the_pin_circle_as_the_20dof_model_does(root):
    """studies/rv80e_production.toml's rule reads the pin-stage clearance as ½(n0_1 + n0_2) + c1·δR + g: on the
    20-DOF torsion curve of the product, a uniform pin-circle change δR moves the lost motion c1 = √(1 − K1²)
    times as much as the same normal clearance at every pin (central differences, ±0.5 µm)."""
    from rvtol.design import load_design
    from rvtol.models.torsion_curve.model import TorsionCurveModel

    design = load_design(root / "data/products/rv80e/design.toml")
    model = TorsionCurveModel(design, ["delta_pin", "R_pc"])
    h = 0.5e-3
    X = np.array([[6.6e-3 - h, 0.0], [6.6e-3 + h, 0.0], [6.6e-3, -h], [6.6e-3, h]])
    lm = Evaluator()(model, X).Y[:, 0]
    rate_clearance, rate_circle = (lm[1] - lm[0]) / (2 * h), (lm[3] - lm[2]) / (2 * h)
    k1 = design["pin.count"] * design["cycloid.eccentricity"] / design["pin.circle_radius"]
    assert rate_circle / rate_clearance == pytest.approx(math.sqrt(1 - k1 ** 2), rel=0.03)


def test_a_target_may_read_design_numbers(root):
    from rvtol.design import load_design
    from rvtol.design import design_numbers

    design = load_design(root / "data/products/rv80e/design.toml")
    assert design_numbers(["design.pin.count", "design.pin.circle_radius", "hole", "design.no.such"], design) == {
        "design.pin.count": 40.0, "design.pin.circle_radius": 76.5}


STUDY = """
[study]
name = "fit"
[[factor]]
name = "hole"
unit = "um"
dist = "normal"
mean = 10.0
sigma = 1.0
[[factor]]
name = "shaft"
unit = "um"
dist = "normal"
mean = 0.0
sigma = 1.0
[model]
kind = "linear"
[[model.output]]
name = "clearance"
unit = "um"
coefficients = { hole = 1.0, shaft = -1.0 }
[[requirement]]
output = "clearance"
lower = 9.0
upper = 11.0
unit = "um"
min_yield = 0.9
[sampling]
n = 4000
seed = 12
method = "random"
[execution]
executor = "serial"
[report]
pdf = false
[[analysis]]
kind = "selective_assembly"
factor = "shaft"
match = "hole"
classes = [2, 4]
stock_ratio = 1.05
[analysis.optimise]
classes = 3
n = 400
max_evaluations = 20
"""


def test_the_study_analysis_compares_cases_with_stock_and_writes_its_summary(tmp_path):
    res = run_study(load_study(write(tmp_path / "s.toml", STUDY), progress=False))
    out = write_outputs(res, tmp_path / "rep")
    cases = json.loads((out / "summary.json").read_text())["analyses"]["selective_assembly"]["cases"]
    assert [c["case"] for c in cases] == ["no grading", "2 equal-probability classes", "4 equal-probability classes",
                                          "optimised limits"]
    y = [c["joint_yield"] for c in cases]
    n = 4000
    assert abs(y[0] - yield_class_to_class(1)) < 4 * math.sqrt(0.25 / n)
    assert y[0] < y[1] < y[2]
    for c in cases[1:]:
        st = c["stock"]
        made, used, left = (np.array(st[k]) for k in ("made", "used", "left_over"))
        assert made.sum() == 4200 and used.sum() == n            # 1.05 × 4000 parts made
        np.testing.assert_array_equal(made - used, left)
    # finite stock: close to the unlimited closed form (substitutions cost a little)
    assert y[2] <= yield_class_to_class(4) + 4 * math.sqrt(0.25 / n)
    assert not res.mc.verdicts()[0].passed                         # the ungraded study fails 0.9


def test_a_supply_of_its_own_adds_the_as_drawn_case(tmp_path):
    """Shafts from a supply shifted by +0.5 µm: 'as drawn' is the study's own sample, 'no grading' the shifted
    supply at random — clearance N(9.5, √2) µm, yield Φ(1.5/√2) − Φ(−0.5/√2) in [9, 11]."""
    text = STUDY.replace("n = 4000", "n = 400")
    text = text.replace("[analysis.optimise]\nclasses = 3\nn = 400\nmax_evaluations = 20\n", "")
    text += '[analysis.supply]\nunit = "um"\ndist = "normal"\nmean = 0.5\nsigma = 1.0\n'
    res = run_study(load_study(write(tmp_path / "s.toml", text), progress=False))
    (sec,) = res.sections
    assert [c["case"] for c in sec.summary["cases"]] == ["as drawn (spec)", "no grading", "2 equal-probability "
                                                         "classes", "4 equal-probability classes"]
    assert sec.summary["cases"][0]["joint_yield"] == res.mc.verdicts()[0].yield_.estimate
    ref = stats.norm.cdf(1.5 / math.sqrt(2)) - stats.norm.cdf(-0.5 / math.sqrt(2))
    assert abs(sec.summary["cases"][1]["joint_yield"] - ref) < 4 * math.sqrt(ref * (1 - ref) / 400)


@pytest.mark.parametrize("old, new, key", [
    ('factor = "shaft"', 'factor = "shaft2"', "analysis[0].factor"),
    ('match = "hole"', 'match = "hole"\ntarget = "hole"', "analysis[0].target"),
    ('match = "hole"', 'target = "shaft * 2"', "analysis[0].target"),
    ('match = "hole"', 'target = "nope + 1"', "analysis[0].target"),
    ('match = "hole"', 'target = "design.pin.count * hole"', "analysis[0].target"),
    ("classes = [2, 4]", "classes = [2, 0]", "analysis[0].classes"),
    ("stock_ratio = 1.05", "stock_ratio = 0.9", "analysis[0].stock_ratio"),
    ("stock_ratio = 1.05", "limits = [1.0, 0.5]", "analysis[0].limits"),
    ("classes = 3\n", "classes = 1\n", "analysis[0].optimise.classes"),
])
def test_bad_selective_assembly_tables_name_the_key(tmp_path, old, new, key):
    assert old in STUDY
    p = write(tmp_path / "s.toml", STUDY.replace(old, new, 1))
    with pytest.raises(InputError) as exc:
        load_study(p)
    assert exc.value.file == str(p) and exc.value.key == key, (exc.value.key, exc.value.reason)
