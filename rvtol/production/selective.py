"""Selective assembly inside the Monte Carlo: grading into classes, matching rules, stock, class limits.

A **graded part** (pins, needle rollers, bearings) comes off production with a size drawn from its
**supply** distribution (by default the spec's distribution of the factor it fills), is measured
and sorted into ``k`` **classes** by limits on its size.  At assembly a **matching rule** says, per
reducer, which class the part must come from:

* ``TargetRule`` — the class that holds a target size computed from the reducer's *measured*
  factors (an expression, base units), e.g. the pin size that brings the pin-stage clearance to a
  target from the measured cycloid profiles, pin-circle radius and groove diameter; a target
  beyond the outer limits takes the end class;
* ``ClassToClassRule`` — the class with the same index as the mating part's class (classic
  selective assembly of a hole and a shaft: both graded into classes of equal probability).

The rule is simulated **inside the Monte Carlo**, as a transform of each sample before it is
evaluated (:func:`assemble`): the graded factor's column is replaced by the part the rule picks,
every other factor stays as sampled (common random numbers between graded and ungraded runs).
"Measured" here means the sample's true values: grading and targets assume a perfect gauge (no
measurement error is added), so the simulated yields are an upper bound of what grading gains.

* **Unlimited supply** (no stock): the part is drawn from the supply *within its class*,
  ``x = F⁻¹(F(lo_c) + u (F(hi_c) − F(lo_c)))`` with ``u`` the sample's own uniform for that factor —
  so ungraded (``k = 1``) gives back the sample exactly.
* **Finite stock**: a batch of parts is drawn from the supply (sub-stream ``selective_stock``) and
  graded; reducers are built in sample order and take the first part of the wanted class in batch
  order; when that class is empty, the part comes from the class whose centre (conditional median)
  is nearest the target (ties: the lower class).  What is left in each class afterwards is counted
  exactly (:class:`StockBalance`, :func:`take_from_stock`).

Several factors may take parts of one family (e.g. six needle sets per reducer, each with its own
target): every reducer takes one part per factor, in the order the factors are given.

:func:`optimise_limits` searches the class limits (their cumulative probabilities under the supply,
so they stay ordered) that maximise a smoothed yield on a fixed design (Nelder–Mead; common random
numbers make the objective a smooth function of the limits under an unlimited supply).
"""
from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np
import pandas as pd
from scipy import optimize, stats

from .. import units
from ..expressions import Expression
from ..spec import Factor, ToleranceSpec

_U_EPS = 2.0 ** -53


# --------------------------------------------------------------------------- supply and classes
@dataclass(frozen=True)
class Supply:
    """The size distribution of the parts before grading (a factor's distribution; base units out)."""

    factor: Factor

    def ppf(self, p) -> np.ndarray:
        return units.to_base(np.asarray(self.factor.dist.ppf(p), dtype=float), self.factor.unit)

    def cdf(self, x) -> np.ndarray:
        return np.asarray(self.factor.dist.cdf(units.from_base(np.asarray(x, float), self.factor.unit)), float)

    def same_as(self, f: Factor) -> bool:
        return self.factor.dist == f.dist and units.canonical(self.factor.unit) == units.canonical(f.unit)


