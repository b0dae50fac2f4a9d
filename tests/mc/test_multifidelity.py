"""Multi-fidelity Monte Carlo (rvtol.multifidelity) on a closed form: f₁ = exp(x), f₂ = 1 + x + x²/2, f₃ = 1 + x,
x ~ U(0, 1): E f₁ = e − 1; the correlations and standard deviations by quadrature (scipy)."""
from __future__ import annotations

import functools
import math

import numpy as np
import pytest
from scipy import integrate

from rvtol.multifidelity import allocation, estimate, inside, pilot

F = (np.exp, lambda x: 1 + x + x * x / 2, lambda x: 1 + x)
COSTS = (1.0, 0.01, 0.001)


def _moments():
    """σₖ and ρ₁ₖ by quadrature."""
    m = [integrate.quad(f, 0, 1)[0] for f in F]
    cov = [[integrate.quad(lambda x: (F[i](x) - m[i]) * (F[j](x) - m[j]), 0, 1)[0] for j in range(3)] for i in range(3)]
    sd = np.sqrt(np.diag(cov))
    return m, sd, np.array([cov[0][k] / (sd[0] * sd[k]) for k in range(3)])


def test_the_pilot_gives_the_quadrature_moments():
    x = np.random.default_rng(1).random(200_000)
    p = pilot(np.column_stack([f(x) for f in F]), COSTS)
    _, sd, rho = _moments()
    np.testing.assert_allclose(p.sigma, sd, rtol=0.01)
    np.testing.assert_allclose(p.rho, rho, atol=2e-4)
    assert p.cost.tolist() == [1.0, 0.01, 0.001]


def test_mfmc_is_unbiased_and_its_variance_is_the_formula_and_the_gain_is_the_theorems():
    m, sd, rho = _moments()
    x = np.random.default_rng(2).random(100_000)
    p = pilot(np.column_stack([f(x) for f in F]), COSTS)
    a = allocation(p, budget=40.0)
    assert a.models == (0, 1, 2) and a.m[0] < a.m[1] < a.m[2]
    # the theorem's ratio from the quadrature moments: (Σ √(wₖ(ρₖ² − ρₖ₊₁²)))²
    r2 = np.append(rho ** 2, 0.0)
    theory = sum(math.sqrt(w * (r2[k] - r2[k + 1])) for k, w in enumerate(COSTS)) ** 2
    assert a.variance_ratio == pytest.approx(theory, rel=0.02) and a.speedup > 20
    g = np.random.default_rng(3)
    runs = []
    for _ in range(2000):
        u = g.random(a.m[-1])                                   # one input stream, nested prefixes
        e = estimate([F[k](u[: a.m[i]]) for i, k in enumerate(a.models)], a, p)
        runs.append((e.value, e.se))
    v = np.array(runs)
    assert abs(v[:, 0].mean() - m[0]) < 4 * v[:, 0].std() / math.sqrt(len(v))          # unbiased
    assert v[:, 0].var() == pytest.approx(np.mean(v[:, 1] ** 2), rel=0.1)               # Var ŝ as the formula says
    plain = sd[0] ** 2 / 40.0                                                           # plain MC, same budget
    assert v[:, 0].var() / plain == pytest.approx(a.variance_ratio, rel=0.15)
    cover = np.mean(np.abs(v[:, 0] - m[0]) <= 1.96 * v[:, 1])
    assert 0.93 <= cover <= 0.97


