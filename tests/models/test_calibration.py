"""Calibration against measured curves (rvtol.models.calibration): the fit and its uncertainty against closed
forms and SciPy, recovery of known parameters from synthetic measurements (with interval coverage over
seeds), identifiability warnings, CSV errors, the written design, and the study analysis."""

import numpy as np
import pytest
from scipy import optimize, stats

from rvtol import units
from rvtol.elements.reducer_chain import with_compliance_scales
from rvtol.models.reducer_20dof.geometry import geometry_from_design
from rvtol.models.calibration import calibrate, calibrated_factors, load_measurement, reproduce
from rvtol.models.calibration.curves import CurveModel
from rvtol.models.calibration.fit import collinear_groups, condition_indices, identifiability, least_squares_fit
from rvtol.models.calibration.measurements import TE, TORSION, Measurement
from rvtol.models.calibration.parameters import (FAMILIES, Parameter, families_in, make_parameter,
                                          scaled_design_values)
from synthetic_curves import synthetic_measurement
from rvtol.cli import main
from rvtol.design import load_design
from rvtol.errors import InputError
from rvtol.model import FunctionModel
from rvtol.models.torsion_curve.model import CAMS
from rvtol.models.torsion_curve.model import TorsionCurveModel
from rvtol.models.transmission_error.model import TransmissionErrorModel
from rvtol.study import load_study, run_study

from conftest import ROOT

DESIGN = load_design(ROOT / "data/designs/rv80e_te.toml")
TORSION_CSV = ROOT / "data/measurements/synthetic_rv80e_torsion_curve.csv"
TE_CSV = ROOT / "data/measurements/synthetic_rv80e_te.csv"
ARCSEC = float(units.to_base(1.0, "arcsec"))
UM = 1e-3
# the parameters the synthetic files were made from (studies/calibration_synthetic_data.py; display units)
TRUTH = {"compliance.all": 1.25, "clearance.crank_bearing": 3.0, "factor.E_c": 5.0, "factor.R_pin": 3.0}
OFFSETS = {"synthetic_rv80e_torsion_curve": 7.0, "synthetic_rv80e_te": -20.0}   # arcsec
KNOWN_ERRORS = {"E_c": 5.0 * UM, "R_pin": 3.0 * UM}


def _param(name, start=0.0, lo=-10.0, hi=10.0):
    return Parameter(name, "factor", "1", start, lo, hi, (name,), name, "a direct measurement")


def _truth(fit, name):
    p = fit.parameters[fit.names.index(name)]
    if p.kind == "offset":
        return OFFSETS[p.targets[0]] * ARCSEC
    return float(units.to_base(TRUTH[name], p.unit))


# --------------------------------------------------------------------------- the fit against closed forms
def test_linear_fit_matches_ordinary_least_squares_and_curve_fit():
    """A model linear in its parameters: estimate, s², covariance and t interval equal OLS in closed form
    and scipy.optimize.curve_fit (absolute_sigma=False)."""
    rng = np.random.default_rng(7)
    t = np.linspace(0.0, 3.0, 25)
    A = np.column_stack([np.sin(t), t ** 2 / 9.0])
    y = A @ [1.5, -0.7] + 0.4 + rng.normal(0.0, 0.05, t.size)
    model = FunctionModel(lambda X: X @ A.T, ["a", "b"], [f"y{i}" for i in range(t.size)])
    offset = (_param("offset.y"), np.ones(t.size, bool))
    fit = least_squares_fit(model, [_param("a"), _param("b")], [offset], y, np.ones(t.size), weighted=False)
    X = np.column_stack([A, np.ones(t.size)])
    beta, *_ = np.linalg.lstsq(X, y, rcond=None)
    r = y - X @ beta
    s2 = r @ r / (t.size - 3)
    cov = s2 * np.linalg.inv(X.T @ X)
    np.testing.assert_allclose(fit.x, beta, rtol=1e-6)
    assert fit.s2 == pytest.approx(s2, rel=1e-6)
    np.testing.assert_allclose(fit.cov, cov, rtol=1e-5)
    popt, pcov = optimize.curve_fit(lambda tt, a, b, c: a * np.sin(tt) + b * tt ** 2 / 9 + c, t, y)
    np.testing.assert_allclose(fit.x, popt, rtol=1e-6)
    np.testing.assert_allclose(fit.cov, pcov, rtol=1e-5)
    q = stats.t.ppf(0.975, t.size - 3)
    np.testing.assert_allclose(fit.ci[:, 1] - fit.x, q * np.sqrt(np.diag(cov)), rtol=1e-5)
    assert fit.dof == t.size - 3 and fit.identifiability.ok


