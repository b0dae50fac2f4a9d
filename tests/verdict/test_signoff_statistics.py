"""Statistics that say what they are: one- or two-sided bounds, the n that would demonstrate a
requirement, the default yield stated, and no vacuous verdicts — through the real CLI (``main``).

References are independent of rvtol's code: SciPy's beta quantiles and binomtest intervals, the
success-run formula n = ln(1 − c)/ln(Y), and Bissell's formula evaluated by hand.
"""
import json
import math

import pytest
from scipy import stats

from rvtol import stats as st
from rvtol.cli import main

SPEC = """
[[factor]]
name = "a"
unit = "um"
dist = "normal"
sigma = 1.0
"""


def study(tmp_path, requirements: str, *, exploratory: bool | None = None, n: int = 2000) -> str:
    (tmp_path / "spec.toml").write_text(SPEC)
    head = '[study]\nname = "s"\nspec = "spec.toml"\n'
    if exploratory is not None:
        head += f"exploratory = {str(exploratory).lower()}\n"
    text = (head + '[model]\nkind = "linear"\n[[model.output]]\nname = "y"\nunit = "um"\n'
            'coefficients = { a = 1.0 }\n' f'[sampling]\nn = {n}\nmethod = "lhs"\nseed = 11\n' + requirements)
    p = tmp_path / "study.toml"
    p.write_text(text)
    return str(p)


def run(tmp_path, path, *extra):
    out = tmp_path / "out"
    rc = main(["run", path, "--out", str(out), "--no-pdf", "--executor", "serial", "--quiet", *extra])
    return rc, (json.loads((out / "summary.json").read_text()) if (out / "summary.json").exists() else None), out


def reqs(s):
    return s["outputs"]["y"]["requirements"]


# --------------------------------------------------------------------------- bounds (unit level)
@pytest.mark.parametrize("method", ["exact", "wilson"])
@pytest.mark.parametrize("k,n", [(990, 1000), (1000, 1000), (3, 40), (0, 25)])
def test_a_two_sided_lower_end_is_the_one_sided_bound_at_one_plus_c_over_two(method, k, n):
    low = stats.binomtest(k, n).proportion_ci(confidence_level=0.95, method=method).low
    assert st.proportion_lower_bound(k, n, 0.975, method) == pytest.approx(low, abs=1e-12)
    if method == "exact" and k > 0:  # one-sided Clopper–Pearson: the 5 % beta quantile
        assert st.proportion_lower_bound(k, n, 0.95) == pytest.approx(stats.beta.ppf(0.05, k, n - k + 1))


def test_success_run_sample_size():
    # zero failures: the smallest n with (1 − c)^(1/n) >= Y, i.e. n >= ln(1 − c)/ln(Y)
    # (1 − 1e-7 at 95 %: 29 957 322 units, found by bisection in n, not by stepping one unit at a time)
    for y, c in [(0.9973, 0.95), (0.99, 0.90), (0.999, 0.99), (1 - 1e-7, 0.95)]:
        assert st.n_for_yield(1.0, y, c) == math.ceil(math.log(1 - c) / math.log(y))
    # the bound reaching the requirement exactly counts: (1 − 0.75)^(1/2) = 0.5, (1 − 0.19)^(1/2) = 0.9
    assert st.n_for_yield(1.0, 0.5, 0.75) == 2 and st.n_for_yield(1.0, 0.9, 0.19) == 2


def test_no_plan_when_even_the_largest_sample_cannot_demonstrate_it():
    # 1e-12 above the requirement: at N_PLAN_MAX = 1e15 the bound still lies ~1.6·√(p(1−p)/1e15) ≈ 3e-9 below
    assert st.n_for_yield(0.9973 + 1e-12, 0.9973, 0.95) is None


def test_n_for_yield_is_the_smallest_n_at_the_observed_rate():
    est, req, c = 0.9990, 0.9973, 0.95
    n = st.n_for_yield(est, req, c)
    bound = lambda m: stats.beta.ppf(1 - c, est * m, m * (1 - est) + 1)  # noqa: E731  (real k: the observed rate)
    assert bound(n) >= req > bound(n - 1)
    assert st.n_for_yield(0.9973, req, c) is None and st.n_for_yield(0.99, req, c) is None


def test_n_for_cpk_inverts_bissell():
    cpk, req, c = 1.52, 1.33, 0.95
    n = st.n_for_cpk(cpk, req, c)
    z = stats.norm.ppf(c)
    bissell = lambda m: cpk - z * math.sqrt(1 / (9 * m) + cpk**2 / (2 * (m - 1)))  # noqa: E731
    assert bissell(n) >= req > bissell(n - 1)
    assert st.n_for_cpk(1.2, req, c) is None


# --------------------------------------------------------------------------- through the CLI

