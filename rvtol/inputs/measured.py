"""A factor's distribution from measured values (a CMM export, a CSV column).

Three ways, each a distribution with the interface rvtol samples through (``ppf`` of a
uniform u, ``cdf``, ``mean``, ``std``, ``tolerance``, ``scaled``, ``describe``), so it plugs
into :class:`rvtol.spec.Factor` and the inverse-CDF sampling of :mod:`rvtol.sampling`:

* :func:`empirical` — the inverse empirical CDF: ``ppf(u) = x₍⌈n·u⌉₎``, i.e. resampling the
  measured parts (a bootstrap); ``interpolate=True`` interpolates linearly between order
  statistics at the Hazen plotting positions (i − ½)/n instead (no new extremes either way).
* :func:`kde` — a Gaussian kernel density (bandwidth by Scott's or Silverman's rule as in
  ``scipy.stats.gaussian_kde``, or given): its CDF is the mean of the kernels' normal CDFs,
  exact; ``ppf`` inverts it numerically (a tabulated bracket, then safeguarded Newton on
  the exact CDF — or on the exact survival function in the upper half, so the tails keep
  their precision — to 1e-12 of the bandwidth); each u is solved on its own, so results do
  not depend on which other samples share the call.
* :func:`fit` — maximum-likelihood fits (``scipy.stats`` ``fit``) of candidate families —
  normal, lognormal, Weibull, gamma, Rayleigh, uniform — ranked by AIC = 2k − 2 ln L (k the
  number of fitted parameters; the positive families are fitted with their location fixed,
  0 by default, as rvtol's one-sided kinds are).  The best fit (or any candidate) becomes
  an ordinary :class:`rvtol.distributions.Distribution` and a factor table for the spec
  (gamma, which rvtol's spec has no kind for, becomes a :class:`FrozenDistribution`).

Goodness of fit.  Every candidate gets the Kolmogorov–Smirnov distance D with scipy's
p-value *for fully specified parameters*; because the parameters were estimated from the
same data that p-value is too large (the test is conservative, Lilliefors' point) and is
reported as such, for ranking only.  The test to judge a fit by is **Anderson–Darling with a
parametric bootstrap** (``scipy.stats.goodness_of_fit``: refit on each Monte Carlo sample,
so the estimation is accounted for): AD weights the tails, where the ppm of a tolerance
analysis live, more than KS does (for the normal family scipy evaluates it with the sample
standard deviation of ddof = 1, as Stephens' tables do).  For the uniform family, whose MLE puts the extreme
points on the support's ends (AD = ∞), the Cramér–von Mises statistic is used instead.
:meth:`FitReport.qq` gives Q-Q plot data (Hazen positions).

Measurement uncertainty.  With ``measurement_sigma`` u (the gauge's standard uncertainty,
in the data's unit; independent of the parts) the observed variance is the part variance
plus u².  The deconvolution used is the moment one: the values are shrunk about their mean,
x' = x̄ + (x − x̄)·√(1 − u²/s²) (s² the sample variance), which leaves the mean and gives
the part variance s² − u², and the method then runs on x'.  It is exact for normal parts
with a normal gauge error; for other shapes it keeps the observed shape (slightly smoother
than the parts').  u ≥ s is refused (the gauge cannot resolve the parts).
"""
from __future__ import annotations

import array
import itertools
import math
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy import special, stats

from ..distributions import Distribution, coverage
from ..precision import shown
from ..errors import did_you_mean, InputError, SpecError
from .inspection import characteristic_values, is_inspection_file
from .sheets import (CommaColumn, blank, byte_progress, col_letter, is_number, skipped, split_number_hint,
                     split_header, stream_rows)

#: candidate families: name -> scipy distribution, whether the support is x > location
FAMILIES: dict[str, tuple[object, bool]] = {
    "normal": (stats.norm, False),
    "lognormal": (stats.lognorm, True),
    "weibull": (stats.weibull_min, True),
    "gamma": (stats.gamma, True),
    "rayleigh": (stats.rayleigh, True),
    "uniform": (stats.uniform, False),
    "beta": (stats.beta, False),
    "gumbel": (stats.gumbel_r, False),
    "johnsonsu": (stats.johnsonsu, False),
    "johnsonsb": (stats.johnsonsb, False),
    "pearson3": (stats.pearson3, False),
}
#: the candidates tried when a spec names none (the families beyond them — beta, gumbel, Johnson SU/SB,
#: Pearson III — are fitted when named: ``families = ["johnsonsu", "normal"]``)
DEFAULT_FAMILIES = ("normal", "lognormal", "weibull", "gamma", "rayleigh", "uniform")
METHODS = ("fit", "empirical", "kde")
_CHUNK = 1 << 22   # elements per block in the KDE sums


# ----------------------------------------------------------------------------- deconvolution
def _clean(values, what: str = "measured values", min_n: int = 2) -> np.ndarray:
    x = np.asarray(values, dtype=float).ravel()
    if x.size < min_n:
        raise InputError(f"{what}: need at least {min_n} values, got {x.size}")
    if not np.all(np.isfinite(x)):
        raise InputError(f"{what}: {int(np.sum(~np.isfinite(x)))} values are not finite numbers")
    if np.ptp(x) == 0.0:
        raise InputError(f"{what}: all values are equal ({x[0]:g}); no spread to describe")
    return x


