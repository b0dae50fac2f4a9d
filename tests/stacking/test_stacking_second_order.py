"""Second-order tolerance analysis against closed forms: exact for quadratic outputs (mean shift, σ, skewness,
kurtosis of x² and of a product of normals), its Pearson tails against the non-central χ² percentiles."""
import math

import numpy as np
import pytest
from scipy import stats

from rvtol.distributions import Distribution
from rvtol.models.formula.model import FormulaModel
from rvtol.spec import Factor, ToleranceSpec
from rvtol.stacking.second_order import SecondOrder, _tail_law, curvature, second_order


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
    from rvtol.stacking.beside_monte_carlo import compare_conventions

    spec = ToleranceSpec("q", (normal("x", 0.0, 0.5),))
    m = FormulaModel.from_spec(spec, {"y": ("x + 0.2*x**2", "1")})
    mc = run_monte_carlo(m, spec, 500, "random", 1, progress=False)
    frame = compare_conventions(m, spec, ["y"], mc, Evaluator(), true_wc=False).outputs["y"].conventions.frame
    said = frame["note"].str.contains("linearised at the nominal point: the output's curvature is left out "
                                      r"\(its mean shift \+0.05", regex=True)
    linear = ~frame["convention"].str.startswith(("second order", "Monte Carlo"))
    assert said[linear].all() and not said[~linear].any() and linear.sum() == 6   # WC, RSS, Bender, stat., 6σ ×2


def test_a_stack_of_two_lognormals_gets_its_pearson_vi_curve():
    """Found by the property test (tests/stacking/test_stacking_property.py): y = −0.2 x₁ − 1.046875 x₂, lognormals of
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


def uniform(name, lower, upper):
    return Factor(name, "1", Distribution.make("uniform", lower=lower, upper=upper))


def test_a_gumbel_factors_skewness_and_kurtosis_are_its_closed_forms():
    """y = x, x Gumbel (largest value) of mode 2 and scale 0.1: skewness 12√6 ζ(3)/π³ and kurtosis 27/5, its
    closed forms — the factor's moments integrate its unbounded lower tail (the left of the normal score read by
    the inverse CDF: by the survival function there, 1 − Φ(s) rounds to 1 and its quantile to −∞)."""
    from scipy.special import zeta

    beta = 0.1
    spec = ToleranceSpec("g", (Factor("x", "1", Distribution.make("gumbel", mode=2.0, scale=beta)),))
    res = second_order(spec, 2.0 + np.euler_gamma * beta, np.array([1.0]), np.zeros((1, 1)))
    assert res.sigma == pytest.approx(math.pi * beta / math.sqrt(6.0), rel=1e-9)
    assert res.skewness == pytest.approx(12 * math.sqrt(6) * zeta(3) / math.pi ** 3, rel=1e-8)
    assert res.kurtosis == pytest.approx(27 / 5, rel=1e-8)


def test_the_curvature_of_a_micrometre_spread_is_not_taken_for_noise():
    """y = x + ¼x², x ~ N(0, σ = 1 µm in mm): y = (σ²/4)·χ'² − 1 with χ'² non-central χ²(1, λ = (2/σ)²) — a mean shift
    σ²/4 = 2.5e-7 and its skewness, where |H|σ² = 5e-7 is far above the differences' noise (1e-9 of the linear
    spread, 1e-12)."""
    s = 1e-3
    res = run(ToleranceSpec("q", (normal("x", 0.0, s),)), "x + 0.25*x**2", "1")
    law = stats.ncx2(1, (2 / s) ** 2, scale=s * s / 4, loc=-1.0)
    m, v, sk, _ = (float(t) for t in law.stats(moments="mvsk"))
    assert res.curved and res.mean_shift == pytest.approx(s * s / 4, rel=1e-6)
    assert res.mean == pytest.approx(m, abs=1e-15) and res.sigma == pytest.approx(math.sqrt(v), rel=1e-9)
    assert res.skewness == pytest.approx(sk, rel=1e-5)


def test_correlated_uniforms_shift_the_mean_of_their_product_by_their_covariance():
    """y = x₁x₂, x₁ ~ U(9, 11), x₂ ~ U(3, 5) with normal-score correlation ρ = 0.6: E y = μ₁μ₂ + Cov(x₁, x₂), and
    two uniforms under a Gaussian copula have the Pearson correlation (6/π) asin(ρ/2) (Kruskal 1958), σᵢ = 1/√3."""
    rho = 0.6
    spec = ToleranceSpec("c", (uniform("a", 9.0, 11.0), uniform("b", 3.0, 5.0)),
                         correlation=np.array([[1.0, rho], [rho, 1.0]]))
    res = run(spec, "a*b", "1")
    cov = 6 / math.pi * math.asin(rho / 2) / 3.0
    assert res.mean_shift == pytest.approx(cov, rel=1e-6) and res.mean == pytest.approx(40.0 + cov, rel=1e-9)


def test_a_uniform_factor_curving_down_from_a_flat_mean():
    """y = −x², x ~ U(−2, 2): the gradient at the mean is 0 and the curvature negative; x²/4 is Beta(½, 1), so
    E y = −4/3, Var y = 64/45 and the skewness is minus Beta(½, 1)'s (scipy)."""
    res = run(ToleranceSpec("u", (uniform("x", -2.0, 2.0),)), "-x**2", "1")
    sk = float(stats.beta(0.5, 1.0).stats(moments="s"))
    assert res.mean == pytest.approx(-4 / 3, rel=1e-9) and res.sigma == pytest.approx(math.sqrt(64 / 45), rel=1e-9)
    assert res.skewness == pytest.approx(-sk, rel=1e-7)


