"""Second-order tolerance analysis: the mean shift, skewness and kurtosis of a non-linear output by the method
of moments, and its tails from a Pearson (or Johnson) curve with those four moments.

The linearised conventions read y ≈ y(μ) + Σ aᵢ dᵢ (dᵢ = xᵢ − μᵢ): a symmetric output centred on y(μ).
A curved output is neither: its mean shifts by ½ Σ Hᵢᵢ σᵢ² and its distribution is skewed.  Following
the second-order method of Glancy & Chase (1999; Evans 1974 for the moments of a Taylor series), the
output is expanded to second order about the factors' means,

    y ≈ y(μ) + Σᵢ (aᵢ dᵢ + ½ Hᵢᵢ dᵢ²) + Σᵢ<ⱼ Hᵢⱼ dᵢ dⱼ,

with a and H by central differences of the model (steps of σᵢ/2: a curvature read over the factors' own
spread), and its first four moments taken from each factor's standardised moments μₙ = E[zⁿ], n ≤ 8
(quadrature of the factor's inverse CDF over its normal score, :func:`standard_moments`), for independent
factors:

* each separable term gᵢ(z) = Aᵢ z + Bᵢ z² (Aᵢ = aᵢσᵢ, Bᵢ = ½Hᵢᵢσᵢ²) has raw moments
  E g = B, E g² = A² + 2ABμ₃ + B²μ₄, E g³ = A³μ₃ + 3A²Bμ₄ + 3AB²μ₅ + B³μ₆,
  E g⁴ = A⁴μ₄ + 4A³Bμ₅ + 6A²B²μ₆ + 4AB³μ₇ + B⁴μ₈, whose cumulants add over the factors;
* the cross terms add Σ Hᵢⱼ² σᵢ²σⱼ² to the variance (exactly) and 6 Σ Hᵢⱼ cᵢ cⱼ to the third cumulant
  (cᵢ = E[gᵢ dᵢ] = σᵢ(Aᵢ + Bᵢμ₃ᵢ)), the leading term; their other contributions to the third and fourth
  cumulants (quadratic and cubic in Hᵢⱼ) are left out — exact for separable outputs, an approximation
  otherwise (said in the result);
* where every factor the output depends on is normal, the expansion is a quadratic form of normals and its
  cumulants are exact, cross terms included: with w the standardised factors, y = y(μ) + bᵀw + wᵀQw
  (b = σ∘a, Q = ½ diag(σ) H diag(σ)), κ₁ = tr Q and κ_r = 2^(r−1)(r−1)! tr Q^r + 2^(r−3) r! bᵀQ^(r−2)b
  (A. M. Mathai and S. B. Provost, *Quadratic Forms in Random Variables*, Dekker 1992, ch. 3).

Correlation.  Correlated normal factors are written as independent standard normals v through the Cholesky
factor of their correlation, w = L v (b → Lᵀb, 2Q → Lᵀ(2Q)L): the moments stay exact.  Correlated factors that
are not all normal have no closed form under the Gaussian copula: their covariance (Pearson's, from the copula:
:func:`rvtol.sampling.factor_correlation`) enters the mean (½ Σ Hᵢⱼ Cov ᵢⱼ, exact) and the linear
part of the variance (aᵀ Cov a), the rest takes them as independent — exact mean and σ for an output linear in
them; the row's note says which.

The mean, σ, skewness √β₁ and kurtosis β₂ select a member of Pearson's system
(:func:`rvtol.distributions.pearson_frozen`; Pearson type IV, which no library here implements, by a
Johnson SU curve with the same four moments instead), whose quantiles give the interval at ±z σ-coverage
and the fraction beyond a limit.  A kink at the means (a centred position zone) has no second-order
expansion: the method says so and gives nothing.

References.  D. H. Evans, "Statistical tolerancing: the state of the art, part II. Methods for estimating
moments", J. Quality Technology 7 (1975) 1–12; C. G. Glancy and K. W. Chase, "A second-order method for
assembly tolerance analysis", Proc. ASME DETC 1999, DAC-8707; E. T. Fortini, *Dimensioning for
Interchangeable Manufacture*, Industrial Press 1967 (the one-way clutch example of non-linear stacks).
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np
from scipy import integrate, optimize, special, stats

from ..distributions import coverage, pearson_frozen
from ..mc import Evaluator
from ..model import Model
from ..spec import ToleranceSpec
from ..stats import rss
from ..sampling import factor_correlation


@dataclass
class SecondOrder:
    """The output's first four moments from its second-order expansion (base units) and the fitted tail law."""

    y_at_means: float
    mean: float
    sigma: float
    skewness: float
    kurtosis: float            # β₂ (3 for a normal)
    law: str                   # "Pearson I" … "Johnson SU"
    frozen: object = None      # scipy-like frozen law of the output
    evaluations: int = 0
    notes: list = field(default_factory=list)          # what the moments take as they are (read with them)
    tail_notes: list = field(default_factory=list)     # what the fitted curve changed
    curved: bool = False       # the expansion has curvature (a Hessian entry above the differences' noise)

    @property
    def mean_shift(self) -> float:
        return self.mean - self.y_at_means

    def interval(self, z: float) -> tuple[float, float]:
        """The central interval with the coverage of ±z σ of a normal, from the fitted law."""
        c = coverage(z)
        return float(self.frozen.ppf(0.5 * (1 - c))), float(self.frozen.ppf(0.5 * (1 + c)))

    def beyond(self, lower: float | None = None, upper: float | None = None) -> float:
        """P(y < lower) + P(y > upper) under the fitted law."""
        p = 0.0
        if lower is not None:
            p += float(self.frozen.cdf(lower))
        if upper is not None:
            p += float(self.frozen.sf(upper)) if hasattr(self.frozen, "sf") else 1.0 - float(self.frozen.cdf(upper))
        return p