@dataclass(frozen=True)
class Classes:
    """``k`` classes by ``k + 1`` increasing limits (base units; the outer ones may be ±inf)."""

    edges: np.ndarray

    def __post_init__(self):
        e = np.asarray(self.edges, dtype=float)
        if e.ndim != 1 or e.size < 2 or np.any(np.isnan(e)) or not np.all(np.diff(e) > 0):
            raise ValueError(f"class limits must increase strictly, got {e}")
        object.__setattr__(self, "edges", e)

    @property
    def k(self) -> int:
        return self.edges.size - 1

    def of(self, x) -> np.ndarray:
        """Class index (0 … k − 1) of sizes ``x``; beyond the outer limits, the end classes."""
        return np.searchsorted(self.edges[1:-1], np.asarray(x, float), side="right").astype(int)

    def probabilities(self, supply: Supply) -> np.ndarray:
        return np.diff(self.cumulative(supply))

    def cumulative(self, supply: Supply) -> np.ndarray:
        c = supply.cdf(self.edges)
        c[0], c[-1] = 0.0, 1.0
        return c

    def centres(self, supply: Supply) -> np.ndarray:
        """The conditional median of each class under the supply."""
        c = self.cumulative(supply)
        return supply.ppf(np.clip(0.5 * (c[:-1] + c[1:]), _U_EPS, 1.0 - _U_EPS))

    @classmethod
    def from_cumulative(cls, supply: Supply, cum: Sequence[float]) -> "Classes":
        """Limits at the cumulative probabilities ``cum`` (the ``k − 1`` inner ones) of the supply."""
        inner = supply.ppf(np.asarray(cum, float))
        return cls(np.concatenate([[-np.inf], np.atleast_1d(inner), [np.inf]]))

    @classmethod
    def equal_probability(cls, supply: Supply, k: int) -> "Classes":
        if k < 1:
            raise ValueError(f"need k >= 1 classes, got {k}")
        return cls.from_cumulative(supply, np.arange(1, k) / k)

    @classmethod
    def from_limits(cls, inner: Sequence[float]) -> "Classes":
        """Classes from the inner limits (base units); the outer classes are open."""
        return cls(np.concatenate([[-np.inf], np.asarray(inner, float), [np.inf]]))

    def describe(self, unit: str, supply: Supply) -> pd.DataFrame:
        """Per class: limits in ``unit`` (the outer ones at the supply's support), probability, centre."""
        lo_s, hi_s = (float(v) for v in supply.factor.dist.frozen.support())
        e = units.from_base(self.edges, unit)
        e[0] = max(e[0], units.convert(lo_s, supply.factor.unit, unit))
        e[-1] = min(e[-1], units.convert(hi_s, supply.factor.unit, unit))
        return pd.DataFrame({"class": np.arange(1, self.k + 1), f"from [{unit}]": e[:-1], f"to [{unit}]": e[1:],
                             "probability": self.probabilities(supply),
                             f"centre [{unit}]": units.from_base(self.centres(supply), unit)})


# --------------------------------------------------------------------------- matching rules
@dataclass(frozen=True)
class TargetRule:
    """The class holding a target size (an expression of the reducer's named values, base units)."""

    expression: Expression

    def wanted(self, env: dict, classes: Classes, supply: Supply, n: int) -> tuple[np.ndarray, np.ndarray]:
        t = np.broadcast_to(np.asarray(self.expression.evaluate(env), float), (n,)).copy()
        return classes.of(t), t

    @property
    def names(self) -> tuple[str, ...]:
        return self.expression.names

    def describe(self) -> str:
        return f"the class holding the target {self.expression.text}"


@dataclass(frozen=True)
class ClassToClassRule:
    """The class with the index of the mating part's class; the mating part is graded by the same
    cumulative probabilities under its own distribution (equal-probability classes match count for
    count)."""

    partner: str
    partner_supply: Supply

    def partner_classes(self, classes: Classes, supply: Supply) -> Classes:
        return Classes.from_cumulative(self.partner_supply, classes.cumulative(supply)[1:-1])

    def wanted(self, env: dict, classes: Classes, supply: Supply, n: int) -> tuple[np.ndarray, np.ndarray]:
        c = self.partner_classes(classes, supply).of(np.broadcast_to(env[self.partner], (n,)))
        return c, classes.centres(supply)[c]

    @property
    def names(self) -> tuple[str, ...]:
        return (self.partner,)

    def describe(self) -> str:
        return f"class to class with {self.partner}"


@dataclass(frozen=True)
class GradedPart:
    """A graded part family: the factors it fills (one part each per reducer), its supply, a rule each."""

    factors: tuple[str, ...]
    supply: Supply
    rules: tuple

    def __post_init__(self):
        if len(self.rules) != len(self.factors) or not self.factors:
            raise ValueError("one matching rule per graded factor")
        for r in self.rules:
            bad = set(r.names) & set(self.factors)
            if bad:
                raise ValueError(f"a matching rule reads the graded factor {sorted(bad)[0]!r} itself")


# --------------------------------------------------------------------------- stock
@dataclass
class StockTake:
    """Which batch part each demand got (index), from which class, and what is left per class."""

    taken: np.ndarray
    given: np.ndarray
    leftover: np.ndarray


def take_from_stock(batch_classes: Sequence[int], k: int, wanted: Sequence[int],
                    prefer: Callable[[int, np.ndarray], int] | None = None) -> StockTake:
    """Serve the demands ``wanted`` (class per demand, in order) from a batch whose parts are in
    ``batch_classes`` (in batch order).  A demand takes the first part of its class still in stock;
    when the class is empty, the class ``prefer(d, classes_with_stock)`` — by default the nearest
    class index, ties to the lower.  Raises ValueError when the batch runs out."""
    queues = [deque() for _ in range(k)]
    for i, c in enumerate(batch_classes):
        queues[int(c)].append(i)
    left = np.array([len(q) for q in queues])
    taken = np.empty(len(wanted), int)
    given = np.empty(len(wanted), int)
    for d, c in enumerate(wanted):
        c = int(c)
        if not queues[c]:
            avail = np.flatnonzero(left > 0)
            if avail.size == 0:
                raise ValueError(f"the stock of {len(batch_classes)} parts ran out at demand {d + 1}")
            c = int(prefer(d, avail)) if prefer is not None else int(avail[np.argmin(np.abs(avail - c))])
        taken[d] = queues[c].popleft()
        given[d] = c
        left[c] -= 1
    return StockTake(taken, given, left)