def test_cross_curvature_between_curved_uniforms_in_the_third_moment():
    """y = x₁ + x₂ + x₁² − x₂² + x₁x₂, x₁, x₂ ~ U(−1, 1) independent.  The cross term's third-cumulant share is
    6 H₁₂ cᵢ c_j with cᵢ = E[gᵢ(xᵢ)(xᵢ − μᵢ)]; the terms the method leaves out are 3H₁₂²ΣE[(gᵢ − E gᵢ)dᵢ²] and
    H₁₂³μ₃₁μ₃₂, both 0 here (symmetric factors, opposite curvatures), so mean, σ and skewness are exact: against
    the moments of y by Gauss–Legendre quadrature over the square (exact for this polynomial)."""
    spec = ToleranceSpec("x", (uniform("a", -1.0, 1.0), uniform("b", -1.0, 1.0)))
    res = run(spec, "a + b + a**2 - b**2 + a*b", "1")
    t, w = np.polynomial.legendre.leggauss(8)
    a, b = np.meshgrid(t, t)
    p = np.outer(w, w) / 4.0
    y = a + b + a ** 2 - b ** 2 + a * b
    mean = float(np.sum(p * y))
    var, m3 = float(np.sum(p * (y - mean) ** 2)), float(np.sum(p * (y - mean) ** 3))
    assert res.mean == pytest.approx(mean, abs=1e-12) and res.sigma == pytest.approx(math.sqrt(var), rel=1e-9)
    assert res.skewness == pytest.approx(m3 / var ** 1.5, rel=1e-7)


def test_a_gumbel_plus_a_normal_gets_a_johnson_su_curve_with_their_four_moments():
    """y = x₁ + x₂, x₁ Gumbel (mode 0, scale 1), x₂ normal of the same σ = π/√6: cumulants add — skewness
    12√6 ζ(3)/π³ / 2^1.5 and excess kurtosis (12/5)/4 (β₁ = 0.162, β₂ = 3.6: Pearson's type IV, no implementation
    here, so a Johnson SU curve) — and the curve has them, its mean and σ those of the sum."""
    from scipy.special import zeta

    s = math.pi / math.sqrt(6.0)
    spec = ToleranceSpec("j", (Factor("g", "1", Distribution.make("gumbel", mode=0.0, scale=1.0)), normal("n", 1.0, s)))
    res = run(spec, "g + n", "1")
    skew, kurt = 12 * math.sqrt(6) * zeta(3) / math.pi ** 3 / 2 ** 1.5, 3 + 12 / 5 / 4
    assert res.law == "Johnson SU"
    m, v, sk, ex = (float(t) for t in res.frozen.stats(moments="mvsk"))
    assert m == pytest.approx(np.euler_gamma + 1.0, rel=1e-9)
    assert math.sqrt(v) == pytest.approx(s * math.sqrt(2), rel=1e-9)
    assert (sk, ex + 3) == (pytest.approx(skew, rel=1e-6), pytest.approx(kurt, rel=1e-6))


def test_beyond_adds_both_tails_of_the_fitted_law():
    """y = x, x ~ N(1, 0.5): the fitted law is that normal, so P(y < 0) + P(y > 2.5) = Φ(−2) + Φ(−3) (scipy); a
    law with a CDF but no survival function (any scipy-like object) gets its upper tail as 1 − F."""
    spec = ToleranceSpec("n", (normal("x", 1.0, 0.5),))
    res = second_order(spec, 1.0, np.array([1.0]), np.zeros((1, 1)))
    lo, hi = stats.norm.cdf(-2.0), stats.norm.cdf(-3.0)
    assert res.beyond(lower=0.0) == pytest.approx(lo, rel=1e-12)
    assert res.beyond(upper=2.5) == pytest.approx(hi, rel=1e-12)
    assert res.beyond(lower=0.0, upper=2.5) == pytest.approx(lo + hi, rel=1e-12)

    class CdfOnly:                      # a law with ppf and cdf only
        def __init__(self, law):
            self.ppf, self.cdf = law.ppf, law.cdf

    bare = SecondOrder(1.0, 1.0, 0.5, 0.0, 3.0, "normal", CdfOnly(stats.norm(1.0, 0.5)))
    assert bare.beyond(upper=0.5) == pytest.approx(stats.norm.cdf(1.0), rel=1e-12)   # P(y > μ − σ) = Φ(1)


