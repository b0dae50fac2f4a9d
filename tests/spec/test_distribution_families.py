"""Beta, gamma, Gumbel, Johnson SU/SB, Pearson III and the Pearson system as spec kinds, each against the
closed forms of its moments; the Pearson system recovering known laws from their four moments; fitting the new
families to measured values."""
import math

import numpy as np
import pytest
from scipy import stats

from rvtol.distributions import EULER_GAMMA, Distribution, pearson_frozen, pearson_type
from rvtol.errors import InputError
from rvtol.inputs.measured import fit
from rvtol.spec import spec_from_table


def one(**kw):
    return spec_from_table({"factor": [{"name": "x", "unit": "mm", **kw}]}).factors[0].dist


def test_beta_gamma_gumbel_from_their_parameters_and_from_mean_and_sigma():
    d = one(dist="beta", lower=1.0, upper=3.0, alpha=2.0, beta=5.0)
    assert d.mean == pytest.approx(1.0 + 2.0 * 2 / 7) and d.std == pytest.approx(2.0 * math.sqrt(10 / (49 * 8)))
    assert d.band == (1.0, 3.0)
    m = one(dist="beta", lower=1.0, upper=3.0, mean=1.5, sigma=0.3)
    assert (m.mean, m.std) == (pytest.approx(1.5), pytest.approx(0.3))
    g = one(dist="gamma", shape=4.0, scale=0.5)
    assert (g.mean, g.std) == (pytest.approx(2.0), pytest.approx(1.0))       # kθ, √k θ
    assert g.one_sided and g.band[0] == 0.0
    g2 = one(dist="gamma", mean=0.02, sigma=0.005)
    assert (g2.mean, g2.std) == (pytest.approx(0.02), pytest.approx(0.005))
    u = one(dist="gumbel", mode=10.0, scale=0.2)
    assert u.mean == pytest.approx(10.0 + EULER_GAMMA * 0.2) and u.std == pytest.approx(math.pi * 0.2 / math.sqrt(6))
    u2 = one(dist="gumbel", mean=10.0, sigma=0.3)
    assert (u2.mean, u2.std) == (pytest.approx(10.0), pytest.approx(0.3))
    with pytest.raises(InputError, match="too large"):
        one(dist="beta", lower=0.0, upper=1.0, mean=0.5, sigma=0.6)


def test_johnson_su_and_sb_as_translations_of_a_normal():
    # SU: x = ξ + λ sinh((z − γ)/δ): its median is ξ + λ sinh(−γ/δ), its 97.5 % point ξ + λ sinh((1.96 − γ)/δ)
    d = one(dist="johnsonsu", gamma=0.5, delta=2.0, location=10.0, scale=0.1)
    z = stats.norm.ppf(0.975)
    assert d.ppf(0.5) == pytest.approx(10.0 + 0.1 * math.sinh(-0.25))
    assert d.ppf(0.975) == pytest.approx(10.0 + 0.1 * math.sinh((z - 0.5) / 2.0))
    b = one(dist="johnsonsb", gamma=-0.3, delta=1.5, location=5.0, scale=0.2)
    assert b.ppf(0.975) == pytest.approx(5.0 + 0.2 / (1.0 + math.exp(-(z + 0.3) / 1.5)))
    assert b.band == (pytest.approx(5.0), pytest.approx(5.2))              # bounded: its support
    s = b.scaled(0.5)                                                        # tighter about its median
    assert s.ppf(0.5) == pytest.approx(b.ppf(0.5)) and s.std == pytest.approx(0.5 * b.std)


@pytest.mark.parametrize("law, kind", [(stats.beta(2, 5), "I"), (stats.beta(0.7, 0.7), "II"),
                                       (stats.gamma(3.0), "III"), (stats.invgamma(6.0), "V"),
                                       (stats.betaprime(3.0, 9.0), "VI"), (stats.t(7), "VII"), (stats.norm(), "0")])
def test_the_pearson_system_recovers_each_type_from_four_moments(law, kind):
    m, v, s, k = (float(x) for x in law.stats(moments="mvsk"))
    assert pearson_type(s, k + 3.0) == kind
    t, f = pearson_frozen(m, math.sqrt(v), s, k + 3.0)
    p = np.array([0.001, 0.05, 0.5, 0.95, 0.999])
    np.testing.assert_allclose(f.ppf(p), law.ppf(p), rtol=1e-6, atol=1e-8)   # the same law, not just its moments


def test_pearson_kinds_in_a_spec_and_type_iv_refused():
    d = one(dist="pearson", mean=1.0, sigma=0.2, skewness=-0.8, kurtosis=4.0)   # type VI, mirrored
    m, v, s, k = d.frozen.stats(moments="mvsk")
    assert (float(m), math.sqrt(v), float(s), float(k) + 3) == (pytest.approx(1.0), pytest.approx(0.2),
                                                                 pytest.approx(-0.8), pytest.approx(4.0))
    p3 = one(dist="pearson3", mean=2.0, sigma=0.1, skewness=0.6)
    assert float(p3.frozen.stats(moments="s")) == pytest.approx(0.6) and p3.std == pytest.approx(0.1)
    with pytest.raises(InputError, match="type IV.*johnsonsu"):
        one(dist="pearson", mean=0.0, sigma=1.0, skewness=0.5, kurtosis=5.0)
    with pytest.raises(InputError, match="kurtosis"):
        one(dist="pearson", mean=0.0, sigma=1.0, skewness=2.0, kurtosis=4.0)   # β₂ ≤ β₁ + 1: no law


def test_the_new_families_are_fitted_to_measured_values():
    rng = np.random.default_rng(20261127)
    true = stats.johnsonsu(0.8, 1.6, loc=25.0, scale=0.01)
    x = true.rvs(1500, random_state=rng)
    rep = fit(x, families=("normal", "johnsonsu", "gumbel", "pearson3"), gof=None)
    assert rep.candidates[0].family == "johnsonsu"
    d = rep.distribution()
    assert d.kind == "johnsonsu"
    p = np.array([0.01, 0.5, 0.99])
    se = np.sqrt(p * (1 - p) / len(x)) / true.pdf(true.ppf(p))     # the standard error of a sample quantile
    assert np.all(np.abs(d.ppf(p) - true.ppf(p)) < 4 * se)
    g = stats.gamma(3.0, scale=0.004).rvs(2000, random_state=rng)
    gd = fit(g, families=("gamma", "normal"), gof=None).distribution()
    assert gd.kind == "gamma" and gd.p["shape"] == pytest.approx(3.0, rel=0.1)
