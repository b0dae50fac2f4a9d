"""Measured parts in, each reducer out: CSV layout and validation, per-unit prediction against closed forms."""
import json
import math

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from conftest import write
from rvtol.errors import InputError
from rvtol.mc import Evaluator
from rvtol.model import FunctionModel, LinearModel, Quantity
from rvtol.production import FamilySource, load_measured_units, predict_units, samples_to_demonstrate
from rvtol.spec import Requirement, spec_from_table
from rvtol.study import load_study, run_study, write_outputs
from rvtol.verdict import CONFORMS, DOES_NOT_CONFORM, UNDECIDED

SPEC = spec_from_table({"factor": [
    {"name": "crank_1.cam.x", "unit": "um", "dist": "normal", "mean": 0.0, "sigma": 1.0},
    {"name": "crank_2.cam.x", "unit": "um", "dist": "normal", "mean": 0.0, "sigma": 1.0},
    {"name": "housing.radius", "unit": "um", "dist": "normal", "mean": 2.0, "sigma": 0.5},
    {"name": "pins[1].d", "unit": "um", "dist": "uniform", "lower": -1.0, "upper": 1.0},
    {"name": "pins[2].d", "unit": "um", "dist": "uniform", "lower": -1.0, "upper": 1.0},
]})

CRANKS = """# crankshafts (test data)
serial, cam.x [um], cam.x.u [um]
C1, 0.5, 0.0
C2, -1.25, 0.0
C3, 2.0, 0.0
C4, 0.0, 0.0
"""
HOUSINGS = """# housings
serial, radius [mm]
uncertainty, 0
H1, 0.0021
H2, 0.0015
"""
PINS = """serial, [1].d, [2].d
uncertainty, 0, 0
P1, 0.3, -0.4
P2, 0.1, 0.9
"""
KITS = """# kit list
reducer, crank_1, crank_2, housing, pins
R1, C1, C2, H1, P1
R2, C3, C4, H2, P2
"""


def _families(tmp_path, cranks=CRANKS, housings=HOUSINGS, pins=PINS):
    return [FamilySource(write(tmp_path / "cranks.csv", cranks), ("crank_1", "crank_2"), "crankshaft"),
            FamilySource(write(tmp_path / "housings.csv", housings), ("housing",)),
            FamilySource(write(tmp_path / "pins.csv", pins), ("pins",))]


def test_csv_values_reach_the_named_factors_in_base_units(tmp_path):
    mu = load_measured_units(SPEC, write(tmp_path / "kits.csv", KITS), _families(tmp_path))
    assert mu.units == ("R1", "R2")
    # R1: crank_1 = C1, crank_2 = C2, housing H1 (2.1 µm written in mm), pins P1
    np.testing.assert_allclose(mu.value[0], np.array([0.5, -1.25, 2.1, 0.3, -0.4]) * 1e-3, rtol=0, atol=1e-15)
    np.testing.assert_allclose(mu.value[1], np.array([2.0, 0.0, 1.5, 0.1, 0.9]) * 1e-3, rtol=0, atol=1e-15)
    assert mu.measured.all() and np.all(mu.uncertainty == 0)
    assert set(mu.files()) == {"kit_list", "parts:crankshaft", "parts:housings", "parts:pins"}


def test_zero_uncertainty_gives_exactly_the_model_at_the_measured_values(tmp_path):
    """Every factor measured with u = 0: each of a unit's samples IS the model at its measured values."""
    mu = load_measured_units(SPEC, write(tmp_path / "kits.csv", KITS), _families(tmp_path))
    f = FunctionModel(lambda X: np.column_stack([np.hypot(X[:, 0], X[:, 1]) + X[:, 2] * np.cos(X[:, 3] * 1e3),
                                                 X[:, 4] ** 2]), SPEC.names, [Quantity("y", "mm", "um"), "z"],
                      ["mm"] * 5)
    pred = predict_units(f, SPEC, mu, 16, evaluator=Evaluator(), seed=3)
    direct = f.evaluate(mu.value)
    for i in range(2):
        np.testing.assert_array_equal(pred.Y[i, :, 0], np.full(16, direct[i, 0] * 1e3))   # µm display
        np.testing.assert_array_equal(pred.Y[i, :, 1], np.full(16, direct[i, 1]))
    out = pred.output_frame()
    assert np.all(out["lo"] == out["hi"]) and np.all(out["std"] == 0)