def factor_moments(dist) -> dict[int, float]:
    """:func:`standard_moments` of orders 3…8, kept per distribution (one quadrature per factor, however many outputs
    are expanded)."""
    try:
        return dict(_kept_moments(dist))
    except TypeError:             # a law that cannot be a key (unhashable): computed each time
        return standard_moments(dist)


@functools.lru_cache(maxsize=1024)
def _kept_moments(dist) -> tuple:
    return tuple(standard_moments(dist).items())


def standard_moments(dist, orders=range(3, 9)) -> dict[int, float]:
    """E[zⁿ] of z = (x − μ)/σ for a factor's distribution, every order from one adaptive Gauss–Kronrod quadrature
    (:func:`scipy.integrate.quad_vec`, relative tolerance 1e-12) over its normal score s:
    E[zⁿ] = ∫ ((x(s) − μ)/σ)ⁿ φ(s) ds, x(s) = F⁻¹(Φ(s)) (by the survival function's inverse above the median, so
    the upper tail keeps its digits) — the transform the sampling uses, smooth where F is; a weight φ(s) below
    1e-300 (|s| > 37) adds nothing."""
    mu, sd = float(dist.mean), float(dist.std)
    fr = getattr(dist, "frozen", dist)
    n = np.array(list(orders), dtype=float)
    isf = getattr(fr, "isf", None)

    def x_of(s):
        if s > 0 and isf is not None:
            return float(isf(special.ndtr(-s)))
        return float(fr.ppf(special.ndtr(s)))

    def integrand(s):
        if abs(s) > 37.0:
            return np.zeros(len(n))
        return ((x_of(s) - mu) / sd) ** n * (math.exp(-0.5 * s * s) / math.sqrt(2.0 * math.pi))

    values, _ = integrate.quad_vec(integrand, -np.inf, np.inf, epsabs=0.0, epsrel=1e-12, limit=500)
    return {int(k): float(v) for k, v in zip(n, values)}


def curvature(model: Model, spec: ToleranceSpec, output: str, x0: np.ndarray | None = None,
              evaluate: Evaluator | None = None, *, step: float = 0.5) -> tuple[float, np.ndarray, np.ndarray, int]:
    """``(y(x0), gradient, Hessian, evaluations)`` of ``output`` at ``x0`` (default: the factors' means) by central
    differences with steps of ``step``·σᵢ (base units)."""
    evaluate = evaluate or Evaluator()
    j = model.output_index(output)
    x0 = spec.mean_base() if x0 is None else np.asarray(x0, dtype=float)
    k = len(spec)
    h = step * spec.std_base()
    rows = [x0]
    for i in range(k):
        for s in (1, -1):
            x = x0.copy()
            x[i] += s * h[i]
            rows.append(x)
    pairs = [(i, m) for i in range(k) for m in range(i + 1, k)]
    for i, m in pairs:
        for si, sm in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
            x = x0.copy()
            x[i] += si * h[i]
            x[m] += sm * h[m]
            rows.append(x)
    ev = evaluate(model, np.array(rows), "second-order expansion")
    y = np.where(ev.ok, ev.Y[:, j], np.nan)
    y0 = y[0]
    g = np.empty(k)
    H = np.zeros((k, k))
    for i in range(k):
        up, dn = y[1 + 2 * i], y[2 + 2 * i]
        g[i] = (up - dn) / (2 * h[i])
        H[i, i] = (up - 2 * y0 + dn) / h[i] ** 2
    r = 1 + 2 * k
    for i, m in pairs:
        pp, pm, mp, mm = y[r:r + 4]
        r += 4
        H[i, m] = H[m, i] = (pp - pm - mp + mm) / (4 * h[i] * h[m])
    return float(y0), g, H, len(rows)


