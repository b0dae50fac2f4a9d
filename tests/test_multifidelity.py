"""Multi-fidelity Monte Carlo (rvtol.multifidelity) on a closed form: f₁ = exp(x), f₂ = 1 + x + x²/2, f₃ = 1 + x,
x ~ U(0, 1): E f₁ = e − 1; the correlations and standard deviations by quadrature (scipy)."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from rvtol.multifidelity import allocation, estimate, pilot

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
