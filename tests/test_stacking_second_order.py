"""Second-order tolerance analysis against closed forms: exact for quadratic outputs (mean shift, σ, skewness,
kurtosis of x² and of a product of normals), its Pearson tails against the non-central χ² percentiles."""
import math

import numpy as np
import pytest
from scipy import stats

from rvtol.distributions import Distribution
from rvtol.models.formula.model import FormulaModel
from rvtol.spec import Factor, ToleranceSpec
from rvtol.stacking.second_order import curvature, second_order


def normal(name, mean, sigma):
    return Factor(name, "1", Distribution.make("normal", mean=mean, sigma=sigma))


def run(spec, formula, unit="mm"):
    m = FormulaModel.from_spec(spec, {"y": (formula, unit)})
    y0, g, H, _ = curvature(m, spec, "y")
    return second_order(spec, y0, g, H)


def test_a_square_of_a_normal_is_exact_and_its_pearson_tail_is_the_noncentral_chi2():
    mu, s = 1.0, 0.5
    res = run(ToleranceSpec("q", (normal("x", mu, s),)), "x**2", "1")
    # y/σ² is non-central χ²(1, λ = μ²/σ²): its moments in closed form
    lam = (mu / s) ** 2
    law = stats.ncx2(1, lam, scale=s * s)
    m, v, sk, ku = (float(t) for t in law.stats(moments="mvsk"))
    assert res.mean == pytest.approx(m, rel=1e-9) and res.mean_shift == pytest.approx(s * s, rel=1e-9)
    assert res.sigma == pytest.approx(math.sqrt(v), rel=1e-9)
    assert res.skewness == pytest.approx(sk, rel=1e-7) and res.kurtosis == pytest.approx(ku + 3, rel=1e-7)
    # Pearson's curve through the four moments: its 99.865 % point within 1 % of the exact one
    assert res.interval(3.0)[1] == pytest.approx(float(law.ppf(stats.norm.cdf(3.0))), rel=0.01)
    assert res.law.startswith("Pearson")


def test_a_product_of_two_normals_mean_variance_and_third_moment():
    m1, s1, m2, s2 = 10.0, 0.2, 4.0, 0.3
    res = run(ToleranceSpec("p", (normal("a", m1, s1), normal("b", m2, s2))), "a*b", "1")
    # E = μ₁μ₂, Var = μ₁²σ₂² + μ₂²σ₁² + σ₁²σ₂², E[(y − E y)³] = 6 μ₁μ₂ σ₁²σ₂² (independent normals)
    var = m1 ** 2 * s2 ** 2 + m2 ** 2 * s1 ** 2 + s1 ** 2 * s2 ** 2
    assert res.mean == pytest.approx(m1 * m2, rel=1e-12) and res.sigma == pytest.approx(math.sqrt(var), rel=1e-9)
    assert res.skewness == pytest.approx(6 * m1 * m2 * s1 ** 2 * s2 ** 2 / var ** 1.5, rel=1e-7)


def test_a_uniform_factor_under_curvature():
    """y = x² with x ~ U(1, 2): E y = 7/3, Var = 31/5 − 49/9 (moments of a uniform in closed form)."""
    spec = ToleranceSpec("u", (Factor("x", "1", Distribution.make("uniform", lower=1.0, upper=2.0)),))
    res = run(spec, "x**2", "1")
    assert res.mean == pytest.approx(7 / 3, rel=1e-9)
    assert res.sigma == pytest.approx(math.sqrt(31 / 5 - 49 / 9), rel=1e-7)
    # the third central moment of x² (from E x^k = (2^(k+1) − 1)/(k + 1))
    E = lambda k: (2 ** (k + 1) - 1) / (k + 1)  # noqa: E731
    mu = E(2)
    m3 = E(6) - 3 * E(4) * mu + 2 * mu ** 3
    assert res.skewness == pytest.approx(m3 / res.sigma ** 3, rel=1e-6)


