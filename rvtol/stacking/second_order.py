"""Second-order tolerance analysis: the mean shift, skewness and kurtosis of a non-linear output by the method
of moments, and its tails from a Pearson (or Johnson) curve with those four moments.

The linearised conventions read y ≈ y(μ) + Σ aᵢ dᵢ (dᵢ = xᵢ − μᵢ): a symmetric output centred on y(μ).
A curved output is neither: its mean shifts by ½ Σ Hᵢᵢ σᵢ² and its distribution is skewed.  Following
the second-order method of Glancy & Chase (1999; Evans 1974 for the moments of a Taylor series), the
output is expanded to second order about the factors' means,

    y ≈ y(μ) + Σᵢ (aᵢ dᵢ + ½ Hᵢᵢ dᵢ²) + Σᵢ<ⱼ Hᵢⱼ dᵢ dⱼ,

with a and H by central differences of the model (steps of σᵢ/2: a curvature read over the factors' own
spread), and its first four moments taken from each factor's standardised moments μₙ = E[zⁿ], n ≤ 8
(scipy, or quadrature of the factor's inverse CDF), for independent factors:

* each separable term gᵢ(z) = Aᵢ z + Bᵢ z² (Aᵢ = aᵢσᵢ, Bᵢ = ½Hᵢᵢσᵢ²) has raw moments
  E g = B, E g² = A² + 2ABμ₃ + B²μ₄, E g³ = A³μ₃ + 3A²Bμ₄ + 3AB²μ₅ + B³μ₆,
  E g⁴ = A⁴μ₄ + 4A³Bμ₅ + 6A²B²μ₆ + 4AB³μ₇ + B⁴μ₈, whose cumulants add over the factors;
* the cross terms add Σ Hᵢⱼ² σᵢ²σⱼ² to the variance (exactly) and 6 Σ Hᵢⱼ cᵢ cⱼ to the third cumulant
  (cᵢ = E[gᵢ dᵢ] = σᵢ(Aᵢ + Bᵢμ₃ᵢ)), the leading term; their other contributions to the third and fourth
  cumulants (quadratic and cubic in Hᵢⱼ) are left out — exact for separable outputs and for a product of
  two normal factors, an approximation otherwise (said in the result).

The mean, σ, skewness √β₁ and kurtosis β₂ select a member of Pearson's system
(:func:`rvtol.distributions.pearson_frozen`; Pearson type IV, which no library here implements, by a
Johnson SU curve with the same four moments instead), whose quantiles give the interval at ±z σ-coverage
and the fraction beyond a limit.  Correlated factors are read as independent here (said); a kink at the
means (a centred position zone) has no second-order expansion: the method says so and gives nothing.

References.  D. H. Evans, "Statistical tolerancing: the state of the art, part II. Methods for estimating
moments", J. Quality Technology 7 (1975) 1–12; C. G. Glancy and K. W. Chase, "A second-order method for
assembly tolerance analysis", Proc. ASME DETC 1999, DAC-8707; E. T. Fortini, *Dimensioning for
Interchangeable Manufacture*, Industrial Press 1967 (the one-way clutch example of non-linear stacks).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import integrate, optimize, stats

from ..distributions import coverage, pearson_frozen
from ..mc import Evaluator
from ..model import Model
from ..spec import ToleranceSpec
from ..stats import rss


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
    notes: list = field(default_factory=list)

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


def standard_moments(dist, orders=range(3, 9)) -> dict[int, float]:
    """E[zⁿ] of z = (x − μ)/σ for a factor's distribution: scipy's ``expect`` where it has one, else quadrature of
    the inverse CDF over u ∈ (0, 1)."""
    mu, sd = float(dist.mean), float(dist.std)
    fr = getattr(dist, "frozen", dist)
    out = {}
    for n in orders:
        f = lambda x, n=n: ((x - mu) / sd) ** n  # noqa: E731
        if hasattr(fr, "expect"):
            v = float(fr.expect(f))
        else:
            v = integrate.quad(lambda u: f(float(dist.ppf(u))), 0.0, 1.0, limit=200)[0]
        out[n] = v
    return out


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
    K = np.zeros(5)    # cumulants 1..4
    c = np.zeros(k)
    for i in range(k):
        A, B = a[i] * sd[i], 0.5 * H[i, i] * sd[i] ** 2
        if A == 0.0 and B == 0.0:
            continue
        mu = {1: 0.0, 2: 1.0, **standard_moments(spec.factors[i].dist)}
        m1 = B
        m2 = A * A + 2 * A * B * mu[3] + B * B * mu[4]
        m3 = A ** 3 * mu[3] + 3 * A * A * B * mu[4] + 3 * A * B * B * mu[5] + B ** 3 * mu[6]
        m4 = (A ** 4 * mu[4] + 4 * A ** 3 * B * mu[5] + 6 * A * A * B * B * mu[6] + 4 * A * B ** 3 * mu[7]
              + B ** 4 * mu[8])
        K[1] += m1
        K[2] += m2 - m1 ** 2
        K[3] += m3 - 3 * m2 * m1 + 2 * m1 ** 3
        K[4] += m4 - 4 * m3 * m1 - 3 * m2 ** 2 + 12 * m2 * m1 ** 2 - 6 * m1 ** 4
        c[i] = sd[i] * (A + B * mu[3])
    cross = False
    for i in range(k):
        for m in range(i + 1, k):
            if H[i, m] != 0.0:
                cross = True
                K[2] += H[i, m] ** 2 * sd[i] ** 2 * sd[m] ** 2
                K[3] += 6.0 * H[i, m] * c[i] * c[m]
    if cross:
        notes.append("off-diagonal curvature enters the variance exactly and the third cumulant to leading order; "
                     "its other third- and fourth-order terms are left out")
    if spec.correlation is not None:
        notes.append("the spec's correlation is not used: the moments assume independent factors")
    mean, var = y0 + K[1], K[2]
    if not var > 0:
        raise ValueError("the output does not vary to second order")
    s = math.sqrt(var)
    skew, kurt = K[3] / s ** 3, 3.0 + K[4] / var ** 2
    law, frozen = _tail_law(mean, s, skew, kurt, notes)
    return SecondOrder(y0, mean, s, skew, kurt, law, frozen, notes=notes)


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
