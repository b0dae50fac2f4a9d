"""Five-point stencils, local sensitivity of models, sensitivity curves, linearisation.

References: exact derivatives of polynomials, the leading error term of the
stencils (h⁴/30·f⁽⁵⁾ central, h⁴/5·f⁽⁵⁾ one-sided), closed-form derivatives
of smooth models and closed-form RSS of linear models.
"""
import math

import numpy as np
import pytest

from rvtol import units
from rvtol.errors import InputError
from rvtol.mc import evaluate as mc_evaluate
from rvtol.model import FunctionModel, LinearModel, Quantity
from rvtol.sensitivity import (contributions, five_point, high_low_table, linear_prediction, sensitivity_curve,
                               stencil_all, stencil_backward, stencil_central, stencil_forward)
from rvtol.spec import spec_from_table
from rvtol.testing import FlakyModel

NODES = np.arange(-2, 3)


def _values(f, x0, h):
    return f(x0 + NODES * h)


# --------------------------------------------------------------------------- pure stencils
@pytest.mark.parametrize("degree", [0, 1, 2, 3, 4])
def test_stencils_exact_for_polynomials_up_to_degree_4(degree):
    g = np.random.default_rng(degree)
    for _ in range(20):
        c = g.normal(size=degree + 1)
        p = np.polynomial.Polynomial(c)
        dp = p.deriv()
        x0, h = g.uniform(-3, 3), g.uniform(0.01, 0.7)
        f = _values(p, x0, h)
        scale = max(1.0, np.max(np.abs(f)) / h)
        d_all = stencil_all(f, h)
        for k in range(5):
            assert d_all[k] == pytest.approx(dp(x0 + NODES[k] * h), abs=1e-11 * scale)
        assert stencil_central(f, h) == pytest.approx(dp(x0), abs=1e-11 * scale)
        assert stencil_forward(f, h) == pytest.approx(dp(x0 - 2 * h), abs=1e-11 * scale)
        assert stencil_backward(f, h) == pytest.approx(dp(x0 + 2 * h), abs=1e-11 * scale)


def test_stencils_not_exact_for_degree_5_leading_error_term():
    # f = x^5, derivative wanted at 0 (true value 0): higher derivatives vanish, so the error is
    # exactly the leading term: −h⁴/30·f⁽⁵⁾ (central), −h⁴/5·f⁽⁵⁾ (one-sided), f⁽⁵⁾ = 120
    h = 0.1
    f = _values(lambda x: x**5, 0.0, h)
    assert stencil_central(f, h) == pytest.approx(-h**4 / 30 * 120, rel=1e-10)
    assert stencil_forward((np.arange(5) * h) ** 5, h) == pytest.approx(-h**4 / 5 * 120, rel=1e-10)
    assert stencil_backward((np.arange(-4, 1) * h) ** 5, h) == pytest.approx(-h**4 / 5 * 120, rel=1e-10)


@pytest.mark.parametrize("stencil,node", [(stencil_central, 0), (stencil_forward, -2), (stencil_backward, 2)])
@pytest.mark.parametrize("func,deriv", [(np.exp, np.exp), (np.sin, np.cos),
                                        (lambda x: 1 / (2 + x), lambda x: -1 / (2 + x) ** 2)])
def test_stencil_error_is_fourth_order(stencil, node, func, deriv):
    x0 = 0.3
    hs = np.array([0.08, 0.04, 0.02, 0.01])
    err = np.array([abs(stencil(_values(func, x0, h), h) - deriv(x0 + node * h)) for h in hs])
    order = np.log2(err[:-1] / err[1:])
    assert np.all(np.abs(order - 4.0) < 0.25), order


def test_stencil_rejects_wrong_shape():
    with pytest.raises(ValueError):
        stencil_central(np.ones(4), 0.1)


# --------------------------------------------------------------------------- five_point on models
def _spec(rows):
    return spec_from_table({"factor": rows})


def _smooth_model():
    # y = sin(a/R) · (1 + b²) as an angle: a (mm) an arc at R, b dimensionless (plain function of two inputs)
    R = 50.0

    def f(X):
        return (np.sin(X[:, 0] / R) * (1 + X[:, 1] ** 2))[:, None]

    model = FunctionModel(f, ["a", "b"], [Quantity("theta", "rad", "arcsec")], input_units=["mm", "1"])
    return model, R