def test_a_model_that_breaks_the_cost_condition_is_dropped_and_the_rest_ordered_by_correlation():
    from rvtol.multifidelity import Pilot

    # ρ = 0.9 at 0.05 of the cost, ρ = 0.5 at 0.04: w₂/w₃ = 1.25 is not above (0.81 − 0.25)/0.25 = 2.24 — dropped
    p = Pilot(np.array([1.0, 1.0, 1.0]), np.array([1.0, 0.5, 0.9]), np.array([1.0, 0.04, 0.05]), 100)
    a = allocation(p, budget=30.0)
    assert a.models == (0, 2) and a.dropped[0][0] == 1 and "too costly" in a.dropped[0][1]
    # two models: ratio (√(1 − ρ²) + √(w ρ²))² by hand
    assert a.variance_ratio == pytest.approx((math.sqrt(1 - 0.81) + math.sqrt(0.05 * 0.81)) ** 2)
    # at half the cost the same model gains nothing ((0.436 + 0.636)² = 1.15): the high fidelity alone
    a = allocation(Pilot(np.ones(2), np.array([1.0, 0.9]), np.array([1.0, 0.5]), 100), budget=30.0)
    assert a.models == (0,) and a.variance_ratio == 1.0 and a.m == (30,) and "no gain" in a.dropped[0][1]
    with pytest.raises(ValueError):
        pilot(np.ones((5, 2)), (1.0, 0.1))


# --- a learned low fidelity (fit_surrogate) on a closed form: f(x) = exp(x₁ + x₂/2), x ~ U(0, 1)²,
# E f = 2(e − 1)(√e − 1); the surrogate a ridge fit on the features (x₁, x₂) from 60 runs drawn apart from the
# estimation's; its moments with f by 40 × 40 Gauss–Legendre quadrature (exact to 1e-12 for these smooth integrands)

def _f(x):
    return np.exp(x[..., 0] + 0.5 * x[..., 1])


def _quadrature(*functions):
    """E, σ of each function and ρ of each with the first, by tensor Gauss–Legendre on [0, 1]²."""
    t, w = np.polynomial.legendre.leggauss(40)
    t, w = 0.5 * (t + 1.0), 0.5 * w
    x = np.stack(np.meshgrid(t, t, indexing="ij"), axis=-1).reshape(-1, 2)
    w2 = np.outer(w, w).ravel()
    v = [fn(x) for fn in functions]
    mean = [float(w2 @ u) for u in v]
    cov = lambda a, b, ma, mb: float(w2 @ ((a - ma) * (b - mb)))  # noqa: E731
    sd = [math.sqrt(cov(u, u, m, m)) for u, m in zip(v, mean)]
    rho = [cov(v[0], u, mean[0], m) / (sd[0] * s) for u, m, s in zip(v, mean, sd)]
    return np.array(mean), np.array(sd), np.array(rho)


@functools.lru_cache(maxsize=1)
def _learned():
    from rvtol.multifidelity import fit_surrogate

    xt = np.random.default_rng(5).random((60, 2))
    return fit_surrogate(xt, _f(xt))


def test_a_learned_low_fidelity_keeps_the_estimate_unbiased_with_the_theorems_variance():
    from rvtol.multifidelity import for_plain_runs

    s = _learned()
    mean, sd, rho = _quadrature(_f, s.predict)
    assert mean[0] == pytest.approx(2 * (math.e - 1) * (math.sqrt(math.e) - 1), rel=1e-12)
    assert s.correlation == pytest.approx(rho[1], abs=0.01) and 0.98 < rho[1] < 0.999   # out of fold: honest ρ
    p = s.pilot(cost=0.01)
    a = for_plain_runs(p, 400)                   # the interval plain Monte Carlo gets from 400 runs
    assert a.models == (0, 1) and a.m[0] < 400 / 10
    # Lemma 3.3 at the allocation's α (fixed by the pilot), with the true σ, ρ of f and the fitted g
    c = 1 / a.m[0] - 1 / a.m[1]
    theory = sd[0] ** 2 / a.m[0] + c * (a.alpha[1] ** 2 * sd[1] ** 2 - 2 * a.alpha[1] * rho[1] * sd[0] * sd[1])
    assert theory == pytest.approx(sd[0] ** 2 / 400, rel=0.15)          # equal width: plain MC's 400 runs
    R = 1000
    u = np.random.default_rng(6).random((R, a.m[1], 2))                 # fresh inputs, never the training's
    g = s.predict(u.reshape(-1, 2)).reshape(R, a.m[1])
    runs = [estimate([_f(u[r, : a.m[0]]), g[r]], a) for r in range(R)]
    v = np.array([e.value for e in runs])
    se = np.array([e.se for e in runs])
    assert abs(v.mean() - mean[0]) < 4 * v.std() / math.sqrt(R)          # unbiased
    assert v.var() == pytest.approx(theory, rel=0.1)                      # the theorem's variance
    assert np.mean(se ** 2) == pytest.approx(theory, rel=0.1)             # the runs' own estimate of it
    assert 0.93 <= np.mean(np.abs(v - mean[0]) <= 1.96 * se) <= 0.97
    assert np.median([e.plain_runs for e in runs]) == pytest.approx(400, rel=0.2)


