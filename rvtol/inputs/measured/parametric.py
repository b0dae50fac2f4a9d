"""Parametric fits to measured values: candidate families by maximum likelihood, ranked, and tested.

:func:`fit` — maximum-likelihood fits (``scipy.stats`` ``fit``) of candidate families —
normal, lognormal, Weibull, gamma, Rayleigh, uniform — ranked by AIC = 2k − 2 ln L (k the
number of fitted parameters; the positive families are fitted with their location fixed,
0 by default, as rvtol's one-sided kinds are).  The best fit (or any candidate) becomes
an ordinary :class:`rvtol.distributions.Distribution` and a factor table for the spec
(gamma, which rvtol's spec has no kind for, becomes a :class:`FrozenDistribution`).  The
families are fitted to the values corrected for the gauge's uncertainty (``measurement_sigma``:
:mod:`rvtol.inputs.measured.values`).

Goodness of fit.  Every candidate gets the Kolmogorov–Smirnov distance D with scipy's
p-value *for fully specified parameters*; because the parameters were estimated from the
same data that p-value is too large (the test is conservative, Lilliefors' point) and is
reported as such, for ranking only.  The test to judge a fit by is **Anderson–Darling with a
parametric bootstrap** (``scipy.stats.goodness_of_fit``: refit on each Monte Carlo sample,
so the estimation is accounted for): AD weights the tails, where the ppm of a tolerance
analysis live, more than KS does (for the normal family scipy evaluates it with the sample
standard deviation of ddof = 1, as Stephens' tables do).  For the uniform family, whose MLE puts the extreme
points on the support's ends (AD = ∞), the Cramér–von Mises statistic is used instead
(:func:`gof_test`).  :meth:`FitReport.qq` gives Q-Q plot data (Hazen positions).
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy import stats

from ...distributions import Distribution, coverage
from ...errors import InputError
from .values import deconvolve

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
            tests.append(gof_test(x, c, location, n_mc, seed))
    return FitReport(x, tuple(cands), skipped, tuple(tests), ratio, origin, location)


def gof_test(x: np.ndarray, c: Candidate, location, n_mc: int, seed: int) -> GoodnessOfFit:
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