def test_no_cpk_plan_without_a_finite_cpk_above_the_requirement():
    for cpk in (None, math.nan, math.inf, -math.inf, 1.33, 1.2):
        assert st.n_for_cpk(cpk, 1.33, 0.95) is None


def test_n_for_cpk_is_the_smallest_n_when_the_root_lies_a_hair_above_an_integer():
    # the requirement is Bissell's bound at 21 + 1e-11: n = 21 falls short by a hair, 22 is the answer
    cpk, c = 1.52, 0.95
    z = stats.norm.ppf(c)
    bissell = lambda m: cpk - z * math.sqrt(1 / (9 * m) + cpk**2 / (2 * (m - 1)))  # noqa: E731
    req = bissell(21 + 1e-11)
    assert bissell(21) < req <= bissell(22)
    assert st.n_for_cpk(cpk, req, c) == 22


def test_one_sided_is_the_default_and_two_sided_is_stricter(tmp_path):
    rc, s, _ = run(tmp_path, study(tmp_path, '[[requirement]]\noutput = "y"\nupper = 2.8\nmin_yield = 0.5\n'))
    r = reqs(s)[0]
    n = s["n"]
    k = round(r["yield"] * n)
    assert 0 < n - k < 30 and r["bound"] == "one-sided" and r["bound_level"] == 0.95
    one = stats.beta.ppf(0.05, k, n - k + 1)
    two = stats.binomtest(k, n).proportion_ci(confidence_level=0.95).low
    assert r["yield_bound"] == pytest.approx(one, rel=1e-12)
    mid = float(0.5 * (one + two))
    text = "".join(f'[[requirement]]\nname = "{b}"\noutput = "y"\nupper = 2.8\nmin_yield = {mid!r}\nbound = "{b}"\n'
                   for b in ("one-sided", "two-sided"))
    rc, s, out = run(tmp_path, study(tmp_path, text))
    by = {r["requirement"]: r for r in reqs(s)}
    assert by["one-sided"]["passed"] and not by["two-sided"]["passed"]
    assert by["two-sided"]["yield_bound"] == pytest.approx(two, rel=1e-12) and by["two-sided"]["bound_level"] == 0.975
    assert rc == 1 and s["verdict"] == "FAIL"
    html = (out / "report.html").read_text()
    assert "95 % one-sided lower bound" in html and "lower end of the two-sided 95 % interval (97.5 % one-sided)" in html


def test_a_requirement_short_of_samples_gets_the_n_that_would_demonstrate_it(tmp_path, capsys):
    # every sample inside (|y| < 5σ): yield 1, but 500 samples cannot demonstrate 99.73 % at 95 %
    rc, s, out = run(tmp_path, study(tmp_path, '[[requirement]]\noutput = "y"\nupper = 5.0\n', n=500))
    r = reqs(s)[0]
    assert rc == 1 and r["yield"] == 1.0 and not r["passed"]
    assert r["min_yield"] == 0.9973 and r["min_yield_default"] is True
    assert r["n_to_demonstrate"] == math.ceil(math.log(0.05) / math.log(0.9973))  # success run: 1109
    assert any("about n = 1109 samples would demonstrate it" in why for why in r["reasons"])
    html = (out / "report.html").read_text()
    assert "yield ≥ 0.9973 (default)" in html and "rvtol&#39;s default" in html
    # and with that many samples it is demonstrated
    rc, s, _ = run(tmp_path, study(tmp_path, '[[requirement]]\noutput = "y"\nupper = 5.0\n', n=1109))
    assert rc == 0 and reqs(s)[0]["passed"] and reqs(s)[0]["n_to_demonstrate"] is None


def test_a_cpk_short_of_samples_gets_bissells_n(tmp_path):
    rc, s, _ = run(tmp_path, study(tmp_path, '[[requirement]]\noutput = "y"\nlower = -4.3\nupper = 4.3\n'
                                             'min_cpk = 1.33\n', n=200))
    r = reqs(s)[0]
    cpk, n_need = r["cpk"], r["n_to_demonstrate"]
    assert cpk > 1.33 and not r["passed"] and n_need > 200
    z = stats.norm.ppf(0.95)
    bissell = lambda m: cpk - z * math.sqrt(1 / (9 * m) + cpk**2 / (2 * (m - 1)))  # noqa: E731
    assert bissell(n_need) >= 1.33 > bissell(n_need - 1)
    assert r["cpk_bound"] == pytest.approx(bissell(200))


def test_an_estimate_that_misses_says_more_samples_will_not_help(tmp_path):
    rc, s, _ = run(tmp_path, study(tmp_path, '[[requirement]]\noutput = "y"\nupper = 1.0\nmin_yield = 0.99\n'))
    r = reqs(s)[0]
    assert rc == 1 and r["n_to_demonstrate"] is None
    assert any("more samples will not demonstrate it" in why for why in r["reasons"])


