"""Requirements on a population statistic (issue 39 item 1): a catalogue's typical value judged as the median's or
mean's confidence interval against a band — PASS inside, FAIL wholly outside, UNDECIDED between — against hand
computations of the order-statistic bounds (math.comb) and of Student's t interval (scipy)."""
import json
import math

import numpy as np
import pytest
from scipy import stats

from rvtol.distributions import Distribution
from rvtol.errors import SpecError
from rvtol.mc import run_monte_carlo
from rvtol.model import LinearModel, Quantity
from rvtol.params import Params
from rvtol.signoff import digest
from rvtol.spec import Factor, Requirement, ToleranceSpec, requirements_from_tables
from rvtol.verdict import judge_statistic, statistic_interval


def _median_ranks(n: int, level: float) -> tuple[int, int]:
    """By hand: the largest rank l with P(B ≤ l − 1) ≤ 1 − level and the smallest u with P(B ≤ u − 1) ≥ level,
    B ~ Binomial(n, ½), from the binomial sums written out."""
    cdf = np.cumsum([math.comb(n, i) for i in range(n + 1)]) / 2.0 ** n       # P(B ≤ i)
    lo = max(l for l in range(0, n + 1) if l == 0 or cdf[l - 1] <= 1.0 - level)
    hi = min(u for u in range(1, n + 2) if u == n + 1 or cdf[u - 1] >= level)
    return lo, hi


@pytest.mark.parametrize("n", [4, 5, 9, 20, 101])     # 4: no lower rank (1/16 > 5 %); 5: the lowest value (1/32)
def test_median_bounds_are_the_order_statistics_of_the_binomial_ranks(n):
    y = np.random.default_rng(n).normal(size=n)
    r = Requirement("k", lower=-1.0, upper=1.0, statistic="median")
    est, lo, hi = statistic_interval(r, y)
    l, u = _median_ranks(n, 0.95)
    s = np.sort(y)
    assert est == pytest.approx(np.median(y))
    assert lo == (s[l - 1] if l >= 1 else None)
    assert hi == (s[u - 1] if u <= n else None)


def test_median_bounds_with_failed_samples_count_them_on_either_side():
    """4 of 30 samples failed: the ranks are those of all 30; the failed are taken below the evaluated for the
    lower bound and above them for the upper."""
    y = np.arange(26, dtype=float)
    r = Requirement("k", lower=0.0, statistic="median")
    l, u = _median_ranks(30, 0.95)
    est, lo, hi = statistic_interval(r, y, n_failed=4)
    assert lo == y[l - 4 - 1] and hi == y[u - 1]
    assert est == np.median(y)


def test_median_bounds_cover_at_their_level():
    """The ranks above (which the bounds are, test before) cover: the one-sided 95 % bounds of the median of an
    exponential (median ln 2) from samples of 25 hold it in ≥ 95 % of the samples — the exact coverage P(B ≥ l) by
    hand, the simulated within 4 standard errors; and the function's bounds on a few of them are those ranks."""
    n, reps = 25, 20000
    ys = np.sort(np.random.default_rng(1).exponential(size=(reps, n)), axis=1)
    l, u = _median_ranks(n, 0.95)
    for got, rank in ((np.mean(ys[:, l - 1] <= math.log(2.0)), l), (np.mean(ys[:, u - 1] >= math.log(2.0)), n + 1 - u)):
        exact = sum(math.comb(n, i) for i in range(rank, n + 1)) / 2.0 ** n
        assert exact >= 0.95
        assert abs(got - exact) < 4.0 * math.sqrt(exact * (1 - exact) / reps)
    r = Requirement("k", lower=0.0, statistic="median")
    for y in ys[:5]:
        assert statistic_interval(r, y)[1:] == (y[l - 1], y[u - 1])


def test_mean_interval_is_students_t_and_unbounded_while_samples_fail():
    y = np.random.default_rng(2).normal(300.0, 20.0, 50)
    r = Requirement("k", lower=250.0, upper=350.0, statistic="mean")
    est, lo, hi = statistic_interval(r, y)
    a, b = stats.t.interval(0.90, 49, loc=y.mean(), scale=stats.sem(y))      # each end one-sided 95 %
    assert (est, lo, hi) == pytest.approx((y.mean(), a, b), rel=1e-12)
    two = Requirement("k", lower=250.0, upper=350.0, statistic="mean", bound="two-sided")
    a2, b2 = stats.t.interval(0.95, 49, loc=y.mean(), scale=stats.sem(y))
    assert statistic_interval(two, y)[1:] == pytest.approx((a2, b2), rel=1e-12)
    assert statistic_interval(r, y, n_failed=1)[1:] == (None, None)
    j = judge_statistic(r, est, None, None, 51, 1)
    assert not j.passed and j.undecided and "not bounded" in " ".join(j.reasons)


