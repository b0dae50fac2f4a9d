import math

import numpy as np
import pytest
from scipy import stats

from rvtol.sampling import sample, uniform_design
from rvtol.spec import spec_from_table


def _spec(corr=None, kinds=("normal", "normal", "normal")):
    fs = []
    for i, k in enumerate(kinds):
        f = {"name": f"x{i}", "unit": "um", "dist": k}
        if k == "normal":
            f.update(mean=0.0, sigma=1.0)
        elif k == "rayleigh":
            f.update(sigma=2.0)
        elif k == "uniform":
            f.update(lower=0.0, upper=1.0)
        fs.append(f)
    d = {"factor": fs}
    if corr:
        d["correlation"] = corr
    return spec_from_table(d, file="t.toml")


@pytest.mark.parametrize("method", ["random", "lhs", "sobol"])
def test_same_seed_same_samples(method):
    s = _spec()
    a = sample(s, 256, method, seed=7)
    b = sample(s, 256, method, seed=7)
    c = sample(s, 256, method, seed=8)
    assert np.array_equal(a.values, b.values)
    assert not np.array_equal(a.values, c.values)
    assert a.names == ("x0", "x1", "x2") and a.method == method and a.seed == 7


def test_values_are_in_base_units():
    s = _spec()
    x = sample(s, 4000, "random", seed=1)
    assert x.values.std() == pytest.approx(1e-3, rel=0.05)  # σ = 1 µm = 1e-3 mm
    assert x.display_values().std() == pytest.approx(1.0, rel=0.05)


def test_lhs_stratifies_every_margin():
    n = 500
    u = uniform_design(n, 4, "lhs", seed=3)
    for j in range(4):
        counts = np.bincount(np.floor(u[:, j] * n).astype(int), minlength=n)
        assert np.all(counts == 1)


def test_sobol_power_of_two_is_balanced():
    n = 1024
    u = uniform_design(n, 3, "sobol", seed=3)
    for j in range(3):
        # each dyadic interval of width 1/64 holds exactly n/64 points (a (t,m,s)-net property)
        counts = np.bincount(np.floor(u[:, j] * 64).astype(int), minlength=64)
        assert np.all(counts == n // 64)


def test_uniforms_strictly_inside():
    u = uniform_design(10_000, 2, "random", seed=0)
    assert u.min() > 0 and u.max() < 1


def test_gaussian_copula_recovers_correlation():
    rho = 0.6
    s = _spec(corr=[{"pair": ["x0", "x1"], "rho": rho}], kinds=("normal", "normal", "rayleigh"))
    n = 40_000
    x = sample(s, n, "random", seed=11).values
    r = np.corrcoef(x[:, 0], x[:, 1])[0, 1]
    se = (1 - rho**2) / math.sqrt(n)  # large-sample s.e. of Pearson's r for bivariate normal
    assert abs(r - rho) < 4 * se
    assert abs(np.corrcoef(x[:, 0], x[:, 2])[0, 1]) < 4 / math.sqrt(n)


def test_copula_rank_correlation_for_non_normal_margins():
    rho = 0.7
    s = _spec(corr=[{"pair": ["x1", "x2"], "rho": rho}], kinds=("normal", "uniform", "rayleigh"))
    n = 40_000
    x = sample(s, n, "lhs", seed=5).values
    rs = stats.spearmanr(x[:, 1], x[:, 2]).statistic
    expected = 6 / math.pi * math.asin(rho / 2)  # Spearman's rho of a Gaussian copula
    assert abs(rs - expected) < 0.01


def test_latin_hypercube_in_place_is_scipys_bit_for_bit():
    """The column-at-a-time LHS draws what scipy's LatinHypercube draws (same generator calls, same
    arithmetic): equal to the last bit, so the seeded studies keep their samples; and the generator is left
    in the same state."""
    from scipy.stats import qmc

    from rvtol.sampling import latin_hypercube

    for n, k, seed in ((1, 1, 0), (7, 3, 1), (1000, 54, 20261111), (4096, 2, 5)):
        g1, g2 = np.random.default_rng(seed), np.random.default_rng(seed)
        np.testing.assert_array_equal(latin_hypercube(n, k, g1), qmc.LatinHypercube(d=k, rng=g2).random(n))
        assert g1.random() == g2.random()
        u = latin_hypercube(n, k, np.random.default_rng(seed))          # and it is a Latin hypercube
        np.testing.assert_array_equal(np.sort(np.floor(u * n), axis=0), np.tile(np.arange(n), (k, 1)).T)


def test_sample_stream_rows_do_not_depend_on_the_batches():
    """A sequential run's rows are the same bits however they were cut into batches: the uniforms of the fixed-n random
    design of the same seed; without a correlation its factor values; through copulas of 3 to 120 factors the same
    values in any batching (and the fixed design's to the last bits)."""
    from rvtol.sampling import SampleStream

    def drawn(s, batches):
        stream = SampleStream(s, 20261129)
        return np.concatenate([stream.next(m) for m in batches])

    s = _spec(kinds=("normal", "uniform", "rayleigh"))
    assert np.array_equal(drawn(s, (1, 7, 300, 1000, 45)), sample(s, 1353, "random", seed=20261129).values)
    import dataclasses

    for k in (3, 42, 120):
        kinds = ("normal", "uniform", "rayleigh") * (k // 3)
        chain = np.eye(k) + 0.3 * (np.eye(k, k=1) + np.eye(k, k=-1))     # positive definite: eigenvalues 1 ± 0.6 cos
        s = dataclasses.replace(_spec(kinds=kinds), correlation=chain)
        got = drawn(s, (1, 7, 300, 1000, 45))
        assert np.array_equal(got, drawn(s, (1353,))) and np.array_equal(got, drawn(s, (500, 500, 353)))
        np.testing.assert_allclose(got, sample(s, 1353, "random", seed=20261129).values, rtol=1e-12, atol=1e-15)
        assert not np.array_equal(got[:100], sample(s, 100, "random", seed=1).values)
