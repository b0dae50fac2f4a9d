"""Numbers users cannot check themselves, pinned to independent references (issue 27, item 9)."""
import math

import numpy as np
import pytest

from rvtol.ci import differences as df
from rvtol.ci.compare import Change


def _paired(n11, n12, n21, n22):
    """The paired 2×2 table as two flag vectors: x (rows) and y (columns)."""
    x = np.r_[np.ones(n11 + n12), np.zeros(n21 + n22)].astype(bool)
    y = np.r_[np.ones(n11), np.zeros(n12), np.ones(n21), np.zeros(n22)].astype(bool)
    return x, y


def test_paired_ppm_interval_reproduces_the_published_newcombe_interval():
    """Newcombe's square-and-add interval for paired proportions (Newcombe 1998, Stat. Med. 17:2635, method 10),
    as published for Cavo et al. (2012), complete response before/after consolidation, table [[59, 6], [16, 80]]:
    estimate −0.0621, 95 % CI −0.1186 to −0.0046 (Fagerland, Lydersen & Laake, Statistical Analysis of
    Contingency Tables, CRC 2017, chapter 8).  p_rows − p_cols = b − a in rvtol's terms."""
    x, y = _paired(59, 6, 16, 80)
    d, lo, hi = df.proportion_change(y, x, paired=True)
    assert d == pytest.approx(-10 / 161)
    assert lo == pytest.approx(-0.1186, abs=5e-5) and hi == pytest.approx(-0.0046, abs=5e-5)


def test_no_infinite_gain_when_nothing_changed():
    c = Change("mean", 1.0, 1.0, 0.0, (0.0, 0.0), (-0.1, 0.1))
    assert c.gain is None and c.to_dict()["gain"] is None
    assert Change("mean", 1.0, 1.1, 0.1, (0.05, 0.15), (-0.1, 0.3)).gain == pytest.approx(4.0)


def test_markdown_escapes_raw_html_from_the_study():
    from rvtol.ci.markdown import render_markdown

    summary = {"verdict": "PASS", "study": "s`x", "title": "<img src=x onerror=alert(1)>", "n": 10, "method": "lhs",
               "seed": 1, "rvtol_version": "0", "outputs": {"y": {"requirements": [{
                   "requirement": "<script>alert(1)</script>", "min_yield": 0.9, "basis": "estimate",
                   "confidence": 0.95, "yield": 1.0, "yield_ci": [0.7, 1.0], "yield_bound": 1.0, "ppm": 0.0,
                   "passed": True, "reasons": []}]}}}
    md = render_markdown(summary)
    assert "<script>" not in md and "<img" not in md
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in md and "`s'x`" in md


# --------------------------------------------------------------------------- a unit's verdict, a figure at its minimum
def test_a_unit_whose_probability_misses_but_whose_upper_bound_reaches_stays_undecided():
    from scipy.stats import beta

    from rvtol.spec import Requirement
    from rvtol.verdict import CONFORMS, DOES_NOT_CONFORM, UNDECIDED, judge_unit

    r = Requirement("y", upper=1.0)
    # 56 of 59 samples conform: P = 0.949 < 0.95; the one-sided 95 % Clopper–Pearson upper bound of P is
    # Beta(0.95; k + 1, n − k) = 0.9905 ≥ 0.95 — neither demonstrated nor refuted
    u = judge_unit(r, conforming=56, n=59, required=0.95)
    assert u.state == UNDECIDED and u.p == pytest.approx(56 / 59)
    assert u.p_hi == pytest.approx(beta.ppf(0.95, 57, 3), rel=1e-9) and u.p_hi >= 0.95
    # 45 of 59: the upper bound Beta(0.95; 46, 14) = 0.8524 < 0.95 — does not conform
    u = judge_unit(r, conforming=45, n=59, required=0.95)
    assert u.state == DOES_NOT_CONFORM and u.p_hi == pytest.approx(beta.ppf(0.95, 46, 14), rel=1e-9)
    # 59 of 59: the lower bound 0.05^(1/59) = 0.95049 ≥ 0.95 (the success-run size) — conforms
    u = judge_unit(r, conforming=59, n=59, required=0.95)
    assert u.state == CONFORMS and u.p_lo == pytest.approx(0.05 ** (1 / 59), rel=1e-9)