def test_weights_follow_the_stated_uncertainty():
    """With σ given, the fit is weighted least squares: the same as curve_fit with sigma=σ."""
    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 1.0, 30)
    sig = np.where(t < 0.5, 0.01, 0.2)
    y = 2.0 * np.exp(-t) + rng.normal(0.0, sig)
    model = FunctionModel(lambda X: X[:, :1] * np.exp(-t)[None, :], ["a"], [f"y{i}" for i in range(t.size)])
    fit = least_squares_fit(model, [_param("a")], [], y, 1.0 / sig, weighted=True)
    popt, pcov = optimize.curve_fit(lambda tt, a: a * np.exp(-tt), t, y, sigma=sig)
    assert fit.x[0] == pytest.approx(popt[0], rel=1e-7)
    assert fit.cov[0, 0] == pytest.approx(pcov[0, 0], rel=1e-5)


# --------------------------------------------------------------------------- identifiability
def test_identifiability_flags_a_correlated_pair_a_collinear_group_and_an_unused_parameter():
    rng = np.random.default_rng(11)
    n = 200
    a, b, c = rng.normal(size=(3, n))
    names = ["p", "q", "r", "s"]
    params = [_param(k) for k in names]
    # p and q nearly the same column; r unrelated; s has no effect
    J = np.column_stack([a, a + 0.05 * b, c, np.zeros(n)])
    cov = np.linalg.pinv(J.T @ J)
    se = np.sqrt(np.abs(np.diag(cov)))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(se, se)
    ident = identifiability(J, corr, [], params, 0.95)
    assert ident.unused == ["s"]
    assert [(x, y) for x, y, _ in ident.pairs] == [("p", "q")]
    assert "p and q cannot be separated" in ident.messages[1] and "To separate them" in ident.messages[1]
    # two competing near-dependencies among four columns: no pair of estimates above |ρ| = 0.95, yet
    # collinear together (Belsley's condition indices, from the eigenvalues of the unit-column J̃ᵀJ̃)
    d = rng.normal(size=n)
    J4 = np.column_stack([a, b, a + b + 0.05 * c, a - b + 0.05 * d])
    cov4 = np.linalg.inv(J4.T @ J4)
    se4 = np.sqrt(np.diag(cov4))
    corr4 = cov4 / np.outer(se4, se4)
    assert np.max(np.abs(corr4 - np.eye(4))) < 0.95
    Jn = J4 / np.linalg.norm(J4, axis=0)
    w = np.linalg.eigvalsh(Jn.T @ Jn)
    np.testing.assert_allclose(np.sort(condition_indices(J4)), np.sort(np.sqrt(w.max() / w)), rtol=1e-8)
    groups = collinear_groups(J4, ["w", "x", "y", "z"], 30.0)
    assert len(groups) == 1 and groups[0][1] == ["w", "x", "y", "z"] and groups[0][0] > 30
    ident4 = identifiability(J4, corr4, [], [_param(k) for k in "wxyz"], 0.95)
    assert ident4.pairs == [] and not ident4.ok and "nearly collinear together" in ident4.messages[0]
    # a well-conditioned design gives no group
    assert collinear_groups(np.column_stack([a, b, c]), ["x", "y", "z"], 30.0) == []


def test_two_compliances_from_one_torsion_curve_are_not_separable():
    """The needle-bearing and pin-contact compliances act in series with the same load law: one torsion
    curve sees a weighted sum; the fit says so, names both, and refuses to call them separable."""
    m = load_measurement(TORSION_CSV)
    cal = calibrate(DESIGN, [m], ["compliance.turning_arm_bearings", "compliance.cycloid_pin",
                                  "clearance.crank_bearing"], fixed_factors=KNOWN_ERRORS)
    ident = cal.fit.identifiability
    assert not ident.ok
    pair = [(a, b) for a, b, _ in ident.pairs]
    assert ("compliance.turning_arm_bearings", "compliance.cycloid_pin") in pair
    msg = next(x for x in ident.messages if "cannot be separated" in x)
    assert "load–deflection test" in msg and "weighted sum" in msg
    frame = cal.fit.to_frame().set_index("parameter")
    assert not frame.loc["compliance.cycloid_pin", "separable"]