def _linear_units(tmp_path, us):
    """Units whose two crank cams are measured with uncertainty u (each unit its own u); housing and pins not."""
    rows = "\n".join(f"C{2 * i}, 0.5, {u}\nC{2 * i + 1}, -1.0, {u}" for i, u in enumerate(us))
    cranks = write(tmp_path / "cranks.csv", f"serial, cam.x [um], cam.x.u [um]\n{rows}\n")
    kits = "reducer, crank_1, crank_2\n" + "\n".join(f"R{i}, C{2 * i}, C{2 * i + 1}" for i in range(len(us)))
    return load_measured_units(SPEC, write(tmp_path / "kits.csv", kits + "\n"),
                               [FamilySource(cranks, ("crank_1", "crank_2"))])


def test_interval_widens_with_measurement_uncertainty_as_the_closed_form_says(tmp_path):
    """y = Σ a_i x_i: σ_pred² = Σ_measured (a_i u_i)² + Σ_unmeasured a_j² σ_j² (independent factors)."""
    a = np.array([2.0, -1.0, 0.5, 3.0, 1.5])
    model = LinearModel(SPEC.names, ["mm"] * 5, [Quantity("y", "mm", "um")], [a])
    us = [0.0, 0.5, 1.0, 2.0]
    mu = _linear_units(tmp_path, us)
    n = 4000
    pred = predict_units(model, SPEC, mu, n, evaluator=Evaluator(), seed=11, interval=0.95)
    sig_unmeasured = np.array([0.5, 2 / math.sqrt(12), 2 / math.sqrt(12)])    # µm
    mean_ref = a[0] * 0.5 + a[1] * -1.0 + a[2] * 2.0                            # pins mean 0
    out = pred.output_frame().set_index("reducer")
    widths = []
    for i, u in enumerate(us):
        s_ref = math.sqrt((a[0] * u) ** 2 + (a[1] * u) ** 2 + np.sum((a[2:] * sig_unmeasured) ** 2))
        row = out.loc[f"R{i}"]
        # sample std of n draws: relative standard error ≤ 1/sqrt(2(n-1)) (LHS only lowers it); 4 of them
        assert abs(row["std"] / s_ref - 1) < 4 / math.sqrt(2 * (n - 1)), (u, row["std"], s_ref)
        assert abs(row["mean"] - mean_ref) < 4 * s_ref / math.sqrt(n)
        widths.append(row["hi"] - row["lo"])
    assert all(w1 < w2 for w1, w2 in zip(widths, widths[1:]))
    # at u = 2 µm the normal measurement errors dominate: the 95 % interval is 2·1.96 σ_pred (quantile s.e. ≈ 0.06 σ)
    s3 = math.sqrt((a[0] * 2.0) ** 2 + (a[1] * 2.0) ** 2 + np.sum((a[2:] * sig_unmeasured) ** 2))
    assert abs(widths[3] - 2 * 1.96 * s3) < 0.25 * s3