def test_five_point_matches_analytic_derivatives_with_units_and_sign():
    model, R = _smooth_model()
    spec = _spec([{"name": "a", "unit": "um", "dist": "normal", "mean": 8.0, "tolerance": 6.0},
                  {"name": "b", "unit": "1", "dist": "normal", "mean": -0.5, "tolerance": 0.3}])
    res = five_point(model, spec, percent=10.0)
    d = res.frame.set_index("factor")
    a0, b0 = 8e-3, -0.5  # base units
    dyda = math.cos(a0 / R) / R * (1 + b0**2)           # rad/mm
    dydb = math.sin(a0 / R) * 2 * b0                    # rad/1
    assert d.loc["a", "S_unit"] == "arcsec/µm"
    assert d.loc["a", "S"] == pytest.approx(units.convert(dyda, "rad", "arcsec") * 1e-3, rel=1e-9)
    assert d.loc["b", "S"] == pytest.approx(units.convert(dydb, "rad", "arcsec"), rel=1e-9)
    assert d.loc["a", "sign"] == "+" and d.loc["b", "sign"] == "−"
    # ±10 % interval, five points spaced h = 5 % of the nominal
    assert d.loc["a", "half_range"] == pytest.approx(0.8) and d.loc["a", "h"] == pytest.approx(0.4)
    # one-sided derivatives at the interval ends vs the analytic derivative there
    b_lo, b_hi = b0 * 0.9, b0 * 1.1  # b0 < 0: "low end" is nominal − 10 % of |nominal|
    b_lo, b_hi = min(b_lo, b_hi), max(b_lo, b_hi)
    assert d.loc["b", "S_low_end"] == pytest.approx(units.convert(math.sin(a0 / R) * 2 * b_lo, "rad", "arcsec"),
                                                    rel=1e-8)
    assert d.loc["b", "S_high_end"] == pytest.approx(units.convert(math.sin(a0 / R) * 2 * b_hi, "rad", "arcsec"),
                                                     rel=1e-8)
    np.testing.assert_allclose(res.gradient("theta", ["b", "a"]), [dydb, dyda], rtol=1e-9)


def test_zero_nominal_uses_tolerance_half_band_or_abs_step():
    model, R = _smooth_model()
    spec = _spec([{"name": "a", "unit": "um", "dist": "normal", "mean": 0.0, "tolerance": 6.0},
                  {"name": "b", "unit": "1", "dist": "normal", "mean": 0.0, "tolerance": 0.3}])
    res = five_point(model, spec, percent=10.0).frame.set_index("factor")
    assert res.loc["a", "half_range"] == pytest.approx(0.3)   # 10 % of T/2 = 3 µm
    assert res.loc["b", "sign"] == "0"                        # dy/db = 0 at b = 0
    assert res.loc["a", "S"] == pytest.approx(units.convert(1 / R, "rad", "arcsec") * 1e-3, rel=1e-9)
    res2 = five_point(model, spec, abs_step={"a": 2.0}).frame.set_index("factor")
    assert res2.loc["a", "half_range"] == pytest.approx(2.0) and res2.loc["b", "half_range"] == pytest.approx(0.015)
    with pytest.raises(InputError):
        five_point(model, spec, percent=0.0)
    with pytest.raises(InputError):
        five_point(model, spec, factors=["nope"])


def test_evaluations_go_through_the_evaluator_once_per_distinct_point():
    model, _ = _smooth_model()
    spec = _spec([{"name": "a", "unit": "um", "dist": "normal", "mean": 8.0, "tolerance": 6.0},
                  {"name": "b", "unit": "1", "dist": "normal", "mean": -0.5, "tolerance": 0.3}])
    seen = []

    def evaluator(m, X, desc):
        seen.append(len(X))
        return mc_evaluate(m, X, progress=False)

    five_point(model, spec, evaluate=evaluator)
    assert seen == [1 + 4 * 2]  # one batch: shared centre + four points per factor


def test_failed_points_give_nan_and_a_note():
    model = FlakyModel(threshold=1.05)
    spec = _spec([{"name": "x0", "unit": "mm", "dist": "normal", "mean": 1.0, "tolerance": 0.3},
                  {"name": "x1", "unit": "mm", "dist": "normal", "mean": 1.0, "tolerance": 0.3}])
    res = five_point(model, spec)
    d = res.frame.set_index("factor")
    assert np.isnan(d.loc["x0", "S"]) and d.loc["x0", "sign"] == "n/a"
    assert d.loc["x1", "S"] == pytest.approx(2000.0, rel=1e-12)  # output in µm per factor mm
    assert any("x0" in n for n in res.notes)