#: E[zⁿ], n = 3 … 8, of a standard normal
NORMAL_MOMENTS = {3: 0.0, 4: 3.0, 5: 0.0, 6: 15.0, 7: 0.0, 8: 105.0}


def second_order(spec: ToleranceSpec, y0: float, gradient: np.ndarray, hessian: np.ndarray) -> SecondOrder:
    """The four moments and the tail law of the expansion about the means (module docstring); base units."""
    a = np.asarray(gradient, dtype=float)
    H = np.asarray(hessian, dtype=float)
    notes = []
    if not (math.isfinite(y0) and np.all(np.isfinite(a)) and np.all(np.isfinite(H))):
        raise ValueError("the model could not be evaluated around the means: no second-order expansion")
    sd = spec.std_base()
    k = len(spec)
    # curvature below the differences' rounding (1e-9 of the linear spread) is noise, not curvature
    lin = rss(a * sd) or 1.0
    H = np.where(np.abs(H) * np.outer(sd, sd) <= 1e-9 * lin, 0.0, H)
    # the expansion in the standardised factors w = (x − μ)/σ: y = y(μ) + bᵀw + ½ wᵀMw
    b, M = a * sd, H * np.outer(sd, sd)
    normal = [f.dist.kind == "normal" for f in spec.factors]
    R = spec.correlation
    correlated = [] if R is None else [i for i in range(k) if np.any(np.delete(np.asarray(R)[i], i) != 0.0)]
    pearson = None
    if correlated and all(normal[i] for i in correlated):
        # correlated normals: w_N = L v_N (L L^T = R_NN), v_N independent standard normals
        T = np.eye(k)
        T[np.ix_(correlated, correlated)] = np.linalg.cholesky(np.asarray(R)[np.ix_(correlated, correlated)])
        b, M = T.T @ b, T.T @ M @ T
        notes.append(NOTE_CORRELATED_NORMALS)
    elif correlated:
        pearson = factor_correlation(spec)
    active = [i for i in range(k) if b[i] != 0.0 or np.any(M[i] != 0.0)]
    if all(normal[i] for i in active):
        K = _normal_quadratic_cumulants(b, M)
    else:
        K, cross = _independent_cumulants(b, M, [None if normal[i] else spec.factors[i].dist for i in range(k)])
        if cross:
            notes.append("off-diagonal curvature enters the variance exactly and the third cumulant to leading order; "
                         "its other third- and fourth-order terms are left out")
    if pearson is not None:
        # their covariance (Pearson's, of the copula) in the mean ½ Σ M_ij P_ij and the linear variance bᵀPb
        off = pearson - np.eye(k)
        K[1] += 0.5 * float(np.sum(M * off))
        K[2] += float(b @ off @ b)
        curved = [i for i in correlated if np.any(M[i] != 0.0)]
        names = ", ".join(spec.names[i] for i in correlated)
        notes.append(NOTE_CORRELATED_OTHERS.format(names=names) + (
            NOTE_CORRELATED_CURVED.format(names=", ".join(spec.names[i] for i in curved)) if curved
            else NOTE_CORRELATED_LINEAR))
    mean, var = y0 + K[1], K[2]
    if not var > 0:
        raise ValueError("the output does not vary to second order")
    s = math.sqrt(var)
    skew, kurt = K[3] / s ** 3, 3.0 + K[4] / var ** 2
    tail_notes: list[str] = []
    law, frozen = _tail_law(mean, s, skew, kurt, tail_notes)
    return SecondOrder(y0, mean, s, skew, kurt, law, frozen, notes=notes, tail_notes=tail_notes,
                       curved=bool(np.any(H != 0.0)))


NOTE_CORRELATED_NORMALS = "the spec's correlation included (correlated normal factors: exact)"
NOTE_CORRELATED_OTHERS = ("correlated factors not all normal ({names}): their covariance (Pearson's, of the Gaussian "
                          "copula) enters the mean and the linear part of the variance")
