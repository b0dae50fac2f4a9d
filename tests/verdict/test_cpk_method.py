"""The verdict basis: a minimum Cpk judged on the normal-theory Cpk (default) or the ISO 22514-2 percentile Cpk
(Requirement.cpk_method), checked on a skewed output whose two Cpk values have closed forms."""
import math

import numpy as np
import pytest

from rvtol.errors import SpecError
from rvtol.mc import run_monte_carlo
from rvtol.model import FunctionModel, Quantity
from rvtol.params import Params
from rvtol.spec import Factor, Requirement, ToleranceSpec, requirements_from_tables
from rvtol.stats import Shape
from rvtol.distributions import Distribution

# r = hypot(x, y) of two standard normals is Rayleigh(σ = 1)
MEAN, SD = math.sqrt(math.pi / 2), math.sqrt(2 - math.pi / 2)
MEDIAN, P99865 = math.sqrt(2 * math.log(2)), math.sqrt(-2 * math.log(0.00135))
USL = 4.2
CPK_NORMAL = (USL - MEAN) / (3 * SD)                 # 1.4995: passes 1.33
CPK_PERCENTILE = (USL - MEDIAN) / (P99865 - MEDIAN)  # 1.2298: fails 1.33


def run(method):
    spec = ToleranceSpec("xy", tuple(Factor(n, "mm", Distribution.make("normal", mean=0.0, sigma=1.0))
                                     for n in ("x", "y")))
    model = FunctionModel(lambda X: np.hypot(X[:, 0], X[:, 1])[:, None], ["x", "y"], [Quantity("r", "mm")],
                          ["mm", "mm"])
    req = Requirement("r", upper=USL, unit="mm", min_cpk=1.33, cpk_method=method)
    return run_monte_carlo(model, spec, 40000, "lhs", seed=3, requirements=[req], progress=False).verdicts()[0]


def test_normal_theory_and_percentile_cpk_judge_differently():
    normal, pct = run("normal"), run("percentile")
    n = 40000
    # estimates against the closed forms (s.e. of Cpk ≈ sqrt(1/9n + Cpk²/2n); percentile Cpk from sample quantiles)
    assert normal.judged_cpk[0] == pytest.approx(CPK_NORMAL, abs=4 * math.sqrt(1 / (9 * n) + CPK_NORMAL ** 2 / (2 * n)))
    assert pct.judged_cpk[0] == pytest.approx(CPK_PERCENTILE, rel=0.03)
    # normal theory alone would pass it (Bissell's bound ≥ 1.33); but the output is demonstrably not normal (Rayleigh
    # skewness 2√π(π − 3)/(4 − π)^1.5 = 0.631) and its percentile Cpk misses: not demonstrated (issue 37)
    assert normal.judged_cpk[1] >= 1.33 and not normal.passed and not pct.passed
    assert normal.shape.non_normal and normal.shape.skewness == pytest.approx(
        2 * math.sqrt(math.pi) * (math.pi - 3) / (4 - math.pi) ** 1.5, abs=0.05)
    assert any("the output is not normal" in why and "percentile Cpk (ISO 22514-2) lower bound" in why
               for why in normal.reasons)
    assert any("percentile Cpk lower bound" in why for why in pct.reasons)
    assert any("the normal-theory Cpk lower bound" in note and "would pass" in note for note in pct.notes)
    assert pct.to_dict()["cpk_method"] == "percentile"
    # the judged bound is the one-sided 95 % bound: the lower end of the two-sided 90 % bootstrap interval, inside
    # the two-sided 95 % interval the report shows
    lo, hi = pct.cpk_percentile_ci
    assert lo < pct.judged_cpk[1] < pct.judged_cpk[0] < hi


def test_the_requirement_key_is_read_and_checked():
    t = Params({"output": "r", "upper": 1.0, "min_cpk": 1.33, "cpk_method": "percentile"}, file="s.toml",
               key="requirement[0]")
    assert requirements_from_tables([t])[0].cpk_method == "percentile"
    t = Params({"output": "r", "upper": 1.0, "cpk_method": "median"}, file="s.toml", key="requirement[0]")
    with pytest.raises(SpecError, match="requirement\\[0\\].cpk_method: unknown value 'median'"):
        requirements_from_tables([t])


