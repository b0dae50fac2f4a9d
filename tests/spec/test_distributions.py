"""Distributions against scipy.stats: moments and percentiles of our samples, from the spec forms."""
import math

import numpy as np
import pytest
from scipy import stats

from rvtol.distributions import Distribution, coverage, from_params
from rvtol.params import Params
from rvtol.sampling import uniform_design

N = 200_000


def dist(**kw):
    return from_params(Params(kw, file="t.toml", key="factor"))


CASES = [
    (dict(dist="normal", mean=2.0, sigma=0.5), stats.norm(2.0, 0.5)),
    (dict(dist="normal", mean=1.0, tolerance=12.0), stats.norm(1.0, 2.0)),            # ±6 at 3σ
    (dict(dist="normal", mean=1.0, tolerance=12.0, sigma_level=2), stats.norm(1.0, 3.0)),
    (dict(dist="normal", lower=-3.0, upper=9.0), stats.norm(3.0, 2.0)),
    (dict(dist="normal", mean=0.0, sigma=1.0, shift=0.25), stats.norm(0.25, 1.0)),
    (dict(dist="uniform", lower=-1.0, upper=3.0), stats.uniform(-1.0, 4.0)),
    (dict(dist="uniform", mean=5.0, tolerance=2.0), stats.uniform(4.0, 2.0)),
    (dict(dist="truncnorm", mean=0.0, sigma=1.0, lower=-1.0, upper=2.0), stats.truncnorm(-1, 2, 0, 1)),
    (dict(dist="truncnorm", mean=0.0, tolerance=6.0), stats.truncnorm(-3, 3, 0, 1)),
    (dict(dist="triangular", lower=0.0, mode=1.0, upper=4.0), stats.triang(0.25, 0.0, 4.0)),
    (dict(dist="rayleigh", sigma=2.0), stats.rayleigh(0, 2.0)),
    (dict(dist="lognormal", median=2.0, shape=0.3), stats.lognorm(0.3, 0, 2.0)),
    (dict(dist="weibull", shape=1.5, scale=3.0), stats.weibull_min(1.5, 0, 3.0)),
    (dict(dist="weibull", shape=2.0, scale=3.0, shift=1.0), stats.weibull_min(2.0, 1.0, 3.0)),
]


@pytest.mark.parametrize("kw,ref", CASES, ids=[f"{c[0]['dist']}-{i}" for i, c in enumerate(CASES)])
def test_sample_moments_and_percentiles_match_scipy(kw, ref):
    d = dist(**kw)
    assert d.mean == pytest.approx(ref.mean(), rel=1e-9, abs=1e-12)
    assert d.std == pytest.approx(ref.std(), rel=1e-9)
    x = d.ppf(uniform_design(N, 1, "random", seed=1)[:, 0])
    sd = ref.std()
    # sample mean within 4 standard errors; sample std within 4 of its (normal-theory-ish) s.e.,
    # using the reference 4th moment for the variance of s²
    assert abs(x.mean() - ref.mean()) < 4 * sd / math.sqrt(N)
    kurt = ref.stats(moments="k") + 3.0
    se_var = sd**2 * math.sqrt((kurt - 1) / N)
    assert abs(x.var(ddof=1) - sd**2) < 4 * se_var
    # percentiles: order-statistic band of the reference quantile, from the binomial
    xs = np.sort(x)
    for q in (0.00135, 0.05, 0.5, 0.95, 0.99865):
        lo = int(stats.binom.ppf(0.00005, N, q))
        hi = int(stats.binom.ppf(0.99995, N, q)) + 1
        assert xs[max(lo - 1, 0)] <= ref.ppf(q) <= xs[min(hi - 1, N - 1)]


def test_rayleigh_and_weibull_tolerance_is_coverage_quantile():
    p = coverage(3.0)
    assert p == pytest.approx(0.9973002, abs=1e-7)
    r = dist(dist="rayleigh", tolerance=10.0)
    assert r.cdf(10.0) == pytest.approx(p)
    assert r.tolerance == pytest.approx(10.0)
    w = dist(dist="weibull", shape=2.5, tolerance=8.0)
    assert w.cdf(8.0) == pytest.approx(p)


def test_lognormal_from_moments():
    d = dist(dist="lognormal", mean=3.0, sigma=1.2)
    assert d.mean == pytest.approx(3.0)
    assert d.std == pytest.approx(1.2)


@pytest.mark.parametrize("kw", [c[0] for c in CASES])
def test_scaled_multiplies_the_spread(kw):
    d = dist(**kw)
    s = d.scaled(0.5)
    assert s.std == pytest.approx(0.5 * d.std, rel=1e-9)
    assert s.tolerance == pytest.approx(0.5 * d.tolerance, rel=1e-9)
    if not d.one_sided:
        # two-sided kinds keep their centre
        centre = d.p.get("mean", d.p.get("mode", None))
        if centre is None:
            centre = 0.5 * (d.p["lower"] + d.p["upper"])
        s_centre = s.p.get("mean", s.p.get("mode", None))
        if s_centre is None:
            s_centre = 0.5 * (s.p["lower"] + s.p["upper"])
        assert s_centre == pytest.approx(centre)


def test_normal_tolerance_band_reads_sigma_level():
    d = dist(dist="normal", tolerance=0.021)
    assert d.std == pytest.approx(0.0035)
    assert d.tolerance == pytest.approx(0.021)


def test_the_normal_inverse_cdf_is_scipys_bit_for_bit_at_every_u():
    # Distribution.ppf of a normal computes ndtri(u)·σ + μ itself (scipy's frozen law per call cost 0.3 ms): it must
    # stay scipy's norm.ppf to the last bit, the edges 0 and 1 (±inf) and values outside [0, 1] (NaN) included
    d = Distribution.make("normal", mean=40.0035, sigma=0.0028, shift=0.001)
    u = np.concatenate([np.random.default_rng(3).random(20000), [0.0, 1.0, 2.0 ** -53, 1 - 2.0 ** -53, 0.5,
                                                                  -0.25, 1.5, np.nan]])
    ref = stats.norm(loc=40.0035 + 0.001, scale=0.0028).ppf(u)
    assert np.array_equal(d.ppf(u), ref, equal_nan=True)
    assert d.ppf(0.3) == stats.norm(loc=40.0035 + 0.001, scale=0.0028).ppf(0.3) and np.ndim(d.ppf(0.3)) == 0
