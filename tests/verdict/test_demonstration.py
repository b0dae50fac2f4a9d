"""What a requirement can demonstrate (issue 37): a yield of exactly 1 refused at load, a constant output's Cpk
stated instead of crashing, the n that demonstrates a yield-and-Cpk requirement the larger of the two needs, and a
normal-theory Cpk that a skewed output would pass on normal theory alone.

References are independent of rvtol's code: the success-run formula n = ln(1 − c)/ln(Y), Bissell's bound written
out by hand, scipy.stats' gamma distribution for the skewed output's ppm and percentile Cpk.
"""
import math
import re

import numpy as np
import pytest
from scipy import stats

from rvtol import signoff
from rvtol.distributions import Distribution
from rvtol.mc import run_monte_carlo
from rvtol.model import FunctionModel, Quantity
from rvtol.spec import Factor, Requirement, ToleranceSpec
from rvtol.verdict import judge

from bad_input_study import REQ, run, setup


# --------------------------------------------------------------------------- min_yield that cannot be demonstrated
@pytest.mark.parametrize("value,reason", [
    ("1.0", "a yield of exactly 1 cannot be demonstrated by any finite sample"),
    ("1", "a yield of exactly 1 cannot be demonstrated by any finite sample"),
    ("1.0000001", "must lie in (0, 1)"),
    ("0.0", "must lie in (0, 1)"),
    ("-0.5", "must lie in (0, 1)"),
    ("nan", "must be a finite number"),
])
def test_a_yield_no_sample_can_demonstrate_is_refused_at_load(tmp_path, capsys, value, reason):
    rc, err, out = run(tmp_path, capsys, setup(tmp_path, req=REQ + f"min_yield = {value}\n"))
    assert rc == 2 and len(err) == 1, err
    m = re.match(r"^rvtol: error: (.+?): (\S+): (.+)$", err[0])
    assert m and m.group(1).endswith("req.toml") and m.group(2) == "requirement[0].min_yield", err[0]
    assert reason in m.group(3), err[0]
    assert not out.exists()


# --------------------------------------------------------------------------- n to demonstrate: the larger need
def _bissell(cpk: float, n: int, c: float = 0.95) -> float:
    return cpk - stats.norm.ppf(c) * math.sqrt(1 / (9 * n) + cpk ** 2 / (2 * (n - 1)))


def _bissell_n(cpk: float, req: float) -> int:
    """The smallest n whose Bissell bound reaches ``req``, by counting up (no root finder)."""
    n = 2
    while _bissell(cpk, n) < req:
        n += 1
    return n


@pytest.mark.parametrize("cpk", [1.37, 1.60])
def test_the_n_that_demonstrates_yield_and_cpk_is_the_larger_need(cpk):
    """Every sample inside (yield 1): the success run needs n = ⌈ln 0.05/ln 0.9973⌉ = 1109; Bissell's bound needs
    ~ 1 780 for Cpk 1.37 and ~ 50 for 1.60 — the requirement is demonstrated at the larger of the two."""
    success_run = math.ceil(math.log(1 - 0.95) / math.log(0.9973))
    assert success_run == 1109
    need_cpk = _bissell_n(cpk, 1.33)
    assert (need_cpk > success_run) == (cpk == 1.37)          # one case each way round
    r = Requirement("y", upper=1.0, min_yield=0.9973, min_cpk=1.33)
    n = 150
    j = judge(r, yield_=1.0, yield_lo=0.05 ** (1 / n), cpk=cpk, cpk_lo=_bissell(cpk, n), n=n)
    assert not j.passed
    assert j.n_to_demonstrate == max(success_run, need_cpk)
    assert any(f"about n = {max(success_run, need_cpk)} samples would demonstrate it" in w for w in j.reasons)


# --------------------------------------------------------------------------- a constant output
def test_a_constant_output_with_a_min_cpk_is_stated_not_a_crash():
    """σ = 0: Cpk = (USL − μ)/3σ is undefined — the tightening advice divided by σ (ZeroDivisionError: the run
    ended with exit 3). The verdict and the digest say what it is instead."""
    spec = ToleranceSpec("s", (Factor("a", "um", Distribution.make("normal", mean=0.0, sigma=1.0)),))
    model = FunctionModel(lambda X: 0.0 * X[:, :1], ["a"], [Quantity("y", "mm", "um")], ["mm"])
    reqs = [Requirement("y", lower=-1.0, upper=5.0, unit="um", min_cpk=1.33, name="capability"),
            Requirement("y", upper=2.0, unit="um", name="yield")]
    mc = run_monte_carlo(model, spec, 500, "lhs", seed=3, requirements=reqs, progress=False)
    digest = {d.label: d for d in signoff.digest(mc, model, spec, seed=3)}
    cap, yld = mc.verdicts()
    assert not cap.passed and cap.capability["cpk"] is None and not cap.undecided
    assert any("Cpk is undefined for a constant output: y = 0 in every evaluated sample" in w and "inside the limits"
               in w for w in cap.reasons)
    # the yield requirement on the same output: every sample inside, 500 < the success run's 1109
    assert yld.n_to_demonstrate == 1109 and yld.undecided
    assert digest["capability"].light == "red" and digest["capability"].fixes == []
    assert "constant" in digest["capability"].change and "min_yield" in digest["capability"].change
    assert digest["yield"].light == "amber"
    assert "no tolerance of the spec moves it" in digest["yield"].change