def deconvolve(values, measurement_sigma: float | None) -> tuple[np.ndarray, float]:
    """``(x', u²/s²)``: the values shrunk about their mean to the part variance s² − u²."""
    x = _clean(values)
    if not measurement_sigma:
        return x, 0.0
    u = float(measurement_sigma)
    if not (math.isfinite(u) and u > 0):
        raise InputError(f"measurement_sigma must be a positive number, got {measurement_sigma!r}")
    s2 = float(np.var(x, ddof=1))
    ratio = u * u / s2
    if ratio >= 1.0:
        raise InputError(f"the measurement uncertainty (σ = {u:g}) is not smaller than the spread of the "
                         f"measured values (s = {math.sqrt(s2):g}): the gauge cannot resolve these parts")
    m = float(np.mean(x))
    return m + (x - m) * math.sqrt(1.0 - ratio), ratio


# ----------------------------------------------------------------------------- the interface
class _Frozen:
    """The part of a scipy frozen distribution rvtol's analyses use (support, ppf, cdf, …)."""

    def __init__(self, d):
        self._d = d

    def support(self):
        return self._d.support()

    def ppf(self, u):
        return self._d.ppf(u)

    def cdf(self, x):
        return self._d.cdf(x)

    def pdf(self, x):
        return self._d.pdf(x)

    def mean(self):
        return self._d.mean

    def std(self):
        return self._d.std

    def var(self):
        return self._d.std ** 2


class _DataDistribution:
    """Shared parts of the distributions built from data (duck-typed like ``Distribution``)."""

    kind = "data"
    shift = 0.0
    sigma_level = 3.0
    one_sided = False

    def __init__(self, data: np.ndarray, gauge_fraction: float = 0.0, origin: str = ""):
        self.data = np.sort(np.asarray(data, dtype=float))
        self.gauge_fraction = float(gauge_fraction)
        self.origin = origin

    @property
    def n(self) -> int:
        return int(self.data.size)

    @property
    def frozen(self) -> _Frozen:
        return _Frozen(self)

    @property
    def params(self) -> tuple[tuple[str, float], ...]:
        return (("n", float(self.n)), ("mean", self.mean), ("std", self.std))

    @property
    def p(self) -> dict[str, float]:
        return dict(self.params)

    @property
    def tolerance(self) -> float:
        """The central band holding the coverage of ±``sigma_level``·σ of a normal (99.73 %)."""
        lo, hi = self.band
        return hi - lo

    @property
    def band(self) -> tuple[float, float]:
        """The central interval holding the coverage of ±``sigma_level``·σ of a normal (99.73 %)."""
        q = 0.5 * (1.0 - coverage(self.sigma_level))
        return float(self.ppf(q)), float(self.ppf(1.0 - q))

    @property
    def half_band(self) -> float:
        return 0.5 * self.tolerance

    def _scaled_data(self, f: float) -> np.ndarray:
        if not f > 0:
            raise ValueError("scale factor must be > 0")
        m = float(np.mean(self.data))
        return m + (self.data - m) * f

    def __reduce__(self):  # picklable for the process / Dask executors
        return (self._rebuild, self._state())


# ----------------------------------------------------------------------------- empirical
class EmpiricalDistribution(_DataDistribution):
    """Resampling of measured values: the inverse empirical CDF (see the module docstring)."""

    kind = "empirical"

    def __init__(self, data, interpolate: bool = False, gauge_fraction: float = 0.0, origin: str = ""):
        super().__init__(_clean(data), gauge_fraction, origin)
        self.interpolate = bool(interpolate)
        n = self.n
        self._pos = (np.arange(1, n + 1) - 0.5) / n
        self._steps = np.arange(1, n + 1) / n

    @classmethod
    def _rebuild(cls, data, interpolate, gauge_fraction, origin):
        return cls(data, interpolate, gauge_fraction, origin)

    def _state(self):
        return (self.data, self.interpolate, self.gauge_fraction, self.origin)

    def ppf(self, u):
        u = np.asarray(u, dtype=float)
        if self.interpolate:
            return np.interp(u, self._pos, self.data)
        # x₍k₎ for u in ((k−1)/n, k/n]: searching the grid k/n (computed as u would be) keeps u = k/n on x₍k₎
        i = np.clip(np.searchsorted(self._steps, u, side="left"), 0, self.n - 1)
        return self.data[i]

    def cdf(self, x):
        x = np.asarray(x, dtype=float)
        if self.interpolate:
            return np.interp(x, self.data, self._pos, left=0.0, right=1.0)
        return np.searchsorted(self.data, x, side="right") / self.n

    def pdf(self, x):
        """Density of the linearly interpolated ECDF (for plots; the step ECDF has none)."""
        x = np.asarray(x, dtype=float)
        d, pos = self.data, self._pos
        j = np.clip(np.searchsorted(d, x, side="right") - 1, 0, self.n - 2)
        w = d[j + 1] - d[j]
        with np.errstate(divide="ignore", invalid="ignore"):
            f = np.where(w > 0, (pos[j + 1] - pos[j]) / w, 0.0)
        return np.where((x < d[0]) | (x > d[-1]), 0.0, f)

    def support(self):
        return float(self.data[0]), float(self.data[-1])

    @property
    def mean(self) -> float:
        if self.interpolate:
            return float(_interp_moments(self.data, self._pos)[0])
        return float(np.mean(self.data))

    @property
    def std(self) -> float:
        if self.interpolate:
            return float(math.sqrt(_interp_moments(self.data, self._pos)[1]))
        return float(np.std(self.data))   # the resampled population: ddof = 0

    def scaled(self, f: float) -> "EmpiricalDistribution":
        return EmpiricalDistribution(self._scaled_data(f), self.interpolate, self.gauge_fraction,
                                     f"{self.origin} ×{f:.4g}" if self.origin else "")

    def describe(self, unit: str = "", number=None) -> str:
        """``number`` formats the quantities in the unit (:meth:`rvtol.distributions.Distribution.describe`)."""
        g = number or (lambda x: f"{x:.4g}")
        how = "interpolated" if self.interpolate else "resampled"
        return f"empirical({how}, n={self.n}, x̄={g(self.mean)}, s={g(self.std)}) {unit}".strip()


