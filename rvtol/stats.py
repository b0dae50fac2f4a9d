"""Statistics of Monte Carlo outputs, every figure with its confidence interval.

* mean: Student-t interval; std: chi-square interval (normal theory);
* percentiles: distribution-free order-statistic interval (binomial ranks);
  a bound the sample is too small to give is ``None``;
* yield: Clopper–Pearson (exact) or Wilson interval of the binomial proportion;
* Cp/Cpk: normal-theory, with Bissell's interval for Cpk; and the
  percentile ("non-normal") Cpk of ISO 22514-2, with a bootstrap interval.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats

#: the percentiles every output reports (in %), including the ±3σ-equivalent ones
PERCENTILES = (0.135, 1.0, 5.0, 50.0, 95.0, 99.0, 99.865)


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


def yield_of(y: np.ndarray, ok: np.ndarray, lower: float | None, upper: float | None,
             confidence: float = 0.95, method: str = "exact") -> YieldResult:
    """Yield over *all* samples: a sample the model could not evaluate counts as non-conforming."""
    inside = ok.copy()
    if lower is not None:
        inside &= np.nan_to_num(y, nan=-np.inf) >= lower
    if upper is not None:
        inside &= np.nan_to_num(y, nan=np.inf) <= upper
    k, n = int(inside.sum()), len(y)
    lo, hi = proportion_ci(k, n, confidence, method)
    return YieldResult(n, k, k / n if n else math.nan, lo, hi)


def convergence_trace(y: np.ndarray, ok: np.ndarray, limits: list[tuple[float | None, float | None]],
                      points: int = 60, confidence: float = 0.95) -> dict[str, np.ndarray]:
    """Running mean (with its CI) and running yields at log-spaced sample counts."""
    n = len(y)
    ns = np.unique(np.geomspace(min(10, n), n, points).astype(int))
    yv = np.where(ok, y, 0.0)
    c1 = np.cumsum(yv)
    c2 = np.cumsum(yv * yv)
    cn = np.cumsum(ok)
    m = c1[ns - 1] / np.maximum(cn[ns - 1], 1)
    var = np.maximum(c2[ns - 1] / np.maximum(cn[ns - 1], 1) - m * m, 0) * cn[ns - 1] / np.maximum(cn[ns - 1] - 1, 1)
    z = stats.norm.ppf(0.5 + confidence / 2)
    half = z * np.sqrt(var / np.maximum(cn[ns - 1], 1))
    out = {"n": ns, "mean": m, "mean_lo": m - half, "mean_hi": m + half}
    for i, (lo, hi) in enumerate(limits):
        inside = ok.copy()
        if lo is not None:
            inside &= np.nan_to_num(y, nan=-np.inf) >= lo
        if hi is not None:
            inside &= np.nan_to_num(y, nan=np.inf) <= hi
        out[f"yield_{i}"] = np.cumsum(inside)[ns - 1] / ns
    return out