def test_an_unmeasured_factor_correlated_with_a_measured_one_is_drawn_conditionally(tmp_path):
    """Bivariate normal (ρ): x2 | x1 = m is normal with mean μ2 + ρ σ2 (m − μ1)/σ1 and σ2 √(1 − ρ²)."""
    rho = 0.8
    spec = spec_from_table({"factor": [
        {"name": "disc_1.mod", "unit": "um", "dist": "normal", "mean": -15.0, "sigma": 0.667},
        {"name": "disc_2.mod", "unit": "um", "dist": "normal", "mean": -15.0, "sigma": 0.667}],
        "correlation": [{"pair": ["disc_1.mod", "disc_2.mod"], "rho": rho}]})
    discs = write(tmp_path / "discs.csv", "serial, mod\nuncertainty, 0\nD1, -14.0\n")
    mu = load_measured_units(spec, write(tmp_path / "kits.csv", "reducer, disc_1, disc_2\nR1, D1, -\n"),
                             [FamilySource(discs, ("disc_1", "disc_2"))])
    model = LinearModel(spec.names, ["mm"] * 2, [Quantity("x1", "mm", "um"), Quantity("x2", "mm", "um")],
                        [[1.0, 0.0], [0.0, 1.0]])
    n = 4000
    pred = predict_units(model, spec, mu, n, evaluator=Evaluator(), seed=2)
    x1, x2 = pred.Y[0, :, 0], pred.Y[0, :, 1]
    assert np.all(x1 == -14.0)
    m_ref = -15.0 + rho * (1.0 / 0.667) * 0.667
    s_ref = 0.667 * math.sqrt(1 - rho ** 2)
    assert abs(x2.mean() - m_ref) < 4 * s_ref / math.sqrt(n)
    assert abs(x2.std(ddof=1) / s_ref - 1) < 4 / math.sqrt(2 * (n - 1))


def test_samples_to_demonstrate_is_the_clopper_pearson_count():
    r = Requirement("y", upper=1.0, min_yield=0.9973)
    assert samples_to_demonstrate([r]) == math.ceil(math.log(0.05) / math.log(0.9973)) == 1109   # one-sided 95 %
    r2 = Requirement("y", upper=1.0, min_yield=0.9973, bound="two-sided")
    assert samples_to_demonstrate([r2]) == math.ceil(math.log(0.025) / math.log(0.9973)) == 1365
    r90 = Requirement("y", upper=1.0, min_yield=0.9, confidence=0.9)
    assert samples_to_demonstrate([r90]) == math.ceil(math.log(0.1) / math.log(0.9))
    assert samples_to_demonstrate([]) == 1
    # a Cpk-only requirement: the one-sided yield Φ(3·1.33)
    rc = Requirement("y", upper=1.0, min_cpk=1.33, min_yield=None)
    p = stats.norm.cdf(3 * 1.33)
    assert samples_to_demonstrate([rc]) == math.ceil(math.log(0.05) / math.log(p))


def test_unit_verdicts_conform_fail_and_undecided_by_their_probability(tmp_path):
    """y = cam_1 + cam_2 (µm), cams measured, housing/pins unused. Limit y ≤ 1 µm, P ≥ 0.9 at 95 %."""
    a = np.array([1.0, 1.0, 0.0, 0.0, 0.0])
    model = LinearModel(SPEC.names, ["mm"] * 5, [Quantity("y", "mm", "um")], [a])
    rows = "C0, -1.0, 0.1\nC1, -1.0, 0.1\nC2, 1.0, 0.1\nC3, 1.0, 0.1\nC4, 0.3, 1.0\nC5, 0.3, 1.0\n"
    cranks = write(tmp_path / "c.csv", "serial, cam.x, cam.x.u\n" + rows)
    kits = write(tmp_path / "k.csv", "reducer, crank_1, crank_2\nA, C0, C1\nB, C2, C3\nC, C4, C5\n")
    mu = load_measured_units(SPEC, kits, [FamilySource(cranks, ("crank_1", "crank_2"))])
    r = Requirement("y", upper=1.0, unit="um", min_yield=0.9)
    n = samples_to_demonstrate([r])
    pred = predict_units(model, SPEC, mu, n, evaluator=Evaluator(), requirements=[r], seed=4)
    v = pred.verdicts()
    # A: y ~ N(-2, 0.14) far below 1 -> conforms; B: N(2, 0.14) far above -> does not conform;
    # C: N(0.6, 1.41): P(y ≤ 1) = Φ(0.28) ≈ 0.61 — below 0.9 with certainty at this n -> does not conform
    assert v == {"A": CONFORMS, "B": DOES_NOT_CONFORM, "C": DOES_NOT_CONFORM}
    req = pred.requirement_frame().set_index("reducer")
    assert abs(req.loc["C", "P"] - stats.norm.cdf(0.4 / math.sqrt(2))) < 4 * math.sqrt(0.25 / n)
    # with fewer samples than needed, a unit whose samples all conform is undecided
    pred2 = predict_units(model, SPEC, mu, 10, evaluator=Evaluator(), requirements=[r], seed=4)
    assert pred2.verdicts()["A"] == UNDECIDED
    # a conformance probability of its own (ISO 14253-1's 95 %): 59 samples demonstrate it
    n95 = samples_to_demonstrate([r], probability=0.95)
    assert n95 == math.ceil(math.log(0.05) / math.log(0.95)) == 59
    pred3 = predict_units(model, SPEC, mu, n95, evaluator=Evaluator(), requirements=[r], seed=4, probability=0.95)
    assert pred3.verdicts() == {"A": CONFORMS, "B": DOES_NOT_CONFORM, "C": DOES_NOT_CONFORM}
    assert set(pred3.requirement_frame()["required"]) == {0.95}