def test_a_clearance_the_torsion_curve_does_not_see_is_named():
    """The carrier–housing bearing carries no load in the locked-input torsion test: its clearance has a zero
    Jacobian column, infinite standard error, and the warning says so."""
    m = load_measurement(TORSION_CSV)
    cal = calibrate(DESIGN, [m], ["compliance.all", "clearance.carrier_housing"], fixed_factors=KNOWN_ERRORS)
    assert cal.fit.identifiability.unused == ["clearance.carrier_housing"]
    j = cal.fit.names.index("clearance.carrier_housing")
    assert np.isinf(cal.fit.se[j])
    assert "does not depend on it" in cal.fit.identifiability.messages[0]


# --------------------------------------------------------------------------- the curve model
def test_torsion_curve_at_measured_torques_equals_the_hysteresis_model():
    """Solving positive and negative torques in two warm-started runs gives the torsion-curve model's own
    0 → +T → −T → 0 loop (frictionless: the angle depends on the torque alone away from zero)."""
    tc = TorsionCurveModel(DESIGN, CAMS, points=10)
    x = np.full(6, 2e-3)
    curve = tc.curve(x)
    sel = curve.torque != 0
    meas = Measurement(TORSION, "m", "<test>", "", curve.torque[sel], np.zeros(sel.sum()), None, "torque",
                       "angle", "N*m", "arcsec", np.arange(sel.sum()) + 1, (), np.ones(sel.sum(), bool))
    p = make_parameter("clearance.crank_bearing", DESIGN)
    got, status = CurveModel(DESIGN, [meas], [p]).predict([2e-3])
    assert status == 0
    # both converge to tol_f = 1e-6 N: ~1e-6 N / (1e5 N/mm · 42 mm) ≈ 2e-13 rad apart at most
    np.testing.assert_allclose(got[0], curve.angle[sel], rtol=0, atol=1e-6 * ARCSEC)


def test_scaling_every_compliance_scales_the_clearance_free_curve():
    """Without clearances and errors, multiplying every element's deflection law by c multiplies every
    deflection — and the output angle — by c at unchanged forces (compatibility is homogeneous)."""
    torques = np.array([0.05, 0.3, 1.0, -0.2, -1.0]) * float(DESIGN["reducer.rated_torque"])
    meas = Measurement(TORSION, "m", "<test>", "", torques, np.zeros(5), None, "torque", "angle", "N*m",
                       "arcsec", np.arange(5) + 1, (), np.ones(5, bool))
    model = CurveModel(DESIGN, [meas], [make_parameter("compliance.all", DESIGN)])
    one, _ = model.predict([1.0])
    c = 1.7
    scaled, _ = model.predict([c])
    np.testing.assert_allclose(scaled[0], c * one[0], rtol=1e-7)


def test_te_curve_at_measured_angles_equals_the_te_model():
    te = TransmissionErrorModel(DESIGN, ["E_c", "R_pin"], per_crank_rev=8)
    r = te.run({"E_c": 5e-3, "R_pin": 3e-3})
    n = r.theta_c.size
    meas = Measurement(TE, "m", "<test>", "", r.theta_c, np.zeros(n), None, "output_angle", "te", "deg", "arcsec",
                       np.arange(n) + 1, (), np.ones(n, bool), te.load_torque)
    got, status = CurveModel(DESIGN, [meas], [], {"E_c": 5e-3, "R_pin": 3e-3}).predict([])
    assert status == 0
    np.testing.assert_allclose(units.from_base(got[0], "arcsec"), r.te, rtol=0, atol=1e-7)