# ------------------------------------------------------------------------- a skewed output, a normal-theory Cpk
SHAPE = 16 / 9                                       # gamma: skewness 2/√k = 1.5
GAMMA = stats.gamma(SHAPE)
USL = float(GAMMA.mean() + 3 * 1.41 * GAMMA.std())   # normal-theory Cpk 1.41


def skewed(cpk_method: str):
    spec = ToleranceSpec("s", (Factor("g", "mm", Distribution.make("gamma", shape=SHAPE, scale=1.0)),))
    model = FunctionModel(lambda X: X, ["g"], [Quantity("y", "mm")], ["mm"])
    req = Requirement("y", upper=USL, unit="mm", min_cpk=1.33, cpk_method=cpk_method)
    return run_monte_carlo(model, spec, 20000, "lhs", seed=4, requirements=[req], progress=False).verdicts()[0]


def test_a_skewed_output_does_not_pass_a_cpk_on_normal_theory_alone():
    """Skewness 1.5: normal theory says Cpk 1.41 (a normal process at 1.41 has 12 ppm beyond the limit); the gamma
    has 3 400 ppm there and its ISO 22514-2 percentile Cpk is 0.86 — the verdict was PASS without a word."""
    v = skewed("normal")
    ppm = GAMMA.sf(USL) * 1e6
    percentile = (USL - GAMMA.median()) / (GAMMA.ppf(0.99865) - GAMMA.median())
    assert 3000 < ppm < 4000 and percentile == pytest.approx(0.86, abs=0.02)
    assert v.capability["cpk"] == pytest.approx(1.41, abs=0.03) and v.cpk_bound > 1.33   # normal theory alone: pass
    assert v.capability["cpk_percentile"] == pytest.approx(percentile, rel=0.05)
    assert v.yield_.ppm == pytest.approx(ppm, rel=0.15)
    assert v.shape.skewness == pytest.approx(1.5, abs=0.15) and v.shape.non_normal
    assert not v.passed and not v.undecided
    assert any(w.startswith("the output is not normal (skewness 1.") and "percentile Cpk (ISO 22514-2) lower bound 0.8"
               in w for w in v.reasons), v.reasons
    assert v.to_dict()["shape"]["non_normal"] is True


def test_a_percentile_cpk_requirement_notes_the_normal_theory_disagreement():
    v = skewed("percentile")
    assert not v.passed
    assert any(n.startswith("the normal-theory Cpk lower bound 1.") and "would pass" in n and "not normal" in n
               for n in v.notes), v.notes


def test_a_normal_output_keeps_its_normal_theory_verdict():
    """A normal output whose percentile bound (the less efficient one) falls short while normal theory passes: the
    disagreement is noted, the verdict stays normal theory's."""
    spec = ToleranceSpec("s", (Factor("x", "mm", Distribution.make("normal", mean=0.0, sigma=1.0)),))
    model = FunctionModel(lambda X: X, ["x"], [Quantity("y", "mm")], ["mm"])
    req = Requirement("y", lower=-4.2, upper=4.2, unit="mm", min_cpk=1.33)
    v = run_monte_carlo(model, spec, 3000, "lhs", seed=2, requirements=[req], progress=False).verdicts()[0]
    assert not v.shape.non_normal
    assert v.cpk_bound > 1.33 and v.passed
    assert any("would fail" in n and "no departure from normality" in n for n in v.notes), v.notes


def test_the_optimisers_constraint_applies_the_same_rule():
    """The allocation's Monte Carlo constraint judges with the sign-off's rule (rvtol.verdict.other_cpk in its lazy
    form: only what can refute a pass): the skewed output's normal-theory pass is refuted there too."""
    from rvtol import stats as st
    from rvtol.verdict import cpk_figures, other_cpk

    y = GAMMA.rvs(4000, random_state=np.random.default_rng(5))
    r = Requirement("y", upper=USL, min_cpk=1.33)
    cap = st.capability(y, None, USL)
    cpk, lo = cpk_figures(r, cap, y.size)
    shape, other = other_cpk(r, y, cap, (cpk, lo))
    assert lo > 1.33 and shape.non_normal and other[1] < 1.33
    j = judge(r, cpk=cpk, cpk_lo=lo, shape=shape, other_cpk=other)
    assert not j.passed and j.violation > 0
    z = np.random.default_rng(5).normal(0.0, 1.0, 4000)                # a normal output: nothing computed
    cap = st.capability(z, -4.5, 4.5)
    assert other_cpk(Requirement("y", lower=-4.5, upper=4.5, min_cpk=1.33), z, cap,
                     cpk_figures(Requirement("y", lower=-4.5, upper=4.5, min_cpk=1.33), cap, z.size)) == (None, None)