@pytest.mark.parametrize("basis", ["estimate", "lower_bound"])
def test_a_figure_exactly_at_its_minimum_passes_and_a_hair_below_fails(basis):
    """The rule (rvtol/docs/reports.md): a requirement passes when the figure judged *reaches* the required value."""
    from rvtol.spec import Requirement
    from rvtol.verdict import judge

    ry = Requirement("y", upper=1.0, min_yield=0.9973, basis=basis)
    rc = Requirement("y", upper=1.0, min_cpk=1.33, basis=basis)
    below = math.nextafter(0.9973, 0.0)
    assert judge(ry, yield_=0.9973, yield_lo=0.9973, n=1000).passed
    assert not judge(ry, yield_=below, yield_lo=below, n=1000).passed
    assert judge(rc, cpk=1.33, cpk_lo=1.33, n=1000).passed
    assert not judge(rc, cpk=math.nextafter(1.33, 0.0), cpk_lo=math.nextafter(1.33, 0.0), n=1000).passed


def test_the_success_run_bound_is_the_closed_form():
    """No failure in n: the one-sided Clopper–Pearson lower bound is (1 − c)^(1/n); 1109 samples demonstrate 0.9973."""
    from rvtol.spec import Requirement
    from rvtol.verdict import yield_bound

    r = Requirement("y", upper=1.0)
    for n in (59, 1108, 1109, 5000):
        assert yield_bound(r, n, n) == pytest.approx(0.05 ** (1 / n), rel=1e-12)
    assert yield_bound(r, 1108, 1108) < 0.9973 <= yield_bound(r, 1109, 1109)


# --------------------------------------------------------------------------- a truncated normal's mean
def test_the_mean_of_an_asymmetrically_truncated_normal_is_the_closed_form():
    """E[X] = μ + σ·(φ(α) − φ(β))/(Φ(β) − Φ(α)), α = (a − μ)/σ, β = (b − μ)/σ (Johnson, Kotz & Balakrishnan,
    Continuous Univariate Distributions 1, §10.1), written with math.erf — no scipy."""
    from rvtol.params import Params
    from rvtol.distributions import from_params

    phi = lambda z: math.exp(-0.5 * z * z) / math.sqrt(2 * math.pi)   # noqa: E731
    Phi = lambda z: 0.5 * (1 + math.erf(z / math.sqrt(2)))           # noqa: E731
    mu, sigma, lo, hi = 10.0, 2.0, 9.0, 16.0
    a, b = (lo - mu) / sigma, (hi - mu) / sigma
    mean = mu + sigma * (phi(a) - phi(b)) / (Phi(b) - Phi(a))   # 10 + 2·(0.35207 − 0.00443)/0.69011 = 11.0075
    var = sigma ** 2 * (1 + (a * phi(a) - b * phi(b)) / (Phi(b) - Phi(a)) - ((phi(a) - phi(b)) / (Phi(b) - Phi(a))) ** 2)
    d = from_params(Params({"dist": "truncnorm", "mean": mu, "sigma": sigma, "lower": lo, "upper": hi}))
    assert d.mean == pytest.approx(mean, rel=1e-12) and d.std == pytest.approx(math.sqrt(var), rel=1e-10)
    assert mean - mu == pytest.approx(1.0075, abs=1e-4)
    # the sampler's inverse CDF on a fine midpoint grid has the same mean
    u = (np.arange(200_000) + 0.5) / 200_000
    assert float(np.mean(d.ppf(u))) == pytest.approx(mean, abs=1e-5)
    # a shifted process: the shift adds to the truncated mean
    s = from_params(Params({"dist": "truncnorm", "mean": mu, "sigma": sigma, "lower": lo, "upper": hi, "shift": 0.5}))
    assert s.mean == pytest.approx(mean + 0.5, rel=1e-12)