@pytest.mark.parametrize("which, text, key", [
    ("cranks", "serial, cam.y [um]\nuncertainty, 0\nC1, 1\n", "row 1, column 'cam.y [um]'"),
    ("cranks", "serial, cam.x\nuncertainty, 0\nC1, 1\nC1, 2\n", "row 4, column 'serial'"),
    ("cranks", "serial, cam.x\nuncertainty, 0\nC1, abc\n", "row 3, column 'cam.x'"),
    ("cranks", "serial, cam.x\nC1, 1\n", "row 1, column 'cam.x'"),
    ("cranks", "serial, cam.x\nuncertainty, -0.1\nC1, 1\n", "row 2, column 'cam.x'"),
    ("cranks", "serial, cam.x, cam.x.u\nuncertainty, 0.1,\nC1, 1, 0.2\n", "row 2, column 'cam.x'"),
    ("cranks", "serial, cam.x [deg]\nuncertainty, 0\nC1, 1\n", "row 1, column 'cam.x [deg]'"),
    ("cranks", "serial, cam.x\nuncertainty, 0\nC1, 1, 2\n", "row 3"),
    ("cranks", "part, cam.x\nuncertainty, 0\nC1, 1\n", "row 1, column 'part'"),
    ("kits", "reducer, crank_1, crank_2, housing, pins\nR1, C1, C9, H1, P1\n", "row 2, column 'crank_2'"),
    ("kits", "reducer, crank_1, crank_2, housing, pins\nR1, C1, C2, H1, P1\nR2, C1, C3, H2, P2\n",
     "row 3, column 'crank_1'"),
    ("kits", "reducer, crank_1, crank_2, housing\nR1, C1, C2, H1\n", "row 1"),
    ("kits", "reducer, crank_1, crank_2, housing, pins, carrier\nR1, C1, C2, H1, P1, X\n", "row 1, column 'carrier'"),
    ("kits", "reducer, crank_1, crank_2, housing, pins\nR1, C1, , H1, P1\n", "row 2, column 'crank_2'"),
    ("kits", "reducer, crank_1, crank_2, housing, pins\nR1, C1, C2, H1, P1\nR1, C3, C4, H2, P2\n",
     "row 3, column 'reducer'"),
])
def test_bad_measured_files_name_the_file_line_and_column(tmp_path, which, text, key):
    fams = _families(tmp_path)
    kits = write(tmp_path / "kits.csv", KITS)
    bad = write(tmp_path / ("cranks.csv" if which == "cranks" else "kits.csv"), text)
    with pytest.raises(InputError) as exc:
        load_measured_units(SPEC, kits, fams)
    assert exc.value.file == str(bad) and exc.value.key == key, (exc.value.file, exc.value.key, exc.value.reason)


