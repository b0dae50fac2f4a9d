"""Statistics against independent references: beta/binomial closed forms, hand formulas."""
import math

import numpy as np
import pytest
from scipy import stats

from rvtol import stats as st


@pytest.mark.parametrize("k,n", [(0, 50), (7, 50), (50, 50), (9970, 10000), (123, 456)])
def test_clopper_pearson_matches_beta_quantiles(k, n):
    lo, hi = st.proportion_ci(k, n, 0.95, "exact")
    ref_lo = 0.0 if k == 0 else stats.beta.ppf(0.025, k, n - k + 1)
    ref_hi = 1.0 if k == n else stats.beta.ppf(0.975, k + 1, n - k)
    assert lo == pytest.approx(ref_lo, abs=1e-10)
    assert hi == pytest.approx(ref_hi, abs=1e-10)


@pytest.mark.parametrize("k,n", [(7, 50), (9970, 10000)])
def test_wilson_matches_hand_formula(k, n):
    z = stats.norm.ppf(0.975)
    p = k / n
    c = (p + z * z / (2 * n)) / (1 + z * z / n)
    h = z / (1 + z * z / n) * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    lo, hi = st.proportion_ci(k, n, 0.95, "wilson")
    assert lo == pytest.approx(c - h, rel=1e-9)
    assert hi == pytest.approx(c + h, rel=1e-9)


def test_yield_counts_failures_as_nonconforming():
    y = np.array([1.0, 2.0, np.nan, 4.0, 10.0])
    ok = np.array([True, True, False, True, True])
    r = st.yield_of(y, ok, lower=0.0, upper=5.0)
    assert (r.conforming, r.n) == (3, 5)
    assert r.estimate == pytest.approx(0.6)
    assert r.ppm == pytest.approx(400_000)


def test_mean_and_std_ci_hand_computed():
    y = np.array([1.0, 2.0, 3.0, 4.0, 5.0])
    m, lo, hi = st.mean_ci(y, 0.95)
    h = stats.t.ppf(0.975, 4) * math.sqrt(2.5) / math.sqrt(5)
    assert (m, lo, hi) == pytest.approx((3.0, 3 - h, 3 + h))
    s, slo, shi = st.std_ci(y, 0.95)
    assert s == pytest.approx(math.sqrt(2.5))
    assert slo == pytest.approx(math.sqrt(4 * 2.5 / stats.chi2.ppf(0.975, 4)))
    assert shi == pytest.approx(math.sqrt(4 * 2.5 / stats.chi2.ppf(0.025, 4)))


def test_percentile_ci_ranks_and_missing_tail():
    y = np.arange(1.0, 1001.0)
    est, lo, hi = st.percentile_ci(y, 0.5, 0.95)
    l_rank = int(stats.binom.ppf(0.025, 1000, 0.5))
    u_rank = int(stats.binom.ppf(0.975, 1000, 0.5)) + 1
    assert (lo, hi) == (float(l_rank), float(u_rank))
    assert lo <= est <= hi
    # 0.135 % from 1000 samples: no lower rank exists -> None, not a number
    _, lo2, _ = st.percentile_ci(y, 0.00135, 0.95)
    assert lo2 is None


def test_percentile_ci_coverage_is_at_least_nominal():
    # the order-statistic interval is distribution-free: check coverage by simulation
    g = np.random.default_rng(0)
    q, n, trials = 0.9, 200, 2000
    true = stats.expon.ppf(q)
    hits = 0
    for _ in range(trials):
        ys = np.sort(g.exponential(size=n))
        _, lo, hi = st.percentile_ci(ys, q, 0.95)
        hits += lo <= true <= hi
    assert hits / trials >= 0.95 - 3 * math.sqrt(0.95 * 0.05 / trials)


def test_cpk_hand_computed_and_bissell():
    g = np.random.default_rng(1)
    y = g.normal(10.0, 1.0, 5000)
    c = st.capability(y, 4.0, 18.0)
    mu, s = y.mean(), y.std(ddof=1)
    assert c["cp"] == pytest.approx(14 / (6 * s))
    assert c["cpk"] == pytest.approx(min(18 - mu, mu - 4) / (3 * s))
    h = stats.norm.ppf(0.975) * math.sqrt(1 / (9 * 5000) + c["cpk"] ** 2 / (2 * 4999))
    assert c["cpk_lo"] == pytest.approx(c["cpk"] - h)
    # percentile Cpk of a normal sample approaches the normal Cpk
    assert c["cpk_percentile"] == pytest.approx(c["cpk"], rel=0.08)