def test_the_linearised_rows_say_they_leave_a_curvature_out():
    """y = x + 0.2 x², x ~ N(0, 0.5): every row read from the gradient at the nominal point misses the mean shift
    0.2σ² = 0.05 and says so in its own note (issue 37); the second-order and Monte Carlo rows do not need to."""
    from rvtol.mc import Evaluator, run_monte_carlo
    from rvtol.stacking.compare import compare_conventions

    spec = ToleranceSpec("q", (normal("x", 0.0, 0.5),))
    m = FormulaModel.from_spec(spec, {"y": ("x + 0.2*x**2", "1")})
    mc = run_monte_carlo(m, spec, 500, "random", 1, progress=False)
    frame = compare_conventions(m, spec, ["y"], mc, Evaluator(), true_wc=False).outputs["y"].conventions.frame
    said = frame["note"].str.contains("linearised at the nominal point: the output's curvature is left out "
                                      r"\(its mean shift \+0.05", regex=True)
    linear = ~frame["convention"].str.startswith(("second order", "Monte Carlo"))
    assert said[linear].all() and not said[~linear].any() and linear.sum() == 6   # WC, RSS, Bender, stat., 6σ ×2


def test_a_stack_of_two_lognormals_gets_its_pearson_vi_curve():
    """Found by the property test (tests/test_stacking_property.py): y = −0.2 x₁ − 1.046875 x₂, lognormals of
    median 0.95 and 0.3113, log-σ 0.1565 and 0.3042 — skewness −0.8675, kurtosis 4.4546, Pearson VI.  The beta
    prime's search stepped to β − 4 = e⁻⁶⁸, 0 in floating point, and the second order (and a spec's
    ``dist = "pearson"`` with those moments) stopped on a ZeroDivisionError; now the curve has the four moments
    (scipy's own betaprime.stats)."""
    from rvtol.distributions import pearson_frozen

    fs = (Factor("x1", "1", Distribution.make("lognormal", median=0.95, shape=0.1565168525905048)),
          Factor("x2", "1", Distribution.make("lognormal", median=0.311302979623293, shape=0.3041955319219173)))
    res = run(ToleranceSpec("l", fs), "-0.2*x1 - 1.046875*x2", "1")
    # the linear stack's exact skewness and kurtosis from the lognormals' cumulants (scipy), κ_r(cX) = c^r κ_r(X)
    k = np.zeros(4)
    for c, f in zip((-0.2, -1.046875), fs):
        m, v, s, e = (float(t) for t in stats.lognorm(f.dist.p["shape"], scale=f.dist.p["median"]).stats(moments="mvsk"))
        k += [c * m, c ** 2 * v, c ** 3 * s * v ** 1.5, c ** 4 * e * v ** 2]
    assert res.skewness == pytest.approx(k[2] / k[1] ** 1.5, rel=1e-7)
    assert res.law == "Pearson VI"
    mean, var, skew, excess = (float(t) for t in res.frozen.stats(moments="mvsk"))
    assert (mean, math.sqrt(var)) == (pytest.approx(res.mean, rel=1e-9), pytest.approx(res.sigma, rel=1e-9))
    assert (skew, excess + 3) == (pytest.approx(res.skewness, rel=1e-7), pytest.approx(res.kurtosis, rel=1e-7))
    # the moments the property test met (from scipy's lognormal cumulants), where the search divided by zero
    skew, kurt = -0.8675098856573679, 4.45455674365578
    assert (skew, kurt) == (pytest.approx(res.skewness, rel=1e-9), pytest.approx(res.kurtosis, rel=1e-9))
    t, law = pearson_frozen(0.0, 1.0, skew, kurt)
    m = [float(v) for v in law.stats(moments="mvsk")]
    assert t == "VI" and m[2] == pytest.approx(skew, rel=1e-7) and m[3] + 3 == pytest.approx(kurt, rel=1e-7)