STUDY = """
[study]
name = "units"
[[factor]]
name = "crank_1.cam.x"
unit = "um"
dist = "normal"
sigma = 1.0
[[factor]]
name = "crank_2.cam.x"
unit = "um"
dist = "normal"
sigma = 1.0
[[factor]]
name = "housing.radius"
unit = "um"
dist = "normal"
mean = 2.0
sigma = 0.5
[model]
kind = "linear"
[[model.output]]
name = "play"
unit = "um"
coefficients = { "crank_1.cam.x" = 1.0, "crank_2.cam.x" = 1.0, "housing.radius" = 0.5 }
[[requirement]]
output = "play"
upper = 3.0
unit = "um"
min_yield = 0.95
[sampling]
n = 200
seed = 9
[execution]
executor = "serial"
[report]
pdf = false
[[analysis]]
kind = "per_unit_prediction"
kits = "kits.csv"
[[analysis.parts]]
file = "cranks.csv"
slots = ["crank_1", "crank_2"]
"""


def test_the_analysis_writes_a_row_per_unit_and_a_summary_entry(tmp_path):
    write(tmp_path / "cranks.csv", CRANKS)
    write(tmp_path / "kits.csv", "reducer, crank_1, crank_2\nR1, C1, C2\nR2, C3, C4\nR3, -, -\n")
    study = load_study(write(tmp_path / "s.toml", STUDY), progress=False)
    assert "per_unit_prediction:kit_list" in study.inputs
    res = run_study(study)
    out = write_outputs(res, tmp_path / "report")
    table = pd.read_csv(out / "per_unit.csv")
    assert list(table["reducer"]) == ["R1", "R2", "R3"]
    assert table.loc[0, "n"] == samples_to_demonstrate(study.requirements)
    summary = json.loads((out / "summary.json").read_text())
    units = summary["analyses"]["per_unit_prediction"]["units"]
    n = int(table.loc[0, "n"])
    # R1: play = 0.5 − 1.25 + 0.5·housing (N(1, 0.25)): median −0.75 + 1.0 µm; well below 3 µm. The sample
    # median's standard error is √(π/2)·σ/√n = 1.2533 · 0.25/√n; within 4 of them
    assert units[0]["verdict"] == "conforms"
    assert abs(units[0]["outputs"]["play"]["median"] - 0.25) < 4 * 1.2533 * 0.25 / math.sqrt(n)
    # R2: 2.0 + 0 + 0.5·housing: P(≤ 3) = Φ(0/0.25) = 0.5 -> does not conform
    assert units[1]["verdict"] == "does not conform"
    assert table.loc[1, "verdict"] == "does not conform"
    # R3: nothing measured: the spec's own spread (σ = √(1 + 1 + 0.0625)); P from n samples, within 4 binomial
    # standard errors (n = 59 is what the verdict needs, not a precise P: the check is loose by design)
    p = stats.norm.cdf(2.0 / math.sqrt(2.0625))
    assert abs(units[2]["requirements"][0]["P"] - p) < 4 * math.sqrt(p * (1 - p) / n)


def test_a_bad_kit_file_fails_the_study_at_load_time(tmp_path):
    write(tmp_path / "cranks.csv", CRANKS)
    kits = write(tmp_path / "kits.csv", "reducer, crank_1, crank_2\nR1, C1, C1\n")
    with pytest.raises(InputError) as exc:
        load_study(write(tmp_path / "s.toml", STUDY))
    assert exc.value.file == str(kits) and exc.value.key == "row 2, column 'crank_2'"


def test_a_two_sided_cpk_asks_a_unit_for_the_yield_of_both_tails():
    """Cpk-only, both limits: a normal process at Cpk 1.33 (centred) keeps 2Φ(3·1.33) − 1 inside, so one unit must
    show that probability; its success run is ⌈ln 0.05 / ln(2Φ(3.99) − 1)⌉."""
    from rvtol.verdict import unit_probability_required

    rc = Requirement("y", lower=-1.0, upper=1.0, min_cpk=1.33)
    p = 2 * stats.norm.cdf(3 * 1.33) - 1
    assert unit_probability_required(rc) == pytest.approx(p, rel=1e-12)
    assert samples_to_demonstrate([rc]) == math.ceil(math.log(0.05) / math.log(p))
    # Cpk 3 (±9σ): 2Φ(9) − 1 = 1 − 2.3e-19, which is 1 in floating point (where Φ(9) itself is 1)
    r9 = Requirement("y", lower=-1.0, upper=1.0, min_cpk=3.0)
    assert unit_probability_required(r9) == pytest.approx(1.0 - 2.0 * stats.norm.sf(9.0), abs=1e-15)