def test_a_requirement_read_from_a_study_file_is_judged_on_the_cpk_it_names():
    """cpk_figures on requirements parsed from TOML text (strings built at run time, not the source's literals): the
    percentile one judges the percentile Cpk and its bootstrap bound, the default the normal-theory Cpk and Bissell's
    bound Ĉ − z·√(1/(9n) + Ĉ²/(2(n − 1))) (written out)."""
    import tomllib

    from scipy.stats import norm

    from rvtol.verdict import cpk_figures, cpk_name

    tables = tomllib.loads('[[requirement]]\noutput = "r"\nupper = 4.2\nmin_cpk = 1.33\ncpk_method = "percentile"\n'
                           '[[requirement]]\noutput = "r"\nupper = 4.2\nmin_cpk = 1.33\n')["requirement"]
    pct, normal = requirements_from_tables([Params(t, file="s.toml", key=f"requirement[{i}]")
                                            for i, t in enumerate(tables)])
    cap, n = {"cpk": 1.5, "cpk_percentile": 1.2}, 1000
    assert cpk_figures(pct, cap, n, (1.1, 1.3)) == (1.2, 1.1) and cpk_name(pct) == "percentile Cpk"
    c, lo = cpk_figures(normal, cap, n, (1.1, 1.3))
    z = norm.ppf(0.95)
    assert c == 1.5 and lo == pytest.approx(1.5 - z * math.sqrt(1 / (9 * n) + 1.5 ** 2 / (2 * (n - 1))), rel=1e-12)
    assert cpk_name(normal) == "Cpk"


def _from_study_file(text: str) -> list[Requirement]:
    """Requirements parsed from TOML text, as a study file gives them (strings built at run time)."""
    import tomllib

    return requirements_from_tables([Params(t, file="s.toml", key=f"requirement[{i}]")
                                     for i, t in enumerate(tomllib.loads(text)["requirement"])])


def test_the_percentile_cpk_is_looked_up_for_a_non_normal_output_judged_on_its_estimate():
    """other_cpk for an optimiser (``judged`` given) with basis = "estimate": the normal-theory estimate 1.5 passes
    1.33 (its bound 1.2 would not — the estimate is what is judged), the output, exponential, is demonstrably not
    normal (scipy's Anderson–Darling p ≤ 1 %), so the percentile Cpk (the capability's, 1.2) is
    the one returned to refute it — not Bissell's normal-theory figure."""
    from scipy import stats

    from rvtol.verdict import other_cpk

    r, = _from_study_file('[[requirement]]\noutput = "r"\nupper = 10.0\nmin_cpk = 1.33\nbasis = "estimate"\n'
                          'cpk_method = "normal"\n')
    good = np.random.default_rng(5).exponential(size=400)
    assert stats.anderson(good, "norm", method="interpolate").pvalue <= 0.01
    shape, other = other_cpk(r, good, {"cpk": 1.5, "cpk_percentile": 1.2}, judged=(1.5, 1.2))
    assert shape.non_normal and other[0] == 1.2 and other[1] is not None


def _skewed() -> Shape:
    return Shape(skewness=1.5, excess_kurtosis=4.0, ad_statistic=9.0, ad_pvalue=0.01)


def test_a_non_normal_output_judged_on_its_estimate_needs_both_cpk_estimates():
    """basis = "estimate": the rule compares the two estimates (1.5 passes 1.33, the percentile 1.0 does not): not
    demonstrated, and the reason quotes the estimates, not the bounds (0.9 and 0.8 would agree: both fail)."""
    from rvtol.verdict import judge

    r = Requirement("r", upper=4.2, min_cpk=1.33, basis="estimate")
    j = judge(r, cpk=1.5, cpk_lo=0.9, other_cpk=(1.0, 0.8), shape=_skewed())
    assert not j.passed
    assert any("its normal-theory Cpk 1.500 passes but its percentile Cpk (ISO 22514-2) 1.000 < required 1.33" in w
               for w in j.reasons)


def test_a_non_normal_output_from_a_study_file_is_judged_on_both_cpk_bounds():
    """basis = "lower_bound" written in the study file: the bounds are compared — normal theory's 1.4 passes 1.33,
    the percentile bound 1.2 does not — so it is not demonstrated, although both estimates (1.5, 1.45) pass."""
    from rvtol.verdict import judge

    r, = _from_study_file('[[requirement]]\noutput = "r"\nupper = 4.2\nmin_cpk = 1.33\nbasis = "lower_bound"\n')
    j = judge(r, cpk=1.5, cpk_lo=1.4, other_cpk=(1.45, 1.2), shape=_skewed())
    assert not j.passed
    assert any("normal-theory Cpk lower bound 1.400 passes but its percentile Cpk (ISO 22514-2) lower bound 1.200"
               in w for w in j.reasons)