def test_one_sided_cpk_and_no_cp():
    y = np.random.default_rng(2).normal(0, 1, 1000)
    c = st.capability(y, None, 3.0)
    assert c["cp"] is None
    assert c["cpk"] == pytest.approx((3 - y.mean()) / (3 * y.std(ddof=1)))


def test_convergence_trace_ends_at_the_full_sample_mean_and_yield():
    g = np.random.default_rng(3)
    y = g.normal(size=3000)
    ok = np.ones(3000, bool)
    tr = st.convergence_trace(y, ok, [(None, 1.0)])
    assert tr["n"][-1] == 3000
    assert tr["mean"][-1] == pytest.approx(y.mean())
    assert tr["yield_0"][-1] == pytest.approx(np.mean(y <= 1.0))


def test_order_statistic_bootstrap_has_the_resampling_bootstrap_distribution():
    """Quantiles of bootstrap resamples drawn from the Dirichlet spacings of uniform order statistics
    (O(1) per resample) against resamples formed explicitly: the same distribution (two-sample KS at 1e-3,
    per quantile; a rank or interpolation error shifts it by ≥ one order statistic and fails)."""
    rng = np.random.default_rng(3)
    y = np.sort(rng.gamma(2.0, size=301))
    qs = [0.00135, 0.1, 0.5, 0.9, 0.99865]
    fast = st.bootstrap_quantiles(y, qs, n_boot=4000, seed=5)
    slow = np.quantile(y[rng.integers(0, y.size, (4000, y.size))], qs, axis=1).T
    for j in range(len(qs)):
        assert stats.ks_2samp(fast[:, j], slow[:, j]).pvalue > 1e-3, qs[j]
    # the percentile-Cpk interval of both routes (2000 resamples each): endpoints within their sampling error
    lo_f, hi_f = st.percentile_cpk_ci(y, None, 12.0, 0.9, n_boot=2000, seed=6)
    lo_s, hi_s = st.bootstrap_ci(y, lambda s: st.percentile_cpk(s, None, 12.0), 0.9, n_boot=2000, seed=7)
    spread = hi_s - lo_s
    assert abs(lo_f - lo_s) < 0.1 * spread and abs(hi_f - hi_s) < 0.1 * spread


def test_normality_of_a_sample_with_a_small_spread_is_scipys():
    # skewness, kurtosis and A² do not depend on the scale: a spread of 1e-3 is measured like any other
    y = 1e-3 * np.random.default_rng(5).gamma(4.0, size=400)
    s = st.normality(y)
    assert s.skewness == pytest.approx(stats.skew(y), rel=1e-9)
    assert s.excess_kurtosis == pytest.approx(stats.kurtosis(y), rel=1e-9)
    assert s.ad_statistic == pytest.approx(stats.anderson(y, "norm", method="interpolate").statistic, rel=1e-9)
    assert st.normality(np.full(20, 0.5)) is None and st.normality(y[:7]) is None


def test_convergence_trace_mean_interval_is_the_running_normal_interval():
    # at each n: the mean of the evaluated samples so far ± z·s/√m, s with Bessel's n − 1 (m evaluated samples)
    g = np.random.default_rng(4)
    y = g.normal(2.0, 0.5, 500)
    ok = g.random(500) > 0.1
    tr = st.convergence_trace(y, ok, [], confidence=0.90)
    assert (tr["n"][0], tr["n"][-1]) == (10, 500)                     # from 10 samples on, to the last
    assert list(st.convergence_trace(y[:6], ok[:6], [])["n"]) == [6]
    ns = st.convergence_trace(np.zeros(100_000), np.ones(100_000, bool), [])["n"]     # 60 log-spaced counts
    assert len(ns) == 60 and (ns[0], ns[-1]) == (10, 100_000) and np.all(np.diff(ns) > 0)
    assert ns[30] == int(np.geomspace(10, 100_000, 60)[30])                          # geometric, not linear
    z = stats.norm.ppf(0.95)
    for n, m, lo, hi in zip(tr["n"], tr["mean"], tr["mean_lo"], tr["mean_hi"]):
        seen = y[:n][ok[:n]]
        half = z * seen.std(ddof=1) / math.sqrt(seen.size)
        assert (m, lo, hi) == (pytest.approx(seen.mean()), pytest.approx(seen.mean() - half),
                               pytest.approx(seen.mean() + half))