def _read(basis: str) -> Requirement:
    """A requirement as a study file gives it (its strings built by the TOML parser, not the source's literals)."""
    import tomllib

    from rvtol.params import Params
    from rvtol.spec import requirements_from_tables

    t = tomllib.loads(f'output = "y"\nupper = 1.0\nmin_yield = 0.9\nbasis = "{basis}"\n')
    return requirements_from_tables([Params(t, file="s.toml", key="requirement[0]")])[0]


def test_a_unit_judged_on_its_estimate_has_no_guard_band():
    """basis = "estimate": P = 56/59 = 0.949 < 0.95 does not conform, though the upper bound 0.99 would leave a
    lower-bound verdict undecided; one conforming sample demonstrates conformance (P = 1)."""
    from rvtol.verdict import judge_unit

    est, lb = _read("estimate"), _read("lower_bound")
    u = judge_unit(est, conforming=56, n=59, required=0.95)
    assert u.state == DOES_NOT_CONFORM and u.reasons[0] == f"P(conforms) {56 / 59:.5f} < required 0.95"
    assert judge_unit(lb, conforming=56, n=59, required=0.95).state == UNDECIDED
    assert samples_to_demonstrate([est]) == 1 and judge_unit(est, conforming=1, n=1).state == CONFORMS
    from rvtol.verdict import samples_for_unit

    assert samples_for_unit(est) == 1               # one sample: P = 1/1, no bound to wait for (none has no P at all)


def test_a_units_upper_bound_reaching_the_requirement_exactly_does_not_refute_it():
    """ISO 14253-1 read as judge_unit does: non-conformance is shown only when even the upper bound stays *below* the
    probability required; 56 of 59 conform, upper bound Beta(0.95; 57, 3) — required exactly that: undecided."""
    from scipy.stats import beta

    from rvtol.verdict import judge_unit

    r = Requirement("y", upper=1.0)
    p_hi = judge_unit(r, conforming=56, n=59, required=0.95).p_hi
    assert p_hi == pytest.approx(beta.ppf(0.95, 57, 3), rel=1e-9)
    assert judge_unit(r, conforming=56, n=59, required=p_hi).state == UNDECIDED
    assert judge_unit(r, conforming=56, n=59, required=math.nextafter(p_hi, 1.0)).state == DOES_NOT_CONFORM


def test_a_unit_that_does_not_conform_says_why_once():
    """45 of 59: upper bound Beta(0.95; 46, 14) < 0.95 — the reason is the upper bound against the requirement (the
    population verdict's 'yield lower bound …' line is replaced, not repeated), then that more samples will not help."""
    from scipy.stats import beta

    from rvtol.verdict import judge_unit

    u = judge_unit(Requirement("y", upper=1.0), conforming=45, n=59, required=0.95)
    assert u.state == DOES_NOT_CONFORM
    assert u.reasons == [f"P(conforms) upper bound {beta.ppf(0.95, 46, 14):.5f} < required 0.95",
                         "the estimate itself misses the requirement: more samples will not demonstrate it"]


def test_an_undecided_unit_says_how_many_samples_would_decide_it():
    """20 of 20 conform, required 0.95: lower bound 0.05^(1/20) = 0.861 < 0.95 ≤ upper bound 1 — undecided; the
    reasons: the lower bound, the upper bound, and the samples that would decide it — the success-run size
    ⌈ln 0.05 / ln 0.95⌉ = 59."""
    from rvtol.verdict import judge_unit

    u = judge_unit(Requirement("y", upper=1.0), conforming=20, n=20, required=0.95)
    assert u.state == UNDECIDED and len(u.reasons) == 3
    assert u.reasons[0] == f"yield lower bound {0.05 ** (1 / 20):.5f} < required 0.95"
    assert u.reasons[1].startswith(f"upper bound {1.0:.5f} ≥ 0.95")
    assert f"about n = {math.ceil(math.log(0.05) / math.log(0.95))} samples would demonstrate it" in u.reasons[2]
