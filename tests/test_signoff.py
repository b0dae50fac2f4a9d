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


@pytest.mark.parametrize("n", [600])
def test_family_share_is_summed_unbiased_and_absent_where_it_cannot_act(n):
    """The pins carry exactly half the variance of y1 (w² K = 1 = var a) and none of y2. The family's
    summed S1 on y1 is the unbiased sum of K estimates (4 standard errors from its 0.5, the s.e. estimated
    from the K-fold noise of one estimate, sqrt(2(M − 1))/n with M ≈ √n classes); on y2 the pins are left
    out (they do not enter y2), so `a` explains it all on its own."""
    spec = _spec()
    w = 1.0 / math.sqrt(K)
    model = _model(spec, w)
    reqs = [Requirement("y1", upper=100.0, unit="mm"), Requirement("y2", upper=100.0, unit="mm")]
    with make_executor("serial") as ex:
        mc = run_monte_carlo(model, spec, n, "random", 3, reqs, ex, progress=False)
    d = {r.output: r for r in digest(mc, model, spec, seed=3)}
    pins_y1 = next(x for x in d["y1"].drivers if x.tolerance.startswith("pins"))
    assert len(pins_y1.factors) == K
    M = math.isqrt(n)
    se = math.sqrt(K) * math.sqrt(2 * (M - 1)) / n
    assert abs(pins_y1.s1 - 0.5) < 4 * se + 0.05          # + the classes' discretisation bias of `a`'s half
    assert [x.tolerance for x in d["y2"].drivers] == ["shaft: diameter"]
    assert d["y2"].drivers[0].s1 == pytest.approx(1.0, abs=0.1)