def test_rss_by_hand():
    assert st.rss([3.0, 4.0]) == 5.0 and st.rss([3.0, 4.0], squared=True) == 25.0
    assert st.rss([1.0, 2.0], [[1.0, 0.5], [0.5, 1.0]]) == pytest.approx(math.sqrt(1 + 4 + 2 * 0.5 * 2))
    assert st.rss([3.0, 4.0], weights=np.array([1.0, 0.25])) == pytest.approx(math.sqrt(13.0))
    assert st.rss([3.0, 4.0], variances=np.array([1.0, 0.0])) == pytest.approx(math.sqrt(26.0))
    assert st.rss([[3.0, 4.0], [5.0, 12.0]], axis=1) == pytest.approx([5.0, 13.0])
    assert st.rss([3.0, np.nan, 4.0], skip_nan=True) == 5.0 and math.isnan(st.rss([3.0, np.nan, 4.0]))


@pytest.mark.parametrize("outliers, defined", [(1, False), (3, True)])
def test_a_percentile_cpk_interval_needs_a_cpk_on_half_the_resamples(outliers, defined):
    # 1000 values, all 0 but `outliers` ones: a resample's 99.865 % point (linear, between its 998th and 999th
    # values) lies above its median only when it draws an outlier twice or more — K ~ Poisson(outliers):
    # P(K ≥ 2) = 1 − 2/e = 0.26 for one (too few resamples have a Cpk: no interval), 1 − 4/e³ = 0.80 for three
    y = np.sort(np.r_[np.zeros(1000 - outliers), np.ones(outliers)])
    lo, hi = st.percentile_cpk_ci(y, -1.0, 2.0)
    assert (lo is not None and hi is not None and lo <= hi) if defined else (lo, hi) == (None, None)


def test_normality_needs_eight_values():
    y = np.array([0.1, 0.4, 0.2, 0.9, 0.5, 0.3, 0.8, 0.6])
    assert st.normality(y[:7]) is None
    assert st.normality(y).skewness == pytest.approx(stats.skew(y), rel=1e-9)


def test_a_value_on_a_limit_conforms():
    y = np.array([1.0, 1.5, 2.0, 0.999, 2.001])
    r = st.yield_of(y, np.ones(5, bool), 1.0, 2.0)
    assert (r.n, r.conforming, r.estimate) == (5, 3, 0.6)
    assert st.yield_of(y, np.ones(5, bool), None, 2.0).conforming == 4
    assert st.yield_of(y, np.ones(5, bool), 1.0, None).conforming == 4


def test_the_reported_percentiles_pair_about_the_median_and_reach_three_sigma():
    assert 50.0 in st.PERCENTILES
    assert sorted(st.PERCENTILES) == sorted(round(100.0 - p, 6) for p in st.PERCENTILES)
    assert min(st.PERCENTILES) == round(100.0 * stats.norm.cdf(-3.0), 3)          # 0.135 %: the −3σ point


@pytest.mark.parametrize("confidence, n", [(0.3, 40), (0.95, 40), (0.95, 2)])
def test_std_interval_is_the_chi_square_interval_at_any_level_from_two_values(confidence, n):
    y = np.random.default_rng(6).normal(0.0, 2.0, n)
    s, lo, hi = st.std_ci(y, confidence)
    a = 1.0 - confidence
    assert s == pytest.approx(np.std(y, ddof=1))
    assert lo == pytest.approx(s * math.sqrt((n - 1) / stats.chi2.ppf(1 - a / 2, n - 1)))
    assert hi == pytest.approx(s * math.sqrt((n - 1) / stats.chi2.ppf(a / 2, n - 1)))
    assert all(math.isnan(v) for v in st.std_ci(y[:1], confidence))