def test_every_element_family_of_the_chain_is_a_calibration_parameter():
    """The calibration's families are the compliance chain's (rvtol.elements.reducer_chain.FAMILIES): a family
    the design's model has scales its compliance_scale key, and the model's compliance scales with it."""
    from rvtol.elements.reducer_chain import FAMILIES as CHAIN

    assert set(FAMILIES) == set(CHAIN)
    product = load_design(ROOT / "data/products/rv80e/design.toml")
    assert set(families_in(product)) == set(CHAIN)                         # the product gives every element
    assert set(families_in(DESIGN)) == {"sun_support", "sun_planet_mesh", "cycloid_pin", "turning_arm_bearings",
                                        "crank_support_bearings", "carrier_housing_bearing"}   # doc 000's laws
    for family in families_in(product):
        p = make_parameter(f"compliance.{family}", product)
        assert p.targets == (f"compliance_scale.{family}",)
        assert scaled_design_values(product, [p], [2.0]) == {f"compliance_scale.{family}": 2.0}
    with pytest.raises(InputError, match="no pin_groove element"):
        make_parameter("compliance.pin_groove", DESIGN)
    k0 = make_parameter("compliance.cycloid_pin", DESIGN)
    scaled = geometry_from_design(with_compliance_scales(DESIGN, {"cycloid_pin": 2.0}))
    assert scaled.k0_pin == pytest.approx(geometry_from_design(DESIGN).k0_pin / 2.0, rel=1e-15)
    assert scaled_design_values(DESIGN, [k0], [2.0]) == {"compliance_scale.cycloid_pin": 2.0}


# --------------------------------------------------------------------------- recovery of known parameters
def test_torsion_curve_fit_recovers_the_true_parameters_within_their_intervals():
    """The repository's synthetic hysteresis curve (made once with its seed, not chosen): every true value
    lies inside its stated 95 % interval, and the reduced χ² (σ given in the file) is near 1."""
    m = load_measurement(TORSION_CSV)
    cal = calibrate(DESIGN, [m], ["compliance.all", "clearance.crank_bearing"], fixed_factors=KNOWN_ERRORS)
    f = cal.fit
    assert f.success and f.identifiability.ok and f.weighted
    for j, name in enumerate(f.names):
        assert f.ci[j, 0] <= _truth(f, name) <= f.ci[j, 1], name
    # reduced χ² ~ χ²(ν)/ν: inside its two-sided 99.9 % range
    assert stats.chi2.ppf(0.0005, f.dof) / f.dof < f.s2 < stats.chi2.ppf(0.9995, f.dof) / f.dof


def test_joint_torsion_and_te_fit_recovers_the_true_parameters_within_their_intervals():
    cal = calibrate(DESIGN, [load_measurement(TORSION_CSV), load_measurement(TE_CSV)], list(TRUTH))
    f = cal.fit
    assert f.success and f.identifiability.ok and f.dof == 158 + 360 - 6
    for j, name in enumerate(f.names):
        assert f.ci[j, 0] <= _truth(f, name) <= f.ci[j, 1], name


def test_ignoring_part_errors_shows_in_the_reduced_chi_square():
    """The same torsion curve fitted without its cam and pin errors: a biased fit, and the residuals say so
    (reduced χ² far above its 99.9 % bound) — the statistic a user reads before trusting the intervals."""
    cal = calibrate(DESIGN, [load_measurement(TORSION_CSV)], ["compliance.all", "clearance.crank_bearing"])
    f = cal.fit
    assert f.s2 > stats.chi2.ppf(0.9995, f.dof) / f.dof


def test_interval_coverage_over_seeds():
    """40 synthetic torsion curves (seeds 1..40, σ = 0.5″): per parameter, the number of 95 % intervals that
    hold the truth lies in the binomial(40, 0.95) 99.9 % range, and Σ z² (z = error / standard error) in the
    χ²(40) 99.9 % range — intervals neither too narrow nor too wide."""
    truth = {"compliance.all": 1.2, "clearance.crank_bearing": 2.0}
    offset = 5.0 * ARCSEC
    names = [*truth, "offset.synthetic"]
    true_base = np.array([1.2, 2.0 * UM, offset])
    covered, z2 = np.zeros(3), np.zeros(3)
    seeds = range(1, 41)
    for seed in seeds:
        m = synthetic_measurement(DESIGN, TORSION, truth, sigma=0.5 * ARCSEC, seed=seed, points=12, offset=offset)
        f = calibrate(DESIGN, [m], list(truth)).fit
        assert f.names == names
        covered += (f.ci[:, 0] <= true_base) & (true_base <= f.ci[:, 1])
        z2 += ((f.x - true_base) / f.se) ** 2
    n = len(seeds)
    assert np.all(covered >= stats.binom.ppf(0.0005, n, 0.95)), covered
    assert np.all((stats.chi2.ppf(0.0005, n) < z2) & (z2 < stats.chi2.ppf(0.9995, n))), z2


