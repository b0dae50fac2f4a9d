"""Torsion (hysteresis) curve of the 20-DOF model: metrics, linearity, clearance rates, virtual work."""

import numpy as np
import pytest

from rvtol.design import load_design
from rvtol.errors import InputError
from rvtol.models.torsion_curve.model import (EPSILON, TorsionCurve, TorsionCurveModel, compliance_breakdown, from_study,
                                        torque_schedule)
from rvtol.models.torsion_curve.beside_analytical_models import CAMS, analytic_lost_motion, output_ratio
from rvtol.models.reducer_20dof import layout as L
from rvtol.models.reducer_20dof.compliance import GROUPS
from rvtol.models.reducer_20dof.geometry import geometry_from_design
from rvtol.models.reducer_20dof.layout import ST_BAD_CLEARANCE
from rvtol.models.reducer_20dof.quasistatic import QuasiStaticSolver
from numpy_twin import ReferenceModel
from rvtol.params import Params
from rvtol.spec import spec_from_table

from conftest import ROOT

DESIGN = load_design(ROOT / "data/designs/rv80e_te.toml")
G = geometry_from_design(DESIGN)
T = G.rated_torque


def _synthetic(backlash, k, width=0.0):
    """Backlash b, linear stiffness k and a loop of width w (1 - (τ/T)²) closing at ±T."""
    torque, branch = torque_schedule(T, 20, 3.0)
    core = np.sign(torque) * backlash / 2 + torque / k
    half = width / 2 * (1 - (torque / T) ** 2)
    return TorsionCurve(torque, np.where(branch == 1, core + half, core - half), branch, T)


def test_metrics_of_a_synthetic_curve_follow_the_definitions():
    b, k, p = 2e-4, 1.5e9, 3.0
    m = _synthetic(b, k).metrics(p)
    assert m.lost_motion == pytest.approx(b + 2 * p / 100 * T / k, rel=1e-12)
    assert m.rigidity == pytest.approx(2 * T / (b + 2 * T / k), rel=1e-12)
    assert m.backlash == pytest.approx(b + 2 * EPSILON * T / k, rel=1e-12)
    assert m.hysteresis_width == pytest.approx(0.0, abs=1e-18)
    # the other two readings of the maker's b/a: the slope between 50 % and 100 % rated is the elastic k; b/a
    # with the backlash (the width at ±ε) taken out of a is k/(1 − ε)
    assert m.rigidity_50_100 == pytest.approx(k, rel=1e-12)
    assert m.rigidity_clearance_free == pytest.approx(k / (1 - EPSILON), rel=1e-12)
    assert m.readings() == {"torsional_rigidity": m.rigidity, "rigidity_50_100": m.rigidity_50_100,
                            "rigidity_clearance_free": m.rigidity_clearance_free}
    # a loop of width w (1 - (τ/T)²): mid-points (lost motion, rigidity) unchanged, backlash grows by
    # the width at ±ε, the largest width away from zero is the one at ±3 %
    w = 5e-5
    mw = _synthetic(b, k, w).metrics(p)
    assert mw.lost_motion == pytest.approx(m.lost_motion, rel=1e-12)
    assert mw.rigidity == pytest.approx(m.rigidity, rel=1e-12)
    assert mw.backlash == pytest.approx(m.backlash + w * (1 - EPSILON ** 2), rel=1e-12)
    assert mw.hysteresis_width == pytest.approx(w * (1 - 0.03 ** 2), rel=1e-12)
    # the percentage is a parameter: ±5 % widens the lost motion by the elastic part only
    assert _synthetic(b, k).metrics(5.0).lost_motion == pytest.approx(b + 2 * 0.05 * T / k, rel=1e-12)


def test_schedule_runs_zero_to_plus_to_minus_to_zero():
    torque, branch = torque_schedule(T, 10, 3.0)
    assert torque[0] == 0 and torque[-1] == 0 and torque.max() == T and torque.min() == -T
    for v in (0.03 * T, -0.03 * T, EPSILON * T, -EPSILON * T):
        assert np.any(np.isclose(torque, v, rtol=0, atol=1e-9))
    assert list(np.unique(branch)) == [0, 1, 2] and np.all(np.diff(branch) >= 0)
    odd, _ = torque_schedule(T, 7, 3.0)                  # half rated is a point of every schedule (50–100 % reading)
    for v in (0.5 * T, -0.5 * T):
        assert np.any(np.isclose(odd, v, rtol=0, atol=1e-9))