def test_capability_gives_bissells_two_sided_cpk_interval():
    y = np.random.default_rng(7).normal(10.0, 0.1, 60)
    c = st.capability(y, 9.6, 10.5, confidence=0.90)
    mu, s = y.mean(), y.std(ddof=1)
    cpk = min(10.5 - mu, mu - 9.6) / (3 * s)
    h = stats.norm.ppf(0.95) * math.sqrt(1 / (9 * 60) + cpk**2 / (2 * 59))
    assert (c["cp"], c["cpk"], c["cpk_lo"], c["cpk_hi"]) == (
        pytest.approx(0.9 / (6 * s)), pytest.approx(cpk), pytest.approx(cpk - h), pytest.approx(cpk + h))


def test_percentile_cpk_interval_cuts_equal_tails_off_the_resamples():
    y = np.sort(np.random.default_rng(8).gamma(5.0, size=300))
    lo, hi = st.percentile_cpk_ci(y, 0.0, 20.0, confidence=0.5, n_boot=400, seed=3)
    q = st.bootstrap_quantiles(y, st.CPK_QUANTILES, 400, 3)
    vals = st._cpk_from_quantiles(q[:, 0], q[:, 1], q[:, 2], 0.0, 20.0)       # the resamples' Cpk
    # a quarter of the 400 below and a quarter above, to the two resamples the linear interpolation spans
    assert np.mean(vals < lo) == pytest.approx(0.25, abs=0.01) and np.mean(vals > hi) == pytest.approx(0.25, abs=0.01)


def test_ppm_and_its_interval_from_the_clopper_pearson_yield_interval():
    y = np.r_[np.zeros(997), np.full(3, 5.0)]                  # 3 of 1000 outside: 3000 ppm
    r = st.yield_of(y, np.ones(1000, bool), None, 1.0)
    lo, hi = stats.beta.ppf(0.025, 997, 4), stats.beta.ppf(0.975, 998, 3)
    assert r.ppm == pytest.approx(3000.0, rel=1e-9)
    assert r.ppm_ci == (pytest.approx((1 - hi) * 1e6, rel=1e-9), pytest.approx((1 - lo) * 1e6, rel=1e-9))


def test_a_percentile_interval_narrows_with_its_confidence():
    # order statistics y_(l), y_(u) with l, u the a/2 and 1 − a/2 points of Binomial(n, q): a 30 % interval lies
    # strictly inside the 90 % one
    y = np.sort(np.random.default_rng(9).normal(size=200))
    _, lo30, hi30 = st.percentile_ci(y, 0.5, 0.30)
    _, lo90, hi90 = st.percentile_ci(y, 0.5, 0.90)
    assert lo90 < lo30 < hi30 < hi90
    assert st.percentile_ci(y, 0.5) == st.percentile_ci(y, 0.5, 0.95)      # 95 % unless told
    assert (lo30, hi30) == (y[int(stats.binom.ppf(0.35, 200, 0.5)) - 1], y[int(stats.binom.ppf(0.65, 200, 0.5))])


def test_combined_lower_bound_adds_the_deviations_in_quadrature():
    # 0.99 with its own bound 0.97 (deviation 0.02) and another error of deviation 0.01: 0.99 − √(0.02² + 0.01²)
    assert st.combined_lower_bound(0.99, 0.97, 0.01) == pytest.approx(0.99 - math.sqrt(0.02**2 + 0.01**2))
    assert st.combined_lower_bound(0.99, 0.97, 0.0) == pytest.approx(0.97)
    assert st.combined_lower_bound(1.0, 1.0, 0.01) == pytest.approx(0.99)
    assert st.combined_lower_bound(None, 0.97, 0.01) == 0.97 and st.combined_lower_bound(0.99, None, 0.01) is None
    assert st.combined_lower_bound(math.inf, 0.97, 0.01) == 0.97
    assert math.isnan(st.combined_lower_bound(0.99, math.nan, 0.01))


def test_a_nan_output_is_outside_either_limit_even_where_marked_evaluated():
    y = np.array([0.5, np.nan, 1.5, 0.7])
    ok = np.ones(4, bool)
    for limits, k in [((0.0, 1.0), 2), ((0.0, None), 3), ((None, 1.0), 2)]:
        assert st.yield_of(y, ok, *limits).conforming == k
        tr = st.convergence_trace(y, ok, [limits])
        assert tr["yield_0"][-1] == k / 4