@dataclass
class StockBalance:
    """Parts per class: made (graded batch), wanted by the rule, used, left over; substitutions."""

    made: np.ndarray
    wanted: np.ndarray
    used: np.ndarray
    leftover: np.ndarray
    substituted: int

    def to_frame(self) -> pd.DataFrame:
        return pd.DataFrame({"class": np.arange(1, self.made.size + 1), "made": self.made, "wanted": self.wanted,
                             "used": self.used, "left over": self.leftover})


@dataclass
class Assembly:
    """Samples after selective assembly, and per reducer and graded factor the class wanted and given."""

    X: np.ndarray
    wanted: np.ndarray        # [n, factors]
    given: np.ndarray
    target: np.ndarray
    stock: StockBalance | None = None

    @property
    def substituted(self) -> int:
        return int((self.wanted != self.given).sum())


def stock_size(ratio: float, parts_used: int) -> int:
    """Parts in a graded batch: ``ratio`` per part used, rounded up (``1.1 × 200`` is 220, not 221)."""
    return int(np.ceil(round(ratio * parts_used, 9)))


def stock_batch(supply: Supply, size: int, seed: int | None) -> np.ndarray:
    """A production batch of ``size`` part sizes (base units) from the sub-stream ``selective_stock``."""
    from ..sampling import substream

    u = substream(seed, "selective_stock").random(size)
    return supply.ppf(np.clip(u, _U_EPS, 1.0 - _U_EPS))


def assemble(X: np.ndarray, spec: ToleranceSpec, part: GradedPart, classes: Classes, env: dict,
             stock: np.ndarray | None = None) -> Assembly:
    """Selective assembly of every sample (row of ``X``, base units; module docstring).

    ``env``: the named values the rules read (factors and mapped quantities of the *as-drawn*
    samples, base units); ``stock``: a batch of part sizes (base units), or None for an unlimited
    supply.
    """
    n = len(X)
    cols = [spec.index(f) for f in part.factors]
    wanted = np.empty((n, len(cols)), int)
    target = np.empty((n, len(cols)))
    for s, rule in enumerate(part.rules):
        wanted[:, s], target[:, s] = rule.wanted(env, classes, part.supply, n)
    Xg = np.array(X, dtype=float, copy=True)
    if stock is None:
        c = classes.cumulative(part.supply)
        for s, j in enumerate(cols):
            u = _uniform(spec.factors[j], X[:, j])
            w = wanted[:, s]
            Xg[:, j] = part.supply.ppf(np.clip(c[w] + u * (c[w + 1] - c[w]), _U_EPS, 1.0 - _U_EPS))
        return Assembly(Xg, wanted, wanted.copy(), target)
    batch_classes = classes.of(stock)
    centres = classes.centres(part.supply)
    flat_target = target.reshape(-1)

    def nearest_centre(d: int, avail: np.ndarray) -> int:
        return int(avail[np.argmin(np.abs(centres[avail] - flat_target[d]))])

    take = take_from_stock(batch_classes, classes.k, wanted.reshape(-1), nearest_centre)
    given = take.given.reshape(n, len(cols))
    vals = np.asarray(stock, float)[take.taken].reshape(n, len(cols))
    for s, j in enumerate(cols):
        Xg[:, j] = vals[:, s]
    k = classes.k
    balance = StockBalance(np.bincount(batch_classes, minlength=k), np.bincount(wanted.reshape(-1), minlength=k),
                           np.bincount(take.given, minlength=k), take.leftover,
                           int((take.given != wanted.reshape(-1)).sum()))
    return Assembly(Xg, wanted, given, target, balance)


def ungraded(X: np.ndarray, spec: ToleranceSpec, part: GradedPart) -> np.ndarray:
    """The samples with parts picked at random from the supply (the sample itself when the supply is
    the factor's own distribution): the baseline of a comparison, with the same random numbers."""
    Xg = np.array(X, dtype=float, copy=True)
    for f in part.factors:
        j = spec.index(f)
        if not part.supply.same_as(spec.factors[j]):
            Xg[:, j] = part.supply.ppf(_uniform(spec.factors[j], X[:, j]))
    return Xg


