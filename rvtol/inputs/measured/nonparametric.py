"""Distributions that are the measured values themselves: resampling them, or their kernel density.

Each has the interface rvtol samples through (``ppf`` of a uniform u, ``cdf``, ``mean``, ``std``,
``tolerance``, ``scaled``, ``describe``), so it plugs into :class:`rvtol.spec.Factor` and the
inverse-CDF sampling of :mod:`rvtol.sampling`:

* :func:`empirical` — the inverse empirical CDF: ``ppf(u) = x₍⌈n·u⌉₎``, i.e. resampling the
  measured parts (a bootstrap); ``interpolate=True`` interpolates linearly between order
  statistics at the Hazen plotting positions (i − ½)/n instead (no new extremes either way).
* :func:`kde` — a Gaussian kernel density (bandwidth by Scott's or Silverman's rule as in
  ``scipy.stats.gaussian_kde``, or given): its CDF is the mean of the kernels' normal CDFs,
  exact; ``ppf`` inverts it numerically (a tabulated bracket, then safeguarded Newton on
  the exact CDF — or on the exact survival function in the upper half, so the tails keep
  their precision — to 1e-12 of the bandwidth); each u is solved on its own, so results do
  not depend on which other samples share the call.

Both run on the values corrected for the gauge's uncertainty (``measurement_sigma``:
:mod:`rvtol.inputs.measured.values`).
"""
from __future__ import annotations

import math

import numpy as np
from scipy import special, stats

from ...distributions import coverage
from ...errors import InputError
from .values import clean_values, deconvolve

_CHUNK = 1 << 22   # elements per block in the KDE sums


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
        super().__init__(clean_values(data), gauge_fraction, origin)
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
    """The empirical distribution of measured values (optionally deconvolved, :mod:`rvtol.inputs.measured.values`)."""
    x, ratio = deconvolve(values, measurement_sigma)
    return EmpiricalDistribution(x, interpolate, ratio, origin)


# ----------------------------------------------------------------------------- kernel density
class KDEDistribution(_DataDistribution):
    """Gaussian kernel density of measured values with an exact CDF and a numerically inverted ppf."""

    kind = "kde"
    _GRID = 2049
    _TAIL = 9.0     # Φ(−9) ≈ 1e-19 < the smallest u rvtol draws (2^-53)

    def __init__(self, data, bandwidth: float, gauge_fraction: float = 0.0, origin: str = ""):
        super().__init__(clean_values(data), gauge_fraction, origin)
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
