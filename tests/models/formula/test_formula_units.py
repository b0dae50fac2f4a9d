"""Factors carry their units into formulas (issue 27, item 1): dimension-checked at load time, angles in
radians inside trigonometric functions whatever unit they were given in, conversions compiled into
plain float arithmetic.  References: hand computations written out below."""
import math

import numpy as np
import pytest

from rvtol.errors import InputError
from rvtol.expressions import ExpressionError
from rvtol.models.formula.model import FormulaModel, FormulaOutput, from_study
from rvtol.params import Params
from rvtol.spec import spec_from_table

# A gauge pin of diameter d resting in a V-groove of included angle α: the top of the pin stands
# h = d/2 · (1 + 1/sin(α/2)) above the groove's vertex (the pin's centre is (d/2)/sin(α/2) above it).
# By hand, d = 2.54 mm, α = 90°: h = 1.27 · (1 + √2) = 3.066051 mm = 3066.05 µm.
# Fed 90 as radians, sin(45 rad) = 0.850904: h = 1.27 · (1 + 1/0.850904) = 2.76253 mm — the silent error.
V_GROOVE = "d/2 * (1 + 1/sin(alpha/2))"
H_BY_HAND = 1.27 * (1.0 + math.sqrt(2.0))


def v_groove(d_unit="mm", d=2.54, a_unit="deg", alpha=90.0, units="checked", out_unit="um"):
    spec = spec_from_table({"factor": [
        {"name": "d", "unit": d_unit, "dist": "normal", "mean": d, "tolerance": d * 0.002},
        {"name": "alpha", "unit": a_unit, "dist": "normal", "mean": alpha, "tolerance": alpha * 0.002}]})
    return spec, FormulaModel.from_spec(spec, [FormulaOutput("h", V_GROOVE, out_unit)], units=units)


@pytest.mark.parametrize("d_unit,d,a_unit,alpha", [
    ("mm", 2.54, "deg", 90.0), ("um", 2540.0, "deg", 90.0), ("mm", 2.54, "arcmin", 5400.0),
    ("in", 0.1, "rad", math.pi / 2), ("mm", 2.54, "arcsec", 324000.0)])
def test_v_groove_gives_the_hand_computed_height_whatever_the_units(d_unit, d, a_unit, alpha):
    spec, m = v_groove(d_unit, d, a_unit, alpha)
    y = m.evaluate(spec.nominal_base()[None, :])[0, 0]          # base units: mm
    assert y == pytest.approx(H_BY_HAND, rel=1e-12)
    assert 1e3 * y == pytest.approx(3066.05, abs=0.01)
    # exact derivative in base units (mm per mm, mm per rad), by hand:
    # ∂h/∂d = (1 + 1/sin(α/2))/2 = (1 + √2)/2;  ∂h/∂α = -(d/2)·cos(α/2)/(2 sin²(α/2)) = -1.27·(√2/2)/(2·½)
    G = m.gradient(spec.nominal_base()[None, :])[0, 0]
    np.testing.assert_allclose(G, [(1 + math.sqrt(2)) / 2, -1.27 * math.sqrt(2) / 2], rtol=1e-12)


def test_the_unchecked_factor_mode_refuses_the_sine_of_degrees():
    with pytest.raises(ExpressionError) as e:
        v_groove(units="factor")
    assert str(e.value) == (
        "<input>: -: output 'h': sin() takes radians, and with units = \"factor\" the angle 'alpha' enters in deg — "
        "use units = \"checked\" (the default: angles are converted) or give 'alpha' in rad "
        "(in 'd/2 * (1 + 1/sin(alpha/2))')")
    # in radians the unchecked mode computes the same number
    spec, m = v_groove(a_unit="rad", alpha=math.pi / 2, units="factor", out_unit="mm")
    assert m.evaluate(spec.nominal_base()[None, :])[0, 0] == pytest.approx(H_BY_HAND, rel=1e-12)


NAMES = ["g_mm", "w_um", "alpha_deg", "beta_rad", "F_N"]
UNITS = ["mm", "um", "deg", "rad", "N"]
X = np.array([[24.08, 0.012, math.radians(30.0), 0.25, 100.0]])   # base units: mm, mm, rad, rad, N