# --------------------------------------------------------------------------- global sensitivity on a subset
def test_sobol_on_a_subset_of_unequally_distributed_factors_uses_each_factors_own_distribution():
    """y = x1 + x2 + x3, x1 ~ U(−1, 1) (variance 1/3), x2 ~ N(0, 0.1²), x3 ~ N(0, 2²); analysing the subset
    [x3, x1] (out of spec order) with x2 at its nominal: S_T(x3) = 4/(4 + 1/3) = 0.9231, S_T(x1) = 0.0769 — a
    factor read through another's inverse CDF swaps them."""
    from rvtol.model import FunctionModel
    from rvtol.params import Params
    from rvtol.sensitivity.global_ import sobol
    from rvtol.spec import ToleranceSpec, factor_from_params

    def f(name, **kw):
        return factor_from_params(Params({"name": name, "unit": "mm", **kw}))

    spec = ToleranceSpec("s", (f("x1", dist="uniform", lower=-1, upper=1), f("x2", dist="normal", sigma=0.1),
                               f("x3", dist="normal", sigma=2.0)))
    model = FunctionModel(lambda X: X.sum(axis=1, keepdims=True), spec.names, ["y"], input_units=["mm"] * 3)
    res = sobol(model, spec, n=1024, factors=["x3", "x1"], second_order=False, seed=3)
    frame = res.to_frame().reset_index()
    col_f = next(c for c in frame.columns if c in ("factor", "name", "group"))
    got = {row[col_f]: row for _, row in frame.iterrows()}
    assert got["x3"]["ST"] == pytest.approx(4 / (4 + 1 / 3), abs=0.03)
    assert got["x1"]["ST"] == pytest.approx((1 / 3) / (4 + 1 / 3), abs=0.03)
    assert got["x3"]["S1"] == pytest.approx(4 / (4 + 1 / 3), abs=0.05)


# --------------------------------------------------------------------------- torsion-curve metrics on an asymmetric loop
def test_torsion_curve_metrics_of_an_asymmetric_hysteresis_loop_by_hand():
    """An analytic loop with different stiffness and clearance on each side and a friction width h: loading
    θ = τ/k₊ + g₊ (τ > 0), θ = τ/k₋ − g₋ (τ < 0), the descending branch h above the ascending one, the branches
    meeting at the turning points ±T (where the descending branch starts and the ascending one starts again).
    The maker's definitions (module docstring of rvtol.models.torsion_curve.model) by hand:
    lost motion = p/k₊ + p/k₋ + g₊ + g₋ (h cancels in the mid-line); mid(T) = T/k₊ + g₊, mid(−T) = −T/k₋ − g₋ + h,
    rigidity = 2T/(mid(T) − mid(−T)); backlash = D(ε) − A(−ε) = g₊ + g₋ + h + ε(1/k₊ + 1/k₋); width = h."""
    from rvtol.models.torsion_curve.model import EPSILON, TorsionCurve, torque_schedule

    T, kp, kn, gp, gn, h = 784e3, 8.0e7, 6.0e7, 1.0e-4, 2.5e-4, 2.0e-5   # N·mm, N·mm/rad, rad
    torque, branch = torque_schedule(T, points=20, percent=3.0)
    side = np.where(torque > 0, torque / kp + gp, torque / kn - gn)
    side[(branch == 0) & (torque == 0)] = gp
    side[(branch == 2) & (torque == 0)] = -gn
    angle = side + np.where(branch == 1, h, 0.0)
    m = TorsionCurve(torque, angle, branch, T).metrics(percent=3.0)
    p, e = 0.03 * T, EPSILON * T
    span = (T / kp + gp) - (-T / kn - gn + h)
    assert m.lost_motion == pytest.approx(p / kp + p / kn + gp + gn, rel=1e-12)
    assert m.rigidity == pytest.approx(2 * T / span, rel=1e-12)
    assert m.backlash == pytest.approx(gp + gn + h + e * (1 / kp + 1 / kn), rel=1e-12)
    assert m.angle_at_rated == pytest.approx(T / kp + gp, rel=1e-12)
    assert m.hysteresis_width == pytest.approx(h, rel=1e-9)
    # asymmetric: swapping the sides changes the rated-angle figure but not lost motion
    swapped = np.where(torque > 0, torque / kn + gn, torque / kp - gp) + np.where(branch == 1, h, 0.0)
    m2 = TorsionCurve(torque, swapped, branch, T).metrics(percent=3.0)
    assert m2.angle_at_rated == pytest.approx(T / kn + gn, rel=1e-12)
    assert m2.lost_motion == pytest.approx(m.lost_motion, rel=1e-12)
