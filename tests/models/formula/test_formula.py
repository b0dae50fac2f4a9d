"""Formula models: equal to the same model written in Python, exact derivatives (hand and finite
differences), units, study factory errors located (the language itself, malicious input included,
is tested in test_expressions.py)."""
import math
import pickle

import numpy as np
import pytest

from rvtol.errors import InputError
from rvtol.expressions import ExpressionError
from rvtol.models.formula.model import FormulaModel, FormulaOutput, from_study
from rvtol.model import FunctionModel, Quantity
from rvtol.params import Params
from rvtol.sampling import sample
from rvtol.spec import load_spec

NAMES = ["e", "t", "R", "a", "b"]

# A small lost-motion-like model: the angle of an eccentric point, a radial clearance, a tilt
OUTPUTS = {
    "angle": "atan2(e*sin(t), R + e*cos(t))",
    "clearance": "hypot(a, b) - sqrt(a**2 + 0.5*b**2) + abs(a - b)/2",
    "mixed": "exp(-a/R) * log(R) + tan(t/4) - asin(a/4) + acos(b/4) - atan(e) + min(a, b)*max(a, 2*b) + pi",
    "power": "(R/2)**3 - 2**a + a**b",
}


def python_model(X):
    e, t, R, a, b = X.T
    return np.stack([
        np.arctan2(e * np.sin(t), R + e * np.cos(t)),
        np.hypot(a, b) - np.sqrt(a ** 2 + 0.5 * b ** 2) + np.abs(a - b) / 2,
        np.exp(-a / R) * np.log(R) + np.tan(t / 4) - np.arcsin(a / 4) + np.arccos(b / 4) - np.arctan(e)
        + np.minimum(a, b) * np.maximum(a, 2 * b) + np.pi,
        (R / 2) ** 3 - 2 ** a + a ** b,
    ], axis=1)


def points(n=500, seed=0):
    rng = np.random.default_rng(seed)
    return np.column_stack([rng.uniform(0.1, 2, n), rng.uniform(-3, 3, n), rng.uniform(5, 50, n),
                            rng.uniform(0.2, 1.9, n), rng.uniform(0.2, 1.9, n)])


def test_equals_the_same_model_written_in_python():
    X = points()
    fm = FormulaModel(OUTPUTS, NAMES)
    pm = FunctionModel(python_model, NAMES, list(OUTPUTS))
    np.testing.assert_allclose(fm.evaluate(X), pm.evaluate(X), rtol=1e-14, atol=1e-14)
    # row-deterministic: any split gives the same bits
    np.testing.assert_array_equal(fm.evaluate(X), np.vstack([fm.evaluate(X[:123]), fm.evaluate(X[123:])]))
    assert fm.output_names == tuple(OUTPUTS) and fm.input_units == ("1",) * 5


def hand_gradient(X):
    e, t, R, a, b = X.T
    n = len(X)
    G = np.zeros((n, 4, 5))
    den = (R + e * np.cos(t)) ** 2 + (e * np.sin(t)) ** 2
    G[:, 0, 0] = (np.sin(t) * R) / den                          # ∂/∂e of atan2(e sin t, R + e cos t)
    G[:, 0, 1] = (e * R * np.cos(t) + e * e) / den               # ∂/∂t
    G[:, 0, 2] = -e * np.sin(t) / den                            # ∂/∂R
    h, s = np.hypot(a, b), np.sqrt(a ** 2 + 0.5 * b ** 2)
    G[:, 1, 3] = a / h - a / s + 0.5 * np.sign(a - b)
    G[:, 1, 4] = b / h - 0.5 * b / s - 0.5 * np.sign(a - b)
    mn, mx = np.minimum(a, b), np.maximum(a, 2 * b)
    dmn_a, dmn_b = (a <= b).astype(float), (a > b).astype(float)
    dmx_a, dmx_b = (a >= 2 * b).astype(float), 2.0 * (a < 2 * b)
    G[:, 2, 0] = -1 / (1 + e * e)
    G[:, 2, 1] = 0.25 / np.cos(t / 4) ** 2
    G[:, 2, 2] = np.exp(-a / R) * (a / R ** 2 * np.log(R) + 1 / R)
    G[:, 2, 3] = (-np.exp(-a / R) / R * np.log(R) - 0.25 / np.sqrt(1 - (a / 4) ** 2)
                  + dmn_a * mx + mn * dmx_a)
    G[:, 2, 4] = -0.25 / np.sqrt(1 - (b / 4) ** 2) + dmn_b * mx + mn * dmx_b
    G[:, 3, 2] = 1.5 * (R / 2) ** 2
    G[:, 3, 3] = -np.log(2) * 2 ** a + b * a ** (b - 1)
    G[:, 3, 4] = np.log(a) * a ** b
    return G