@pytest.mark.parametrize("formula,unit,expected", [
    ("g_mm - w_um", "mm", 24.08 - 0.012),                  # 12 µm subtracted from 24.08 mm
    ("w_um + g_mm", "um", 24092.0),                        # in the first operand's unit, converted out
    ("pi/2 - alpha_deg", "deg", 60.0),                     # a bare number beside an angle is in radians
    ("alpha_deg + beta_rad", "rad", math.radians(30.0) + 0.25),
    ("cos(alpha_deg) * g_mm", "mm", 24.08 * math.cos(math.radians(30.0))),
    ("atan2(w_um, g_mm)", "arcsec", math.degrees(math.atan2(0.012, 24.08)) * 3600),
    ("g_mm / w_um", "1", 24.08 / 0.012),                   # a ratio of lengths is a pure number
    ("exp(w_um / g_mm)", "1", math.exp(0.012 / 24.08)),
    ("F_N * g_mm", "N*m", 100.0 * 24.08 / 1000),          # a torque
    ("sqrt(g_mm * w_um)", "um", 1000 * math.sqrt(24.08 * 0.012)),
    ("hypot(g_mm, w_um)", "mm", math.hypot(24.08, 0.012)),
    ("min(w_um, g_mm)", "um", 12.0),
    ("g_mm**2 / g_mm", "mm", 24.08),
    ("2 * g_mm", "mm", 48.16),
])
def test_checked_formulas_against_hand_values(formula, unit, expected):
    m = FormulaModel([FormulaOutput("y", formula, unit)], NAMES, UNITS)
    from rvtol.units import from_base

    assert from_base(m.evaluate(X)[0, 0], unit) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("formula,unit,message", [
    ("g_mm + alpha_deg", "mm",
     "output 'y': cannot add or subtract a length (mm) and an angle (°) (alpha_deg)"),
    ("alpha_deg - g_mm", "deg",
     "output 'y': cannot add or subtract an angle (°) and a length (mm) (g_mm)"),
    ("g_mm + 0.02", "mm",
     "output 'y': cannot add or subtract a length (mm) and a bare number (0.02): a number in a formula has no "
     "unit — give the constant as a factor, or as a [model.define] entry with a unit"),
    ("sin(g_mm)", "1", "output 'y': sin() needs an angle or a ratio, got a length (mm) (g_mm)"),
    ("exp(F_N)", "1", "output 'y': exp() needs an angle or a ratio, got a force (N) (F_N)"),
    ("max(F_N, g_mm)", "N", "output 'y': max() cannot combine a force (N) and a length (mm) (g_mm)"),
    ("g_mm * F_N", "mm", "output 'y': the formula gives a torque (N·mm), the output's unit 'mm' is a length (mm)"),
    ("(g_mm - w_um) * 1000", "um",
     "output 'y': the formula multiplies by 1000, the conversion from a length (mm) to 'um' that rvtol makes "
     "itself: remove it (or write units = \"factor\" to keep the numbers as written, unchecked)"),
    ("g_mm ** beta_rad", "1", "output 'y': a variable exponent's base needs an angle or a ratio, got a length "
                              "(mm) (g_mm)"),
])
def test_dimension_errors_name_the_formula(formula, unit, message):
    with pytest.raises(ExpressionError) as e:
        FormulaModel([FormulaOutput("y", formula, unit)], NAMES, UNITS)
    assert str(e.value) == (f"<input>: -: {message} (in {formula!r}; factors carry their units into the formula: "
                            "rvtol docs writing-a-study, \"Units in formulas\")")


def test_a_formula_whose_units_agree_is_evaluated_exactly_as_written():
    """No conversion inserted: the checked model gives the unchecked model's bits."""
    rng = np.random.default_rng(4)
    Xr = np.column_stack([rng.uniform(20, 30, 200), rng.uniform(11, 13, 200), rng.uniform(11, 13, 200)])
    out = [FormulaOutput("gap", "hypot(g - w1 - w2, 0.5 * (w1 - w2))", "mm", "um")]
    a = FormulaModel(out, ["g", "w1", "w2"], ["mm"] * 3)
    b = FormulaModel(out, ["g", "w1", "w2"], ["mm"] * 3, checked=False)
    np.testing.assert_array_equal(a.evaluate(Xr), b.evaluate(Xr))
    np.testing.assert_array_equal(a.gradient(Xr), b.gradient(Xr))


def test_definitions_with_a_unit_and_the_study_factory():
    spec, _ = v_groove()
    p = Params({"define": {"r": "d/2", "L": {"formula": "25", "unit": "mm"}},
                "output": [{"name": "h", "formula": "r * (1 + 1/sin(alpha/2)) + L", "unit": "mm"}]},
               file="study.toml", key="model")
    m = from_study(p, None, spec)
    assert m.evaluate(spec.nominal_base()[None, :])[0, 0] == pytest.approx(H_BY_HAND + 25.0, rel=1e-12)
    bad = Params({"output": [{"name": "h", "formula": "d + alpha", "unit": "mm"}]}, file="study.toml", key="model")
    with pytest.raises(InputError) as e:
        from_study(bad, None, spec)
    assert str(e.value) == ("study.toml: model.output[0].formula: output 'h': cannot add or subtract a length (mm) "
                            "and an angle (°) (alpha) (in 'd + alpha'; factors carry their units into the formula: "
                            "rvtol docs writing-a-study, \"Units in formulas\")")
    bad = Params({"define": {"L": {"formula": "alpha", "unit": "mm"}},
                  "output": [{"name": "h", "formula": "L", "unit": "mm"}]}, file="study.toml", key="model")
    with pytest.raises(InputError, match=r"^study.toml: model.define.L: definition 'L': the formula gives an angle "
                                         r"\(°\), the definition's unit 'mm' is a length \(mm\)"):
        from_study(bad, None, spec)
    bad = Params({"units": "factor", "define": {"L": {"formula": "25", "unit": "mm"}},
                  "output": [{"name": "h", "formula": "L", "unit": "mm"}]}, file="study.toml", key="model")
    with pytest.raises(InputError, match="a unit for a definition needs units = \"checked\""):
        from_study(bad, None, spec)