@pytest.mark.parametrize("method,shape,then", [
    ("normal", Shape(0.1, 0.2, 0.3, 0.5), "normal theory judges it (the percentile bound is the less efficient one)"),
    ("percentile", _skewed(), "the percentile Cpk judges it"),
    ("percentile", Shape(0.1, 0.2, 0.3, 0.5), "the percentile Cpk judges it")])
def test_a_disagreement_that_does_not_refute_the_verdict_says_which_cpk_judges(method, shape, then):
    """The two Cpk bounds disagree (1.4 passes 1.33, 1.2 does not, or the reverse), and the output's shape leaves the
    verdict to the judged Cpk: the note ends by naming it."""
    from rvtol.verdict import judge

    r = Requirement("r", upper=4.2, min_cpk=1.33, cpk_method=method)
    judged, other = ((1.6, 1.4), (1.45, 1.2)) if method == "normal" else ((1.45, 1.2), (1.6, 1.4))
    j = judge(r, cpk=judged[0], cpk_lo=judged[1], other_cpk=other, shape=shape)
    assert j.passed == (method == "normal")
    assert len(j.notes) == 1 and j.notes[0].endswith(f"; {then}")


def test_no_percentile_bound_leaves_the_normal_theory_verdict_alone():
    """Fewer evaluated samples than a bootstrap bound needs: the other Cpk has an estimate but no bound, so the
    non-normal rule has nothing to compare — the normal-theory bound 1.4 ≥ 1.33 passes, with no note."""
    from rvtol.verdict import judge

    r = Requirement("r", upper=4.2, min_cpk=1.33)
    j = judge(r, cpk=1.5, cpk_lo=1.4, other_cpk=(1.0, None), shape=_skewed())
    assert j.passed and j.notes == [] and j.violation == 0.0


@pytest.mark.parametrize("judged,other,passed", [((1.5, 1.33), (1.45, 1.2), False), ((1.5, 1.4), (1.45, 1.33), True)])
def test_a_cpk_bound_exactly_at_its_minimum_passes_in_the_non_normal_rule(judged, other, passed):
    """Either Cpk's bound equal to min_cpk reaches it (≥, as judge's own check): the normal-theory bound 1.33 passes
    and the percentile bound 1.2 refutes it on a skewed output; a percentile bound of 1.33 agrees with a passing 1.4
    — no disagreement, no note."""
    from rvtol.verdict import judge

    j = judge(Requirement("r", upper=4.2, min_cpk=1.33), cpk=judged[0], cpk_lo=judged[1], other_cpk=other,
              shape=_skewed())
    assert j.passed == passed
    assert (j.notes == []) and (passed or any("normal theory misstates the tail" in w for w in j.reasons))


def test_a_basis_written_in_a_study_file_is_judged_on_the_bound():
    """basis = "lower_bound" written out (a string built at run time, not the source's literal): a yield of 0.999
    whose bound is 0.995 does not demonstrate 0.997; basis = "estimate" passes on the 0.999."""
    from rvtol.verdict import judge

    written, estimate = _from_study_file('[[requirement]]\noutput = "r"\nupper = 4.2\nmin_yield = 0.997\n'
                                         'basis = "lower_bound"\n[[requirement]]\noutput = "r"\nupper = 4.2\n'
                                         'min_yield = 0.997\nbasis = "estimate"\n')
    assert not judge(written, yield_=0.999, yield_lo=0.995).passed
    assert judge(estimate, yield_=0.999, yield_lo=0.995).passed


def test_a_run_without_requirements_is_exploratory_only_when_declared():
    from rvtol.verdict import EXPLORATORY, NO_REQUIREMENTS, study_verdict

    assert study_verdict([]) == NO_REQUIREMENTS and study_verdict([], exploratory=True) == EXPLORATORY


