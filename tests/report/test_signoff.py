"""The sign-off digest's drivers: summed per drawing tolerance, only over factors the output can depend on."""
import math

import numpy as np
import pytest

from rvtol.executors import make_executor
from rvtol.mc import run_monte_carlo
from rvtol.model import LinearModel, Quantity
from rvtol.model import dependencies
from rvtol.signoff import digest
from rvtol.spec import Factor, Requirement, ToleranceSpec
from rvtol.distributions import Distribution

K = 40          # a per-pin family


def _spec():
    unit = Distribution.make("normal", mean=0.0, sigma=1.0)
    fs = [Factor("a", "mm", unit, part="shaft", feature="diameter")]
    fs += [Factor(f"pin[{k}]", "mm", unit, part="pins", feature="pin k diameter", family="pin[k]")
           for k in range(1, K + 1)]
    return ToleranceSpec("digest", tuple(fs))


def _model(spec, w):
    """y1 = a + w·Σ pin[k]; y2 = a (the pins cannot move it)."""
    return LinearModel(spec.names, spec.units, [Quantity("y1", "mm"), Quantity("y2", "mm")],
                       [[1.0] + [w] * K, [1.0] + [0.0] * K])


def test_linear_model_dependencies_are_its_non_zero_coefficients():
    spec = _spec()
    deps = dependencies(_model(spec, 0.5))
    assert deps["y2"] == {"a"} and deps["y1"] == set(spec.names)


def captured_fraction(M: int) -> float:
    """The share of a normal factor's variance its M equal-probability classes keep (the class means):
    Σ (1/M) m_i², m_i = M (φ(e_i) − φ(e_{i+1})) between the quantiles e_i = Φ⁻¹(i/M) — what the
    correlation ratio of a linear effect converges to (0.9868 at M = 24)."""
    from scipy.stats import norm

    e = norm.ppf(np.arange(M + 1) / M)
    m = M * (norm.pdf(e[:-1]) - norm.pdf(e[1:]))
    return float(np.sum(m * m) / M)


@pytest.mark.parametrize("seed", [3, 4, 5])
def test_family_share_is_summed_unbiased_and_absent_where_it_cannot_act(seed):
    """The pins carry exactly half the variance of y1 (w² K = 1 = var a) and none of y2. The family's
    summed S1 on y1 is the unbiased sum of K estimates: its expectation is ½ × the share M classes keep of a
    linear effect (the classes' discretisation, by hand 0.5 × 0.9960 at M = 63), within 4 standard errors (the s.e.
    from the K-fold noise of one estimate, sqrt(2(M − 1))/n with M = ⌊√n⌋ = 63 classes: ±0.07). On y2 the
    pins are left out (they do not enter y2), so `a` explains it all."""
    n = 4000
    spec = _spec()
    w = 1.0 / math.sqrt(K)
    model = _model(spec, w)
    reqs = [Requirement("y1", upper=100.0, unit="mm"), Requirement("y2", upper=100.0, unit="mm")]
    with make_executor("serial") as ex:
        mc = run_monte_carlo(model, spec, n, "random", seed, reqs, ex, progress=False)
    d = {r.output: r for r in digest(mc, model, spec, seed=3)}
    pins_y1 = next(x for x in d["y1"].drivers if x.tolerance.startswith("pins"))
    assert len(pins_y1.factors) == K
    M = math.isqrt(n)
    se = math.sqrt(K) * math.sqrt(2 * (M - 1)) / n
    expected = 0.5 * captured_fraction(M)
    assert abs(pins_y1.s1 - expected) < 4 * se
    assert [x.tolerance for x in d["y2"].drivers] == ["shaft: diameter"]
    assert d["y2"].drivers[0].s1 == pytest.approx(1.0, abs=0.1)