def test_the_variance_and_a_yield_from_a_learned_low_fidelity_are_unbiased_and_their_intervals_cover():
    s = _learned()
    mean, sd, _ = _quadrature(_f)
    variance = sd[0] ** 2                        # closed form: E f² − (E f)², E f² = (e² − 1)(e − 1)/2
    assert variance == pytest.approx((math.e ** 2 - 1) * (math.e - 1) / 2 - mean[0] ** 2, rel=1e-10)
    upper = math.exp(0.75)                       # P(x₁ + x₂/2 ≤ t) = t − 1/4 for ½ ≤ t ≤ 1: a yield of ½
    R = 1000
    rng = np.random.default_rng(7)
    for statistic, limits, truth in (("variance", None, variance), ("mean", (-math.inf, upper), 0.5)):
        p = s.pilot(cost=0.05, statistic=statistic, limits=limits)
        a = allocation(p, budget=60.0)
        assert a.models == (0, 1)
        u = rng.random((R, a.m[1], 2))
        g = s.predict(u.reshape(-1, 2)).reshape(R, a.m[1])
        hi = _f(u[:, : a.m[0]])
        if limits is not None:
            hi, g = inside(hi, *limits), s.within(g, *limits)
        runs = [estimate([hi[r], g[r]], a, statistic=statistic) for r in range(R)]
        v = np.array([e.value for e in runs])
        se = np.array([e.se for e in runs])
        assert abs(v.mean() - truth) < 4 * v.std() / math.sqrt(R), statistic      # unbiased
        assert np.mean(se ** 2) == pytest.approx(v.var(), rel=0.15), statistic    # its se as the spread says
        assert 0.92 <= np.mean(np.abs(v - truth) <= 1.96 * se) <= 0.975, statistic
        assert np.median([e.plain_runs for e in runs]) > 60, statistic              # fewer runs than plain MC


def test_the_variances_interval_holds_with_few_high_fidelity_runs_beside_a_near_exact_cheap_model():
    """f₁ = exp(x), f₂ its cubic Taylor model (ρ of the centred squares 0.9996), f₃ = 1 + x: the allocation gives f₁ its
    minimum of 10 runs.  The interval's variance, from the runs, centres every model's squares on its mean over the
    same rows; centred each on its own whole sample, the 10 runs' centring error did not cancel against f₂'s (se²
    came out 27 times the estimates' spread)."""
    F3 = (np.exp, lambda x: 1 + x + x * x / 2 + x ** 3 / 6, lambda x: 1 + x)
    x = np.random.default_rng(8).random(100_000)
    p = pilot(np.column_stack([f(x) for f in F3]), (1.0, 0.3, 0.01), statistic="variance")
    a = allocation(p, 40.0, min_high=10)
    assert a.models == (0, 1, 2) and a.m[0] == 10
    truth = (math.e ** 2 - 1) / 2 - (math.e - 1) ** 2
    g = np.random.default_rng(9)
    runs = []
    for _ in range(800):
        u = g.random(a.m[-1])
        runs.append(estimate([F3[k](u[: a.m[i]]) for i, k in enumerate(a.models)], a, statistic="variance"))
    v = np.array([e.value for e in runs])
    se = np.array([e.se for e in runs])
    assert abs(v.mean() - truth) < 4 * v.std() / math.sqrt(len(v))
    assert np.mean(se ** 2) == pytest.approx(v.var(), rel=0.15)
    assert 0.92 <= np.mean(np.abs(v - truth) <= 1.96 * se) <= 0.975
    assert v.var() < 0.1 * p.sigma[0] ** 2 / 40                       # > 10× plain Monte Carlo's 40 runs
