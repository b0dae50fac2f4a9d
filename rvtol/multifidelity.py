"""Multi-fidelity Monte Carlo: an expensive model's mean, variance and yield from few of its runs, many of cheap ones.

The 20-DOF outputs (lost motion of the torsion curve, TE of the sweep) cost 30–150 ms per sample on one core, most of
a sign-off; cheaper models of the same quantities come from rvtol itself (doc 001's lost-motion screening, the
20-DOF torsion curve without friction) or are learned from a few 20-DOF runs (below).  Where the cheap model
correlates with the expensive one, its many samples carry information about the expensive mean (what the RV-80E
sign-off gains, measured: studies/multifidelity.md).  The MFMC
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
(:func:`pilot`).  The interval is ŝ ± z √Var ŝ, Var ŝ by Lemma 3.3 (valid for any αₖ) with the estimation's own
runs (αₖ fixed; :func:`sampling_variance`: unbiased, and ≥ 0), or with the pilot's figures where
:func:`estimate` is given the pilot.  :attr:`Estimate.plain_runs` = σ̂₁²/Var ŝ is how many high-fidelity runs
plain Monte Carlo needs for the same interval.

**The variance** (``statistic="variance"``): ŝ² = V̂₁(m₁) + Σₖ αₖ (V̂ₖ(mₖ) − V̂ₖ(mₖ₋₁)) with V̂ the unbiased sample
variance — unbiased for Var f₁ (Qian, Peherstorfer, O'Malley, Vesselinov & Willcox 2018).  Since
Var V̂(m) = (μ₄ − (m−3)/(m−1) σ⁴)/m → Var[(y − μ)²]/m, its variance is Lemma 3.3's with σ and ρ those of the
centred squares (y − μ)², to first order in 1/m: the pilot and the interval take them (:func:`fluctuation`).  The
standard deviation is its square root, se by the delta method (:meth:`Estimate.square_root`).

**A learned low fidelity** (:func:`fit_surrogate`): where no cheap model of the same quantity is at hand, one is
learned from n_t high-fidelity runs on inputs drawn independently of the estimation's — g(x) = b₀ + Σⱼ bⱼ φⱼ(x),
ridge regression (Hoerl & Kennard 1970) on standardised features φ(x) (cheap functions of the inputs the caller
chooses), the penalty by leave-one-out (scikit-learn ``RidgeCV``).  g is fixed before the estimation's inputs are
drawn, so each E[ȳₖ(mₖ) − ȳₖ(mₖ₋₁)] = 0 and ŝ stays unbiased; the n_t runs are part of the estimator's cost
(Peherstorfer 2019 trades them against the estimation's).  The pilot needs ρ between f₁ and g on runs g has not
seen: the training runs' K-fold out-of-fold predictions give it with no further high-fidelity run
(:meth:`Surrogate.pilot`).  A yield's control variate is the surrogate's probability of the output lying within the
limits, Φ((u − g)/s) − Φ((l − g)/s), s the out-of-fold residual standard deviation (:meth:`Surrogate.within`): any
fixed function keeps the estimate unbiased, this one correlates with the indicator about as well as g allows.

References: B. Peherstorfer, K. Willcox, M. Gunzburger, "Optimal model management for multifidelity Monte Carlo
estimation", SIAM J. Sci. Comput. 38 (2016) A3163–A3194.  E. Qian, B. Peherstorfer, D. O'Malley, V. Vesselinov,
K. Willcox, "Multifidelity Monte Carlo estimation of variance and sensitivity indices", SIAM/ASA J. Uncertainty
Quantification 6 (2018) 683–706.  B. Peherstorfer, "Multifidelity Monte Carlo estimation with adaptive
low-fidelity models", SIAM/ASA J. Uncertainty Quantification 7 (2019) 579–603.  A. E. Hoerl, R. W. Kennard,
"Ridge regression", Technometrics 12 (1970) 55–67.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats

#: what :func:`estimate` estimates: the high-fidelity output's mean or its variance
STATISTICS = ("mean", "variance")


@dataclass(frozen=True)
class Pilot:
    """The pilot's figures: per model its standard deviation, its correlation with model 1 and its cost."""

    sigma: np.ndarray       # (K,)
    rho: np.ndarray         # (K,), rho[0] = 1
    cost: np.ndarray        # (K,), relative to model 1 (cost[0] = 1)
    n: int


def fluctuation(Y: np.ndarray, statistic: str = "mean") -> np.ndarray:
    """The per-run quantity whose mean's sampling variance is ``statistic``'s, column by column: the runs themselves
    for the mean, their centred squares (y − ȳ)² for the variance (module docstring)."""
    if statistic not in STATISTICS:
        raise ValueError(f"unknown statistic {statistic!r} (expected one of: {', '.join(STATISTICS)})")
    Y = np.asarray(Y, dtype=float)
    return Y if statistic == "mean" else (Y - Y.mean(axis=0)) ** 2


