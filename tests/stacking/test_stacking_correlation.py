"""Every convention honours the spec's correlation (issue 37): the σ rows of the stack-up conventions and the
second-order moments against closed forms — a sum of two correlated normals, the copula's Pearson correlation of
uniforms and lognormals, a product of correlated normals by Gauss–Hermite quadrature — and the second-order
moments of skewed factors (a lognormal, a shifted asymmetric triangle) against their exact moments from scipy's raw
moments, which the odd-moment terms decide."""
import math

import numpy as np
import pytest
from scipy import stats

from rvtol.distributions import Distribution
from rvtol.models.formula.model import FormulaModel
from rvtol.spec import Factor, ToleranceSpec, spec_from_table
from rvtol.stacking import stack_conventions
from rvtol.sampling import factor_correlation
from rvtol.stacking.second_order import curvature, second_order

SIGMA_ROWS = ("RSS", "statistical ±3σ (the distributions)", "6σ static ±3σ", "6σ dynamic RSS ±3σ")


def moments_of(spec, formula):
    m = FormulaModel({"y": formula}, spec.names, [f.unit for f in spec.factors], checked=False)
    y0, g, H, _ = curvature(m, spec, "y")
    return second_order(spec, y0, g, H)


def test_two_factors_at_rho_08_widen_every_sigma_row():
    """The issue's case: a = 10 ±0.3, b = 20 ±0.3 (normal, σ = 0.1), ρ = +0.8, y = a + b: σ_y = 0.1·√(2 + 2·0.8) =
    0.18974 mm by every row that adds variances (the rows used 0.14142, 25 % too small: ρ dropped)."""
    spec = spec_from_table({"factor": [{"name": "a", "tolerance": "10 ±0.3", "unit": "mm"},
                                       {"name": "b", "tolerance": "20 ±0.3", "unit": "mm"}],
                            "correlation": [{"pair": ["a", "b"], "rho": 0.8}]})
    m = FormulaModel.from_spec(spec, {"y": ("a + b", "mm")})
    x0 = spec.nominal_base()
    sc = stack_conventions(spec, m.gradient(x0[None])[0, 0], 30.0, x0, out_unit="mm")
    exact = 0.1 * math.sqrt(2 + 2 * 0.8)
    for name in SIGMA_ROWS:
        r = sc.row(name)
        assert r["sigma"] == pytest.approx(exact, rel=1e-12), name
        assert "correlation included" in r["note"], name
    # the 1.5σ-shift convention reads each band as a ±6σ normal shifted 1.5σ: σ_i = 0.3/4.5, with ρ
    assert sc.row("6σ dynamic, 1.5σ shift ±3σ")["sigma"] == pytest.approx(0.3 / 4.5 * math.sqrt(3.6), rel=1e-12)
    assert sc.row("MRSS, Bender")["half_width"] == pytest.approx(1.5 * 3 * exact, rel=1e-12)
    so = moments_of(spec, "a + b")
    assert so.sigma == pytest.approx(exact, rel=1e-9) and so.mean == pytest.approx(30.0, rel=1e-12)
    assert any("correlation included" in n for n in so.notes)