def test_pass_fail_undecided_and_the_samples_that_would_decide():
    r = Requirement("k", lower=156.8, upper=235.2, statistic="median")
    assert judge_statistic(r, 200.0, 190.0, 210.0, 100).passed
    f = judge_statistic(r, 349.0, 345.0, 353.0, 1500)                  # an over-stiff model: wholly above
    assert not f.passed and not f.undecided and f.n_to_demonstrate is None and "above" in f.reasons[0]
    assert f.violation > 1.0
    # straddling the upper limit, the estimate inside: n (h/d)² with h = its upper half-width, d to the limit
    u = judge_statistic(r, 230.0, 226.0, 240.0, 400)
    assert u.undecided and not u.passed
    assert u.n_to_demonstrate == math.ceil(400 * (10.0 / 5.2) ** 2)
    assert "PASS, if the estimate held" in u.reasons[-1]
    # the estimate outside, its interval reaching in: more samples would show the FAIL
    w = judge_statistic(r, 240.0, 232.0, 248.0, 400)
    assert w.undecided and w.n_to_demonstrate == math.ceil(400 * (8.0 / 4.8) ** 2)
    assert "FAIL, if the estimate held" in w.reasons[-1]
    # one-sided band: only a lower limit
    one = Requirement("k", lower=196.0, statistic="median")
    assert judge_statistic(one, 349.0, 345.0, 353.0, 1500).passed


def test_a_statistic_requirement_is_read_and_refused_as_written():
    t = lambda d: [Params({"requirement": [d]}, file="req.toml").tables("requirement")[0]]  # noqa: E731
    r, = requirements_from_tables(t({"output": "k", "statistic": "median", "lower": 1.0, "upper": 2.0,
                                     "reading": "b/a", "source": "catalogue", "status": "recalled"}))
    assert (r.statistic, r.min_yield, r.min_cpk, r.reading, r.status) == ("median", None, None, "b/a", "recalled")
    assert r.label == "median of k in [1, 2]" and not r.per_unit
    with pytest.raises(SpecError) as e:
        requirements_from_tables(t({"output": "k", "statistic": "median", "lower": 1.0, "min_yield": 0.99}))
    assert e.value.key == "requirement[0].min_yield" and "confidence interval" in e.value.reason
    with pytest.raises(SpecError) as e:
        requirements_from_tables(t({"output": "k", "statistic": "mode", "lower": 1.0}))
    assert e.value.key == "requirement[0].statistic"
    with pytest.raises(SpecError) as e:
        requirements_from_tables(t({"output": "k", "lower": 1.0, "status": "guessed"}))
    assert e.value.key == "requirement[0].status"
    with pytest.raises(SpecError) as e:
        requirements_from_tables(t({"output": "k", "statistic": "mean", "lower": 1.0, "cpk_method": "normal"}))
    assert e.value.key == "requirement[0].cpk_method"


def _run(reqs, n=400, seed=7):
    spec = ToleranceSpec("s", (Factor("x", "1", Distribution.make("normal", mean=0.0, sigma=1.0)),))
    model = LinearModel(("x",), ("1",), [Quantity("k", "1")], [[20.0]], [300.0])
    return spec, model, run_monte_carlo(model, spec, n, "lhs", seed, reqs, progress=False)


def test_the_verdict_digest_and_summary_rows_of_a_statistic_requirement():
    """k = 300 + 20 x: the median 300 judged against a band around 196 FAILs (an over-stiff model cannot pass), a
    band around 300 PASSes, a band whose limit sits within the interval is UNDECIDED (amber, more samples)."""
    reqs = [Requirement("k", lower=156.8, upper=235.2, statistic="median", name="far", source="catalogue",
                        status="recalled", reading="b/a"),
            Requirement("k", lower=280.0, upper=320.0, statistic="median", name="near"),
            Requirement("k", lower=300.5, upper=400.0, statistic="median", name="edge")]
    spec, model, mc = _run(reqs)
    far, near, edge = mc.verdicts()
    y = np.sort(mc.column("k"))
    l, u = _median_ranks(400, 0.95)
    assert far.statistic == pytest.approx((np.median(y), y[l - 1], y[u - 1]))
    assert (far.passed, far.undecided, near.passed, edge.passed, edge.undecided) == (False, False, True, False, True)
    d = {x.label: x for x in digest(mc, model, spec)}
    assert (d["far"].light, d["near"].light, d["edge"].light) == ("red", "green", "amber")
    assert [f.kind for f in d["far"].fixes] == ["redesign"] and [f.kind for f in d["edge"].fixes] == ["more samples"]
    row = json.loads(json.dumps(d["far"].to_dict()))
    assert row["status"] == "recalled" and row["source"] == "catalogue" and row["reading"] == "b/a"
    assert row["statistic"]["estimate"] == pytest.approx(np.median(y)) and row["yield_lower_bound"] is None
    v = far.to_dict()
    assert v["statistic"] == "median" and v["statistic_interval"] == pytest.approx([y[l - 1], y[u - 1]])
    assert v["undecided"] is False and edge.to_dict()["undecided"] is True


