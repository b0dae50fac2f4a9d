"""Statistics of Monte Carlo outputs, every figure with its confidence interval.

* mean: Student-t interval; std: chi-square interval (normal theory);
* percentiles: distribution-free order-statistic interval (binomial ranks);
  a bound the sample is too small to give is ``None``;
* yield: Clopper–Pearson (exact) or Wilson interval of the binomial proportion;
* Cp/Cpk: normal-theory, with Bissell's interval for Cpk; and the
  percentile ("non-normal") Cpk of ISO 22514-2, with a bootstrap interval.

The intervals shown are two-sided at the stated confidence.  A *bound* (what
a requirement is judged on, :mod:`rvtol.verdict`) is one-sided at a level ℓ:
:func:`proportion_lower_bound` and :func:`cpk_lower_bound`; the lower end of a
two-sided interval at confidence c is the one-sided bound at ℓ = (1 + c)/2.
:func:`n_for_yield` and :func:`n_for_cpk` invert them: the sample size at
which the observed yield or Cpk would be demonstrated.  :func:`combined_lower_bound` adds an
independent error (a fitted law's, :mod:`rvtol.fit_uncertainty`) to a bound; :func:`normality`
gives an output's :class:`Shape` (skewness, kurtosis, Anderson–Darling) for the non-normal Cpk rule of
:mod:`rvtol.verdict`.

:func:`rss` is the root sum of squares of a linear stack — every RSS in rvtol (the linearised
prediction, the stack-up conventions, the stack-up chain's linearisation, the allocation's
constraint) is this one function.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats

#: the percentiles every output reports (in %), including the ±3σ-equivalent ones
PERCENTILES = (0.135, 1.0, 5.0, 50.0, 95.0, 99.0, 99.865)


def rss(terms, correlation=None, *, weights=None, variances=None, axis=None, squared: bool = False,
        skip_nan: bool = False):
    """Root sum of squares of a linear stack's contributions ``c_i`` (a sensitivity times a spread: S_i·σ_i,
    a_i·t_i): √Σ c_i² — the standard deviation of Σ S_i x_i for independent x_i of standard deviations σ_i.

    ``correlation`` R (the factors' correlation matrix): √(cᵀ R c), clipped at 0.  ``weights`` w_i:
    √Σ w_i c_i²; ``variances`` v_i: each term a quantity of mean c_i and variance v_i, √Σ w_i (c_i² + v_i)
    (its root mean square).  ``axis``: sum along this axis of an array of stacks (default: every term);
    ``squared``: the sum of squares itself (a variance budget, not rounded through a square root);
    ``skip_nan``: NaN terms left out (a factor without a derivative).
    """
    c = np.asarray(terms, dtype=float)
    if correlation is not None:
        v = max(float(c @ np.asarray(correlation, dtype=float) @ c), 0.0)
        return v if squared else math.sqrt(v)
    sq = c ** 2
    if variances is not None:
        sq = sq + variances
    if weights is not None:
        sq = weights * sq
    v = (np.nansum if skip_nan else np.sum)(sq, axis=axis)
    if squared:
        return v
    return float(np.sqrt(v)) if axis is None else np.sqrt(v)


def mean_ci(y: np.ndarray, confidence: float = 0.95) -> tuple[float, float, float]:
    n = len(y)
    m = float(np.mean(y))
    if n < 2:
        return m, math.nan, math.nan
    h = stats.t.ppf(0.5 + confidence / 2, n - 1) * np.std(y, ddof=1) / math.sqrt(n)
    return m, m - h, m + h


def std_ci(y: np.ndarray, confidence: float = 0.95) -> tuple[float, float, float]:
    n = len(y)
    if n < 2:
        return math.nan, math.nan, math.nan
    s = float(np.std(y, ddof=1))
    a = 1 - confidence
    lo = s * math.sqrt((n - 1) / stats.chi2.ppf(1 - a / 2, n - 1))
    hi = s * math.sqrt((n - 1) / stats.chi2.ppf(a / 2, n - 1))
    return s, lo, hi


def percentile_ci(y_sorted: np.ndarray, q: float, confidence: float = 0.95):
    """``(estimate, lo, hi)`` of the ``q``-quantile (0..1) from sorted data.

    The interval [y_(l), y_(u)] uses ranks from Binomial(n, q), so it holds
    for any continuous distribution; where a rank falls outside 1..n the bound
    is ``None`` (not enough samples for that tail).
    """
    n = len(y_sorted)
    est = float(np.quantile(y_sorted, q, method="linear")) if n else math.nan
    a = 1 - confidence
    lo_rank = int(stats.binom.ppf(a / 2, n, q))          # y_(lo_rank), 1-based; 0 means none
    hi_rank = int(stats.binom.ppf(1 - a / 2, n, q)) + 1
    lo = float(y_sorted[lo_rank - 1]) if lo_rank >= 1 else None
    hi = float(y_sorted[hi_rank - 1]) if hi_rank <= n else None
    return est, lo, hi


def proportion_ci(k: int, n: int, confidence: float = 0.95, method: str = "exact") -> tuple[float, float]:
    """Clopper–Pearson (``exact``) or ``wilson`` interval of a binomial proportion."""
    if n == 0:
        return math.nan, math.nan
    ci = stats.binomtest(int(k), int(n)).proportion_ci(confidence_level=confidence, method=method)
    return float(ci.low), float(ci.high)


def proportion_lower_bound(k: float, n: float, level: float, method: str = "exact") -> float:
    """One-sided lower confidence bound at ``level`` of a binomial proportion ``k/n``.

    ``exact`` (Clopper–Pearson): the ``1 − level`` quantile of Beta(k, n − k + 1), 0 when k = 0 —
    with no failures it is ``(1 − level)^(1/n)``, the success-run bound; ``wilson``: the lower
    root of the score test at z = Φ⁻¹(level).  ``k`` and ``n`` may be real (sample-size planning).
    """
    if not n > 0:
        return math.nan
    if method == "exact":
        return 0.0 if k <= 0 else float(stats.beta.ppf(1.0 - level, k, n - k + 1.0))
    if method != "wilson":
        raise ValueError(f"unknown proportion interval {method!r}")
    z = float(stats.norm.ppf(level))
    p = k / n
    den = 1.0 + z * z / n
    centre = (p + z * z / (2.0 * n)) / den
    half = z * math.sqrt(max(p * (1.0 - p) / n + z * z / (4.0 * n * n), 0.0)) / den
    return float(max(0.0, centre - half))


def cpk_lower_bound(cpk: float | None, n: float, level: float) -> float | None:
    """Bissell's (1990) one-sided lower bound of Cpk at ``level``: Ĉ − z·√(1/(9n) + Ĉ²/(2(n−1)))."""
    if cpk is None or not n > 1 or not math.isfinite(cpk):
        return None
    z = float(stats.norm.ppf(level))
    return float(cpk - z * math.sqrt(1.0 / (9.0 * n) + cpk**2 / (2.0 * (n - 1.0))))


#: an output is demonstrably not normal when the Anderson–Darling test rejects normality at this level
NON_NORMAL_P = 0.01


@dataclass(frozen=True)
class Shape:
    """How far an output departs from a normal distribution (:func:`normality`): sample skewness,
    excess kurtosis and the Anderson–Darling test of normality (estimated mean and σ; p interpolated from
    Stephens' tables, so 0.01 means ≤ 0.01 and 0.15 ≥ 0.15)."""

    skewness: float
    excess_kurtosis: float
    ad_statistic: float
    ad_pvalue: float

    @property
    def non_normal(self) -> bool:
        return self.ad_pvalue <= NON_NORMAL_P

    def describe(self) -> str:
        p = (f"p ≤ {NON_NORMAL_P:g}" if self.non_normal else
             f"p ≥ {self.ad_pvalue:.2g}" if self.ad_pvalue >= 0.15 else f"p = {self.ad_pvalue:.2g}")
        return (f"skewness {self.skewness:.2f}, excess kurtosis {self.excess_kurtosis:.2f}, "
                f"Anderson–Darling A² = {self.ad_statistic:.3g} ({p})")


def normality(y: np.ndarray) -> Shape | None:
    """The :class:`Shape` of a sample (None below 8 values or with no spread): skewness g₁ = m₃/m₂^1.5 and excess
    kurtosis g₂ = m₄/m₂² − 3 from the central moments mₖ (the biased ratios ``scipy.stats.skew``/``kurtosis``
    give, without their per-call overhead: an optimiser asks for thousands) and the Anderson–Darling test of
    normality with estimated mean and σ (``scipy.stats.anderson``, p interpolated from Stephens' (1974) tables)."""
    y = np.asarray(y, dtype=float)
    if y.size < 8 or not np.ptp(y) > 0:
        return None
    ad = stats.anderson(y, "norm", method="interpolate")
    d = y - y.mean()
    d2 = d * d
    m2 = float(d2.mean())
    return Shape(float((d2 * d).mean()) / m2 ** 1.5, float((d2 * d2).mean()) / m2 ** 2 - 3.0, float(ad.statistic),
                 float(ad.pvalue))


def combined_lower_bound(estimate: float | None, bound: float | None, deviation: float) -> float | None:
    """A lower bound that also carries an independent error whose one-sided deviation at the same level is
    ``deviation``: estimate − √((estimate − bound)² + deviation²).

    Two independent errors, each with its own one-sided deviation d₁ = z·σ₁ and d₂ = z·σ₂ at level ℓ (z = Φ⁻¹(ℓ)),
    add to one of deviation z·√(σ₁² + σ₂²) = √(d₁² + d₂²) when both are normal — the root-sum-square of
    deviations of the GUM (JCGM 100:2008, §5.1.2, uncorrelated inputs).  Each deviation keeps its own
    (possibly skewed) form — the bound's own, e.g. Clopper–Pearson's; the result is the bound itself at
    ``deviation = 0`` and estimate − ``deviation`` for an exact estimate."""
    if estimate is None or bound is None or not math.isfinite(estimate) or not math.isfinite(bound):
        return bound
    d = max(0.0, estimate - bound)
    return float(estimate - math.sqrt(d * d + max(0.0, deviation) ** 2))


#: the largest sample size the planning functions look at
N_PLAN_MAX = 1e15


def smallest_integer(ok, guess: int, low: int, high: int) -> int:
    """The smallest integer n in [low, high] with ``ok(n)``, for ``ok`` false below some n and true from there on
    (``ok(high)`` holds), looked for from ``guess`` (a continuous root's ceiling): two calls when the guess is the
    answer, else bisection — O(log(high − low)) calls where stepping one integer at a time from a rounded root
    took minutes at plans of 10¹² samples, whose bounds differ between neighbours by less than rounding."""
    n = min(max(guess, low), high)
    if ok(n):
        if n == low or not ok(n - 1):
            return n
        below, above = low - 1, n - 1          # ok(above); every n <= below is out of range
    else:
        below, above = n, high                 # not ok(below), ok(above)
    while above - below > 1:
        mid = (below + above) // 2
        if ok(mid):
            above = mid
        else:
            below = mid
    return above


def n_for_yield(estimate: float, required: float, level: float, method: str = "exact") -> int | None:
    """Smallest n whose lower bound at ``level`` reaches ``required`` if the yield stays at ``estimate``.

    ``None`` when the estimate itself does not exceed the requirement (no n demonstrates it).
    With no observed failures (``estimate = 1``, Clopper–Pearson) this is the success-run
    sample size ⌈ln(1 − level) / ln(required)⌉.
    """
    if not (estimate > required) or required <= 0.0:
        return None
    if required >= 1.0:
        return None

    def gap(log_n: float) -> float:
        n = math.exp(log_n)
        return proportion_lower_bound(estimate * n, n, level, method) - required

    lo, hi = 0.0, math.log(N_PLAN_MAX)
    if gap(hi) < 0:
        return None
    if gap(lo) >= 0:
        return 1
    from scipy.optimize import brentq

    guess = math.ceil(math.exp(brentq(gap, lo, hi, xtol=1e-12)))
    return smallest_integer(lambda n: gap(math.log(n)) >= 0, guess, 1, int(N_PLAN_MAX))


def n_for_cpk(cpk: float | None, required: float, level: float) -> int | None:
    """Smallest n whose Bissell lower bound at ``level`` reaches ``required`` if Cpk stays at ``cpk``.

    The inverse of :func:`cpk_lower_bound` in n; ``None`` when ``cpk`` does not exceed ``required``.
    """
    if cpk is None or not math.isfinite(cpk) or not cpk > required:
        return None

    def gap(n: float) -> float:
        return cpk_lower_bound(cpk, n, level) - required

    if gap(N_PLAN_MAX) < 0:
        return None
    from scipy.optimize import brentq

    guess = math.ceil(brentq(gap, 1.0 + 1e-9, N_PLAN_MAX, xtol=1e-9))
    return smallest_integer(lambda n: gap(n) >= 0, guess, 2, int(N_PLAN_MAX))


def capability(y: np.ndarray, lower: float | None, upper: float | None,
               confidence: float = 0.95) -> dict:
    """Cp (two-sided only), Cpk with Bissell's interval, and the percentile Cpk."""
    n = len(y)
    out = dict(cp=None, cpk=None, cpk_lo=None, cpk_hi=None, cpk_percentile=None)
    if n < 2:
        return out
    mu, s = float(np.mean(y)), float(np.std(y, ddof=1))
    if s > 0:
        sides = []
        if upper is not None:
            sides.append((upper - mu) / (3 * s))
        if lower is not None:
            sides.append((mu - lower) / (3 * s))
        cpk = min(sides)
        if lower is not None and upper is not None:
            out["cp"] = float((upper - lower) / (6 * s))
        z = stats.norm.ppf(0.5 + confidence / 2)
        h = z * math.sqrt(1 / (9 * n) + cpk**2 / (2 * (n - 1)))
        out.update(cpk=float(cpk), cpk_lo=float(cpk - h), cpk_hi=float(cpk + h))
    out["cpk_percentile"] = percentile_cpk(y, lower, upper)
    return out


#: the quantiles of the percentile ("non-normal") Cpk of ISO 22514-2
CPK_QUANTILES = (0.00135, 0.5, 0.99865)


def _cpk_from_quantiles(p_lo, med, p_hi, lower: float | None, upper: float | None) -> np.ndarray:
    """Percentile Cpk from the quantiles (arrays broadcast); NaN where no side is defined."""
    p_lo, med, p_hi = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (p_lo, med, p_hi)))
    out = np.full(med.shape, np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        if upper is not None:
            out = np.where(p_hi > med, np.minimum(out, (upper - med) / (p_hi - med)), out)
        if lower is not None:
            out = np.where(med > p_lo, np.minimum(out, (med - lower) / (med - p_lo)), out)
    return np.where(np.isinf(out), np.nan, out)


def percentile_cpk(y: np.ndarray, lower: float | None, upper: float | None) -> float | None:
    """ISO 22514-2 style Cpk from the 0.135 %, 50 % and 99.865 % points (any distribution; ``y`` in any
    order: the quantiles are found by partial sorting, O(n))."""
    v = float(_cpk_from_quantiles(*np.quantile(y, CPK_QUANTILES), lower, upper))
    return v if math.isfinite(v) else None


def bootstrap_quantiles(y_sorted: np.ndarray, qs, n_boot: int = 200, seed: int = 0) -> np.ndarray:
    """``[n_boot, len(qs)]``: the ``qs``-quantiles (NumPy's "linear" definition) of ``n_boot`` bootstrap
    resamples of the sorted sample ``y_sorted``, drawn without forming the resamples.

    A resample is n draws from the empirical distribution F_n, so its k-th order statistic is
    F_n⁻¹(U_(k)) = y_(⌈n U_(k)⌉), U_(k) the k-th order statistic of n uniforms; the order statistics of
    uniforms at ranks r₁ < … < r_m are jointly the partial sums of a Dirichlet(r₁, r₂ − r₁, …,
    n + 1 − r_m) vector (spacings of uniform order statistics).  A quantile at position h = (n − 1) q
    interpolates the order statistics at ranks ⌊h⌋ + 1 and ⌊h⌋ + 2.  Exact in distribution, O(m) per
    resample instead of O(n).
    """
    y = np.asarray(y_sorted, dtype=float)
    n = len(y)
    h = (n - 1) * np.asarray(qs, dtype=float)
    lo = np.floor(h).astype(np.int64)
    frac = h - lo
    ranks = np.unique(np.concatenate([lo + 1, np.minimum(lo + 2, n)]))      # 1-based
    alpha = np.diff(np.concatenate([[0], ranks, [n + 1]])).astype(float)
    from .sampling import rng

    g = rng(seed).gamma(alpha, size=(n_boot, alpha.size))
    u = np.cumsum(g, axis=1)[:, :-1] / g.sum(axis=1, keepdims=True)        # U_(r) for each rank
    values = y[np.clip(np.ceil(n * u).astype(np.int64) - 1, 0, n - 1)]     # resample order statistics
    at = {r: values[:, i] for i, r in enumerate(ranks)}
    out = np.empty((n_boot, len(h)))
    for j, (l0, f) in enumerate(zip(lo, frac)):
        a = at[l0 + 1]
        b = at[min(l0 + 2, n)]
        out[:, j] = a + f * (b - a)
    return out


def percentile_cpk_ci(y_sorted: np.ndarray, lower: float | None, upper: float | None, confidence: float = 0.95,
                      n_boot: int = 200, seed: int = 0) -> tuple[float | None, float | None]:
    """Percentile bootstrap interval of :func:`percentile_cpk` (fixed seed: reproducible), the resamples'
    quantiles drawn by :func:`bootstrap_quantiles` (O(n_boot), whatever n)."""
    q = bootstrap_quantiles(y_sorted, CPK_QUANTILES, n_boot, seed)
    vals = _cpk_from_quantiles(q[:, 0], q[:, 1], q[:, 2], lower, upper)
    vals = vals[np.isfinite(vals)]
    if len(vals) < n_boot // 2:
        return None, None
    a = 1 - confidence
    return float(np.quantile(vals, a / 2)), float(np.quantile(vals, 1 - a / 2))


def bootstrap_ci(y: np.ndarray, statistic, confidence: float = 0.95, n_boot: int = 200,
                 seed: int = 0) -> tuple[float | None, float | None]:
    """Percentile bootstrap interval of ``statistic(resample)`` (fixed seed: reproducible), by resampling:
    O(n) per resample (the reference :func:`percentile_cpk_ci` is tested against)."""
    from .sampling import rng

    g = rng(seed)
    vals = []
    for _ in range(n_boot):
        v = statistic(g.choice(y, size=len(y), replace=True))
        if v is not None and np.isfinite(v):
            vals.append(v)
    if len(vals) < n_boot // 2:
        return None, None
    a = 1 - confidence
    return float(np.quantile(vals, a / 2)), float(np.quantile(vals, 1 - a / 2))


@dataclass(frozen=True)
class YieldResult:
    n: int
    conforming: int
    estimate: float
    lo: float
    hi: float

    @property
    def ppm(self) -> float:
        return (1 - self.estimate) * 1e6

    @property
    def ppm_ci(self) -> tuple[float, float]:
        return (1 - self.hi) * 1e6, (1 - self.lo) * 1e6


def conforming(y: np.ndarray, ok: np.ndarray, lower: float | None, upper: float | None) -> np.ndarray:
    """Which samples conform: evaluated (``ok``) and within [``lower``, ``upper``] (a missing limit: no limit)."""
    inside = np.array(ok, dtype=bool)
    if lower is not None:
        inside &= np.nan_to_num(y, nan=-np.inf) >= lower
    if upper is not None:
        inside &= np.nan_to_num(y, nan=np.inf) <= upper
    return inside


def yield_of(y: np.ndarray, ok: np.ndarray, lower: float | None, upper: float | None,
             confidence: float = 0.95, method: str = "exact") -> YieldResult:
    """Yield over *all* samples: a sample the model could not evaluate counts as non-conforming."""
    k, n = int(conforming(y, ok, lower, upper).sum()), len(y)
    lo, hi = proportion_ci(k, n, confidence, method)
    return YieldResult(n, k, k / n if n else math.nan, lo, hi)


def convergence_trace(y: np.ndarray, ok: np.ndarray, limits: list[tuple[float | None, float | None]],
                      points: int = 60, confidence: float = 0.95) -> dict[str, np.ndarray]:
    """Running mean (with its CI) and running yields at log-spaced sample counts.  At a count with no evaluated
    sample the mean is NaN (not 0), and its interval is NaN until two are evaluated (one value has no spread to
    show, not a zero one)."""
    n = len(y)
    ns = np.unique(np.geomspace(min(10, n), n, points).astype(int))
    yv = np.where(ok, y, 0.0)
    c1 = np.cumsum(yv)
    c2 = np.cumsum(yv * yv)
    cn = np.cumsum(ok)
    k = cn[ns - 1]
    m = np.where(k > 0, c1[ns - 1] / np.maximum(k, 1), np.nan)
    var = np.where(k > 1, np.maximum(c2[ns - 1] / np.maximum(k, 1) - m * m, 0) * k / np.maximum(k - 1, 1), np.nan)
    z = stats.norm.ppf(0.5 + confidence / 2)
    half = z * np.sqrt(var / np.maximum(k, 1))
    out = {"n": ns, "mean": m, "mean_lo": m - half, "mean_hi": m + half}
    for i, (lo, hi) in enumerate(limits):
        inside = ok.copy()
        if lo is not None:
            inside &= np.nan_to_num(y, nan=-np.inf) >= lo
        if hi is not None:
            inside &= np.nan_to_num(y, nan=np.inf) <= hi
        out[f"yield_{i}"] = np.cumsum(inside)[ns - 1] / ns
    return out