# --------------------------------------------------------------------------- the calibrated design
def test_written_design_reloads_and_reproduces_the_fitted_curves(tmp_path):
    ms = [load_measurement(TORSION_CSV), load_measurement(TE_CSV)]
    cal = calibrate(DESIGN, ms, list(TRUTH), date="2026-01-02")
    path = tmp_path / "calibrated.toml"
    back = cal.write_design(path)
    again = load_design(path)
    assert dict(again.params) == dict(back.params)
    # changed entries: the scaled stiffnesses and the stored clearance/factors, with provenance
    changed = [k for k in again.params if k not in DESIGN.params or again.param(k) != DESIGN.param(k)]
    assert sorted(changed) == sorted([FAMILIES[f].key for f in families_in(DESIGN)] + [
        "calibration.clearance.crank_bearing", "calibration.factor.E_c", "calibration.factor.R_pin"])
    sha = " + ".join(m.sha256 for m in ms)
    for k in changed:
        p = again.param(k)
        assert p.source == f"calibrated: {sha}, 2026-01-02, fit of {', '.join(cal.fit.names)}"
        assert "±" in p.note and "95% CI" in p.note
    c = cal.fit.value("compliance.all")
    assert again["compliance_scale.cycloid_pin"] == pytest.approx(c, rel=1e-15)
    assert again["stiffness.cycloid_pin_mesh_k0"] == DESIGN["stiffness.cycloid_pin_mesh_k0"]     # untouched
    stored = calibrated_factors(again)
    assert stored["delta_b[2,3]"] == pytest.approx(cal.fit.value("clearance.crank_bearing"), rel=1e-12)
    assert stored["E_c"] == pytest.approx(cal.fit.value("factor.E_c"), rel=1e-12)
    offsets = {m.name: cal.fit.value(f"offset.{m.name}") for m in ms}
    curves = reproduce(again, ms, offsets=offsets)
    for comp, curve in zip(cal.comparisons(), curves):
        np.testing.assert_allclose(units.from_base(curve, comp.measurement.y_unit), comp.model, rtol=0, atol=1e-9)
    # the other entries are untouched, sources included
    for k in DESIGN.params:
        if k not in changed:
            assert again.param(k) == DESIGN.param(k)


def test_factors_held_fixed_are_recorded_so_the_design_reproduces_the_curve(tmp_path):
    m = load_measurement(TORSION_CSV)
    cal = calibrate(DESIGN, [m], ["compliance.all", "clearance.crank_bearing"], fixed_factors=KNOWN_ERRORS)
    d = cal.write_design(tmp_path / "c.toml")
    assert calibrated_factors(d) == pytest.approx({**KNOWN_ERRORS, **{b: cal.fit.value("clearance.crank_bearing")
                                                                      for b in CAMS}}, rel=1e-12)
    assert d.param("calibration.factor.E_c").source.startswith("held fixed in the calibration")
    curve = reproduce(d, [m], offsets={m.name: cal.fit.value(f"offset.{m.name}")})[0]
    np.testing.assert_allclose(units.from_base(curve, "arcsec"), cal.comparisons()[0].model, rtol=0, atol=1e-9)
    # calibrating the calibrated design again starts from what it stores, and finds the same values
    again = calibrate(d, [m], ["compliance.all", "clearance.crank_bearing"])
    assert again.fit.value("compliance.all") == pytest.approx(1.0, abs=1e-4)    # the stiffnesses are scaled already
    assert again.fit.value("clearance.crank_bearing") == pytest.approx(cal.fit.value("clearance.crank_bearing"),
                                                                       rel=1e-4)