def _uniform(f: Factor, x_base: np.ndarray) -> np.ndarray:
    """The uniform behind a sampled value: F(x) under the factor's distribution (the CRN of the sample)."""
    return np.clip(f.dist.cdf(units.from_base(x_base, f.unit)), _U_EPS, 1.0 - _U_EPS)


def named_values(model, spec: ToleranceSpec, X: np.ndarray) -> dict[str, np.ndarray]:
    """Factors and, in a composed study, its mapped quantities for the rows of ``X`` (base units) —
    without evaluating any model stage."""
    n = len(X)
    env = {name: X[:, j] for j, name in enumerate(spec.names)}
    for q in getattr(model, "quantities", ()):
        env[q.name] = np.broadcast_to(np.asarray(q.expression.evaluate(env), float), (n,))
    return env


def known_names(model, spec: ToleranceSpec) -> set[str]:
    """The names a matching rule may read: the factors and the composed study's quantities."""
    return set(spec.names) | {q.name for q in getattr(model, "quantities", ())}


# --------------------------------------------------------------------------- yield and optimiser
def smoothed_yield(Y: np.ndarray, ok: np.ndarray, requirements, outputs: Sequence[str], h: Sequence[float]) -> float:
    """Mean over samples of Π_r Φ((U_r − y)/h_r)·Φ((y − L_r)/h_r) (failed samples: 0) — the yield with the
    indicator smoothed by a normal kernel of bandwidth ``h_r``, a smooth function of the limits."""
    w = ok.astype(float)
    for r, hr in zip(requirements, h):
        y = np.where(ok, Y[:, list(outputs).index(r.output)], 0.0)
        if r.upper is not None:
            w = w * stats.norm.cdf((r.upper - y) / hr)
        if r.lower is not None:
            w = w * stats.norm.cdf((y - r.lower) / hr)
    return float(w.mean())


def bandwidths(Y: np.ndarray, ok: np.ndarray, requirements, outputs: Sequence[str]) -> list[float]:
    """Silverman's rule ``0.9 min(σ, IQR/1.34) n^(−1/5)`` per requirement's output (a floor of 1e-12)."""
    out = []
    for r in requirements:
        y = Y[ok, list(outputs).index(r.output)]
        if y.size < 2:
            out.append(1.0)
            continue
        q75, q25 = np.quantile(y, [0.75, 0.25])
        s = min(float(np.std(y, ddof=1)), (q75 - q25) / 1.34) or float(np.std(y, ddof=1))
        out.append(max(0.9 * s * y.size ** -0.2, 1e-12))
    return out


@dataclass
class LimitOptimisation:
    """The optimised classes, the objective at the start (equal probability) and at the end, the trace."""

    classes: Classes
    start: float
    best: float
    evaluations: int
    history: list[float] = field(default_factory=list)
    message: str = ""


def cumulative_from_parameters(theta: np.ndarray) -> np.ndarray:
    """``k − 1`` parameters -> the ``k − 1`` inner cumulative probabilities (softmax weights of
    ``[0, θ]``): any θ gives ordered limits; θ = 0 gives equal probabilities."""
    z = np.concatenate([[0.0], np.asarray(theta, float)])
    w = np.exp(z - z.max())
    return np.cumsum(w / w.sum())[:-1]


def optimise_limits(objective: Callable[[Classes], float], supply: Supply, k: int, *,
                    max_evaluations: int = 60, step: float = 0.5) -> LimitOptimisation:
    """Maximise ``objective(classes)`` over the limits of ``k`` classes (Nelder–Mead from equal
    probabilities, in the parameters of :func:`cumulative_from_parameters`)."""
    if k < 2:
        raise ValueError("optimising class limits needs k >= 2")
    history: list[float] = []

    def f(theta):
        v = objective(Classes.from_cumulative(supply, cumulative_from_parameters(theta)))
        history.append(v)
        return -v

    x0 = np.zeros(k - 1)
    simplex = np.vstack([x0] + [x0 + step * np.eye(k - 1)[i] for i in range(k - 1)])
    res = optimize.minimize(f, x0, method="Nelder-Mead",
                            options={"maxfev": max_evaluations, "initial_simplex": simplex, "xatol": 1e-3,
                                     "fatol": 1e-6})
    classes = Classes.from_cumulative(supply, cumulative_from_parameters(res.x))
    return LimitOptimisation(classes, history[0], float(-res.fun), len(history), history, str(res.message))