def _tangent_compliance(g, q, theta_c=0.0):
    """Carrier compliance (rad per N·mm) from the NumPy reference model's tangent stiffness at ``q``."""
    _, K, _ = ReferenceModel(g).forces(theta_c, q)
    e = np.zeros(L.NDOF)
    e[L.THCA] = 1.0
    return np.linalg.solve(K, e)[L.THCA]


def test_clearance_free_linear_model_is_linear_with_the_linearised_slope():
    g = geometry_from_design(DESIGN.with_values(**{"stiffness.hertz_exponent": 0.0}))   # linear contact laws
    taus = np.array([0.001, 0.005, 0.01, 0.02, 0.05, 0.1]) * T
    r = QuasiStaticSolver(g, tol_f=1e-9).torsion(taus)
    assert r.ok
    slopes = taus / r.te
    np.testing.assert_allclose(slopes, slopes[0], rtol=1e-6)
    k_lin = 1.0 / _tangent_compliance(g, r.q[2])
    assert slopes[0] == pytest.approx(k_lin, rel=1e-6)
    # and the curve model's rigidity is that same slope (linear and clearance-free: b/a = k)
    m = TorsionCurveModel(g).curve().metrics()
    assert m.rigidity == pytest.approx(k_lin, rel=1e-6)


def test_hertz_model_slope_equals_tangent_stiffness_at_half_rated():
    h = 1e-3 * T
    r = QuasiStaticSolver(G, tol_f=1e-10, maxit=100).torsion([0.5 * T - h, 0.5 * T, 0.5 * T + h])
    assert r.ok
    slope = 2 * h / (r.te[2] - r.te[0])
    # central difference error ~ (h/T)² relative for a smooth law: well inside 1e-4
    assert slope == pytest.approx(1.0 / _tangent_compliance(G, r.q[1]), rel=1e-4)


def test_virtual_work_breakdown_sums_to_the_solver_angle():
    m = TorsionCurveModel(G, CAMS + ("delta_pin",))
    x = np.array([0.002, 0.001, 0.0, 0.003, 0.002, 0.001, 0.002])
    c = m.curve(x)
    for frac in (1.0, 0.25):
        k = int(np.flatnonzero(np.isclose(c.torque, frac * T))[0])
        parts = compliance_breakdown(G, m.state(x), c.q[k], c.torque[k])
        assert sum(parts.values()) == pytest.approx(c.angle[k], rel=1e-6)


def test_lost_motion_grows_with_crank_bearing_clearance_at_the_analytical_rate():
    m = TorsionCurveModel(G, CAMS)
    d = np.array([2.0, 4.0, 6.0]) * 1e-3                          # δ_b on all six bearings, mm
    Y = m.evaluate(np.repeat(d[:, None], 6, axis=1))
    lm, bl = Y[:, 0], Y[:, 2]
    rate_bl = np.polyfit(d, bl, 1)[0]
    rate_lm = np.polyfit(d, lm, 1)[0]
    ib = output_ratio(G)
    # doc 001's Δφ_b = Δ/(K r) with Δ = 2δ_b, vector-analysis K = 1 for three bearings at 120°, times i_b
    kinematic = ib * np.polyfit(d, analytic_lost_motion(G, 1.0, 2 * d), 1)[0]
    assert rate_bl == pytest.approx(kinematic, rel=2e-3)
    # lost motion adds the elastic part within ±3 %: first order, its rate is the same to within 3 %
    assert rate_lm == pytest.approx(kinematic, rel=3e-2)
    assert rate_lm > rate_bl
    # doc 001 as written (K = 1.5) predicts a rate 1/(1.5 i_b) of the 20-DOF's
    doc = np.polyfit(d, analytic_lost_motion(G, 1.5, 2 * d), 1)[0]
    assert rate_bl / doc == pytest.approx(1.5 * ib, rel=2e-3)
    # its consistent mode is the kinematic rate (K = 1, × i_b), whatever K the document mode is given
    consistent = np.polyfit(d, analytic_lost_motion(G, 1.5, 2 * d, mode="consistent"), 1)[0]
    assert consistent == pytest.approx(kinematic, rel=1e-12)