@pytest.mark.parametrize("value,where", [(6.0, "inside"), (5.0, "outside"), (6.5, "outside"), (5.8, "inside")])
def test_a_constant_output_is_placed_against_both_limits(value, where):
    """The reason says where the constant lies against 5.8 ≤ y ≤ 6.2: inside only when it is within both limits (a
    limit itself counts as inside, as for a yield)."""
    r = Requirement("y", lower=5.8, upper=6.2, min_cpk=1.33)
    j = judge(r, cpk=None, cpk_lo=None, constant=value, n=500)
    assert not j.passed and any(f"{where} the limits" in w for w in j.reasons), j.reasons


def _shape(non_normal: bool):
    """An output's shape as judge is handed it: Anderson–Darling p ≤ 0.01 (Stephens' table's last row) rejects
    normality."""
    from rvtol.stats import Shape

    return Shape(1.5, 3.0, 5.0, 0.01) if non_normal else Shape(0.05, 0.1, 0.3, 0.5)


def test_the_percentile_cpk_that_refutes_a_normal_theory_pass_sets_the_violation():
    """A non-normal output whose normal-theory Cpk passes (bound 1.5) and percentile Cpk misses (bound 1.0 < 1.33): not
    demonstrated, and the violation is the percentile bound's relative shortfall (1.33 − 1.0)/1.33."""
    r = Requirement("y", upper=1.0, min_cpk=1.33)
    j = judge(r, cpk=1.6, cpk_lo=1.5, other_cpk=(1.1, 1.0), shape=_shape(True))
    assert not j.passed and j.violation == pytest.approx((1.33 - 1.0) / 1.33)


def test_a_normal_theory_miss_the_percentile_cpk_would_pass_is_a_note_and_plans_on_normal_theory():
    """Normal theory judges (Ĉ = 1.5 from 100 samples, Bissell's bound 1.316 < 1.33) and the percentile Cpk (1.45,
    bound 1.35) would pass on a non-normal output: the disagreement is a note that names the percentile method, the
    verdict stays normal theory's (undecided), and the n that would demonstrate it is Bissell's for Ĉ = 1.5."""
    n = 100
    r = Requirement("y", upper=1.0, min_cpk=1.33)
    assert _bissell(1.5, n) < 1.33
    j = judge(r, cpk=1.5, cpk_lo=_bissell(1.5, n), other_cpk=(1.45, 1.35), shape=_shape(True), n=n)
    assert not j.passed and j.undecided
    assert j.n_to_demonstrate == _bissell_n(1.5, 1.33)
    note, = j.notes
    assert note.startswith("the percentile Cpk (ISO 22514-2) lower bound 1.350 would pass where the normal-theory Cpk "
                           "fails: the output is not normal (")
    assert note.endswith('; cpk_method = "percentile" judges a non-normal output by its own tails')


def test_the_second_cpk_needs_a_hundred_samples_and_is_computed_only_when_it_can_refute_a_pass():
    """other_cpk: no percentile Cpk below 100 evaluated samples; given the judged (Cpk, bound), the percentile one is
    computed only when the figure judged — the bound, by default — passes on a non-normal output."""
    from rvtol import stats as st
    from rvtol.verdict import other_cpk

    y = np.random.default_rng(1).exponential(1.0, 100)            # skewness 2: demonstrably not normal
    r = Requirement("y", upper=6.0, min_cpk=1.33)
    assert other_cpk(r, y[:99], st.capability(y[:99], None, 6.0)) == (None, None)
    cap = st.capability(y, None, 6.0)
    shape, other = other_cpk(r, y, cap)
    assert shape.non_normal and other[0] == cap["cpk_percentile"] and other[1] is not None
    assert other_cpk(r, y, cap, (2.0, 1.0)) == (None, None)       # the estimate passes, the bound judged does not
    shape, other = other_cpk(r, y, cap, (2.0, 1.5))
    assert shape.non_normal and other[0] == cap["cpk_percentile"]


@pytest.mark.parametrize("cpk", [math.nan, math.inf])
def test_a_cpk_estimate_that_is_no_finite_number_plans_no_samples(cpk):
    """judge() with a Cpk of nan or inf (and any bound) is a FAIL that says no sample size can be planned from it —
    it raised TypeError subtracting the bound Bissell's rule does not give for such an estimate."""
    from rvtol.verdict import judge

    r = Requirement("y", lower=0.0, upper=1.0, min_cpk=1.33)
    j = judge(r, cpk=cpk, cpk_lo=1.0, n=100)
    assert not j.passed and j.n_to_demonstrate is None
    assert j.reasons[-1] == f"the estimate is {cpk}: no sample size can be planned from it"