# --------------------------------------------------------------------------- bad CSV files
GOOD = "# a comment\ntorque [N*m], angle [arcsec]\n10, 1.0\n20, 2.0\n-10, -1.0\n-20, -2.0\n"


@pytest.mark.parametrize("text,key,reason", [
    ("", "row 1", "no header"),
    ("time [s], temp\n1, 2\n", "row 1", "no recognised columns"),
    ("torque [N*m]\n1\n2\n3\n", "row 1", "missing column 'angle'"),
    ("torque [N*m], angle\n1, 2\n2, 3\n3, 4\n", "row 1, column 'angle'", "no unit"),
    ("torque [N*m], angle [milimeter]\n1, 2\n", "row 1, column 'angle [milimeter]'", "unknown unit"),
    ("torque [N*m], angle [mm]\n1, 2\n", "row 1, column 'angle [mm]'", "angle"),
    ("torque [N*m], angle [arcsec], angle [arcmin]\n1, 2, 3\n", "row 1, column 'angle [arcmin]'", "twice"),
    (GOOD.replace("20, 2.0", "20, two"), "row 4, column 'angle [arcsec]'", "not a number: 'two'"),
    (GOOD.replace("-10, -1.0", "-10"), "row 5", "1 fields, the header has 2"),
    (GOOD.replace("20, 2.0", "20, inf"), "row 4, column 'angle [arcsec]'", "finite"),
    ("torque [N*m], angle [arcsec], sigma [arcsec]\n1, 2, 0\n2, 3, 1\n-1, 1, 1\n", "row 2, column 'sigma [arcsec]'",
     "must be > 0"),
    ("torque [N*m], te [arcsec]\n1, 2\n", "row 1", "both 'torque' and 'te'"),
    ("input_angle [deg], te [arcsec]\n1, 2\n2, 3\n3, 4\n", "row 1, column 'input_angle [deg]'", "ratio"),
    ("torque [N*m], angle [arcsec]\n1, 2\n", "row 1", "need at least 3"),
    ("torque [N*m], angle [arcsec]\n0, 2\n0, 3\n0, 4\n", "row 1, column 'torque [N*m]'", "every torque is zero"),
])
def test_bad_csv_gives_file_line_and_column(tmp_path, text, key, reason):
    path = tmp_path / "m.csv"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(InputError) as e:
        load_measurement(path)
    assert e.value.file == str(path)
    assert e.value.key == key
    assert reason in e.value.reason


def test_csv_units_from_the_header_or_a_key(tmp_path):
    p = tmp_path / "m.csv"
    p.write_text("Torque [N·m], Angle, Time [s]\n10, 1.0, 0\n-10, -1.0, 1\n20, 2.0, 2\n", encoding="utf-8")
    m = load_measurement(p, column_units={"angle": "arcmin"}, sigma=0.1 * ARCSEC)
    assert m.kind == TORSION and m.ignored == ("Time [s]",)
    np.testing.assert_allclose(m.x, [1e4, -1e4, 2e4])
    np.testing.assert_allclose(m.y, units.to_base(np.array([1.0, -1.0, 2.0]), "arcmin"))
    with pytest.raises(InputError, match="the header says"):
        load_measurement(TORSION_CSV, column_units={"angle": "arcmin"})
    q = tmp_path / "te.csv"
    q.write_text("input_angle [deg], te [arcsec]\n0, 1\n81, 2\n162, 3\n", encoding="utf-8")
    te = load_measurement(q, ratio=81.0)
    assert te.kind == TE
    np.testing.assert_allclose(te.x, np.radians([0.0, 1.0, 2.0]))


def test_excluded_torques_near_zero(tmp_path):
    p = tmp_path / "m.csv"
    p.write_text("torque [N*m], angle [arcsec]\n0, 0\n1, 1\n-1, -1\n50, 5\n-50, -5\n100, 9\n-100, -9\n",
                 encoding="utf-8")
    m = load_measurement(p, exclude_below=2.0)
    np.testing.assert_array_equal(m.used, [False, False, False, True, True, True, True])