def pilot(values: np.ndarray, costs, statistic: str = "mean") -> Pilot:
    """:class:`Pilot` from ``values`` (n₀ × K: every model on the same n₀ inputs, column 0 the high fidelity) and the
    models' costs per run (any unit; made relative to model 1); for ``statistic="variance"`` the figures are those
    of the centred squares (:func:`fluctuation`)."""
    Y = np.asarray(values, dtype=float)
    if Y.ndim != 2 or Y.shape[0] < 3 or not np.all(np.isfinite(Y)):
        raise ValueError("the pilot needs at least 3 finite joint runs of every model")
    Y = fluctuation(Y, statistic)
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


def allocation(p: Pilot, budget: float, min_high: int = 2) -> Allocation:
    """The optimal :class:`Allocation` for ``budget`` (in high-fidelity runs), after dropping the models that break
    the ordering or the cost condition (module docstring); sample sizes rounded down, m₁ ≥ ``min_high`` (≥ 2: the
    interval's variance is estimated from these runs; a well-correlated cheap model can leave the optimum at a few)."""
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
    m = np.maximum.accumulate(np.maximum([max(2, min_high)] + [2] * (len(r) - 1), np.floor(m1 * r)).astype(int))
    alpha = tuple([1.0] + [float(p.rho[k] * p.sigma[0] / p.sigma[k]) for k in keep[1:]])
    ratio = float(np.sum(np.sqrt(w * (r2[:-1] - r2[1:])))) ** 2 / w[0]
    return Allocation(tuple(keep), tuple(int(x) for x in m), alpha, ratio, tuple(dropped))


def for_plain_runs(p: Pilot, runs: float, min_high: int = 2) -> Allocation:
    """The allocation whose mean-squared error is plain Monte Carlo's with ``runs`` high-fidelity runs (the same
    interval): budget = runs × the variance ratio, which does not depend on the budget."""
    return allocation(p, runs * allocation(p, runs).variance_ratio, min_high)


@dataclass(frozen=True)
class Estimate:
    """An MFMC estimate with its standard error and the interval at ``confidence``."""

    value: float
    se: float
    confidence: float
    runs: tuple[int, ...]           # per model used
    plain_runs: float = math.nan    # high-fidelity runs plain Monte Carlo needs for the same se: σ̂₁² / se² (σ̂₁ of
                                    # the m₁ runs: rough where they are few)

    @property
    def interval(self) -> tuple[float, float]:
        z = float(stats.norm.ppf(0.5 + 0.5 * self.confidence))
        return self.value - z * self.se, self.value + z * self.se

    def square_root(self) -> Estimate:
        """The standard deviation from a variance estimate: √ŝ², se by the delta method se(ŝ²) / (2 √ŝ²) (plain Monte
        Carlo's the same way, so ``plain_runs`` is unchanged)."""
        root = math.sqrt(max(self.value, 0.0))
        return Estimate(root, self.se / (2.0 * root) if root > 0 else math.inf, self.confidence, self.runs,
                        self.plain_runs)


def estimate(values: list[np.ndarray], a: Allocation, p: Pilot | None = None, confidence: float = 0.95,
             statistic: str = "mean") -> Estimate:
    """The MFMC estimate of model 1's mean (or variance, ``statistic``) from ``values[i]``, the outputs of model
    ``a.models[i]`` on the first ``a.m[i]`` inputs of one input stream (nested: the first a.m[i−1] are those model
    i−1 ran on).  Its variance from these runs (:func:`sampling_variance`), or by Lemma 3.3 with the pilot ``p``'s
    figures where given."""
    y = [np.asarray(v, dtype=float) for v in values]
    for v, mk in zip(y, a.m):
        if len(v) != mk:
            raise ValueError(f"expected {mk} runs, got {len(v)}")
    of = np.mean if statistic == "mean" else (lambda v: np.var(v, ddof=1))
    s = float(of(y[0]))
    for i in range(1, len(a.models)):
        s += a.alpha[i] * (float(of(y[i])) - float(of(y[i][: a.m[i - 1]])))
    if p is None:
        var = sampling_variance(y, a, statistic)
    else:
        var = p.sigma[0] ** 2 / a.m[0]
        for i in range(1, len(a.models)):
            k = a.models[i]
            var += (1.0 / a.m[i - 1] - 1.0 / a.m[i]) * (a.alpha[i] ** 2 * p.sigma[k] ** 2
                                                        - 2.0 * a.alpha[i] * p.rho[k] * p.sigma[0] * p.sigma[k])
        var = max(var, 0.0)
    var1 = float(np.var(fluctuation(y[0], statistic), ddof=1))
    return Estimate(s, math.sqrt(var), confidence, a.m, var1 / var if var > 0 else math.inf)