# --------------------------------------------------------------------------- no vacuous verdicts
def test_no_requirement_is_not_a_pass(tmp_path, capsys):
    rc, s, out = run(tmp_path, study(tmp_path, ""))
    assert rc == 4
    assert s["verdict"] == "NO REQUIREMENTS" and s["passed"] is False and s["requirements_checked"] == 0
    assert "verdict: NO REQUIREMENTS" in capsys.readouterr().out
    assert "NO REQUIREMENTS" in (out / "report.html").read_text()


def test_an_exploratory_study_says_so_and_exits_0(tmp_path, capsys):
    rc, s, out = run(tmp_path, study(tmp_path, "", exploratory=True))
    assert rc == 0 and s["verdict"] == "EXPLORATORY" and s["passed"] is False and s["exploratory"] is True
    assert "verdict: EXPLORATORY" in capsys.readouterr().out


def test_every_study_either_checks_a_requirement_or_declares_itself_exploratory(root):
    from conftest import names_a_wing_kind, wing_installed
    from rvtol.study import load_study

    for p in sorted((root / "studies").glob("*.toml")):
        if names_a_wing_kind(p) and not wing_installed():
            continue                                     # the wing's studies need the wing (its kinds)
        st_ = load_study(p)
        assert st_.requirements or st_.exploratory, p.name


# --------------------------------------------------------------------------- judge's violation, failed samples, words
def test_the_violation_is_each_figures_shortfall_normalised():
    """The violation an optimiser minimises (rvtol.verdict module docstring): 0 exactly when the requirement passes,
    else the yield's shortfall over what the requirement leaves for non-conformance, (Y_min − Y)/(1 − Y_min), plus
    the Cpk's relative shortfall (Cpk_min − Cpk)/Cpk_min — the figure judged being the lower bound (the default
    basis).  A yield that could not be measured falls short by the whole yield: 1/(1 − Y_min)."""
    from rvtol.spec import Requirement
    from rvtol.verdict import judge

    ry = Requirement("y", upper=1.0, min_yield=0.99)
    assert judge(ry, yield_=0.999, yield_lo=0.995).violation == 0.0
    j = judge(ry, yield_=0.999, yield_lo=0.985)
    assert not j.passed and j.violation == pytest.approx((0.99 - 0.985) / (1 - 0.99))        # 0.5
    low = Requirement("y", upper=1.0, min_yield=0.4)        # a minimum below ½: 1 − Y_min is 0.6, not 1 mod 0.4
    assert judge(low, yield_=0.5, yield_lo=0.3).violation == pytest.approx((0.4 - 0.3) / (1 - 0.4))   # 1/6
    for missing in (None, math.nan):
        j = judge(ry, yield_=missing, yield_lo=missing)
        assert not j.passed and j.violation == pytest.approx(1 / (1 - 0.99))                  # 100
    rc = Requirement("y", upper=1.0, min_cpk=1.33)
    assert judge(rc, cpk=1.5, cpk_lo=1.4).violation == 0.0
    j = judge(rc, cpk=1.5, cpk_lo=1.0)
    assert not j.passed and j.violation == pytest.approx((1.33 - 1.0) / 1.33)                # 0.248
    both = Requirement("y", upper=1.0, min_yield=0.99, min_cpk=1.33)
    assert judge(both, yield_=0.999, yield_lo=0.985, cpk=1.5, cpk_lo=1.0).violation == pytest.approx(
        (0.99 - 0.985) / (1 - 0.99) + (1.33 - 1.0) / 1.33)


def test_samples_that_fail_fail_a_cpk_but_not_a_yield_that_counts_them():
    """While samples fail a Cpk demonstrates nothing (it describes only the evaluated ones); a yield already counts
    them as non-conforming, so a yield bound that reaches its minimum still passes."""
    from rvtol.spec import Requirement
    from rvtol.verdict import judge

    j = judge(Requirement("y", upper=1.0, min_cpk=1.33), cpk=2.0, cpk_lo=1.8, n_failed=1)
    assert not j.passed and any("Cpk is not demonstrated while samples fail" in w for w in j.reasons)
    j = judge(Requirement("y", upper=1.0, min_yield=0.9), yield_=0.99, yield_lo=0.95, n_failed=1)
    assert j.passed and j.violation == 0.0
    assert j.reasons == ["1 sample(s) could not be evaluated and count as non-conforming"]