@pytest.mark.parametrize("percentile_estimate", [1.45, None])
def test_a_pass_the_percentile_cpk_refutes_is_planned_on_the_smaller_estimate_or_not_at_all(percentile_estimate):
    """Normal theory passes (bound 1.4 ≥ 1.33), the percentile bound 1.2 refutes it on a skewed output, at n = 150.
    With a percentile estimate of 1.45 the n offered is the one that demonstrates the smaller estimate: the smallest
    n with Bissell's bound 1.45 − z·√(1/(9n) + 1.45²/(2(n − 1))) ≥ 1.33 (z = Φ⁻¹(0.95), counted up by hand).  With no
    percentile estimate (its bound alone) no estimate can be held: no n is offered and it is not UNDECIDED."""
    from scipy.stats import norm

    from rvtol.verdict import judge

    j = judge(Requirement("r", upper=4.2, min_cpk=1.33), cpk=1.5, cpk_lo=1.4, other_cpk=(percentile_estimate, 1.2),
              shape=_skewed(), n=150)
    assert not j.passed and any("normal theory misstates the tail" in w for w in j.reasons)
    if percentile_estimate is None:
        assert not j.undecided and j.n_to_demonstrate is None
        return
    z, c = norm.ppf(0.95), percentile_estimate
    need = next(m for m in range(2, 10_000) if c - z * math.sqrt(1 / (9 * m) + c * c / (2 * (m - 1))) >= 1.33)
    assert j.undecided and j.n_to_demonstrate == need > 150


def test_a_basis_of_estimate_written_in_a_study_file_is_described_as_the_point_estimate():
    """basis = "estimate" parsed from TOML (a string built at run time, not the source's literal): the report says
    the point estimate is judged, not a lower bound."""
    from rvtol.verdict import describe_bound

    r, = _from_study_file('[[requirement]]\noutput = "r"\nupper = 4.2\nmin_yield = 0.997\nbasis = "estimate"\n')
    assert describe_bound(r) == "point estimate"


def _exponential_output() -> np.ndarray:
    """400 exponential values: demonstrably not normal (scipy's Anderson–Darling p ≤ 1 %)."""
    from scipy import stats

    good = np.random.default_rng(5).exponential(size=400)
    assert stats.anderson(good, "norm", method="interpolate").pvalue <= 0.01
    return good


def test_an_optimiser_looks_nothing_up_for_a_passing_percentile_requirement():
    """cpk_method = "percentile", its bound 1.4 passing 1.33, on a non-normal output: the non-normal rule fails only a
    normal-theory pass, so other_cpk given the judged figures computes nothing — (None, None) — and judge's verdict is
    the one the full look-up (the sign-off's) gives: a pass."""
    from rvtol import stats as st
    from rvtol.verdict import judge, other_cpk

    r, = _from_study_file('[[requirement]]\noutput = "r"\nupper = 10.0\nmin_cpk = 1.33\ncpk_method = "percentile"\n')
    good = _exponential_output()
    cap = st.capability(good, None, 10.0)
    assert other_cpk(r, good, cap, judged=(1.5, 1.4)) == (None, None)
    shape, other = other_cpk(r, good, cap)
    assert judge(r, cpk=1.5, cpk_lo=1.4, other_cpk=other, shape=shape).passed
    assert judge(r, cpk=1.5, cpk_lo=1.4).passed


def test_an_optimisers_candidate_whose_bound_is_exactly_its_minimum_is_put_to_the_non_normal_rule():
    """A normal-theory bound equal to min_cpk passes (≥, judge's own check), so other_cpk given the judged figures
    looks up the shape and the percentile bound of a non-normal output — the figures that can refute the pass."""
    from rvtol import stats as st
    from rvtol.verdict import other_cpk

    r = Requirement("r", upper=10.0, min_cpk=1.33)
    good = _exponential_output()
    shape, other = other_cpk(r, good, st.capability(good, None, 10.0), judged=(1.5, 1.33))
    assert shape is not None and shape.non_normal and other is not None and other[1] is not None


@pytest.mark.parametrize("judged,other", [((np.float64(1.5), np.float64(1.4)), (1.45, 1.35)),
                                          ((1.5, 1.4), (np.float64(1.45), np.float64(1.35)))])
def test_two_passing_cpk_bounds_pass_the_non_normal_rule_whatever_float_type_carries_them(judged, other):
    """np.float64 is a float (an optimiser's figures come as NumPy scalars): both bounds, 1.4 and 1.35, pass 1.33 on a
    skewed output — the two Cpk agree, so the requirement passes with no note (their comparisons give a NumPy and a
    Python bool: equal, not one object)."""
    from rvtol.verdict import judge

    j = judge(Requirement("r", upper=4.2, min_cpk=1.33), cpk=judged[0], cpk_lo=judged[1], other_cpk=other,
              shape=_skewed())
    assert j.passed and j.notes == [] and j.violation == 0.0