def test_the_copula_gives_each_pair_its_pearson_correlation():
    """Normal-score ρ = 0.8: two normals keep it; two U(−1, 1) get (6/π) asin(ρ/2) (Kruskal 1958); two lognormals of
    log-σ 1 and 0.5, (e^{ρ s₁ s₂} − 1)/√((e^{s₁²} − 1)(e^{s₂²} − 1)); a normal and an independent factor stay 0."""
    fs = (Factor("n1", "mm", Distribution.make("normal", mean=0, sigma=1)),
          Factor("n2", "mm", Distribution.make("normal", mean=0, sigma=2)),
          Factor("u1", "mm", Distribution.make("uniform", lower=-1, upper=1)),
          Factor("u2", "mm", Distribution.make("uniform", lower=0, upper=3)),
          Factor("l1", "mm", Distribution.make("lognormal", median=1.0, shape=1.0)),
          Factor("l2", "mm", Distribution.make("lognormal", median=2.0, shape=0.5)))
    R = np.eye(6)
    for i, j in ((0, 1), (2, 3), (4, 5)):
        R[i, j] = R[j, i] = 0.8
    R[0, 4] = R[4, 0] = -0.3
    P = factor_correlation(ToleranceSpec("c", fs, R))
    assert P[0, 1] == 0.8
    assert P[2, 3] == pytest.approx(6 / math.pi * math.asin(0.4), abs=1e-10)
    assert P[4, 5] == pytest.approx((math.exp(0.8 * 0.5) - 1) / math.sqrt((math.e - 1) * (math.exp(0.25) - 1)),
                                    abs=1e-9)
    # a normal and a lognormal of log-σ s: corr = ρ s / √(e^{s²} − 1) (Cov(z, e^{s z'}) = ρ s e^{s²/2})
    assert P[0, 4] == pytest.approx(-0.3 / math.sqrt(math.e - 1), abs=1e-10)
    assert P[1, 2] == 0.0 and np.allclose(P, P.T) and np.all(np.diag(P) == 1.0)
    assert factor_correlation(ToleranceSpec("i", fs)) is None


def test_correlated_uniforms_by_the_statistical_row_and_the_second_order():
    """y = u₁ + u₂, U(−1, 1) each at normal-score ρ = 0.8: Var y = 2/3 (1 + (6/π) asin 0.4)."""
    fs = tuple(Factor(n, "mm", Distribution.make("uniform", lower=-1.0, upper=1.0)) for n in ("u1", "u2"))
    spec = ToleranceSpec("u", fs, np.array([[1.0, 0.8], [0.8, 1.0]]))
    exact = math.sqrt(2 / 3 * (1 + 6 / math.pi * math.asin(0.4)))
    sc = stack_conventions(spec, np.ones(2), 0.0, np.zeros(2), out_unit="mm")
    assert sc.row("statistical ±3σ (the distributions)")["sigma"] == pytest.approx(exact, rel=1e-9)
    so = moments_of(spec, "u1 + u2")
    assert so.sigma == pytest.approx(exact, rel=1e-9)
    assert any("not all normal" in n and "skewness and kurtosis take them as independent" in n for n in so.notes)
    # curved in a correlated uniform: σ approximate, and the note says so
    assert any("σ approximate" in n for n in moments_of(spec, "u1 + u1**2 + u2").notes)


def gauss_hermite_moments(f, mu, sd, rho, nodes=20):
    """Mean, σ, skewness, kurtosis of f(x₁, x₂) for correlated normals by a tensor Gauss–Hermite rule: exact for a
    polynomial of degree < 2·nodes (here ≤ 8)."""
    z, w = np.polynomial.hermite_e.hermegauss(nodes)
    w = w / math.sqrt(2 * math.pi)
    Z1, Z2 = np.meshgrid(z, z, indexing="ij")
    W = np.outer(w, w)
    x1 = mu[0] + sd[0] * Z1
    x2 = mu[1] + sd[1] * (rho * Z1 + math.sqrt(1 - rho * rho) * Z2)
    y = f(x1, x2)
    m = float(np.sum(W * y))
    c = [float(np.sum(W * (y - m) ** n)) for n in (2, 3, 4)]
    return m, math.sqrt(c[0]), c[1] / c[0] ** 1.5, c[2] / c[0] ** 2