def test_n_for_cpk_finds_a_plan_of_hundreds_of_millions_by_bisection():
    # Cpk 1.3301 against 1.33: Bissell's bound reaches it only at n ≈ 2.7e8 (stepping one unit at a time never would)
    cpk, req, c = 1.3301, 1.33, 0.95
    z = stats.norm.ppf(c)
    bissell = lambda m: cpk - z * math.sqrt(1 / (9 * m) + cpk**2 / (2 * (m - 1)))  # noqa: E731
    n = st.n_for_cpk(cpk, req, c)
    assert 2.6e8 < n < 2.8e8 and bissell(n) >= req > bissell(n - 1)


def test_rss_of_a_correlation_matrix_that_is_not_positive_semidefinite_is_clipped_at_zero():
    r = [[1.0, 0.9, 0.9], [0.9, 1.0, -0.9], [0.9, -0.9, 1.0]]       # no valid correlation: cᵀRc < 0 for c below
    c = [0.5, -0.5, -0.5]                                             # 0.25·(3 − 5.4) = −0.6
    assert st.rss(c, r) == 0.0 and st.rss(c, r, squared=True) == 0.0


def test_the_default_bootstrap_seed_is_reproducible():
    y = np.sort(np.random.default_rng(10).normal(size=50))
    a, b = st.bootstrap_quantiles(y, st.CPK_QUANTILES), st.bootstrap_quantiles(y, st.CPK_QUANTILES)
    assert a.shape == (200, 3) and np.array_equal(a, b)


def test_a_statistic_undefined_on_most_resamples_gives_no_bootstrap_interval():
    y = np.random.default_rng(11).normal(size=30)
    assert st.bootstrap_ci(y, lambda r: None) == (None, None)
    assert st.bootstrap_ci(y, lambda r: r.mean() if r.max() > 2.5 else None) == (None, None)   # max > 2.5: rare
    lo, hi = st.bootstrap_ci(y, np.mean)
    assert lo < y.mean() < hi


def test_no_capability_from_a_sample_holding_a_nan():
    c = st.capability(np.array([1.0, 2.0, np.nan, 3.0]), 0.0, 5.0)
    assert c == dict(cp=None, cpk=None, cpk_lo=None, cpk_hi=None, cpk_percentile=None)


def test_the_default_proportion_interval_is_the_95_percent_clopper_pearson():
    lo, hi = st.proportion_ci(7, 50)
    assert (lo, hi) == (pytest.approx(stats.beta.ppf(0.025, 7, 44)), pytest.approx(stats.beta.ppf(0.975, 8, 43)))


def test_a_bootstrap_interval_narrows_with_its_confidence():
    y = np.random.default_rng(12).normal(size=40)
    lo30, hi30 = st.bootstrap_ci(y, np.mean, confidence=0.30)
    lo90, hi90 = st.bootstrap_ci(y, np.mean, confidence=0.90)
    assert lo90 < lo30 < hi30 < hi90


def test_no_normality_from_a_sample_holding_a_nan():
    y = np.random.default_rng(13).normal(size=20)
    y[4] = np.nan
    assert st.normality(y) is None


def test_the_mean_interval_of_two_values_is_students_t_with_one_degree_of_freedom():
    # n = 2: s = |y₂ − y₁|/√2 and t with 1 degree of freedom is Cauchy, its quantile tan(π(p − ½)) — for 1 and 3,
    # 2 ± tan(0.475π)·√2/√2 = 2 ± 12.706; one value has no interval
    m, lo, hi = st.mean_ci(np.array([1.0, 3.0]), 0.95)
    t = math.tan(math.pi * 0.475)
    assert (m, lo, hi) == (2.0, pytest.approx(2.0 - t, rel=1e-12), pytest.approx(2.0 + t, rel=1e-12))
    m1, lo1, hi1 = st.mean_ci(np.array([5.0]))
    assert m1 == 5.0 and math.isnan(lo1) and math.isnan(hi1)


def test_a_proportion_of_a_negative_count_is_refused_not_a_nan_interval():
    # no samples: no interval (NaN, NaN); a negative sample count is no sample count at all
    assert all(math.isnan(v) for v in st.proportion_ci(0, 0))
    with pytest.raises(ValueError):
        st.proportion_ci(0, -1)