def test_a_cpk_that_could_not_be_measured_says_more_samples_will_not_help():
    """No Cpk at all (e.g. fewer than two evaluated samples): the estimate cannot meet the requirement."""
    from rvtol.spec import Requirement
    from rvtol.verdict import judge

    j = judge(Requirement("y", upper=1.0, min_cpk=1.33), cpk=None, cpk_lo=None, n=100)
    assert not j.passed and not j.undecided and j.n_to_demonstrate is None
    assert "the estimate itself misses the requirement: more samples will not demonstrate it" in j.reasons


def test_the_point_estimate_basis_is_named_so():
    from rvtol.spec import Requirement
    from rvtol.verdict import describe_bound

    assert describe_bound(Requirement("y", upper=1.0, basis="estimate")) == "point estimate"
    assert describe_bound(Requirement("y", upper=1.0)) == "95 % one-sided lower bound"


def test_an_estimate_no_feasible_sample_could_demonstrate_is_not_undecided():
    """A yield estimate 1e-12 above its minimum: no n up to N_PLAN_MAX demonstrates it (test above), so no n is
    offered and it is not UNDECIDED — more samples will not decide it."""
    from rvtol.spec import Requirement
    from rvtol.verdict import judge

    j = judge(Requirement("y", upper=1.0, min_yield=0.9973), yield_=0.9973 + 1e-12, yield_lo=0.996, n=1000)
    assert not j.passed and not j.undecided and j.n_to_demonstrate is None
    assert j.reasons[-1].endswith("more samples will not demonstrate it")


def test_a_percentile_bound_that_misses_where_bissells_n_suffices_says_more_samples_would_decide():
    """cpk_method = "percentile", Ĉ = 1.6 at n = 10 000: Bissell's rule says far fewer samples demonstrate 1.33 (its
    one-sided 95 % bound 1.6 − 1.645·√(1/(9n) + Ĉ²/(2(n − 1))) = 1.581 already does), but the bootstrap bound (1.2)
    misses — no n is offered; the reason says the estimates meet it and more samples would decide."""
    from scipy.stats import norm

    from rvtol.spec import Requirement
    from rvtol.verdict import judge

    n, cpk = 10000, 1.6
    assert cpk - norm.ppf(0.95) * math.sqrt(1 / (9 * n) + cpk ** 2 / (2 * (n - 1))) > 1.33
    j = judge(Requirement("y", upper=1.0, min_cpk=1.33, cpk_method="percentile"), cpk=cpk, cpk_lo=1.2, n=n)
    assert not j.passed and j.undecided and j.n_to_demonstrate is None
    assert j.reasons[-1] == (f"not demonstrated at n = {n}: the estimates meet the requirement, their bounds do not — "
                             "more samples would decide")


def test_a_requirement_built_in_code_with_an_unknown_basis_is_refused():
    """basis is checked as bound and cpk_method are: a misspelt basis (the loader's "lower-bound") was judged
    silently on the point estimate — judge reads anything but "lower_bound" as the estimate."""
    from rvtol.errors import SpecError
    from rvtol.spec import Requirement

    with pytest.raises(SpecError, match="unknown basis 'lower-bound' \\(expected one of: lower_bound, estimate\\)"):
        Requirement("y", upper=1.0, basis="lower-bound")
    with pytest.raises(SpecError) as e:
        Requirement("y", upper=1.0, basis="Estimate", file="s.toml", key="requirement[0]")
    assert (e.value.file, e.value.key) == ("s.toml", "requirement[0].basis")


def test_a_summary_without_a_state_is_read_from_passed_and_undecided():
    """summary.json written before it recorded ``state`` or ``undecided``: n_to_demonstrate stood for undecided."""
    from rvtol.verdict import state_of

    assert state_of({"passed": False, "n_to_demonstrate": 1109}) == "UNDECIDED"
    assert state_of({"passed": False, "n_to_demonstrate": None}) == "FAIL"
    assert state_of({"passed": False, "undecided": True, "n_to_demonstrate": None}) == "UNDECIDED"
    assert state_of({"passed": False, "undecided": False, "n_to_demonstrate": 1109}) == "FAIL"
    assert state_of({"passed": True}) == "PASS" and state_of({"state": "UNDECIDED", "passed": False}) == "UNDECIDED"


def test_a_requirement_built_in_code_with_an_unknown_interval_is_refused():
    """interval is checked as basis is: an unknown one (built in code; the loader checks its own) was a KeyError when
    the yield was judged (YIELD_INTERVALS[r.interval])."""
    from rvtol.errors import SpecError
    from rvtol.spec import Requirement

    with pytest.raises(SpecError) as e:
        Requirement("y", upper=1.0, interval="agresti", file="s.toml", key="requirement[0]")
    assert (e.value.file, e.value.key) == ("s.toml", "requirement[0].interval")
    assert "unknown interval 'agresti' (expected one of: clopper-pearson, wilson)" in e.value.reason
    assert Requirement("y", upper=1.0, interval="wilson").interval == "wilson"