def test_the_hessian_by_central_differences_of_a_quartic():
    """y = a⁴ + b, a, b ~ N(0, 1): steps h = σ/2, so H_aa = (h⁴ − 0 + h⁴)/h² = 2h² = 0.5 (the central difference by
    hand, not the true 0 of y'' at 0), H_bb = H_ab = 0, from 1 + 2·2 + 4·1 = 9 evaluations (one per pair of factors)."""
    spec = ToleranceSpec("q", (normal("a", 0.0, 1.0), normal("b", 0.0, 1.0)))
    m = FormulaModel.from_spec(spec, {"y": ("a**4 + b", "1")})
    y0, g, H, n = curvature(m, spec, "y")
    assert n == 9 and y0 == 0.0
    assert g == pytest.approx([0.0, 1.0], abs=1e-12)
    assert H == pytest.approx(np.array([[0.5, 0.0], [0.0, 0.0]]), abs=1e-12)


def test_the_noise_threshold_scales_with_the_output():
    """The rule 'curvature below 1e-9 of the linear spread is noise' is relative: y = c(x + 10⁻⁸x²) (x ~ N(0, 1),
    ½Hσ² = 10⁻⁸c, 2·10⁻⁸ of the linear spread c) is curved for every c, and y = c(x + 10⁻¹⁰x²) (2·10⁻¹⁰ of it) for
    none, whatever the unit makes of c."""
    spec = ToleranceSpec("n", (normal("x", 0.0, 1.0),))
    for c in (1e-6, 1.0, 1e6):
        res = second_order(spec, 0.0, np.array([c]), np.array([[2e-8 * c]]))
        assert res.curved and res.mean_shift == pytest.approx(1e-8 * c, rel=1e-9), c
        res = second_order(spec, 0.0, np.array([c]), np.array([[2e-10 * c]]))
        assert not res.curved and res.mean_shift == 0.0, c


def test_a_product_of_normals_read_from_toml_gets_the_exact_kurtosis():
    """y = a·b, a, b ~ N(0, 0.1) read from a spec's TOML text (the kind a parsed string, not the literal): the product
    of two centred normals has variance σ⁴, skewness 0 and kurtosis 9 (E(ab)⁴ = 9σ⁸): the exact quadratic form of
    normals, cross term included, with no note of a left-out term (σ_y = 0.01 mm²)."""
    import tomllib

    from rvtol.spec import spec_from_table

    text = "".join(f'[[factor]]\nname = "{n}"\ntolerance = "0 ±0.3"\nunit = "mm"\ndist = "normal"\n' for n in "ab")
    spec = spec_from_table(tomllib.loads(text))
    res = run(spec, "a*b", "mm^2")
    assert res.sigma == pytest.approx(0.01, rel=1e-9) and res.skewness == pytest.approx(0.0, abs=1e-9)
    assert res.kurtosis == pytest.approx(9.0, rel=1e-9) and res.notes == []


def test_a_curved_normal_beside_a_uniform_gets_the_chi2_skewness():
    """y = x₁² + x₂, x₁ ~ N(0, 0.5), x₂ ~ U(−1, 1): x₁² = σ²χ²(1), whose third cumulant 8σ⁶ and fourth 48σ⁸ (scipy's
    χ²(1)) add to the uniform's (0 and −1.2·(1/3)²); separable, so exact and without the cross-term note."""
    s = 0.5
    spec = ToleranceSpec("m", (normal("a", 0.0, s), uniform("b", -1.0, 1.0)))
    res = run(spec, "a**2 + b", "1")
    m, v, sk, ex = (float(t) for t in stats.chi2(1, scale=s * s).stats(moments="mvsk"))
    var = v + 1 / 3
    assert res.mean == pytest.approx(m, rel=1e-9) and res.sigma == pytest.approx(math.sqrt(var), rel=1e-9)
    assert res.skewness == pytest.approx(sk * v ** 1.5 / var ** 1.5, rel=1e-9)
    assert res.kurtosis == pytest.approx(3 + (ex * v * v - 1.2 / 9) / var ** 2, rel=1e-9)
    assert res.notes == []