def test_an_anderson_darling_p_at_the_top_of_stephens_table_reads_at_least():
    # Stephens' (1974) table stops at 15 %: scipy's interpolated p is 0.15 for any A² below that level's critical
    # value, which means p ≥ 0.15; below 0.15 the interpolated value is shown as it is
    normal_scores = stats.norm.ppf((np.arange(1, 201) - 0.5) / 200)       # the most normal sample of 200
    shape = st.normality(normal_scores)
    assert shape.ad_pvalue == 0.15 and shape.describe().endswith("(p ≥ 0.15)")
    assert st.Shape(0.1, 0.2, 0.5, 0.1).describe().endswith("(p = 0.1)")


def test_the_default_percentile_cpk_interval_cuts_95_percent_of_the_default_resamples():
    # the interval's defaults (95 %, the resamples bootstrap_quantiles draws by default: 200, its fixed seed) by
    # hand: each resample's percentile Cpk min((U − median)/(p99.865 − median), (median − L)/(median − p0.135))
    y = np.sort(np.random.default_rng(14).gamma(5.0, size=300))
    q = st.bootstrap_quantiles(y, st.CPK_QUANTILES)
    cpk = np.minimum((20.0 - q[:, 1]) / (q[:, 2] - q[:, 1]), (q[:, 1] - 0.0) / (q[:, 1] - q[:, 0]))
    assert st.percentile_cpk_ci(y, 0.0, 20.0) == (pytest.approx(np.quantile(cpk, 0.025), rel=1e-12),
                                                  pytest.approx(np.quantile(cpk, 0.975), rel=1e-12))


def test_a_bootstrap_interval_needs_its_statistic_on_half_the_resamples():
    # resamples of size 3 from {0, 1, 2}: one holding both 0 and 1 has probability 1 − 2·(2/3)³ + (1/3)³ = 12/27 = 0.44
    # (under half: no interval, as percentile_cpk_ci), one holding a 0 has 1 − (2/3)³ = 19/27 = 0.70 (an interval)
    y = np.array([0.0, 1.0, 2.0])
    assert st.bootstrap_ci(y, lambda r: r.mean() if 0.0 in r and 1.0 in r else None, n_boot=2000) == (None, None)
    lo, hi = st.bootstrap_ci(y, lambda r: r.mean() if 0.0 in r else None, n_boot=2000)
    assert 0.0 <= lo < hi <= 4 / 3                  # a resample holding a 0 has a mean of at most (0 + 2 + 2)/3


@pytest.mark.parametrize("method", ["exact", "wilson"])
def test_no_samples_give_no_lower_bound_of_a_proportion(method):
    # n = 0 carries no evidence: NaN (neither the 0 of Clopper–Pearson's k = 0 nor Wilson's 0/0)
    assert math.isnan(st.proportion_lower_bound(0, 0, 0.95, method))
    assert st.proportion_lower_bound(0, 1, 0.95, method) == 0.0       # one sample, not conforming: bound 0


def test_convergence_trace_shows_no_mean_before_a_sample_is_evaluated_and_no_interval_before_two():
    """The first ten samples failed: at n = 10 there is no mean (NaN, not 0 ± 0); at the count where one value is
    evaluated, the mean is that value and its interval unknown (NaN, not zero width); later the normal interval."""
    y = np.arange(20.0) + 5
    ok = np.arange(20) >= 10
    tr = st.convergence_trace(y, ok, [], points=20)
    at = {int(n): i for i, n in enumerate(tr["n"])}
    assert np.isnan(tr["mean"][at[10]]) and np.isnan(tr["mean_lo"][at[10]]) and np.isnan(tr["mean_hi"][at[10]])
    assert tr["mean"][at[11]] == 15.0 and np.isnan(tr["mean_lo"][at[11]])
    vals = y[10:20]
    half = st.stats.norm.ppf(0.975) * vals.std(ddof=1) / np.sqrt(10)
    assert tr["mean"][at[20]] == pytest.approx(vals.mean()) and tr["mean_lo"][at[20]] == pytest.approx(vals.mean() - half)


