"""Multi-fidelity Monte Carlo: an expensive model's mean and yield from few of its runs and many of a cheap one.

The 20-DOF outputs (lost motion and TE of the torsion and TE stages) cost seconds per sample; rvtol also has cheap
models of the same quantities (doc 001's statistical lost-motion screening, the stack-up).  Where the cheap model
correlates with the expensive one, its many samples carry information about the expensive mean.  The MFMC
estimator of Peherstorfer, Willcox & Gunzburger (2016) combines models f₁ (high fidelity), f₂ … f_K ordered by
decreasing correlation |ρ₁ₖ| with f₁, on **nested** samples (the first mₖ₋₁ inputs of model k are model k−1's):

    ŝ = ȳ₁(m₁) + Σₖ₌₂ᴷ αₖ (ȳₖ(mₖ) − ȳₖ(mₖ₋₁)),      αₖ = ρ₁ₖ σ₁ / σₖ,

unbiased for E[f₁] whatever the αₖ, with variance (their Lemma 3.3)

    Var ŝ = σ₁²/m₁ + Σₖ₌₂ᴷ (1/mₖ₋₁ − 1/mₖ)(αₖ² σₖ² − 2 αₖ ρ₁ₖ σ₁ σₖ).

For a budget p (in units of one f₁ run: costs wₖ relative to w₁ = 1) the sample sizes minimising it are
mₖ = rₖ m₁ with r₁ = 1, rₖ = √(w₁ (ρ₁ₖ² − ρ₁,ₖ₊₁²) / (wₖ (1 − ρ₁₂²))) (ρ₁,K+1 = 0), m₁ = p / Σ wₖ rₖ (their
Theorem 3.4), valid when the correlations decrease and wₖ₋₁/wₖ > (ρ₁,ₖ₋₁² − ρ₁ₖ²)/(ρ₁ₖ² − ρ₁,ₖ₊₁²) — a model
that breaks it is dropped (:func:`allocation` says which).  Its mean-squared error is then
σ₁²/p · (Σₖ √(wₖ (ρ₁ₖ² − ρ₁,ₖ₊₁²)))², against σ₁²/p for plain Monte Carlo with the same budget: the ratio is
:attr:`Allocation.variance_ratio`, and 1/ratio is how many times fewer f₁ runs give the same interval.

A **yield** is the mean of an indicator (the expensive output within its limits); its control variates are the
cheap outputs themselves (their correlation with the indicator, estimated by the pilot) — the estimator is the same.
The correlations, standard deviations and costs come from a **pilot** of n₀ joint runs of every model
(:func:`pilot`); the interval is ŝ ± z √Var ŝ with the pilot's figures.

Reference: B. Peherstorfer, K. Willcox, M. Gunzburger, "Optimal model management for multifidelity Monte Carlo
estimation", SIAM J. Sci. Comput. 38 (2016) A3163–A3194.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats


@dataclass(frozen=True)
class Pilot:
    """The pilot's figures: per model its standard deviation, its correlation with model 1 and its cost."""

    sigma: np.ndarray       # (K,)
    rho: np.ndarray         # (K,), rho[0] = 1
    cost: np.ndarray        # (K,), relative to model 1 (cost[0] = 1)
    n: int


def pilot(values: np.ndarray, costs) -> Pilot:
    """:class:`Pilot` from ``values`` (n₀ × K: every model on the same n₀ inputs, column 0 the high fidelity) and the
    models' costs per run (any unit; made relative to model 1)."""
    Y = np.asarray(values, dtype=float)
    if Y.ndim != 2 or Y.shape[0] < 3 or not np.all(np.isfinite(Y)):
        raise ValueError("the pilot needs at least 3 finite joint runs of every model")
    c = np.asarray(costs, dtype=float)
    sd = Y.std(axis=0, ddof=1)
    if not sd[0] > 0:
        raise ValueError("the high-fidelity output does not vary in the pilot")
    rho = np.array([1.0] + [float(np.corrcoef(Y[:, 0], Y[:, k])[0, 1]) if sd[k] > 0 else 0.0
                            for k in range(1, Y.shape[1])])
    return Pilot(sd, rho, c / c[0], Y.shape[0])


