"""The interval of a change between two runs: paired (common random numbers) or unpaired.

Two runs with the same seed, n, method and factors draw the same uniform
design, so sample i of both is "the same reducer" under the old and the new
tolerances: the paired difference cancels the sampling noise the two share
and its interval is much narrower than that of two independent runs
(common random numbers, e.g. Glasserman, *Monte Carlo Methods in Financial
Engineering*, §4.2; Law, *Simulation Modeling and Analysis*, §11.2).  Every
function returns ``(change, lo, hi)`` of ``b − a`` at two-sided
``confidence``, treating the samples as independent draws (for a Latin
hypercube or Sobol design the intervals are conservative):

* mean: paired t on the differences; unpaired Welch t;
* standard deviation: the delta method on the sample moments,
  Var(s) ≈ (m₄ − s⁴)/(4 n s²) and, paired, Cov(s_a, s_b) ≈
  (E[(a − ā)²(b − b̄)²] − s_a² s_b²)/(4 n s_a s_b) — distribution-free,
  asymptotic;
* a percentile: the percentile bootstrap of the difference of the two
  sample quantiles, resampling pairs together (paired) or each run on its
  own (unpaired), from the named sub-stream ``compare_bootstrap``;
* a non-conforming fraction: Newcombe's hybrid score interval, for
  independent proportions (Newcombe 1998, *Stat. Med.* 17:873, method 10)
  and for paired ones (Newcombe 1998, *Stat. Med.* 17:2635, method 10, with
  the φ correlation of the paired 2×2 table and Newcombe's continuity
  correction of its cross-product), built on Wilson intervals.
"""
from __future__ import annotations

import math

import numpy as np
from scipy import stats

#: bootstrap resamples of a percentile change
N_BOOT = 400


def _z(confidence: float) -> float:
    return float(stats.norm.ppf(0.5 + confidence / 2))


def mean_change(a: np.ndarray, b: np.ndarray, paired: bool, confidence: float = 0.95):
    if paired:
        d = b - a
        n = len(d)
        m = float(d.mean())
        if n < 2:
            return m, None, None
        h = stats.t.ppf(0.5 + confidence / 2, n - 1) * float(d.std(ddof=1)) / math.sqrt(n)
        return m, m - h, m + h
    na, nb = len(a), len(b)
    m = float(b.mean() - a.mean())
    if na < 2 or nb < 2:
        return m, None, None
    va, vb = a.var(ddof=1) / na, b.var(ddof=1) / nb
    se = math.sqrt(va + vb)
    if se == 0:
        return m, m, m
    df = (va + vb) ** 2 / (va**2 / (na - 1) + vb**2 / (nb - 1))
    h = stats.t.ppf(0.5 + confidence / 2, df) * se
    return m, m - h, m + h


def _var_of_std(x: np.ndarray) -> tuple[float, float]:
    """``(s, Var(s))`` by the delta method: Var(s²) ≈ (m₄ − s⁴)/n, Var(s) ≈ Var(s²)/(4 s²)."""
    n = len(x)
    c = x - x.mean()
    s2 = float(c @ c) / (n - 1)
    m4 = float(np.mean(c**4))
    return math.sqrt(s2), max(m4 - s2 * s2, 0.0) / n / (4.0 * s2) if s2 > 0 else 0.0


def std_change(a: np.ndarray, b: np.ndarray, paired: bool, confidence: float = 0.95):
    if len(a) < 3 or len(b) < 3:
        return None, None, None
    sa, va = _var_of_std(a)
    sb, vb = _var_of_std(b)
    var = va + vb
    if paired and sa > 0 and sb > 0:
        ca, cb = a - a.mean(), b - b.mean()
        cov4 = float(np.mean(ca * ca * cb * cb))
        var -= 2.0 * (cov4 - sa * sa * sb * sb) / len(a) / (4.0 * sa * sb)
    d = sb - sa
    h = _z(confidence) * math.sqrt(max(var, 0.0))
    return d, d - h, d + h


def percentile_change(a: np.ndarray, b: np.ndarray, q: float, paired: bool, confidence: float,
                      rng: np.random.Generator, n_boot: int = N_BOOT):
    """Change of the ``q``-quantile (0..1): estimate and percentile-bootstrap interval."""
    if len(a) < 2 or len(b) < 2:
        return None, None, None
    d = float(np.quantile(b, q) - np.quantile(a, q))
    diffs = np.empty(n_boot)
    batch = max(1, int(2e6 // max(len(a), len(b))))  # bound the memory of one batch of resamples
    for i in range(0, n_boot, batch):
        k = min(batch, n_boot - i)
        ia = rng.integers(0, len(a), size=(k, len(a)))
        ib = ia if paired else rng.integers(0, len(b), size=(k, len(b)))
        diffs[i:i + k] = np.quantile(b[ib], q, axis=1) - np.quantile(a[ia], q, axis=1)
    al = 1 - confidence
    lo, hi = np.quantile(diffs, [al / 2, 1 - al / 2])
    return d, float(lo), float(hi)


def _wilson(k: float, n: float, z: float) -> tuple[float, float]:
    if n <= 0:
        return math.nan, math.nan
    p = k / n
    den = 1 + z * z / n
    c = (p + z * z / (2 * n)) / den
    h = z * math.sqrt(max(p * (1 - p) / n + z * z / (4 * n * n), 0.0)) / den
    return max(0.0, c - h), min(1.0, c + h)


def proportion_change(out_a: np.ndarray, out_b: np.ndarray, paired: bool, confidence: float = 0.95):
    """Change of the fraction of ``True`` (non-conforming) from ``out_a`` to ``out_b``: Newcombe's interval."""
    z = _z(confidence)
    na, nb = len(out_a), len(out_b)
    pa, pb = float(np.mean(out_a)), float(np.mean(out_b))
    la, ua = _wilson(pa * na, na, z)
    lb, ub = _wilson(pb * nb, nb, z)
    d = pb - pa
    phi = 0.0
    if paired:
        x, y = np.asarray(out_a, bool), np.asarray(out_b, bool)
        n11, n10, n01, n00 = [int(v) for v in ((x & y).sum(), (x & ~y).sum(), (~x & y).sum(), (~x & ~y).sum())]
        den = (n11 + n10) * (n01 + n00) * (n11 + n01) * (n10 + n00)
        # Newcombe's φ̂ with his continuity correction of the cross-product (1998, Stat. Med. 17:2635, §2.10):
        # A = n11·n00 − n10·n01; A − N/2 when A > N/2, 0 when 0 ≤ A ≤ N/2, A when A < 0
        big_a, half = n11 * n00 - n10 * n01, 0.5 * (n11 + n10 + n01 + n00)
        num = big_a - half if big_a > half else (0.0 if big_a >= 0 else big_a)
        phi = num / math.sqrt(den) if den > 0 else 0.0
    # b − a: the lower end pairs b's lower Wilson limit with a's upper one (and vice versa)
    lo = d - math.sqrt(max((pb - lb) ** 2 - 2 * phi * (pb - lb) * (ua - pa) + (ua - pa) ** 2, 0.0))
    hi = d + math.sqrt(max((ub - pb) ** 2 - 2 * phi * (ub - pb) * (pa - la) + (pa - la) ** 2, 0.0))
    return d, lo, hi