def test_cross_curvature_with_a_skewed_curved_factor_in_the_third_moment():
    """y = A z₁ + B z₁² + z₂ + M z₁z₂ in the standardised factors of x₁ ~ triangular(0, 0.2, 1) (skewed) and
    x₂ ~ U(−1, 1): the cross term's third-cumulant share 6M c₁c₂ with c₁ = E[g₁z₁] = A + Bμ₃.  With A = −B(μ₄ − 1)/μ₃
    the terms the method leaves out (3M²E[(g₁ − E g₁)z₁²], 3M²E[(g₂ − E g₂)z₂²], M³μ₃₁μ₃₂) are 0, so the skewness
    is exact: against the moments of y by Gauss–Legendre quadrature over the triangle's two linear pieces and the
    square (exact for this polynomial)."""
    tri = stats.triang(0.2)
    m1, v1, s3, ex = (float(t) for t in tri.stats(moments="mvsk"))
    s1 = math.sqrt(v1)
    B, M = 0.3, 0.4
    A = -B * (ex + 2.0) / s3                       # μ₄ − 1 = excess + 2
    spec = ToleranceSpec("t", (Factor("a", "1", Distribution.make("triangular", lower=0.0, mode=0.2, upper=1.0)),
                               uniform("b", -1.0, 1.0)))
    z1, z2 = f"((a - {m1!r})/{s1!r})", f"(b*{math.sqrt(3.0)!r})"
    res = run(spec, f"{A!r}*{z1} + {B!r}*{z1}**2 + {z2} + {M!r}*{z1}*{z2}", "1")
    t, w = np.polynomial.legendre.leggauss(8)
    x1, p1 = [], []
    for lo, hi in ((0.0, 0.2), (0.2, 1.0)):        # the triangle's pdf is linear on each piece
        x = lo + (hi - lo) * (t + 1) / 2
        x1.append(x), p1.append(w * (hi - lo) / 2 * tri.pdf(x))
    x1, p1 = np.concatenate(x1), np.concatenate(p1)
    u1, u2 = np.meshgrid((x1 - m1) / s1, t * math.sqrt(3.0), indexing="ij")
    p = np.outer(p1, w / 2)
    y = A * u1 + B * u1 ** 2 + u2 + M * u1 * u2
    mean = float(np.sum(p * y))
    var, m3 = float(np.sum(p * (y - mean) ** 2)), float(np.sum(p * (y - mean) ** 3))
    assert res.mean == pytest.approx(mean, abs=1e-10) and res.sigma == pytest.approx(math.sqrt(var), rel=1e-9)
    assert res.skewness == pytest.approx(m3 / var ** 1.5, rel=1e-7)


def test_moments_on_or_below_pearsons_bound_are_raised_to_it():
    """β₂ ≥ β₁ + 1 for every law, with equality only for a two-point one (Pearson 1916): a truncated expansion's
    kurtosis on or below the bound is raised to just above it (1e-6), said in a note, and the curve has the
    skewness and the raised kurtosis (scipy's moments of the fitted law)."""
    for skew, kurt in ((0.5, 1.25), (2.0, 4.0), (-1.0, 1.5)):    # on the bound (exact in binary), below it
        notes = []
        law, frozen = _tail_law(0.0, 1.0, skew, kurt, notes)
        assert law.startswith("Pearson") and notes == [
            f"the expansion's kurtosis {kurt:.4g} is below skewness² + 1: raised to the bound"]
        m, v, s, ex = (float(t) for t in frozen.stats(moments="mvsk"))
        assert (m, v) == (pytest.approx(0.0, abs=1e-9), pytest.approx(1.0, rel=1e-9))
        assert s == pytest.approx(skew, rel=1e-6) and ex + 3 == pytest.approx(skew * skew + 1 + 1e-6, rel=1e-6)


def test_a_slightly_curved_uniform_keeps_its_low_kurtosis():
    """y = x + 0.01x², x ~ U(−1, 1): skewness 0.0139 and kurtosis 1.8002 (moments by Gauss–Legendre quadrature, exact
    for this polynomial) — admissible (above skewness² + 1), so the Pearson curve has them unchanged, no note."""
    res = run(ToleranceSpec("u", (uniform("x", -1.0, 1.0),)), "x + 0.01*x**2", "1")
    t, w = np.polynomial.legendre.leggauss(8)
    y, p = t + 0.01 * t ** 2, w / 2
    d = y - float(np.sum(p * y))
    var = float(np.sum(p * d ** 2))
    skew, kurt = float(np.sum(p * d ** 3)) / var ** 1.5, float(np.sum(p * d ** 4)) / var ** 2
    assert 0.0138 < skew < 0.0139 and 1.8 < kurt < 1.8003
    assert res.skewness == pytest.approx(skew, rel=1e-7) and res.kurtosis == pytest.approx(kurt, rel=1e-9)
    assert res.tail_notes == [] and res.law == "Pearson I"
    _, _, s, ex = (float(x) for x in res.frozen.stats(moments="mvsk"))
    assert s == pytest.approx(skew, rel=1e-7) and ex + 3 == pytest.approx(kurt, rel=1e-9)