def sampling_variance(values: list[np.ndarray], a: Allocation, statistic: str = "mean") -> float:
    """Var ŝ from the runs themselves (``values[i]``: model ``a.models[i]``'s outputs on its a.m[i] inputs).

    The nested inputs fall into blocks Bⱼ = (mⱼ₋₁, mⱼ] (m₀ = 0), block j run by the models i ≥ j.  ŝ weighs model i's
    output on a row of block j by wⱼᵢ = αᵢ (1[j ≤ i]/mᵢ − 1[j ≤ i−1]/mᵢ₋₁) (w₁₁ = 1/m₁, α₁ = 1): ŝ = Σⱼ Σ_{x∈Bⱼ} hⱼ(x),
    hⱼ = Σ_{i≥j} wⱼᵢ fᵢ, a sum over independent rows, so Var ŝ = Σⱼ |Bⱼ| Var hⱼ — Lemma 3.3 rearranged, every term
    ≥ 0.  Var hⱼ is the sample variance of hⱼ on the first mⱼ rows (every model i ≥ j ran them): unbiased, and no
    difference of large terms as σ̂₁²/m₁ − … would be with few high-fidelity runs.  For the variance fᵢ is the
    :func:`fluctuation`, every model's centred on its mean over the same mⱼ rows (as V̂ᵢ(mⱼ) is), so that their
    centring errors cancel in hⱼ as the models agree."""
    K, m = len(a.m), a.m
    var = 0.0
    for j in range(K):
        h = np.zeros(m[j])
        for i in range(j, K):
            w = 1.0 / m[0] if i == 0 else a.alpha[i] * (1.0 / m[i] - (1.0 / m[i - 1] if j <= i - 1 else 0.0))
            h += w * fluctuation(values[i][: m[j]], statistic)
        var += (m[j] - (m[j - 1] if j else 0)) * float(np.var(h, ddof=1))
    return var


def inside(y: np.ndarray, lower: float = -math.inf, upper: float = math.inf) -> np.ndarray:
    """1.0 where ``lower`` ≤ y ≤ ``upper``, else 0.0: the indicator whose mean is the yield."""
    y = np.asarray(y, dtype=float)
    return ((y >= lower) & (y <= upper)).astype(float)


@dataclass(frozen=True)
class Surrogate:
    """A low-fidelity model learned from high-fidelity runs (:func:`fit_surrogate`; module docstring)."""

    regression: object              # the fitted scikit-learn pipeline: standardised features → ridge
    y: np.ndarray                   # the training runs' high-fidelity outputs
    cross_validated: np.ndarray     # their out-of-fold predictions

    @property
    def correlation(self) -> float:
        """ρ between the high fidelity and the surrogate on runs it has not seen (out of fold)."""
        return float(np.corrcoef(self.y, self.cross_validated)[0, 1])

    @property
    def residual_sd(self) -> float:
        """Standard deviation of the out-of-fold prediction errors."""
        return float(np.std(self.y - self.cross_validated, ddof=1))

    def predict(self, features: np.ndarray) -> np.ndarray:
        """g at the rows of ``features`` (n × p)."""
        return self.regression.predict(np.asarray(features, dtype=float))

    def within(self, prediction: np.ndarray, lower: float = -math.inf, upper: float = math.inf) -> np.ndarray:
        """Φ((u − g)/s) − Φ((l − g)/s): the chance that the high fidelity lies within the limits where the surrogate
        predicts g, s = :attr:`residual_sd` — a yield's control variate."""
        g, sd = np.asarray(prediction, dtype=float), self.residual_sd
        return stats.norm.cdf((upper - g) / sd) - stats.norm.cdf((lower - g) / sd)

    def pilot(self, cost: float, statistic: str = "mean", limits: tuple[float, float] | None = None,
              others=()) -> Pilot:
        """The :class:`Pilot` of (high fidelity, ``others``…, surrogate) from the training runs and the surrogate's
        out-of-fold predictions, its ``cost`` per run relative to the high fidelity's; ``others``: (outputs on the
        training runs, cost) of further low-fidelity models run on the same inputs; ``limits``: of the yield within
        them (each model's indicator, the surrogate's :meth:`within`)."""
        columns = [self.y, *(o for o, _ in others)]
        if limits is not None:
            columns = [inside(c, *limits) for c in columns] + [self.within(self.cross_validated, *limits)]
        else:
            columns.append(self.cross_validated)
        return pilot(np.column_stack(columns), (1.0, *(c for _, c in others), cost), statistic)


def fit_surrogate(features: np.ndarray, y: np.ndarray, folds: int = 10) -> Surrogate:
    """Ridge regression of the high-fidelity outputs ``y`` on ``features`` (n_t × p, the training runs'), the
    penalty by leave-one-out, and the ``folds``-fold out-of-fold predictions of the same fit for the pilot."""
    from sklearn.linear_model import RidgeCV
    from sklearn.model_selection import KFold, cross_val_predict
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    F, y = np.asarray(features, dtype=float), np.asarray(y, dtype=float)
    finite = np.all(np.isfinite(F)) and np.all(np.isfinite(y))
    if F.ndim != 2 or len(F) != len(y) or len(y) < 2 * folds or not finite:
        raise ValueError(f"the surrogate needs finite features (n × p) and outputs, n ≥ {2 * folds}")
    make = lambda: make_pipeline(StandardScaler(), RidgeCV(alphas=np.logspace(-6, 6, 49)))  # noqa: E731
    oof = cross_val_predict(make(), F, y, cv=KFold(folds))
    return Surrogate(make().fit(F, y), y, oof)