NOTE_CORRELATED_LINEAR = "; the skewness and kurtosis take them as independent"
NOTE_CORRELATED_CURVED = ("; the curvature's share of the variance, the skewness and the kurtosis take them as "
                          "independent (σ approximate: {names} curved)")


def _normal_quadratic_cumulants(b: np.ndarray, M: np.ndarray) -> np.ndarray:
    """Cumulants 1…4 of bᵀv + vᵀQv (Q = ½M) for independent standard normals v, exact:
    κ₁ = tr Q, κ_r = 2^(r−1) (r−1)! tr Q^r + 2^(r−3) r! bᵀQ^(r−2) b (r ≥ 2) [Mathai & Provost 1992, ch. 3]."""
    Q = 0.5 * M
    K = np.zeros(5)
    K[1] = float(np.trace(Q))
    Qp = np.eye(len(b))      # Q^(r−2)
    for r in (2, 3, 4):
        K[r] = (2 ** (r - 1) * math.factorial(r - 1) * float(np.trace(np.linalg.matrix_power(Q, r)))
                + 2.0 ** (r - 3) * math.factorial(r) * float(b @ Qp @ b))
        Qp = Qp @ Q
    return K


def _independent_cumulants(b: np.ndarray, M: np.ndarray, dists) -> tuple[np.ndarray, bool]:
    """Cumulants 1…4 of bᵀw + ½ wᵀMw for independent standardised factors w (``dists[i]``: the factor's law, None for
    a standard normal), separable terms exact, cross terms to leading order (module docstring); and whether there
    were cross terms."""
    k = len(b)
    K = np.zeros(5)
    c = np.zeros(k)
    for i in range(k):
        A, B = b[i], 0.5 * M[i, i]
        if A == 0.0 and B == 0.0:
            continue
        mu = {1: 0.0, 2: 1.0, **(NORMAL_MOMENTS if dists[i] is None else factor_moments(dists[i]))}
        m1 = B
        m2 = A * A + 2 * A * B * mu[3] + B * B * mu[4]
        m3 = A ** 3 * mu[3] + 3 * A * A * B * mu[4] + 3 * A * B * B * mu[5] + B ** 3 * mu[6]
        m4 = (A ** 4 * mu[4] + 4 * A ** 3 * B * mu[5] + 6 * A * A * B * B * mu[6] + 4 * A * B ** 3 * mu[7]
              + B ** 4 * mu[8])
        K[1] += m1
        K[2] += m2 - m1 ** 2
        K[3] += m3 - 3 * m2 * m1 + 2 * m1 ** 3
        K[4] += m4 - 4 * m3 * m1 - 3 * m2 ** 2 + 12 * m2 * m1 ** 2 - 6 * m1 ** 4
        c[i] = A + B * mu[3]
    cross = False
    for i in range(k):
        for m in range(i + 1, k):
            if M[i, m] != 0.0:
                cross = True
                K[2] += M[i, m] ** 2
                K[3] += 6.0 * M[i, m] * c[i] * c[m]
    return K, cross


def _tail_law(mean, sd, skew, kurt, notes):
    if kurt <= skew * skew + 1.0:   # impossible moments (the truncated expansion): the nearest admissible
        notes.append(f"the expansion's kurtosis {kurt:.4g} is below skewness² + 1: raised to the bound")
        kurt = skew * skew + 1.0 + 1e-6
    try:
        t, f = pearson_frozen(mean, sd, skew, kurt)
        return f"Pearson {t}", f
    except ValueError:
        pass
    # Pearson IV: Johnson SU with the same four moments (Johnson 1949; moments by scipy)
    def res(v):
        s_, k_ = stats.johnsonsu(v[0], math.exp(v[1])).stats(moments="sk")
        return [float(s_) - skew, float(k_) + 3.0 - kurt]

    sol = optimize.least_squares(res, [-skew, 0.5], xtol=1e-12, ftol=1e-12)
    g, d = sol.x[0], math.exp(sol.x[1])
    base = stats.johnsonsu(g, d)
    m, v = (float(x) for x in base.stats(moments="mv"))
    sc = sd / math.sqrt(v)
    notes.append("Pearson type IV (no implementation here): the tails are a Johnson SU curve with the same moments")
    return "Johnson SU", stats.johnsonsu(g, d, loc=mean - m * sc, scale=sc)