def test_derivatives_equal_hand_derivatives():
    X = points()
    np.testing.assert_allclose(FormulaModel(OUTPUTS, NAMES).gradient(X), hand_gradient(X), rtol=1e-12, atol=1e-13)


def test_derivatives_agree_with_central_differences():
    X = points(200, seed=3)
    m = FormulaModel(OUTPUTS, NAMES)
    G = m.gradient(X)
    for j in range(5):
        h = 1e-6 * np.maximum(1.0, np.abs(X[:, j]))
        Xp, Xm = X.copy(), X.copy()
        Xp[:, j] += h
        Xm[:, j] -= h
        Yp, Ym = m.evaluate(Xp), m.evaluate(Xm)
        fd = (Yp - Ym) / (2 * h[:, None])
        # central differences: truncation O(h²) (negligible here) plus rounding, at most a few ulps of
        # |Y| divided by 2h; compared away from the kinks of abs/min/max
        rounding = 4 * np.finfo(float).eps * (np.abs(Yp) + np.abs(Ym)) / (2 * h[:, None])
        a, b = X[:, 3], X[:, 4]
        smooth = (np.abs(a - b) > 1e-4) & (np.abs(a - 2 * b) > 1e-4)
        err = np.abs(G[:, :, j] - fd)[smooth]
        assert np.all(err <= 1e-7 * np.abs(fd[smooth]) + rounding[smooth] + 1e-9), j


def test_units_and_definitions():
    # units = "factor" (unchecked): the numbers as written, the output's unit what they yield —
    # clearance in µm of a gap (mm) minus two widths (mm) converted by hand; the tilt through a definition
    m = FormulaModel([FormulaOutput("gap", "(g - w1 - w2)*1000", "um", "um"),
                      FormulaOutput("tilt", "atan2(d, L)", "rad", "arcmin")],
                     ["g", "w1", "w2", "d"], ["mm", "mm", "mm", "um"], definitions={"L": "12.5*2"}, checked=False)
    assert m.input_units == ("mm", "mm", "mm", "mm")
    assert m.outputs[0] == Quantity("gap", "mm", "um") and m.outputs[1].display_unit == "arcmin"
    X = np.array([[24.08, 11.99, 12.0, 0.002]])      # base units: d = 2 µm = 0.002 mm
    Y, G = m.evaluate_with_gradient(X)
    assert Y[0, 0] == pytest.approx(0.09)              # returned in base units (mm)
    assert Y[0, 1] == pytest.approx(math.atan2(2.0, 25.0))   # d in µm inside the formula
    np.testing.assert_allclose(G[0, 0], [1, -1, -1, 0], rtol=1e-12)
    # ∂tilt/∂d_base = (1/L)/(1+(d/L)²) per µm → × 1000 per mm
    assert G[0, 1, 3] == pytest.approx(1000 * (1 / 25) / (1 + (2 / 25) ** 2), rel=1e-12)


def test_definitions_chain_derivatives():
    m = FormulaModel({"y": "u*u + v"}, ["x", "z"], definitions={"u": "sin(x)*z", "v": "exp(u)"})
    X = np.array([[0.3, 2.0], [1.1, -0.5]])
    x, z = X.T
    u = np.sin(x) * z
    np.testing.assert_allclose(m.evaluate(X)[:, 0], u * u + np.exp(u), rtol=1e-15)
    G = m.gradient(X)
    du = np.stack([np.cos(x) * z, np.sin(x)], axis=1)
    np.testing.assert_allclose(G[:, 0, :], (2 * u + np.exp(u))[:, None] * du, rtol=1e-13)


def test_from_spec_equals_the_linear_stack_and_runs_on_samples():
    spec = load_spec("data/specs/rv80e_axial_stack.toml")
    m = FormulaModel.from_spec(spec, {"clearance": ("carrier_gap - disc1_width - disc2_width", "mm", "um")})
    m.check_spec(spec)
    s = sample(spec, 1000, "lhs", seed=1)
    np.testing.assert_allclose(m.evaluate(s.values)[:, 0], s.values @ [1, -1, -1], rtol=0, atol=1e-13)
    np.testing.assert_array_equal(m.gradient(s.values[:3])[:, 0, :], [[1, -1, -1]] * 3)
    m2 = pickle.loads(pickle.dumps(m))
    np.testing.assert_array_equal(m2.evaluate(s.values), m.evaluate(s.values))


def test_undefined_rows_become_failed_samples_not_exceptions():
    m = FormulaModel({"y": "sqrt(x) + log(x)"}, ["x"])
    Y, status = m.evaluate_with_status(np.array([[4.0], [-1.0], [0.0]]))
    assert Y[0, 0] == pytest.approx(2 + math.log(4)) and list(status) == [0, 1, 1]