@pytest.mark.parametrize("rho", [0.0, 0.6, -0.9])
def test_a_quadratic_of_correlated_normals_is_exact(rho):
    """y = a·b + 0.3 a² − b with a ~ N(2, 0.5), b ~ N(−1, 0.8) at ρ: the four moments of the quadratic form against
    Gauss–Hermite quadrature (exact for polynomials)."""
    fs = (Factor("a", "1", Distribution.make("normal", mean=2.0, sigma=0.5)),
          Factor("b", "1", Distribution.make("normal", mean=-1.0, sigma=0.8)))
    spec = ToleranceSpec("q", fs, None if rho == 0 else np.array([[1.0, rho], [rho, 1.0]]))
    so = moments_of(spec, "a*b + 0.3*a**2 - b")
    m, s, sk, ku = gauss_hermite_moments(lambda a, b: a * b + 0.3 * a * a - b, (2.0, -1.0), (0.5, 0.8), rho)
    assert so.mean == pytest.approx(m, rel=1e-9) and so.sigma == pytest.approx(s, rel=1e-7)
    assert so.skewness == pytest.approx(sk, rel=1e-6, abs=1e-9) and so.kurtosis == pytest.approx(ku, rel=1e-6)
    assert not any("left out" in n for n in so.notes)


def test_skewed_factors_odd_moments_by_exact_raw_moments():
    """y = x₁ + 0.4 x₁² − 2 x₂ + 0.5 x₂², x₁ lognormal (median 1, log-σ 0.4: skewness 1.3), x₂ a triangle on [0, 3] with
    its mode at 0.3, shifted by 0.5: a separable quadratic, for which the method of moments is exact.  Reference: E yⁿ
    from the factors' raw moments in closed form — lognormal E[xʲ] = mʲ e^{j²s²/2}; triangle on [a, b], mode c,
    E[xʲ] = 2/((j+1)(j+2)) · (b^{j+2}/((b−a)(b−c)) − c^{j+2}/((c−a)(b−c)) + a^{j+2}/((b−a)(c−a))) — through
    E[g₁ᵏ] = Σ cⱼ E[x₁ʲ] of the polynomial g₁ᵏ (the factors independent), nothing of rvtol's.  The odd moments μ₃, μ₅,
    μ₇ of the factors enter the variance (2ABμ₃) and the skewness: without them the variance is 11 % and the skewness
    40 % low."""
    d1 = Distribution.make("lognormal", median=1.0, shape=0.4)
    d2 = Distribution.make("triangular", lower=0.0, upper=3.0, mode=0.3, shift=0.5)
    spec = ToleranceSpec("s", (Factor("x1", "1", d1), Factor("x2", "1", d2)))
    so = moments_of(spec, "x1 + 0.4*x1**2 - 2*x2 + 0.5*x2**2")
    P = np.polynomial.Polynomial
    a, b, c = 0.5, 3.5, 0.8      # the triangle, shifted
    lognormal = lambda j: math.exp(j * j * 0.4 ** 2 / 2)  # noqa: E731
    triangle = lambda j: 2 / ((j + 1) * (j + 2)) * (b ** (j + 2) / ((b - a) * (b - c)) - c ** (j + 2) / ((c - a) * (b - c))  # noqa: E731
                                                    + a ** (j + 2) / ((b - a) * (c - a)))

    def raw(g, moment, n):   # E[g(x)^n] from the raw moments E[x^j]
        return sum(cj * moment(j) for j, cj in enumerate((g ** n).coef))

    g1, g2 = P([0, 1, 0.4]), P([0, -2, 0.5])
    Ey = [sum(math.comb(n, j) * raw(g1, lognormal, j) * raw(g2, triangle, n - j) for j in range(n + 1))
          for n in range(5)]
    mean = Ey[1]
    c2 = Ey[2] - mean ** 2
    c3 = Ey[3] - 3 * mean * Ey[2] + 2 * mean ** 3
    c4 = Ey[4] - 4 * mean * Ey[3] + 6 * mean ** 2 * Ey[2] - 3 * mean ** 4
    assert so.mean == pytest.approx(mean, rel=1e-9)
    assert so.sigma == pytest.approx(math.sqrt(c2), rel=1e-7)
    assert so.skewness == pytest.approx(c3 / c2 ** 1.5, rel=1e-6)
    assert so.kurtosis == pytest.approx(c4 / c2 ** 2, rel=1e-6)
    assert float(stats.lognorm(0.4).stats(moments="s")) > 1.3     # the factor is skewed indeed