def _interp_moments(x: np.ndarray, p: np.ndarray) -> tuple[float, float]:
    """Mean and variance of the Hazen-interpolated ECDF: point masses ½/n at the ends, uniform between."""
    n = x.size
    a, b, w = x[:-1], x[1:], 1.0 / n
    m1 = 0.5 * w * (x[0] + x[-1]) + w * np.sum(0.5 * (a + b))
    m2 = 0.5 * w * (x[0] ** 2 + x[-1] ** 2) + w * np.sum((a * a + a * b + b * b) / 3.0)
    return m1, m2 - m1 * m1


def empirical(values, *, interpolate: bool = False, measurement_sigma: float | None = None,
              origin: str = "") -> EmpiricalDistribution:
    """The empirical distribution of measured values (optionally deconvolved, see the module docstring)."""
    x, ratio = deconvolve(values, measurement_sigma)
    return EmpiricalDistribution(x, interpolate, ratio, origin)


# ----------------------------------------------------------------------------- kernel density
class KDEDistribution(_DataDistribution):
    """Gaussian kernel density of measured values with an exact CDF and a numerically inverted ppf."""

    kind = "kde"
    _GRID = 2049
    _TAIL = 9.0     # Φ(−9) ≈ 1e-19 < the smallest u rvtol draws (2^-53)

    def __init__(self, data, bandwidth: float, gauge_fraction: float = 0.0, origin: str = ""):
        super().__init__(_clean(data), gauge_fraction, origin)
        h = float(bandwidth)
        if not (math.isfinite(h) and h > 0):
            raise InputError(f"KDE bandwidth must be a positive number, got {bandwidth!r}")
        self.bandwidth = h
        self._grid = np.linspace(self.data[0] - self._TAIL * h, self.data[-1] + self._TAIL * h, self._GRID)
        self._F = self.cdf(self._grid)
        self._S = self.sf(self._grid)

    @classmethod
    def _rebuild(cls, data, bandwidth, gauge_fraction, origin):
        return cls(data, bandwidth, gauge_fraction, origin)

    def _state(self):
        return (self.data, self.bandwidth, self.gauge_fraction, self.origin)

    def _kernel_mean(self, x, fn) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        flat = x.ravel()
        out = np.empty(flat.size)
        step = max(1, _CHUNK // self.n)
        for i in range(0, flat.size, step):
            z = (flat[i:i + step, None] - self.data[None, :]) / self.bandwidth
            out[i:i + step] = fn(z).mean(axis=1)
        return out.reshape(x.shape)

    def cdf(self, x):
        return self._kernel_mean(x, special.ndtr)

    def sf(self, x):
        return self._kernel_mean(x, lambda z: special.ndtr(-z))

    def pdf(self, x):
        return self._kernel_mean(x, lambda z: np.exp(-0.5 * z * z)) / (self.bandwidth * math.sqrt(2 * math.pi))

    def support(self):
        return -math.inf, math.inf

    def ppf(self, u):
        u = np.asarray(u, dtype=float)
        shape = u.shape
        u = u.ravel()
        x = np.full(u.size, np.nan)
        ok = (u > 0) & (u < 1)
        x[u == 0] = -np.inf
        x[u == 1] = np.inf
        for upper in (False, True):
            sel = ok & ((u > 0.5) if upper else (u <= 0.5))
            if sel.any():
                x[sel] = self._solve(u[sel], upper)
        return x.reshape(shape)

    def _solve(self, u: np.ndarray, upper: bool) -> np.ndarray:
        """Root of g(x) = F(x) − u (lower half) or (1 − u) − S(x) (upper half), both increasing."""
        G = self._GRID
        if upper:
            target = 1.0 - u
            j = np.clip(np.searchsorted(-self._S, -target), 1, G - 1)   # S[j−1] ≥ target ≥ S[j]
            a, b = self._S[j - 1], self._S[j]
            den = a - b
            num = a - target
        else:
            target = u
            j = np.clip(np.searchsorted(self._F, target), 1, G - 1)     # F[j−1] ≤ target ≤ F[j]
            a, b = self._F[j - 1], self._F[j]
            den = b - a
            num = target - a
        lo, hi = self._grid[j - 1].copy(), self._grid[j].copy()
        w = np.clip(np.divide(num, den, out=np.full(u.size, 0.5), where=den > 0), 0.0, 1.0)
        x = lo + w * (hi - lo)
        tol = 1e-12 * self.bandwidth
        active = np.ones(u.size, dtype=bool)
        for _ in range(100):
            idx = np.flatnonzero(active)
            if idx.size == 0:
                break
            xi = x[idx]
            g = (target[idx] - self.sf(xi)) if upper else (self.cdf(xi) - target[idx])
            f = self.pdf(xi)
            below = g < 0
            lo[idx] = np.where(below, xi, lo[idx])
            hi[idx] = np.where(below, hi[idx], xi)
            with np.errstate(divide="ignore", invalid="ignore"):
                xn = xi - g / f
            bad = ~np.isfinite(xn) | (xn < lo[idx]) | (xn > hi[idx])
            xn = np.where(bad, 0.5 * (lo[idx] + hi[idx]), xn)
            xn = np.where(g == 0, xi, xn)
            done = (np.abs(xn - xi) <= tol) | (g == 0) | (hi[idx] - lo[idx] <= tol)
            x[idx] = xn
            active[idx[done]] = False
        return x

    @property
    def mean(self) -> float:
        return float(np.mean(self.data))

    @property
    def std(self) -> float:
        return float(math.sqrt(np.var(self.data) + self.bandwidth ** 2))

    def scaled(self, f: float) -> "KDEDistribution":
        return KDEDistribution(self._scaled_data(f), self.bandwidth * f, self.gauge_fraction,
                               f"{self.origin} ×{f:.4g}" if self.origin else "")

    def describe(self, unit: str = "", number=None) -> str:
        """``number`` formats the quantities in the unit (:meth:`rvtol.distributions.Distribution.describe`)."""
        g = number or (lambda x: f"{x:.4g}")
        return f"kde(n={self.n}, h={g(self.bandwidth)}, x̄={g(self.mean)}, s={g(self.std)}) {unit}".strip()


def kde(values, *, bandwidth: str | float = "scott", measurement_sigma: float | None = None,
        origin: str = "") -> KDEDistribution:
    """A Gaussian KDE of measured values.

    ``bandwidth``: ``"scott"`` or ``"silverman"`` (the rules of ``scipy.stats.gaussian_kde``:
    h = n^(−1/5)·s resp. (3n/4)^(−1/5)·s, s the sample standard deviation) or a number (h in
    the data's unit).
    """
    x, ratio = deconvolve(values, measurement_sigma)
    if isinstance(bandwidth, str):
        if bandwidth not in ("scott", "silverman"):
            raise InputError(f"unknown bandwidth rule {bandwidth!r} (expected scott, silverman or a number)")
        h = float(math.sqrt(stats.gaussian_kde(x, bw_method=bandwidth).covariance[0, 0]))
    else:
        h = float(bandwidth)
    return KDEDistribution(x, h, ratio, origin)


# ----------------------------------------------------------------------------- parametric fits
class FrozenDistribution:
    """A fitted scipy distribution rvtol's spec has no kind for (gamma), usable as a factor's ``dist``."""

    shift = 0.0
    sigma_level = 3.0

    def __init__(self, kind: str, frozen, one_sided: bool, origin: str = ""):
        self.kind, self._frozen, self.one_sided, self.origin = kind, frozen, one_sided, origin

    @property
    def frozen(self):
        return self._frozen

    @property
    def params(self):
        return tuple((f"arg{i}", float(a)) for i, a in enumerate(self._frozen.args)) + tuple(
            (k, float(v)) for k, v in sorted(self._frozen.kwds.items()))

    @property
    def p(self):
        return dict(self.params)

    def ppf(self, u):
        return self._frozen.ppf(u)

    def cdf(self, x):
        return self._frozen.cdf(x)

    def pdf(self, x):
        return self._frozen.pdf(x)

    @property
    def mean(self) -> float:
        return float(self._frozen.mean())

    @property
    def std(self) -> float:
        return float(self._frozen.std())

    @property
    def band(self) -> tuple[float, float]:
        """As :attr:`rvtol.distributions.Distribution.band`: support start to the coverage quantile
        (one-sided), else the central coverage interval."""
        c = coverage(self.sigma_level)
        if self.one_sided:
            return float(self._frozen.support()[0]), float(self._frozen.ppf(c))
        q = 0.5 * (1 - c)
        return float(self._frozen.ppf(q)), float(self._frozen.ppf(1 - q))

    @property
    def tolerance(self) -> float:
        lo, hi = self.band
        return hi - lo

    @property
    def half_band(self) -> float:
        return self.tolerance if self.one_sided else 0.5 * self.tolerance

    def scaled(self, f: float) -> "FrozenDistribution":
        if not f > 0:
            raise ValueError("scale factor must be > 0")
        d = self._frozen
        kw = dict(d.kwds)
        kw["scale"] = kw.get("scale", 1.0) * f
        return FrozenDistribution(self.kind, d.dist(*d.args, **kw), self.one_sided, self.origin)

    def describe(self, unit: str = "", number=None) -> str:
        """``number`` formats loc and scale, in the unit (:meth:`rvtol.distributions.Distribution.describe`)."""
        g = lambda x: f"{x:.4g}"  # noqa: E731
        ps = ", ".join(f"{k}={(number or g)(v) if k in ('loc', 'scale') else g(v)}" for k, v in self.params)
        return f"{self.kind}({ps}) {unit}".strip()


@dataclass(frozen=True)
class Candidate:
    """One fitted family: scipy parameters, log-likelihood, AIC and the (naive) KS test."""

    family: str
    params: dict            # scipy's names: shape(s), loc, scale
    k: int                  # fitted parameters
    loglik: float
    aic: float
    ks_statistic: float
    ks_pvalue_naive: float  # as if the parameters were known: too large (see the module docstring)

    @property
    def frozen(self):
        dist, _ = FAMILIES[self.family]
        return dist(**self.params)


@dataclass(frozen=True)
class GoodnessOfFit:
    family: str
    test: str               # "Anderson-Darling" or "Cramér-von Mises" (uniform), parametric bootstrap
    statistic: float
    pvalue: float
    n_mc: int


@dataclass(frozen=True)
class FitReport:
    """Candidates ranked by AIC, the goodness-of-fit test of the best, Q-Q data."""

    data: np.ndarray                     # the values the families were fitted to (after deconvolution)
    candidates: tuple[Candidate, ...]    # best (lowest AIC) first
    skipped: dict = field(default_factory=dict)   # family -> why it was not fitted
    gof: tuple[GoodnessOfFit, ...] = ()
    gauge_fraction: float = 0.0          # u²/s² of the measurement uncertainty
    origin: str = ""
    location: float | None = 0.0         # the fixed location of the positive families (None: fitted)

    @property
    def best(self) -> Candidate:
        return self.candidates[0]

    def candidate(self, family: str | None = None) -> Candidate:
        if family is None:
            return self.best
        for c in self.candidates:
            if c.family == family:
                return c
        raise InputError(f"{family!r} was not fitted ({self.skipped.get(family, 'not a candidate')})")

    def table(self):
        """The ranking: family, k, ln L, AIC, ΔAIC, Akaike weight, KS D and naive p."""
        import pandas as pd

        aic = np.array([c.aic for c in self.candidates])
        d = aic - aic.min()
        w = np.exp(-0.5 * d)
        return pd.DataFrame({
            "family": [c.family for c in self.candidates],
            "k": [c.k for c in self.candidates],
            "loglik": [c.loglik for c in self.candidates],
            "aic": aic,
            "delta_aic": d,
            "weight": w / w.sum(),
            "ks_D": [c.ks_statistic for c in self.candidates],
            "ks_p_naive": [c.ks_pvalue_naive for c in self.candidates],
        })

    def distribution(self, family: str | None = None):
        """The fitted family as a rvtol distribution (``Distribution`` where the spec has the kind)."""
        c = self.candidate(family)
        kind, kw = _rvtol_kind(c)
        if kind is None:
            return FrozenDistribution(c.family, c.frozen, FAMILIES[c.family][1], self.origin)
        return Distribution.make(kind, origin=self.origin or f"fit {c.family}", **kw)

    def factor_table(self, family: str | None = None) -> dict:
        """Keys for :func:`rvtol.distributions.from_params` (a spec's ``[[factor]]``)."""
        c = self.candidate(family)
        kind, kw = _rvtol_kind(c)
        if kind is None:
            raise InputError(f"{c.family} is not a distribution kind of rvtol's spec; use "
                             f"FitReport.distribution() in Python or another family")
        return {"dist": kind, **{k: float(v) for k, v in kw.items() if not (k == "shift" and v == 0.0)}}

    def qq(self, family: str | None = None):
        """Q-Q plot data: Hazen position p = (i − ½)/n, the fitted quantile, the sorted value."""
        return qq_data(self.data, self.candidate(family).frozen)


def _rvtol_kind(c: Candidate) -> tuple[str | None, dict]:
    p = c.params
    if c.family == "normal":
        return "normal", dict(mean=p["loc"], sigma=p["scale"])
    if c.family == "lognormal":
        return "lognormal", dict(median=p["scale"], shape=p["s"], shift=p["loc"])
    if c.family == "weibull":
        return "weibull", dict(shape=p["c"], scale=p["scale"], shift=p["loc"])
    if c.family == "rayleigh":
        return "rayleigh", dict(sigma=p["scale"], shift=p["loc"])
    if c.family == "uniform":
        return "uniform", dict(lower=p["loc"], upper=p["loc"] + p["scale"])
    if c.family == "gamma":
        return "gamma", dict(shape=p["a"], scale=p["scale"], shift=p["loc"])
    if c.family == "beta":
        return "beta", dict(alpha=p["a"], beta=p["b"], lower=p["loc"], upper=p["loc"] + p["scale"])
    if c.family == "gumbel":
        return "gumbel", dict(mode=p["loc"], scale=p["scale"])
    if c.family in ("johnsonsu", "johnsonsb"):
        return c.family, dict(gamma=p["a"], delta=p["b"], location=p["loc"], scale=p["scale"])
    if c.family == "pearson3":
        return "pearson3", dict(mean=p["loc"], sigma=p["scale"], skewness=p["skew"])
    return None, {}


def qq_data(values, frozen):
    """Q-Q plot data of ``values`` against a (scipy-like) distribution: p, theoretical, sample."""
    import pandas as pd

    x = np.sort(np.asarray(values, dtype=float))
    n = x.size
    p = (np.arange(1, n + 1) - 0.5) / n
    return pd.DataFrame({"p": p, "theoretical": np.asarray(frozen.ppf(p), dtype=float), "sample": x})


def _shape_names(dist) -> list[str]:
    return [s.strip() for s in dist.shapes.split(",")] if dist.shapes else []


def fit_family(x: np.ndarray, family: str, location: float | None = 0.0, start: dict | None = None) -> tuple[dict, int]:
    """``(parameters, k)``: the maximum-likelihood parameters of one family (scipy's names: shape(s), loc, scale;
    ``scipy.stats`` ``fit``) and the number fitted — a positive family's location fixed at ``location`` unless it
    is None; ``start``: starting values for the optimiser (e.g. an earlier fit's parameters).  An
    :class:`InputError` says why the family cannot be fitted."""
    dist, positive = FAMILIES[family]
    fixed = {}
    if positive and location is not None:
        if not np.all(x > location):
            raise InputError(f"needs every value above its location {location:g}")
        fixed["floc"] = float(location)
    names = _shape_names(dist) + ["loc", "scale"]
    guess = {} if start is None else {k: v for k, v in start.items() if k in ("loc", "scale") and f"f{k}" not in fixed}
    shapes = () if start is None else tuple(start[k] for k in names[:-2])
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        try:
            est = dist.fit(x, *shapes, **guess, **fixed)
        except Exception as exc:   # an optimiser failure: said so
            raise InputError(f"fit failed ({type(exc).__name__}: {exc})") from None
    return {k: float(v) for k, v in zip(names, est)}, len(names) - len(fixed)


def fit(values, *, families=DEFAULT_FAMILIES, location: float | None = 0.0,
        measurement_sigma: float | None = None, gof: str | None = "best", n_mc: int = 499,
        seed: int = 0, origin: str = "") -> FitReport:
    """Fit candidate families by maximum likelihood and rank them by AIC (see the module docstring).

    ``location``: the fixed location of the positive families (lognormal, weibull, gamma,
    rayleigh), 0 by default; ``None`` fits it too (three-parameter fits: use with care).
    ``gof``: ``"best"`` (the Anderson–Darling bootstrap test of the best family), ``"all"``
    or ``None``; ``n_mc`` bootstrap samples from ``seed``.
    """
    x, ratio = deconvolve(values, measurement_sigma)
    if x.size < 8:
        raise InputError(f"fitting a distribution needs at least 8 values, got {x.size}")
    fams = list(families)
    if not fams:
        raise InputError("no candidate families")
    cands, skipped = [], {}
    for name in fams:
        if name not in FAMILIES:
            raise InputError(f"unknown family {name!r} (known: {', '.join(FAMILIES)})")
        dist, _ = FAMILIES[name]
        try:
            params, k = fit_family(x, name, location)
        except InputError as exc:   # a family that cannot be fitted is a skipped candidate, said so
            skipped[name] = exc.reason
            continue
        frozen = dist(**params)
        with np.errstate(all="ignore"):
            ll = float(np.sum(frozen.logpdf(x)))
        if not math.isfinite(ll):
            skipped[name] = "the fitted density is zero at some values"
            continue
        ks = stats.kstest(x, frozen.cdf)
        cands.append(Candidate(name, params, k, ll, 2 * k - 2 * ll, float(ks.statistic), float(ks.pvalue)))
    if not cands:
        raise InputError("no candidate family could be fitted: " +
                         "; ".join(f"{k}: {v}" for k, v in skipped.items()))
    cands.sort(key=lambda c: c.aic)
    tests = []
    if gof is not None:
        if gof not in ("best", "all"):
            raise InputError(f"gof must be 'best', 'all' or None, got {gof!r}")
        for c in cands[:1] if gof == "best" else cands:
            tests.append(_gof(x, c, location, n_mc, seed))
    return FitReport(x, tuple(cands), skipped, tuple(tests), ratio, origin, location)


def _gof(x: np.ndarray, c: Candidate, location, n_mc: int, seed: int) -> GoodnessOfFit:
    dist, positive = FAMILIES[c.family]
    known = {"loc": float(location)} if positive and location is not None else {}
    fitted = {k: v for k, v in c.params.items() if k not in known}
    statistic = "cvm" if c.family == "uniform" else "ad"
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        r = stats.goodness_of_fit(dist, x, known_params=known or None, fit_params=fitted, statistic=statistic,
                                  n_mc_samples=int(n_mc), rng=np.random.default_rng(seed))
    name = "Cramér-von Mises" if statistic == "cvm" else "Anderson-Darling"
    return GoodnessOfFit(c.family, f"{name}, parametric bootstrap", float(r.statistic), float(r.pvalue), int(n_mc))


# ----------------------------------------------------------------------------- one entry point
def from_measurements(values, method: str = "fit", **kw):
    """A factor distribution from measured values by ``method`` (fit | empirical | kde).

    ``fit`` returns the best family's distribution (``family=`` picks another); keyword
    arguments go to :func:`fit`, :func:`empirical` or :func:`kde`.
    """
    if method == "empirical":
        return empirical(values, **kw)
    if method == "kde":
        return kde(values, **kw)
    if method == "fit":
        family = kw.pop("family", None)
        return fit(values, **kw).distribution(family)
    raise InputError(f"unknown method {method!r} (expected one of: {', '.join(METHODS)})")


# ----------------------------------------------------------------------------- reading values
def read_measurements(path: str | Path, column: str | int | None = None, *, sheet: str | None = None,
                      unit: str | None = None) -> np.ndarray:
    """Measured values from a CSV/TSV/TXT or XLSX file: one column by header name or 1-based number.

    The rows come through the one table reader (:mod:`rvtol.inputs.sheets`) with its rules: comment
    rows (``# …``) and blank rows skipped, a header cell ``name`` or ``name [unit]``
    (:func:`~rvtol.inputs.sheets.split_header`: ``column = "d"`` finds ``d [mm]``; the name as
    written, and then any case, are tried), numbers read one way only
    (:func:`~rvtol.inputs.sheets.read_number`: a decimal comma outside comma-separated files, thousands
    separators; an ambiguous ``1,250`` decided by the column's other numbers,
    :class:`~rvtol.inputs.sheets.CommaColumn`, or refused).  Unlike a spec table the header is optional: a
    first row that is all numbers is data; a value beyond the header's (or the first row's) columns is refused
    (a decimal comma read as the delimiter splits a number in two).  With a unit in the column's header and ``unit`` (the
    factor's) given, the values are converted to ``unit`` (another dimension is an error at the
    header cell).  Blank cells are skipped (columns of different lengths); anything else that is not
    a number is an error naming row and column.  The rows are read one at a time (only the column's
    numbers are kept: a file of millions of rows takes the memory of its numbers), with a progress
    bar on a terminal for a large file.
    """
    path = Path(path)
    file = str(path)
    rs = stream_rows(path, sheet, delimiters=",;\t ", text_suffixes=(".csv", ".tsv", ".txt", ".dat", ""),
                     what="a file of measured values")
    loc = rs.location(file)
    where_sheet = f"sheet {rs.title!r}, " if rs.title is not None else ""
    rows = ((r, c) for r, c in rs.rows if not skipped(c))
    first_row = next(rows, None)
    if first_row is None:
        raise SpecError("no values", file=file, key="-")
    r0, first = first_row

    has_header = not all(is_number(v) for v in first if not blank(v))
    header, names, col_units = None, None, None
    if has_header:
        header = [("" if v is None else str(v).strip()) for v in first]
        parsed = [split_header(h) if h else ("", None) for h in header]
        names, col_units = [n for n, _ in parsed], [u for _, u in parsed]
    body = rows if has_header else itertools.chain([first_row], rows)
    width = len(first)
    ncols = len(first) - next((k for k, v in enumerate(reversed(first)) if not blank(v)), len(first))
    j = None
    if isinstance(column, int) and not isinstance(column, bool):
        j = column - 1
    elif column is not None:
        if header is None:
            raise SpecError(f"the file has no header row to find column {column!r} in; give its number",
                            file=file, key="column")
        want = str(column).strip()
        hits = ([i for i, h in enumerate(header) if h == want] or [i for i, n in enumerate(names) if n == want]
                or [i for i, n in enumerate(names) if n.lower() == want.lower()])
        if not hits:
            # the header's cells are not echoed (a file's first line may hold anything): a close name only
            raise SpecError(f"no column {column!r} in the header row"
                            f"{did_you_mean(str(column), [n for n in names if n and len(n) <= 64])}",
                            file=file, key=f"{where_sheet}row {r0}")
        if len(hits) > 1:
            raise SpecError(f"column {column!r} appears {len(hits)} times", file=file, key=f"{where_sheet}row {r0}")
        j = hits[0]
    # the values of column j — or, without a column, of every column (exactly one may be used)
    vals: dict[int, array.array] = {}
    commas: dict[int, CommaColumn] = {}     # per column: a 1,250 decided by the column's other numbers

    with byte_progress(rs.size, f"reading {path.name}") as bar:
        step = 0
        for r, cells in body:
            if len(cells) > ncols and any(not blank(c) for c in cells[ncols:]):
                # a value where the first row has none: a decimal comma taken for the delimiter splits "0,1" in two
                raise SpecError(f"{len(cells)} fields, the {'header' if has_header else 'first row'} has {ncols}"
                                + split_number_hint(rs.delimiter), file=file, key=f"{where_sheet}row {r}")
            width = max(width, len(cells))
            cols = (j,) if j is not None else range(len(cells))
            for i in cols:
                v = cells[i] if i < len(cells) else None
                if blank(v):
                    continue
                try:
                    col = vals.setdefault(i, array.array("d"))
                    x = commas.setdefault(i, CommaColumn(rs.delimiter)).read(v, len(col), r)
                except ValueError as exc:
                    label = header[i] if header and i < len(header) and header[i] else f"{i + 1}"
                    why = str(exc) if getattr(exc, "advice", False) and len(str(v)) <= 24 else (
                        "expected a number" + (f", got {str(v).strip()!r}" if len(str(v)) <= 24 else ""))
                    raise SpecError(why, file=file, key=f"{where_sheet}row {r}, column {label!r}") from None
                if not math.isfinite(x):
                    label = header[i] if header and i < len(header) and header[i] else f"{i + 1}"
                    raise SpecError(f"not a finite number: {v!r}", file=file,
                                    key=f"{where_sheet}row {r}, column {label!r}")
                col.append(x)
            step += 1
            if step == 4096:
                bar.advance(4096 * (sum(len(str(c)) + 1 for c in cells)))
                step = 0
    if j is not None and not 0 <= j < width:
        raise SpecError(f"column {column} is out of range (the file has {width})", file=file, key="column")
    if j is None:
        if len(vals) != 1:
            shown = ", ".join(h for h in (header or []) if h) if header and len(header) <= 12 else ""
            raise SpecError(f"the file has several columns{f' ({shown})' if shown else ''}: say which one "
                            "(column = ...)", file=file, key=f"{where_sheet}row {r0}")
        j = next(iter(vals))
    label = header[j] if header and j < len(header) and header[j] else f"{j + 1}"
    got = vals.get(j, array.array("d"))
    undecided = commas[j].settle(got) if j in commas else None
    if undecided is not None:
        raise SpecError(str(undecided), file=file, key=f"{where_sheet}row {undecided.where}, column {label!r}")
    if len(got) < 2:
        raise SpecError(f"column {label!r} holds {len(got)} value(s); need at least 2", file=file,
                        key=f"{where_sheet}column {label!r}")
    out = np.frombuffer(got, dtype=float).copy()
    written = col_units[j] if col_units and j < len(col_units) else None
    if written is not None and unit is not None:       # the header's unit -> the factor's
        from .. import units

        try:
            out = units.convert(out, units.canonical(written, units.dimension(unit)), units.canonical(unit))
        except InputError as exc:
            raise loc.error(exc.reason, r0, header[j], col_letter(j) if rs.lettered else None) from None
    return out


#: the keys of a ``[[factor]]`` table with ``dist = "measured"`` (besides name, unit, …)
MEASURED_KEYS = ("data", "column", "sheet", "method", "families", "family", "location", "interpolate", "bandwidth",
                 "measurement_sigma")


@dataclass(frozen=True, eq=False)
class Measured:
    """The data behind a measured factor's distribution, for the report (fit tables, Q-Q plot)."""

    values: np.ndarray            # as read from the file (before any measurement-uncertainty correction)
    data: str                     # the file as the spec names it
    column: str | int | None
    sheet: str | None
    method: str                   # fit | empirical | kde
    measurement_sigma: float | None = None
    fit: FitReport | None = None  # the ranked candidates (method fit; without the GoF test, run by the report)
    family: str | None = None     # the family used (fit)
    file_statistics: list = field(default_factory=list)   # a QIF file's own Statistics of the values, recomputed
                                                          # (rvtol.inputs.inspection.check_statistics)

    @property
    def n(self) -> int:
        return int(self.values.size)

    @property
    def source(self) -> str:
        return self.data + (f"[{self.column}]" if self.column is not None else "")


def measured_factor(p, base_dir: Path | str = ".") -> tuple[object, Measured]:
    """The spec-loader hook: a ``[[factor]]`` table's measured-data keys → ``(distribution, Measured)``.

    Keys (read through :class:`rvtol.params.Params`, so typos are reported): ``data`` (file,
    relative to ``base_dir``), ``column``, ``sheet``, ``method`` (fit | empirical | kde, default
    fit), ``families`` and ``family`` (fit), ``location`` (fit), ``interpolate`` (empirical),
    ``bandwidth`` (kde: scott | silverman | number), ``measurement_sigma``.  The caller reads
    ``dist``, ``name``, ``unit``… as for any factor.  ``data`` may be a QIF 3.0 or DFQ file
    (:func:`rvtol.inputs.inspection.characteristic_values`): ``column`` then names its characteristic (the QIF item's
    Name or ``id:N``, the DFQ description K2002 or number K2001), the values are every part's reading of it in the
    factor's unit, and a QIF file's own Statistics of them are checked and shown in the report.
    """
    path = p.path_value("data", Path(base_dir))
    col = p.raw("column", None)
    if col is not None and not isinstance(col, (str, int)) or isinstance(col, bool):
        raise p.error("column", "expected a column name or a 1-based number")
    sheet = p.str("sheet", None)
    method = p.str("method", "fit", choices=METHODS)
    u = p.float("measurement_sigma", None, positive=True)
    try:
        unit = p.data.get("unit")    # the factor's unit: a header's unit (d [um]) is converted to it
        unit = unit if isinstance(unit, str) else None
        statistics = []
        if is_inspection_file(path):   # QIF / DFQ: ``column`` names the characteristic
            if sheet is not None:
                raise p.error("sheet", f"a sheet is read from an xlsx file, not from {path.name}")
            got, _, statistics = characteristic_values(path, col, unit)
            values = _clean(got)
        else:
            values = read_measurements(path, col, sheet=sheet, unit=unit)
    except InputError as exc:
        if exc.key in (None, "-"):   # the file as a whole (missing, unreadable): the spec's key
            raise p.error("data", f"{exc.reason}: {exc.file}") from None
        raise                        # a cell of the data file: that file, row and column
    origin = f"{method} of {path.name}" + (f"[{col}]" if col is not None else "")
    record = dict(values=values, data=str(p.data["data"]), column=col, sheet=sheet, method=method,
                  measurement_sigma=u, file_statistics=statistics)
    try:
        if method == "empirical":
            d = empirical(values, interpolate=p.bool("interpolate", False), measurement_sigma=u, origin=origin)
            return d, Measured(**record)
        if method == "kde":
            bw = p.raw("bandwidth", "scott")
            if not isinstance(bw, (str, int, float)) or isinstance(bw, bool):
                raise p.error("bandwidth", "expected scott, silverman or a number")
            return kde(values, bandwidth=bw, measurement_sigma=u, origin=origin), Measured(**record)
        fams = p.strs("families", list(DEFAULT_FAMILIES))
        family = p.str("family", None)
        loc = p.float("location", 0.0)
        rep = fit(values, families=fams, location=loc, measurement_sigma=u, gof=None, origin=origin)
        d = rep.distribution(family)
        return d, Measured(**record, fit=rep, family=rep.candidate(family).family)
    except SpecError:
        raise
    except InputError as exc:
        raise p.error("family" if "was not fitted" in exc.reason else "data", exc.reason) from None


def _band(dist) -> float | None:
    """The band a measured factor's numbers are shown to resolve (:mod:`rvtol.precision`), where it has one."""
    t = getattr(dist, "tolerance", None)          # a distribution without a band: four significant digits
    return float(t) if isinstance(t, (int, float)) and math.isfinite(t) and t > 0 else None


def evidence(m: Measured, dist, *, n_mc: int = 499, seed: int | None = None) -> dict:
    """What a report shows of a measured factor (``dist`` its distribution):

    ``summary`` (one row: source, method, n, mean, s, the gauge share u²/s²), ``ranking`` (the AIC
    table of the fitted families, method fit), ``gof`` (the Anderson–Darling test with parametric
    bootstrap of the family used, ``n_mc`` samples from ``seed``; method fit) and ``qq`` (Q-Q data of
    the values the distribution was built from against it; fit and kde — the empirical distribution
    *is* its data).
    """
    import pandas as pd

    x = m.values
    gauge = (m.measurement_sigma ** 2 / float(np.var(x, ddof=1))) if m.measurement_sigma else 0.0
    out: dict = {"summary": pd.DataFrame([{
        "source": m.source, "method": m.method + (f" ({m.family})" if m.family else ""), "n": m.n,
        "mean": float(np.mean(x)), "s": float(np.std(x, ddof=1)), "min": float(np.min(x)), "max": float(np.max(x)),
        "gauge u²/s²": gauge, "distribution": dist.describe(number=lambda v: shown(v, _band(dist)))}]),
        "ranking": None, "gof": None, "qq": None,
        "file_statistics": pd.DataFrame(m.file_statistics) if m.file_statistics else None}
    if m.fit is not None:
        c = m.fit.candidate(m.family)
        out["ranking"] = m.fit.table()
        out["gof"] = _gof(m.fit.data, c, m.fit.location, n_mc, seed)
        out["qq"] = qq_data(m.fit.data, c.frozen)
    elif m.method == "kde":
        out["qq"] = qq_data(dist.data, dist)
    return out


def measured_from_params(p, base_dir: Path | str = ".") -> object:
    """The distribution of :func:`measured_factor` alone."""
    return measured_factor(p, base_dir)[0]