def test_the_violation_of_a_statistic_is_the_intervals_reach_beyond_the_band_over_its_width():
    """judge_statistic's violation (its docstring), by hand on the band 5.8 … 6.2 (width 0.4): 0 inside, 1 + gap/0.4
    wholly outside, the larger reach beyond a limit / 0.4 across one; a one-sided band scales by |limit|."""
    r = Requirement("k", lower=5.8, upper=6.2, statistic="median")
    assert judge_statistic(r, 6.0, 5.9, 6.1, 100).violation == 0.0
    assert judge_statistic(r, 6.6, 6.5, 6.7, 100).violation == pytest.approx(1 + (6.5 - 6.2) / 0.4)     # above
    assert judge_statistic(r, 5.5, 5.4, 5.6, 100).violation == pytest.approx(1 + (5.8 - 5.6) / 0.4)     # below
    assert judge_statistic(r, 5.85, 5.7, 6.0, 100).violation == pytest.approx((5.8 - 5.7) / 0.4)       # across lower
    assert judge_statistic(r, 6.15, 6.0, 6.3, 100).violation == pytest.approx((6.3 - 6.2) / 0.4)       # across upper
    assert judge_statistic(r, 6.0, 5.7, 6.4, 100).violation == pytest.approx((6.4 - 6.2) / 0.4)        # both: larger
    one = Requirement("k", upper=6.2, statistic="median")
    assert judge_statistic(one, 6.6, 6.5, 6.7, 100).violation == pytest.approx(1 + (6.5 - 6.2) / 6.2)


def test_failed_samples_leave_a_mean_unbounded_but_the_median_only_on_one_side():
    """The reason says which: a failed sample can move the mean by any amount; the median's ranks bound them."""
    mean = Requirement("k", lower=5.8, upper=6.2, statistic="mean")
    j = judge_statistic(mean, 6.0, None, None, 12, n_failed=2)
    assert j.undecided and j.violation == 1.0
    assert j.reasons[-1] == ("2 sample(s) could not be evaluated: the mean is not bounded while they fail (the median "
                             "bounds them on either side)")
    median = Requirement("k", lower=5.8, upper=6.2, statistic="median")
    j = judge_statistic(median, 6.0, None, 6.1, 12, n_failed=2)
    assert j.reasons[-1] == "2 sample(s) could not be evaluated: the median is not bounded while they fail"


@pytest.mark.parametrize("statistic,n", [("median", 4), ("mean", 1)])
def test_too_few_samples_for_a_bound_say_so_not_that_the_estimate_sits_on_a_limit(statistic, n):
    """The median's lower bound needs P(B = 0) = 0.5ⁿ ≤ 5 %, i.e. n ≥ 5; the mean's t interval n ≥ 2.  With fewer the
    interval is unbounded: more samples would bound it (the reason said the estimate, 0.18 inside the band, sat on a
    limit and more samples would not decide it), and the violation is 1, not 0 (0 is a pass)."""
    assert 0.5 ** 4 > 0.05 >= 0.5 ** 5
    r = Requirement("k", lower=5.8, upper=6.2, statistic=statistic)
    y = 6.0 + 0.01 * np.arange(n)
    est, lo, hi = statistic_interval(r, y)
    assert lo is None and hi is None
    j = judge_statistic(r, est, lo, hi, n)
    assert not j.passed and j.undecided and j.violation == 1.0 and j.n_to_demonstrate is None
    assert j.reasons[-1] == f"the {statistic} is not bounded at n = {n} (too few samples for a bound at 95 %): more " \
                            "samples would bound it"