def test_sensitivity_curve_follows_the_analytic_derivative():
    # y = c·e² (+ e·b): S(e) = 2c·e exactly (quadratic: the stencils are exact)
    def f(X):
        return (3.0 * X[:, 0] ** 2 + X[:, 0] * X[:, 1])[:, None]

    model = FunctionModel(f, ["e", "b"], [Quantity("y", "mm", "um")], input_units=["mm", "mm"])
    spec = _spec([{"name": "e", "unit": "um", "dist": "normal", "mean": 1.0, "tolerance": 1.0},
                  {"name": "b", "unit": "um", "dist": "normal", "mean": 0.0, "tolerance": 1.0}])
    mags = [0.5, 1, 5, 15]
    res = sensitivity_curve(model, spec, ["e"], mags, unit="um").frame
    np.testing.assert_allclose(res["S"], [2 * 3.0 * m * 1e-3 for m in mags], rtol=1e-9)  # um/um
    # together: b is set to e as well, so dy/de = 6e + e
    res2 = sensitivity_curve(model, spec, ["e", "b"], mags, unit="um", together=True).frame
    s_e = res2[res2["factor"] == "e"]["S"].to_numpy()
    np.testing.assert_allclose(s_e, [(6.0 * m + m) * 1e-3 for m in mags], rtol=1e-9)
    with pytest.raises(InputError):
        sensitivity_curve(model, spec, ["e"], [0.0, 1.0])


# --------------------------------------------------------------------------- linearisation
def test_linear_prediction_matches_closed_form_rss_and_worst_case():
    A = np.array([[1 / 50, -2 / 50, 0.5 / 50]])  # rad/mm
    model = LinearModel(["p", "q", "r"], ["mm"] * 3, [Quantity("phi", "rad", "arcmin")], A)
    spec = spec_from_table({
        "factor": [{"name": "p", "unit": "um", "dist": "normal", "mean": 3.0, "tolerance": 6.0},
                   {"name": "q", "unit": "um", "dist": "uniform", "lower": -2.0, "upper": 4.0},
                   {"name": "r", "unit": "um", "dist": "triangular", "lower": 0.0, "upper": 9.0}],
        "correlation": [{"pair": ["p", "q"], "rho": 0.4}]})
    pred = contributions(model, spec, "phi")
    sd = spec.std_base()
    # the normal p and the uniform q at normal-score ρ = 0.4 have Pearson's correlation ρ √(3/π): with Stein's
    # lemma cov(z₁, Φ(z₂)) = ρ E[φ(z₂)] = ρ / (2√π), and var Φ(z₂) = 1/12 (the margins' σ cancel)
    r = 0.4 * math.sqrt(3.0 / math.pi)
    C = np.array([[1, r, 0], [r, 1, 0], [0, 0, 1]]) * np.outer(sd, sd)
    sigma = math.sqrt(A[0] @ C @ A[0])
    assert pred.std == pytest.approx(units.convert(sigma, "rad", "arcmin"), rel=1e-9)
    assert pred.mean == pytest.approx(units.convert(A[0] @ spec.mean_base(), "rad", "arcmin"), rel=1e-9)
    lims = np.array([units.to_base(np.array(f.band), f.unit) for f in spec.factors])
    wc_hi = sum(max(a * (lo - x), a * (hi - x)) for a, (lo, hi), x in zip(A[0], lims, spec.nominal_base()))
    y0 = A[0] @ spec.nominal_base()
    assert pred.worst_high == pytest.approx(units.convert(y0 + wc_hi, "rad", "arcmin"), rel=1e-9)
    v = (A[0] * sd) ** 2
    np.testing.assert_allclose(pred.frame["variance_pct"], 100 * v / v.sum(), rtol=1e-9)
    # the generic entry point on a hand gradient gives the same
    again = linear_prediction(spec, A[0], y0, output="phi", out_unit="arcmin", out_base_unit="rad")
    assert again.std == pytest.approx(pred.std, rel=1e-12)


def test_tolerance_limits_by_kind():
    spec = spec_from_table({"factor": [
        {"name": "n", "unit": "um", "dist": "normal", "mean": 1.0, "tolerance": 6.0},
        {"name": "u", "unit": "um", "dist": "uniform", "lower": -1.0, "upper": 2.0},
        {"name": "r", "unit": "um", "dist": "rayleigh", "tolerance": 12.0}]})
    assert spec.factor("n").band == pytest.approx((-2.0, 4.0))
    assert spec.factor("u").band == pytest.approx((-1.0, 2.0))
    assert spec.factor("r").band == pytest.approx((0.0, 12.0))


def test_high_low_table_evaluates_the_model_at_the_limits():
    def f(X):
        return (X[:, 0] ** 2 + 0.0 * X[:, 1])[:, None]

    model = FunctionModel(f, ["a", "b"], [Quantity("y", "mm", "mm")], input_units=["mm", "mm"])
    spec = _spec([{"name": "a", "unit": "mm", "dist": "normal", "mean": 1.0, "tolerance": 0.6},
                  {"name": "b", "unit": "mm", "dist": "normal", "mean": 0.0, "tolerance": 0.6}])
    d = high_low_table(model, spec).frame.set_index("factor")
    assert d.loc["a", "y_low"] == pytest.approx(0.7**2) and d.loc["a", "y_high"] == pytest.approx(1.3**2)
    assert d.loc["a", "y_median"] == pytest.approx(1.0) and d.loc["b", "swing"] == 0.0
