"""Linearised worst case and RSS of magnitudes: zonotope maximum and the norm of a 2-D normal."""
import itertools

import numpy as np
import pytest
from scipy import stats

from rvtol.stacking.chain_conventions import loop_sign, norm_cdf_2d, norm_mean_2d, norm_quantile_2d, zonotope_max_norm


def test_zonotope_maximum_equals_brute_force_over_the_box_vertices():
    g = np.random.default_rng(3)
    for k in (1, 2, 5, 10):
        for _ in range(20):
            c = g.normal(size=2)
            G = g.normal(size=(2, k))
            if k > 2:
                G[:, 0] = 0.0  # a factor that does not act
                G[:, 1] = 2.5 * G[:, 2]  # two parallel generators
            brute = max(np.hypot(*(c + G @ np.array(t))) for t in itertools.product((-1, 1), repeat=k))
            assert zonotope_max_norm(c, G) == pytest.approx(brute, rel=1e-12)
    assert zonotope_max_norm([3.0, 4.0], np.zeros((2, 3))) == pytest.approx(5.0)


def test_norm_of_an_isotropic_normal_is_rice():
    s = 0.7
    for m in ((0.0, 0.0), (1.2, -0.5)):
        nu = np.hypot(*m)
        rice = stats.rice(nu / s, scale=s)
        r = np.array([0.1, 0.8, 1.5, 3.0])
        np.testing.assert_allclose(norm_cdf_2d(r, m, s * s * np.eye(2)), rice.cdf(r), atol=1e-11)
        assert norm_quantile_2d(0.9973, m, s * s * np.eye(2)) == pytest.approx(rice.ppf(0.9973), rel=1e-9)
        assert norm_mean_2d(m, s * s * np.eye(2)) == pytest.approx(rice.mean(), rel=1e-9)


def test_norm_of_an_anisotropic_normal_against_sampling():
    m, C = np.array([0.3, -0.1]), np.array([[1.0, 0.6], [0.6, 0.5]])
    n = 2_000_000
    z = np.random.default_rng(4).multivariate_normal(m, C, n)
    r = np.hypot(z[:, 0], z[:, 1])
    for q in (0.5, 0.9, 0.99):
        x = np.quantile(r, q)
        p = norm_cdf_2d(x, m, C)[0]
        assert abs(p - q) < 4.5 * np.sqrt(q * (1 - q) / n) + 1e-6
    assert abs(norm_mean_2d(m, C) - r.mean()) < 4.5 * r.std() / np.sqrt(n)
    # degenerate covariances: a line and a point
    assert norm_cdf_2d(1.0, (0.0, 0.0), np.diag([1.0, 0.0]))[0] == pytest.approx(stats.norm.cdf(1) - stats.norm.cdf(-1))
    assert norm_cdf_2d([0.9, 1.1], (0.6, 0.8), np.zeros((2, 2))).tolist() == [0.0, 1.0]


def test_loop_signs():
    assert loop_sign([2.0, -1e-3, 0.0, 1e-15]) == ["+", "−", "0", "0"]