@dataclass(frozen=True)
class Allocation:
    """The models used (indices into the pilot), their sample sizes, coefficients and the expected gain."""

    models: tuple[int, ...]
    m: tuple[int, ...]                # nested sample sizes, m[0] high fidelity, non-decreasing
    alpha: tuple[float, ...]          # alpha[0] unused (1)
    variance_ratio: float             # MFMC MSE / plain MC MSE at the same budget
    dropped: tuple[tuple[int, str], ...] = ()

    @property
    def speedup(self) -> float:
        """How many times fewer high-fidelity-equivalent runs give the same interval as plain Monte Carlo."""
        return 1.0 / self.variance_ratio


def allocation(p: Pilot, budget: float) -> Allocation:
    """The optimal :class:`Allocation` for ``budget`` (in high-fidelity runs), after dropping the models that break
    the ordering or the cost condition (module docstring); sample sizes rounded down, m₁ ≥ 2."""
    order = [0] + sorted(range(1, len(p.rho)), key=lambda k: -abs(p.rho[k]))
    dropped: list[tuple[int, str]] = []
    keep = list(order)
    changed = True
    while changed:
        changed = False
        r2 = [p.rho[k] ** 2 for k in keep] + [0.0]
        for i in range(1, len(keep)):
            if not r2[i] < r2[i - 1] or r2[i] == 0.0:
                dropped.append((keep[i], "its correlation does not fall below the previous model's"))
                del keep[i]
                changed = True
                break
            w_prev, w = p.cost[keep[i - 1]], p.cost[keep[i]]
            if not w_prev / w > (r2[i - 1] - r2[i]) / (r2[i] - r2[i + 1]):
                dropped.append((keep[i], "too costly for its correlation (Peherstorfer et al.'s condition)"))
                del keep[i]
                changed = True
                break
    r2 = np.array([p.rho[k] ** 2 for k in keep] + [0.0])
    w = np.array([p.cost[k] for k in keep])
    if len(keep) > 1 and float(np.sum(np.sqrt(w * (r2[:-1] - r2[1:])))) ** 2 / w[0] >= 1.0:
        dropped += [(k, "no gain at its cost: the high-fidelity model alone is as good") for k in keep[1:]]
        keep, r2, w = keep[:1], np.array([1.0, 0.0]), w[:1]
    r = np.ones(len(keep))
    if len(keep) > 1:
        r[1:] = np.sqrt(w[0] * (r2[1:-1] - r2[2:]) / (w[1:] * (1.0 - r2[1])))
    m1 = budget / float(w @ r)
    m = np.maximum.accumulate(np.maximum(2, np.floor(m1 * r)).astype(int))
    alpha = tuple([1.0] + [float(p.rho[k] * p.sigma[0] / p.sigma[k]) for k in keep[1:]])
    ratio = float(np.sum(np.sqrt(w * (r2[:-1] - r2[1:])))) ** 2 / w[0]
    return Allocation(tuple(keep), tuple(int(x) for x in m), alpha, ratio, tuple(dropped))


@dataclass(frozen=True)
class Estimate:
    """An MFMC estimate with its standard error and the interval at ``confidence``."""

    value: float
    se: float
    confidence: float
    runs: tuple[int, ...]           # per model used

    @property
    def interval(self) -> tuple[float, float]:
        z = float(stats.norm.ppf(0.5 + 0.5 * self.confidence))
        return self.value - z * self.se, self.value + z * self.se


def estimate(values: list[np.ndarray], a: Allocation, p: Pilot, confidence: float = 0.95) -> Estimate:
    """The MFMC estimate of model 1's mean from ``values[i]``, the outputs of model ``a.models[i]`` on the first
    ``a.m[i]`` inputs of one input stream (nested: the first a.m[i−1] are those model i−1 ran on)."""
    y = [np.asarray(v, dtype=float) for v in values]
    for v, mk in zip(y, a.m):
        if len(v) != mk:
            raise ValueError(f"expected {mk} runs, got {len(v)}")
    s = float(np.mean(y[0]))
    var = p.sigma[0] ** 2 / a.m[0]
    for i in range(1, len(a.models)):
        k = a.models[i]
        s += a.alpha[i] * (float(np.mean(y[i])) - float(np.mean(y[i][: a.m[i - 1]])))
        var += (1.0 / a.m[i - 1] - 1.0 / a.m[i]) * (a.alpha[i] ** 2 * p.sigma[k] ** 2
                                                    - 2.0 * a.alpha[i] * p.rho[k] * p.sigma[0] * p.sigma[k])
    return Estimate(s, math.sqrt(max(var, 0.0)), confidence, a.m)
