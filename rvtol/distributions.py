"""Distributions of tolerance factors.

A :class:`Distribution` is a frozen description (kind + canonical
parameters, in the factor's own unit) backed by a ``scipy.stats`` frozen
distribution for ``ppf``/``cdf``/moments.  :func:`from_params` reads the
forms an engineer writes in a spec file:

========== ==================================================================
kind       keys (besides ``shift``, an optional mean shift added to the value)
========== ==================================================================
normal     ``mean`` (0) and ``sigma``; or ``tolerance`` T (band ±T/2) read at
           ``sigma_level`` (3, i.e. T/2 = 3σ); or ``lower``/``upper`` band
uniform    ``lower``/``upper``; or ``mean`` ± ``tolerance``/2
truncnorm  ``mean``, ``sigma`` or ``tolerance`` (+``sigma_level``), truncated
           at ``lower``/``upper`` (default mean ± T/2)
triangular ``lower``, ``upper``, ``mode`` (default mid); or ``mean`` ±
           ``tolerance``/2
rayleigh   ``sigma``; or ``tolerance``: the value not exceeded with the
           coverage of ±``sigma_level``·σ of a normal (99.73 % at 3)
lognormal  ``mean`` and ``sigma`` of the variable; or ``median`` and ``shape``
weibull    ``shape`` and ``scale``; or ``shape`` and ``tolerance`` (coverage
           quantile as for rayleigh)
========== ==================================================================
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from scipy import stats

from .errors import SpecError

KINDS = ("normal", "uniform", "truncnorm", "triangular", "rayleigh", "lognormal", "weibull")

#: kinds whose values are magnitudes (never negative before the shift)
ONE_SIDED = ("rayleigh", "lognormal", "weibull")


def coverage(sigma_level: float) -> float:
    """Probability inside ±sigma_level·σ of a normal (0.9973 at 3)."""
    return float(2.0 * stats.norm.cdf(sigma_level) - 1.0)


@dataclass(frozen=True)
class Distribution:
    """One factor distribution.  ``params`` are canonical (see ``_frozen``)."""

    kind: str
    params: tuple[tuple[str, float], ...]
    shift: float = 0.0
    sigma_level: float = 3.0
    origin: str = field(default="", compare=False)  # how it was written, for reports

    # -- construction helpers ---------------------------------------------
    @classmethod
    def make(cls, kind: str, shift: float = 0.0, sigma_level: float = 3.0, origin: str = "", **params):
        if kind not in KINDS:
            raise ValueError(f"unknown distribution {kind!r}")
        return cls(kind, tuple(sorted((k, float(v)) for k, v in params.items())), float(shift),
                   float(sigma_level), origin)

    @property
    def p(self) -> dict[str, float]:
        return dict(self.params)

    @cached_property
    def frozen(self):
        """The ``scipy.stats`` frozen distribution (shift included)."""
        p, s = self.p, self.shift
        if self.kind == "normal":
            return stats.norm(loc=p["mean"] + s, scale=p["sigma"])
        if self.kind == "uniform":
            return stats.uniform(loc=p["lower"] + s, scale=p["upper"] - p["lower"])
        if self.kind == "truncnorm":
            a = (p["lower"] - p["mean"]) / p["sigma"]
            b = (p["upper"] - p["mean"]) / p["sigma"]
            return stats.truncnorm(a, b, loc=p["mean"] + s, scale=p["sigma"])
        if self.kind == "triangular":
            w = p["upper"] - p["lower"]
            return stats.triang((p["mode"] - p["lower"]) / w, loc=p["lower"] + s, scale=w)
        if self.kind == "rayleigh":
            return stats.rayleigh(loc=s, scale=p["sigma"])
        if self.kind == "lognormal":
            return stats.lognorm(p["shape"], loc=s, scale=p["median"])
        if self.kind == "weibull":
            return stats.weibull_min(p["shape"], loc=s, scale=p["scale"])
        raise AssertionError(self.kind)

    # -- the things the engine needs ---------------------------------------
    def ppf(self, u):
        return self.frozen.ppf(u)

    def cdf(self, x):
        return self.frozen.cdf(x)

    def pdf(self, x):
        return self.frozen.pdf(x)

    @property
    def mean(self) -> float:
        return float(self.frozen.mean())

    @property
    def std(self) -> float:
        return float(self.frozen.std())

    @property
    def one_sided(self) -> bool:
        return self.kind in ONE_SIDED

    @property
    def tolerance(self) -> float:
        """The full tolerance band T this distribution stands for.

        Two-sided kinds: the band width (normal: 2·sigma_level·σ).  One-sided
        magnitudes: the coverage quantile above the shift.
        """
        p = self.p
        if self.kind == "normal":
            return 2.0 * self.sigma_level * p["sigma"]
        if self.kind in ("uniform", "truncnorm", "triangular"):
            return p["upper"] - p["lower"]
        return float(self.frozen.ppf(coverage(self.sigma_level)) - self.shift)

    @property
    def band(self) -> tuple[float, float]:
        """The tolerance band ``(low, high)`` this distribution stands for (``high − low`` = :attr:`tolerance`).

        Bounded kinds (uniform, triangular, truncnorm): the support.  One-sided
        magnitudes (rayleigh, lognormal, weibull): from the lower end of the
        support to the coverage quantile.  Normal: the quantiles at
        ±``sigma_level``·σ, i.e. mean ± T/2.  This is the one definition of a
        factor's band (five-point steps, high/low tables, worst case, allocation).
        """
        lo, hi = (float(v) for v in self.frozen.support())
        c = coverage(self.sigma_level)
        if self.one_sided:
            return lo, float(self.ppf(c))
        if np.isfinite(lo) and np.isfinite(hi):
            return lo, hi
        q = 0.5 * (1.0 - c)
        return float(self.ppf(q)), float(self.ppf(1.0 - q))

    @property
    def half_band(self) -> float:
        """The tolerance ±t: ``T/2`` of a two-sided kind, the coverage value ``T`` of a one-sided magnitude."""
        return float(self.tolerance if self.one_sided else self.tolerance / 2.0)

    def scaled(self, f: float) -> "Distribution":
        """The same shape with its spread (tolerance) multiplied by ``f`` > 0.

        Two-sided kinds scale about their centre (mean/mode); one-sided
        magnitudes scale their values (a tighter runout tolerance).
        """
        if not f > 0:
            raise ValueError("scale factor must be > 0")
        p = self.p
        if self.kind == "normal":
            q = dict(mean=p["mean"], sigma=p["sigma"] * f)
        elif self.kind == "uniform":
            c, h = 0.5 * (p["lower"] + p["upper"]), 0.5 * (p["upper"] - p["lower"]) * f
            q = dict(lower=c - h, upper=c + h)
        elif self.kind == "truncnorm":
            m = p["mean"]
            q = dict(mean=m, sigma=p["sigma"] * f, lower=m + (p["lower"] - m) * f,
                     upper=m + (p["upper"] - m) * f)
        elif self.kind == "triangular":
            m = p["mode"]
            q = dict(mode=m, lower=m + (p["lower"] - m) * f, upper=m + (p["upper"] - m) * f)
        elif self.kind == "rayleigh":
            q = dict(sigma=p["sigma"] * f)
        elif self.kind == "lognormal":
            q = dict(median=p["median"] * f, shape=p["shape"])
        else:
            q = dict(shape=p["shape"], scale=p["scale"] * f)
        return Distribution.make(self.kind, shift=self.shift, sigma_level=self.sigma_level,
                                 origin=f"{self.origin} ×{f:.4g}" if self.origin else "", **q)

    def describe(self, unit: str = "") -> str:
        """Short human description for tables, e.g. ``normal(μ=0, σ=1.667) µm``."""
        p = self.p
        g = lambda x: f"{x:.4g}"  # noqa: E731
        if self.kind == "normal":
            s = f"normal(μ={g(p['mean'])}, σ={g(p['sigma'])})"
        elif self.kind == "uniform":
            s = f"uniform[{g(p['lower'])}, {g(p['upper'])}]"
        elif self.kind == "truncnorm":
            s = f"truncnorm(μ={g(p['mean'])}, σ={g(p['sigma'])}; [{g(p['lower'])}, {g(p['upper'])}])"
        elif self.kind == "triangular":
            s = f"triangular({g(p['lower'])}, {g(p['mode'])}, {g(p['upper'])})"
        elif self.kind == "rayleigh":
            s = f"rayleigh(σ={g(p['sigma'])})"
        elif self.kind == "lognormal":
            s = f"lognormal(median={g(p['median'])}, s={g(p['shape'])})"
        else:
            s = f"weibull(k={g(p['shape'])}, λ={g(p['scale'])})"
        if self.shift:
            s += f" + {g(self.shift)}"
        return f"{s} {unit}".strip()


def from_params(p) -> Distribution:
    """Read a distribution from a factor table (a :class:`rvtol.params.Params`)."""
    kind = p.str("dist", choices=KINDS)
    shift = p.float("shift", 0.0)
    level = p.float("sigma_level", 3.0, positive=True)
    origin = ", ".join(f"{k}={p.data[k]}" for k in ("dist", "mean", "sigma", "tolerance", "lower", "upper",
                                                     "mode", "median", "shape", "scale") if k in p.data)

    def make(**kw) -> Distribution:
        return Distribution.make(kind, shift=shift, sigma_level=level, origin=origin, **kw)

    def band_order(lo: float, hi: float) -> None:
        if not lo < hi:
            raise p.error("upper", f"upper ({hi}) must be greater than lower ({lo})")

    has = lambda *ks: any(k in p for k in ks)  # noqa: E731

    if kind == "normal":
        if has("lower", "upper"):
            lo, hi = p.float("lower"), p.float("upper")
            band_order(lo, hi)
            return make(mean=0.5 * (lo + hi), sigma=0.5 * (hi - lo) / level)
        mean = p.float("mean", 0.0)
        if "sigma" in p:
            return make(mean=mean, sigma=p.float("sigma", positive=True))
        if "tolerance" in p:
            return make(mean=mean, sigma=0.5 * p.float("tolerance", positive=True) / level)
        raise p.error("sigma", "normal needs 'sigma', 'tolerance' or 'lower'/'upper'")
    if kind == "uniform":
        if has("lower", "upper"):
            lo, hi = p.float("lower"), p.float("upper")
        else:
            mean, t = p.float("mean", 0.0), p.float("tolerance", positive=True)
            lo, hi = mean - t / 2, mean + t / 2
        band_order(lo, hi)
        return make(lower=lo, upper=hi)
    if kind == "truncnorm":
        mean = p.float("mean", 0.0)
        t = p.float("tolerance", None, positive=True)
        sigma = p.float("sigma", None, positive=True)
        if sigma is None:
            if t is None:
                raise p.error("sigma", "truncnorm needs 'sigma' or 'tolerance'")
            sigma = 0.5 * t / level
        if has("lower", "upper") or t is None:
            lo, hi = p.float("lower"), p.float("upper")
        else:
            lo, hi = mean - t / 2, mean + t / 2
        band_order(lo, hi)
        if not lo <= mean <= hi:
            raise p.error("mean", f"mean {mean} is outside the truncation [{lo}, {hi}]")
        return make(mean=mean, sigma=sigma, lower=lo, upper=hi)
    if kind == "triangular":
        if has("lower", "upper"):
            lo, hi = p.float("lower"), p.float("upper")
        else:
            mean, t = p.float("mean", 0.0), p.float("tolerance", positive=True)
            lo, hi = mean - t / 2, mean + t / 2
        band_order(lo, hi)
        mode = p.float("mode", 0.5 * (lo + hi))
        if not lo <= mode <= hi:
            raise p.error("mode", f"mode {mode} is outside [{lo}, {hi}]")
        return make(lower=lo, upper=hi, mode=mode)
    if kind == "rayleigh":
        if "sigma" in p:
            return make(sigma=p.float("sigma", positive=True))
        t = p.float("tolerance", positive=True)
        return make(sigma=t / math.sqrt(-2.0 * math.log(1.0 - coverage(level))))
    if kind == "lognormal":
        if "median" in p or "shape" in p:
            return make(median=p.float("median", positive=True), shape=p.float("shape", positive=True))
        m, s = p.float("mean", positive=True), p.float("sigma", positive=True)
        shape = math.sqrt(math.log1p((s / m) ** 2))
        return make(median=m / math.sqrt(1.0 + (s / m) ** 2), shape=shape)
    # weibull
    k = p.float("shape", positive=True)
    if "scale" in p:
        return make(shape=k, scale=p.float("scale", positive=True))
    t = p.float("tolerance", positive=True)
    return make(shape=k, scale=t / (-math.log(1.0 - coverage(level))) ** (1.0 / k))


def check_finite_samples(x: np.ndarray, name: str) -> None:
    if not np.all(np.isfinite(x)):
        raise SpecError("distribution produced non-finite samples", key=name)
