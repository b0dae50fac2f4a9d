"""The one-way clutch, the literature's non-linear stack (Fortini 1967; Glancy & Chase 1999):
φ = acos((a + c)/(e − c)).  References independent of rvtol: the angle at the nominal dimensions (7.0184°,
the figure the literature quotes), the worst case at the corners (φ is monotone in every dimension:
∂φ/∂a, ∂φ/∂c < 0, ∂φ/∂e > 0), and a 4-million-sample NumPy Monte Carlo for the moments and quantiles."""
import math

import numpy as np
import pytest
from scipy import stats

from rvtol.distributions import Distribution
from rvtol.models.formula.model import FormulaModel
from rvtol.spec import Factor, ToleranceSpec
from rvtol.stacking.second_order import curvature, second_order
from rvtol.stacking.worst_case import true_worst_case

NOM = {"a": 27.645, "c": 11.43, "e": 50.8}            # mm (data/examples/one_way_clutch.csv)
TOL = {"a": 0.0508, "c": 0.0127, "e": 0.0254}         # ± mm, each band ±3σ of a centred normal


def phi(a, c, e):
    return np.arccos((a + c) / (e - c))


@pytest.fixture(scope="module")
def clutch():
    spec = ToleranceSpec("clutch", tuple(Factor(n, "mm", Distribution.make("normal", mean=NOM[n], sigma=TOL[n] / 3))
                                         for n in NOM))
    return spec, FormulaModel.from_spec(spec, {"phi": ("acos((a + c)/(e - c))", "rad")})


@pytest.fixture(scope="module")
def reference():
    rng = np.random.default_rng(19990912)
    n = 4_000_000
    y = phi(*(rng.normal(NOM[k], TOL[k] / 3, n) for k in NOM))
    return y, n


def test_the_nominal_angle_is_the_literatures():
    assert math.degrees(phi(**NOM)) == pytest.approx(7.0184, abs=5e-5)


def test_second_order_moments_follow_the_monte_carlo(clutch, reference):
    spec, model = clutch
    y0, g, H, _ = curvature(model, spec, "phi")
    so = second_order(spec, y0, g, H)
    y, n = reference
    se_mean = y.std() / math.sqrt(n)
    shift_mc = y.mean() - phi(**NOM)
    # the curvature's mean shift (−0.0045°) is what a linearised stack misses; the expansion drops terms of
    # relative order (σ_u/(1 − u))²·15 ≈ 7 % (u = cos φ near 1): 10 % and four standard errors allowed
    assert shift_mc < -20 * se_mean
    assert so.mean - so.y_at_means == pytest.approx(shift_mc, rel=0.10, abs=4 * se_mean)
    assert so.sigma == pytest.approx(y.std(), rel=0.01)
    assert so.skewness == pytest.approx(stats.skew(y), rel=0.02)       # third cumulant: exact to this order
    # the 3σ-coverage interval from the Pearson curve is nearer the Monte Carlo quantiles than the linearised one
    q_lo, q_hi = np.quantile(y, [stats.norm.cdf(-3), stats.norm.cdf(3)])
    lo, hi = so.interval(3.0)
    s_lin = math.sqrt(float(np.sum((g * spec.std_base()) ** 2)))
    lin_lo, lin_hi = y0 - 3 * s_lin, y0 + 3 * s_lin
    assert abs(lo - q_lo) < abs(lin_lo - q_lo) and abs(hi - q_hi) < abs(lin_hi - q_hi)


def test_the_true_worst_case_is_the_corner_pair(clutch):
    spec, model = clutch
    wc = true_worst_case(model, spec, "phi")
    lo = phi(NOM["a"] + TOL["a"], NOM["c"] + TOL["c"], NOM["e"] - TOL["e"])
    hi = phi(NOM["a"] - TOL["a"], NOM["c"] - TOL["c"], NOM["e"] + TOL["e"])
    assert wc.low == pytest.approx(lo, rel=1e-9) and wc.high == pytest.approx(hi, rel=1e-9)
    # the arithmetic (linearised) worst case under-states the low side: the curvature bends it down
    g = np.array([(phi(**{**NOM, k: NOM[k] + 1e-6}) - phi(**{**NOM, k: NOM[k] - 1e-6})) / 2e-6 for k in NOM])
    assert phi(**NOM) - float(np.abs(g) @ np.array(list(TOL.values()))) > lo