# --------------------------------------------------------------------------- the study analysis
STUDY = """
[study]
name = "cal"
design = "{design}"
[[factor]]
name = "delta_b"
unit = "um"
dist = "uniform"
lower = 0.0
upper = 2.0
[model]
kind = "torsion_curve"
points = 4
[sampling]
n = 2
seed = 1
[execution]
executor = "serial"
[[analysis]]
kind = "calibration"
output = "out/calibrated.toml"
fixed_factors = {{ E_c = 5.0, R_pin = {{ value = 3.0, unit = "um" }} }}
[[analysis.measurement]]
file = "{csv}"
[[analysis.parameter]]
name = "compliance.all"
bounds = [0.2, 5.0]
[[analysis.parameter]]
name = "clearance.crank_bearing"
"""


def _study(tmp_path, text=None, **fmt):
    fmt = {"design": (ROOT / "data/designs/rv80e_te.toml").as_posix(), "csv": TORSION_CSV.as_posix(), **fmt}
    path = tmp_path / "study.toml"
    path.write_text((text or STUDY).format(**fmt), encoding="utf-8")
    return path


def test_calibration_analysis_writes_the_design_and_refuses_foreign_files(tmp_path):
    path = _study(tmp_path)
    res = run_study(load_study(path))
    sec = next(s for s in res.sections if s.key == "calibration")
    assert sec.summary["identifiable"] and sec.summary["design_written"]
    est = {p["parameter"]: p for p in sec.summary["parameters"]}
    assert est["compliance.all"]["95% CI low"] <= 1.25 <= est["compliance.all"]["95% CI high"]
    out = tmp_path / "out/calibrated.toml"
    assert load_design(out).param("compliance_scale.sun_support").source.startswith("calibrated: ")
    load_study(path)                                   # its own earlier output may be replaced
    out.write_text('[design]\nname = "x"\n[a]\nb = { value = 1, unit = "1", source = "s" }\n')
    with pytest.raises(InputError) as e:
        load_study(path)
    assert e.value.key == "analysis[0].output" and "not a calibrated design" in e.value.reason


@pytest.mark.parametrize("change,key,reason", [
    (lambda s: s.replace('"compliance.all"', '"compliance.gearbox"'), "analysis[0].parameter[0].name",
     "unknown element family"),
    (lambda s: s.replace("[0.2, 5.0]", "[5.0, 0.2]"), "analysis[0].parameter[0].bounds", "lower < upper"),
    (lambda s: s.replace("[0.2, 5.0]", "[0.0, 5.0]"), "analysis[0].parameter[0].bounds", "stay > 0"),
    (lambda s: s + '[[analysis.parameter]]\nname = "factor.delta_b[1,1]"\n', "analysis[0].parameter",
     "both act on"),
    (lambda s: s.replace("E_c = 5.0", "E_x = 5.0"), "analysis[0].fixed_factors", "unknown error factor"),
    (lambda s: s.replace('output = "out/calibrated.toml"', 'output = "{design}"'), "analysis[0].output",
     "overwrite the study's design"),
    (lambda s: s.replace('file = "{csv}"', 'file = "{csv}"\nload_torque = 10'),
     "analysis[0].measurement[0].load_torque", "no load torque"),
    (lambda s: s.replace('[[analysis.parameter]]\nname = "compliance.all"',
                         '[[analysis.measurement]]\nfile = "{te}"\n[[analysis.parameter]]\nname = "compliance.all"')
     .replace('file = "{csv}"', 'file = "{csv}"\nname = "a"'),
     "analysis[0].parameter[0]", None),
])
def test_calibration_analysis_bad_input_names_file_and_key(tmp_path, change, key, reason):
    path = _study(tmp_path, change(STUDY), te=TE_CSV.as_posix())
    if reason is None:                                      # the joint case is valid: both files carry sigma
        load_study(path)
        return
    with pytest.raises(InputError) as e:
        load_study(path)
    assert e.value.file == str(path)
    assert e.value.key == key
    assert reason in e.value.reason


def test_a_bad_measurement_file_is_reported_by_the_cli_with_its_line(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("torque [N*m], angle [arcsec]\n1, 2\n2, x\n-1, 1\n", encoding="utf-8")
    path = _study(tmp_path, csv=bad.as_posix())
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"rvtol: error: {bad}: row 3, column 'angle [arcsec]': not a number: 'x'"