@pytest.mark.parametrize("statistic", ["median", "mean"])
def test_no_evaluated_value_gives_no_estimate_and_no_bound_without_a_warning(statistic):
    """Every sample failed: the statistic is NaN and unbounded — said as such, not through numpy's "Mean of empty
    slice" RuntimeWarning on the user's terminal."""
    import warnings

    r = Requirement("k", lower=5.8, upper=6.2, statistic=statistic)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        est, lo, hi = statistic_interval(r, [], n_failed=12)
    assert math.isnan(est) and lo is None and hi is None


@pytest.mark.parametrize("n", [6, 20])
def test_a_median_interval_at_fifty_percent_is_the_binomial_ranks(n):
    """confidence = 0.5, the smallest a study file admits: each end a one-sided 50 % bound, the ranks of the binomial
    sums (no rank sits exactly on ½ for an even n), e.g. y_(3) and y_(4) of six values."""
    r = Requirement("k", lower=0.0, statistic="median", confidence=0.5)
    y = np.arange(1.0, n + 1.0)
    l, u = _median_ranks(n, 0.5)
    assert statistic_interval(r, y) == (np.median(y), y[l - 1], y[u - 1])
    assert n != 6 or (l, u) == (3, 4)


def test_an_interval_reaching_a_limit_exactly_lies_inside_the_band():
    """The band is closed: an interval whose end is a limit is inside it (PASS), at either limit."""
    r = Requirement("k", lower=156.8, upper=235.2, statistic="median")
    assert judge_statistic(r, 200.0, 190.0, 235.2, 100).passed
    assert judge_statistic(r, 200.0, 156.8, 210.0, 100).passed


def test_the_samples_that_would_decide_use_the_half_width_on_the_estimates_side_of_the_limit():
    """n (h/d)², d = |estimate − limit|, h the half-width from the estimate towards the limit: the upper one
    (hi − estimate) when the estimate lies below the limit, the lower one (estimate − lo) when above — on an
    asymmetric interval, with binary-exact numbers."""
    r = Requirement("k", lower=-1.0, upper=1.0, statistic="median")
    up = judge_statistic(r, 0.5, 0.25, 1.5, 100)               # straddles +1 from below: h = 1.0, d = 0.5
    assert up.undecided and up.n_to_demonstrate == 100 * 4
    down = judge_statistic(r, -0.75, -1.5, -0.625, 100)        # straddles −1 from above: h = 0.75, d = 0.25
    assert down.undecided and down.n_to_demonstrate == 100 * 9
    assert "PASS, if the estimate held" in down.reasons[-1]


def test_a_one_sided_band_straddled_by_its_interval_has_the_reach_beyond_its_limit_as_violation():
    """Only a lower limit (1.0, so the scale is |1.0|): the interval [0.5, 1.5] reaches 0.5 below it; with no upper
    limit nothing is charged above.  Only an upper limit: likewise."""
    lower = Requirement("k", lower=1.0, statistic="median")
    j = judge_statistic(lower, 1.25, 0.5, 1.5, 100)
    assert j.undecided and j.violation == pytest.approx(0.5) and j.n_to_demonstrate == 100 * 9
    upper = Requirement("k", upper=2.0, statistic="median")
    j = judge_statistic(upper, 1.5, 1.0, 3.0, 100)
    assert j.undecided and j.violation == pytest.approx((3.0 - 2.0) / 2.0) and j.n_to_demonstrate == 100 * 9


def test_an_estimate_on_a_limit_says_more_samples_will_not_decide_and_the_bound_is_described():
    """The median 235.2 sits on the upper limit: its interval straddles the limit at every n (d = 0), so no n is
    given; the report names the interval — each end a one-sided 95 % bound, or the two-sided 95 % interval."""
    from rvtol.verdict import describe_bound

    r = Requirement("k", lower=156.8, upper=235.2, statistic="median")
    j = judge_statistic(r, 235.2, 230.0, 240.0, 100)
    assert j.undecided and j.n_to_demonstrate is None
    assert j.reasons[-1] == "the estimate sits on a limit: more samples will not decide it"
    assert describe_bound(r) == "the median's interval, each end a 95 % one-sided bound"
    two = Requirement("k", lower=156.8, upper=235.2, statistic="mean", bound="two-sided", confidence=0.9)
    assert describe_bound(two) == "the mean's interval, two-sided 90 %"