def test_rss_takes_its_correlation_by_keyword_and_every_other_option_only_by_keyword():
    # √(cᵀRc) = √(1 + 4 + 2·0.5·1·2) = √7 with the correlation named; a third positional argument is refused, not read
    # as the weights (weights, variances, axis, ... are keyword-only)
    assert st.rss([1.0, 2.0], correlation=[[1.0, 0.5], [0.5, 1.0]]) == pytest.approx(math.sqrt(7.0))
    assert st.rss(terms=[3.0, 4.0]) == 5.0
    with pytest.raises(TypeError):
        st.rss([3.0, 4.0], None, np.array([1.0, 0.25]))


def test_a_negative_deviation_adds_no_error_to_a_lower_bound():
    # a one-sided deviation below 0 (the other error's quantile above the estimate, as FitEffect clips it) lowers
    # nothing: the bound stays 0.99 − √(0.02² + 0²) = 0.97, for −0.01 as for −2
    for deviation in (-0.01, -2.0):
        assert st.combined_lower_bound(0.99, 0.97, deviation) == pytest.approx(0.97, rel=1e-14)


@pytest.mark.parametrize("d", [1e-14, 3e-14, 1e-13])
def test_n_for_yield_of_a_requirement_reached_just_past_one_sample_is_two(d):
    # no failures (Clopper–Pearson): the bound at n is (1 − c)^(1/n), so a requirement (1 − c)^(1/n*) with
    # n* = 1 + d (d below the search's 1e-12 resolution in ln n, where it lands on n = 1) takes the success-run
    # size ⌈ln(1 − c) / ln(required)⌉ = ⌈n*⌉ = 2 samples
    level = 0.95
    required = (1.0 - level) ** (1.0 / (1.0 + d))
    assert math.ceil(math.log(1.0 - level) / math.log(required)) == 2
    assert st.n_for_yield(1.0, required, level) == 2


@pytest.mark.parametrize("estimate,method", [(1e-9, "exact"), (3e-9, "exact"), (3e-10, "wilson")])
def test_n_for_yield_reaches_a_requirement_the_largest_plan_meets_exactly(estimate, method):
    # the requirement is the bound of the largest plan itself: it reaches it (≥), so there is a plan — at the top of
    # the range (the bound grows with n at a fixed rate; at 1e15 it moves by less than an ulp over a few samples)
    required = st.proportion_lower_bound(estimate * st.N_PLAN_MAX, st.N_PLAN_MAX, 0.95, method)
    n = st.n_for_yield(estimate, required, 0.95, method)
    assert n is not None and 0.999 * st.N_PLAN_MAX < n <= st.N_PLAN_MAX


@pytest.mark.parametrize("method", ["exact", "wilson"])
@pytest.mark.parametrize("level", [0.5, 0.95])
def test_no_plan_for_a_yield_estimate_that_only_equals_its_requirement(level, method):
    # 45 of 50 conform against a requirement of 0.9 (read from a file: equal values, not one object): the estimate
    # does not exceed the requirement, so no n is offered — also at level 0.5, where Wilson's bound is the estimate
    conforming, n = 45, 50
    assert st.n_for_yield(conforming / n, float("0.9"), level, method) is None


def test_one_value_has_no_capability_and_raises_no_warning():
    # one value has no spread: no Cp, Cpk or percentile Cpk — said by None, not by NumPy's "Degrees of freedom <= 0"
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        c = st.capability(np.array([2.0]), 0.0, 4.0)
    assert c == {"cp": None, "cpk": None, "cpk_lo": None, "cpk_hi": None, "cpk_percentile": None}


def test_the_resampling_bootstrap_draws_as_many_resamples_by_default_as_the_order_statistic_one():
    # bootstrap_ci is the reference percentile_cpk_ci is checked against, and the sign-off judges a percentile Cpk with
    # it: by default it draws the 200 resamples bootstrap_quantiles draws (its [200, 3], test above) — one call each
    calls = []
    st.bootstrap_ci(np.arange(10.0), lambda r: calls.append(1) or float(r.mean()))
    assert len(calls) == 200 == st.bootstrap_quantiles(np.arange(10.0), st.CPK_QUANTILES).shape[0]