def test_a_factor_named_like_a_constant_is_braced():
    m = FormulaModel({"y": "{pi} * 3.141592653589793"}, ["pi"])
    assert m.evaluate(np.array([[2.0]]))[0, 0] == pytest.approx(2 * math.pi)
    with pytest.raises(ExpressionError, match="both a name and a constant"):
        FormulaModel({"y": "{pi} * pi"}, ["pi"])


def test_model_construction_errors():
    with pytest.raises(ExpressionError, match="output 'y': unknown name 'z'"):
        FormulaModel({"y": "x + z"}, ["x"])
    with pytest.raises(ExpressionError, match="duplicate output"):
        FormulaModel([("y", "x"), ("y", "2*x")], ["x"])
    with pytest.raises(ExpressionError, match="unknown unit"):
        FormulaModel([("y", "x", "milimeter")], ["x"])
    with pytest.raises(ExpressionError, match="definition 'x' has the name of an input"):
        FormulaModel({"y": "x"}, ["x"], definitions={"x": "1"})
    with pytest.raises(ExpressionError, match="unit 'mm' is a length, expected angle"):
        FormulaModel([FormulaOutput("y", "x", "rad", "mm")], ["x"])


def test_study_factory_locates_errors():
    spec = load_spec("data/specs/rv80e_axial_stack.toml")
    p = Params({"units": "checked", "define": {"w": "disc1_width + disc2_width"},
                "output": [{"name": "gap", "formula": "carrier_gap - w", "unit": "mm", "display_unit": "um"}]},
               file="study.toml", key="model")
    m = from_study(p, None, spec)
    assert m.outputs[0] == Quantity("gap", "mm", "um")
    bad = Params({"output": [{"name": "gap", "formula": "carrier_gap.real", "unit": "mm"}]},
                 file="study.toml", key="model")
    with pytest.raises(InputError) as e:
        from_study(bad, None, spec)
    assert str(e.value).startswith("study.toml: model.output[0].formula: output 'gap': unknown name 'carrier_gap.real'")
    bad = Params({"define": {"w": "nope"}, "output": [{"name": "gap", "formula": "w", "unit": "mm"}]},
                 file="study.toml", key="model")
    with pytest.raises(InputError, match="study.toml: model.define.w: definition 'w': unknown name 'nope'"):
        from_study(bad, None, spec)
    bad = Params({"output": [{"name": "gap", "formula": "1", "unit": "mm", "colour": "red"}]},
                 file="study.toml", key="model")
    with pytest.raises(InputError, match="model.output\\[0\\].colour: unknown key"):
        from_study(bad, None, spec)


def test_the_linearised_analyses_use_the_exact_gradient():
    from rvtol.sensitivity.linearisation import contributions, linear_prediction

    spec = load_spec("data/specs/rv80e_axial_stack.toml")
    m = FormulaModel.from_spec(spec, {"ratio": ("carrier_gap * disc1_width / disc2_width**2", "1")})
    pred = contributions(m, spec)
    x0 = spec.nominal_base()
    g, w1, w2 = x0
    exact = np.array([w1 / w2 ** 2, g / w2 ** 2, -2 * g * w1 / w2 ** 3])   # by hand
    ref = linear_prediction(spec, exact, g * w1 / w2 ** 2, output="ratio", out_unit="1")
    assert pred.std == pytest.approx(ref.std, rel=1e-13) and pred.worst_high == pytest.approx(ref.worst_high, rel=1e-13)
    assert any("exact" in n for n in pred.notes)


def test_each_output_depends_on_the_inputs_its_formula_names():
    """dependencies(): an output lists the inputs it names, through the definitions it uses — and the model's
    exact derivatives are zero for every other input (at random points)."""
    m = FormulaModel({"t1": "hypot(a1, b1)", "t2": "hypot(a2, s)", "k": "pi * c"}, ["a1", "b1", "a2", "b2", "c"],
                     definitions={"s": "2 * b2 + c"}, checked=False)
    deps = m.dependencies()
    assert deps == {"t1": {"a1", "b1"}, "t2": {"a2", "b2", "c"}, "k": {"c"}}
    X = np.random.default_rng(1).normal(size=(20, 5))
    G = m.gradient(X)
    for i, q in enumerate(m.outputs):
        free = [j for j, n in enumerate(m.inputs) if n not in deps[q.name]]
        assert np.all(G[:, i, free] == 0.0) and np.all(np.any(G[:, i, :] != 0.0, axis=0)[
            [j for j, n in enumerate(m.inputs) if n in deps[q.name]]])