def test_an_estimate_at_a_limit_or_below_it_is_judged_if_it_held():
    """The median 5 equal to its own lower bound and to the lower limit (values computed, as a study's are), its
    interval crossing the upper limit 10: only the upper limit is straddled — n (6/5)², PASS if it held (on the limit
    is inside the closed band).  An estimate 4.5 below the lower limit 5, its interval [4, 5.5] reaching in: FAIL if it
    held, n (1.0/0.5)² — the half-width toward the limit, hi − estimate, over the distance to it."""
    r = Requirement("k", lower=5.0, upper=10.0, statistic="median")
    five = float(np.float64(2.5) * 2)
    j = judge_statistic(r, five, five, 11.0, 100)
    assert j.undecided and j.n_to_demonstrate == math.ceil(100 * (6.0 / 5.0) ** 2)
    assert j.reasons[-1] == f"about n = {j.n_to_demonstrate} samples would decide it (PASS, if the estimate held)"
    j = judge_statistic(r, 4.5, 4.0, 5.5, 100)
    assert j.undecided and j.n_to_demonstrate == 100 * 4
    assert j.reasons[-1] == "about n = 400 samples would decide it (FAIL, if the estimate held)"


def test_a_mean_requirement_read_from_a_study_file_is_judged_on_students_t():
    """statistic = "mean" parsed from TOML (a string built at run time, not the source's literal): Student's t
    interval of the mean, not the median's order statistics."""
    import tomllib

    t = tomllib.loads('output = "k"\nlower = 250.0\nupper = 350.0\nstatistic = "mean"\n')
    r, = requirements_from_tables([Params(t, file="s.toml", key="requirement[0]")])
    y = np.random.default_rng(2).normal(300.0, 20.0, 50)
    a, b = stats.t.interval(0.90, 49, loc=y.mean(), scale=stats.sem(y))      # each end one-sided 95 %
    assert statistic_interval(r, y) == pytest.approx((y.mean(), a, b), rel=1e-12)


def test_two_values_bound_a_mean_by_students_t_with_one_degree_of_freedom():
    """5.75 and 6.25: mean 6, s.e. s/√2 = 0.25 — the interval t(0.95; 1) = 6.31 s.e. either side."""
    r = Requirement("k", lower=5.8, upper=6.2, statistic="mean")
    a, b = stats.t.interval(0.90, 1, loc=6.0, scale=0.25)
    assert statistic_interval(r, [5.75, 6.25]) == pytest.approx((6.0, a, b), rel=1e-12)


def test_an_interval_touching_a_limit_from_outside_is_not_wholly_outside_the_band():
    """The band is closed: an interval whose lower end is the upper limit (or whose upper end is the lower limit) still
    holds a value of the band — UNDECIDED, not FAIL — and its violation is its reach beyond the limit over the band's
    width 2, not 1 + a gap."""
    r = Requirement("k", lower=-1.0, upper=1.0, statistic="median")
    above = judge_statistic(r, 1.5, 1.0, 2.0, 100)
    assert not above.passed and above.undecided and above.violation == 0.5
    below = judge_statistic(r, -1.5, -2.0, -1.0, 100)
    assert not below.passed and below.undecided and below.violation == 0.5


def test_an_interval_touching_a_limit_from_outside_says_how_many_samples_would_decide_it():
    """[1, 2] with the estimate 1.5 against the band [−1, 1]: the estimate is 0.5 beyond the limit, not on it, so more
    samples decide it (FAIL if the estimate held).  The half-width 0.5 at n = 100 shrinks as 1/√n: n (0.5/0.5)² = 100
    is the n it has, undecided, so one more — 101 — makes the interval's end leave the limit.  The estimate on the
    limit (1.0 in [0.5, 1.5]) stays the case more samples cannot decide."""
    r = Requirement("k", lower=-1.0, upper=1.0, statistic="median")
    above = judge_statistic(r, 1.5, 1.0, 2.0, 100)
    assert above.n_to_demonstrate == 101 and above.reasons[-1] == ("about n = 101 samples would decide it (FAIL, if "
                                                                   "the estimate held)")
    assert judge_statistic(r, -1.5, -2.0, -1.0, 100).n_to_demonstrate == 101
    on_it = judge_statistic(r, 1.0, 0.5, 1.5, 100)
    assert on_it.n_to_demonstrate is None and on_it.reasons[-1] == ("the estimate sits on a limit: more samples will "
                                                                    "not decide it")


def test_a_one_sided_band_at_zero_charges_the_gap_itself():
    """|limit| = 0 cannot scale a one-sided band's violation: the gap is charged as it is (scale 1) — [0.5, 0.75]
    wholly above the upper limit 0: 1 + 0.5; [−0.25, 0.5] across the lower limit 0: 0.25."""
    above = Requirement("k", upper=0.0, statistic="median")
    assert judge_statistic(above, 0.625, 0.5, 0.75, 100).violation == 1.5
    across = Requirement("k", lower=0.0, statistic="median")
    assert judge_statistic(across, 0.25, -0.25, 0.5, 100).violation == 0.25