def test_the_running_mean_interval_of_two_evaluated_values_divides_by_n_minus_1():
    # only samples 5 and 8 evaluated (values 5, 8): mean 6.5, s² = (1.5² + 1.5²)/(2 − 1) = 4.5, half-width
    # z·√(4.5/2) = 1.5 z at every count from 10 on
    y = np.arange(12.0)
    ok = np.isin(np.arange(12), [5, 8])
    tr = st.convergence_trace(y, ok, [], confidence=0.95)
    z = stats.norm.ppf(0.975)
    assert list(tr["n"]) == [10, 11, 12]
    assert np.all(tr["mean"] == 6.5)
    assert tr["mean_lo"] == pytest.approx(6.5 - 1.5 * z, rel=1e-12) and tr["mean_hi"] == pytest.approx(6.5 + 1.5 * z)


@pytest.mark.parametrize("first", [1, 2, 3, 57, 1000, 10**12 + 7])
@pytest.mark.parametrize("guess", [1, 2, 56, 57, 58, 999, 10**12, 10**15])
def test_smallest_integer_finds_the_first_true_from_any_guess(first, guess):
    """Against the definition: ok(n) and not ok(n - 1), whatever side of the answer the guess lies."""
    calls = []

    def ok(n):
        calls.append(n)
        return n >= first

    assert st.smallest_integer(ok, guess, 1, 10**15) == first
    assert len(calls) <= 2 + 52          # two looks, then bisection over at most 10^15 integers
    assert st.smallest_integer(lambda n: n >= first, guess, first, 10**15) == first   # the answer at the low end


def test_n_for_yield_of_a_plan_near_a_trillion_samples_looks_a_few_dozen_times(monkeypatch):
    """A requirement 5e-13 below its estimate needs about 1.2e13 samples; neighbouring plans' bounds then differ by
    less than rounding, and stepping one integer at a time from the rounded root made millions of bound evaluations
    (minutes).  The plan is the smallest n whose bound meets the requirement, within rounding."""
    calls = []
    bound = st.proportion_lower_bound

    def counted(*a, **k):
        calls.append(1)
        if len(calls) > 10_000:
            raise AssertionError("more than 10 000 bound evaluations")
        return bound(*a, **k)

    monkeypatch.setattr(st, "proportion_lower_bound", counted)
    est, req = 0.9999999999995, 0.999999999999
    n = st.n_for_yield(est, req, 0.95)
    assert len(calls) < 200
    assert bound(est * n, n, 0.95, "exact") >= req
    # in the Poisson limit (about six failures among 10^13), Clopper-Pearson's upper failure rate with F failures is
    # chi2(0.95; 2F + 2) / 2n: the plan solves chi2(0.95; 2(1 - est)n + 2) / 2n = 1 - req
    from scipy.optimize import brentq

    poisson = brentq(lambda m: stats.chi2.ppf(0.95, 2 * (1 - est) * m + 2) / (2 * m) - (1 - req), 1e10, 1e15)
    assert n == pytest.approx(poisson, rel=1e-3)


def test_a_bootstrap_interval_needs_at_least_half_the_resamples_finite(monkeypatch):
    """The rule of both bootstrap intervals: an interval from at least half the resamples (n_boot // 2 of them, an odd
    n_boot rounding the half down), None from fewer.  Exactly at the half (mutation survivors: < read as <=, // as /)."""
    calls = []

    def every_other(sample):           # finite on even calls: 100 of 201 resamples, 100 = 201 // 2
        calls.append(1)
        return float(np.mean(sample)) if len(calls) % 2 == 0 else math.nan

    y = np.linspace(0.0, 1.0, 20)
    lo, hi = st.bootstrap_ci(y, every_other, n_boot=201)
    assert lo is not None and lo <= hi and len(calls) == 201
    calls.clear()
    assert st.bootstrap_ci(y, lambda s: (calls.append(1), math.nan if len(calls) > 99 else 0.5)[1], n_boot=201) \
        == (None, None)               # 99 finite of 201: fewer than the half

    def half_finite(*_):               # the Cpk of each of 200 resamples: the first 100 undefined
        return np.concatenate([np.full(100, np.nan), np.linspace(1.0, 2.0, 100)])

    monkeypatch.setattr(st, "_cpk_from_quantiles", half_finite)
    lo, hi = st.percentile_cpk_ci(np.sort(y), 0.0, 1.0, n_boot=200)
    assert (lo, hi) == pytest.approx((float(np.quantile(np.linspace(1.0, 2.0, 100), 0.025)),
                                      float(np.quantile(np.linspace(1.0, 2.0, 100), 0.975))))