def test_model_status_and_row_determinism():
    m = TorsionCurveModel(G, ("delta_b", "delta_pin"))
    X = np.array([[0.002, 0.001], [-0.001, 0.0], [0.0, 0.002]])
    Y, st = m.evaluate_with_status(X)
    assert list(st) == [0, ST_BAD_CLEARANCE, 0]
    assert np.isnan(Y[1]).all() and np.isfinite(Y[[0, 2]]).all()
    Y2, _ = m.evaluate_with_status(X[2:])
    np.testing.assert_array_equal(Y2[0], Y[2])
    assert m.status_reasons[ST_BAD_CLEARANCE].startswith("negative bearing clearance")


def test_from_study_checks_inputs():
    spec = spec_from_table({"factor": [{"name": "delta_b", "unit": "um", "dist": "uniform", "lower": 0,
                                        "upper": 3}]})
    m = from_study(Params({"percent": 5.0}), DESIGN, spec)
    assert m.percent == 5.0 and m.inputs == ("delta_b",)
    bad = spec_from_table({"factor": [{"name": "bogus", "unit": "um", "dist": "normal", "mean": 0, "sigma": 1}]})
    with pytest.raises(InputError):
        from_study(Params({}), DESIGN, bad)
    with pytest.raises(InputError, match="percent"):
        from_study(Params({"percent": 80.0}), DESIGN, spec)
    with pytest.raises(InputError, match="20-DOF design"):
        from_study(Params({}), None, spec)


def test_a_bad_stiffness_design_fails_when_the_study_loads(tmp_path):
    """The analysis checks its part-1 design up front (here a 20-DOF design without doc 004's keys)."""
    from conftest import write
    from rvtol.study import load_study

    te = (ROOT / "data/designs/rv80e_te.toml").as_posix()
    study = write(tmp_path / "s.toml", f"""
[study]
name = "tc"
design = "{te}"
[model]
kind = "torsion_curve"
[[factor]]
name = "delta_b"
unit = "um"
dist = "uniform"
lower = 0
upper = 3
[[analysis]]
kind = "torsion_curve"
stiffness_design = "{te}"
""")
    with pytest.raises(InputError) as exc:
        load_study(study)
    assert exc.value.file == te and exc.value.key



def test_contact_work_of_the_kernels_equals_the_numpy_twin():
    """The production breakdown (kernel contact table) against the NumPy twin's explicit Jacobians."""
    m = TorsionCurveModel(G, CAMS + ("delta_pin",))
    x = np.array([0.002, 0.001, 0.0, 0.003, 0.002, 0.001, 0.002])
    c = m.curve(x)
    k = int(np.argmax(c.torque))
    st = m.state(x)
    ref = ReferenceModel(G, st)
    _, _, parts = ref.forces(0.0, c.q[k])
    P = ref.linear_parts(0.0)
    twin = {}
    for name in ("sun", "mesh", "pin", "cam", "crank", "housing"):
        Gm, h = P[name]
        d_el = Gm @ c.q[k]
        f = np.ravel(parts[name])
        if name in ("cam", "crank", "housing"):
            dv = (d_el + h).reshape(-1, 2)
            r = np.linalg.norm(dv, axis=1)
            twin[name] = float(((f / np.where(r > 0, r, 1.0))[:, None] * dv * d_el.reshape(-1, 2)).sum())
        else:
            twin[name] = float((f * np.ravel(d_el)).sum())
    prod = QuasiStaticSolver(G, st).contact_work(0.0, c.q[k])
    scale = max(abs(v) for v in twin.values())
    assert set(prod) == set(GROUPS.values())           # doc 000's design: its six contact laws, no chain
    for name, v in twin.items():
        assert prod[GROUPS[name]] == pytest.approx(v, abs=1e-9 * scale), name