def test_drivers_the_spec_correlates_are_flagged_as_overlapping():
    """y = a + b + 0.1 c with a, b correlated (ρ = 0.8 on normal scores): a's first-order share is
    (1 + ρ)² / (2 + 2ρ + 0.01) ≈ 0.90 and so is b's — they overlap, and the digest says so; c is independent."""
    unit = Distribution.make("normal", mean=0.0, sigma=1.0)
    fs = tuple(Factor(x, "mm", unit, part="p", feature=x) for x in "abc")
    C = np.array([[1.0, 0.8, 0.0], [0.8, 1.0, 0.0], [0.0, 0.0, 1.0]])
    spec = ToleranceSpec("corr", fs, correlation=C)
    model = LinearModel(spec.names, spec.units, [Quantity("y", "mm")], [[1.0, 1.0, 0.1]])
    with make_executor("serial") as ex:
        mc = run_monte_carlo(model, spec, 2000, "random", 1, [Requirement("y", upper=100.0, unit="mm")], ex,
                             progress=False)
    (d,) = digest(mc, model, spec, seed=1)
    s1 = {x.tolerance: x.s1 for x in d.drivers}
    expected = (1 + 0.8) ** 2 / (2 + 2 * 0.8 + 0.01)
    assert s1["p: a"] == pytest.approx(expected, abs=0.03) and s1["p: b"] == pytest.approx(expected, abs=0.03)
    assert d.overlaps == ["p: a and p: b (|ρ| = 0.8)"]
    assert d.to_dict()["correlated_drivers"] == d.overlaps


def test_a_requirement_failed_only_by_samples_the_model_cannot_evaluate_says_the_evaluated_units_meet_it():
    """y = x, x uniform on [0, 1], the model failing (non-finite) for x > 0.97: 3 % of the samples count as failing a
    requirement 0 ≤ y ≤ 1 that allows 0.27 %, the evaluated units all inside — the failures alone fail it, and no fix is
    read from the evaluated units (whose mean, 0.485, is that of a selection)."""
    from rvtol.model import FunctionModel

    spec = ToleranceSpec("f", (Factor("x", "mm", Distribution.make("uniform", lower=0.0, upper=1.0)),))
    model = FunctionModel(lambda X: np.where(X[:, :1] > 0.97, np.inf, X[:, :1]), ["x"], [Quantity("y", "mm")], ["mm"])
    with make_executor("serial") as ex:
        mc = run_monte_carlo(model, spec, 2000, "random", 1, [Requirement("y", lower=0.0, upper=1.0, unit="mm")],
                             ex, progress=False)
    (d,) = digest(mc, model, spec, seed=1)
    share = 100 * np.mean(~mc.ok)
    assert 2.0 < share < 4.0
    assert d.change.startswith(f"{share:.3g} % of the samples could not be evaluated")
    assert "the evaluated units meet it (0 % of all samples outside the limits)" in d.change
    assert [f.kind for f in d.fixes] == ["model failures"]


@pytest.mark.parametrize("req,says", [
    ({"upper": 0.96, "min_yield": 0.965}, "together they fail it"),   # 3 % failed, 1 % outside: 4 % > 3.5 % allowed
    ({"upper": 1.0, "min_cpk": 1.0}, "the evaluated units meet it"),  # a Cpk requirement: 3 % > 0.27 % (Cpk 1)
])
def test_failures_that_fail_a_requirement_with_the_evaluated_spread_or_under_a_cpk_requirement_are_said(req, says):
    """The third audit's D5a (neither part alone, together: the 'alone' text claimed 'more than the 30 % allowed' for
    27.8 %) and D5b (a Cpk-only requirement got 'move the mean … tightening cannot help' from the evaluated units)."""
    from rvtol.model import FunctionModel

    spec = ToleranceSpec("f", (Factor("x", "mm", Distribution.make("uniform", lower=0.0, upper=1.0)),))
    model = FunctionModel(lambda X: np.where(X[:, :1] > 0.97, np.inf, X[:, :1]), ["x"], [Quantity("y", "mm")], ["mm"])
    with make_executor("serial") as ex:
        mc = run_monte_carlo(model, spec, 4000, "random", 2, [Requirement("y", lower=0.0, unit="mm", **req)], ex,
                             progress=False)
    (d,) = digest(mc, model, spec, seed=1)
    assert says in d.change and [f.kind for f in d.fixes] == ["model failures"]
    assert "tightening cannot help" not in d.change + " ".join(f.action + f.effect for f in d.fixes)
