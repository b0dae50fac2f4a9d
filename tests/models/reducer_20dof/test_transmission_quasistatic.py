"""Quasi-static solver and TransmissionErrorModel: error-free TE, torque ratio, linearity, failures."""

import numpy as np
import pytest

from rvtol import units
from rvtol.errors import InputError
from rvtol.mc import evaluate
from rvtol.models.reducer_20dof import layout as L
from rvtol.models.reducer_20dof.factors import ErrorFactors
from rvtol.models.reducer_20dof.quasistatic import QuasiStaticSolver
from rvtol.models.transmission_error.model import TransmissionErrorModel
from rvtol.models.transmission_error.orders import order_spectrum

from conftest import ROOT

ARCSEC = units.to_base(1.0, "arcsec")


def test_error_free_reducer_has_no_transmission_error(te_geom):
    r = QuasiStaticSolver(te_geom).rotation(per_crank_rev=36)     # 1440 positions, 3 % rated torque
    assert r.ok and r.te.size == 1440
    pp = (r.te.max() - r.te.min()) / ARCSEC
    assert pp < 0.01
    assert r.te.mean() < -1.0 * ARCSEC              # but it winds up elastically under the load


def test_locked_input_output_torque_is_ratio_times_input_torque(te_geom):
    """Input locked, output torque swept (with clearances and errors): T_out = −i·T_in at equilibrium.

    Bound: by virtual work along the rigid kinematic mode v, |T_in + T_out/i| = |Σ R_a v_a| ≤ tol_f Σ
    |ρ_a v_a| with ρ the arc radii (the converged scaled residual is below tol_f on every DOF)."""
    st = ErrorFactors(["delta_b", "E_c", "R_pin", "delta_oc"], te_geom.z_b).state([0.004, 0.002, 0.002, 0.003])
    tol_f = 1e-8
    solver = QuasiStaticSolver(te_geom, st, tol_f=tol_f)
    T = te_geom.rated_torque
    torques = np.concatenate([np.linspace(0.02 * T, T, 8), np.linspace(T, -T, 15), [-0.3 * T]])
    r = solver.torsion(torques, theta_c=0.41)
    assert r.ok
    from test_transmission_kernels import kinematic_mode

    bound = tol_f * np.sum(np.abs(te_geom.arc_radii() * kinematic_mode(te_geom, 0.41)))   # N·mm per rad of input
    T_in = r.input_torque
    np.testing.assert_array_less(np.abs(T_in + torques / te_geom.ratio), bound)
    np.testing.assert_allclose(-te_geom.ratio * T_in, torques, rtol=0, atol=te_geom.ratio * bound)
    assert te_geom.ratio * bound < 1e-7 * T      # i.e. equal to better than 1e-7 of the rated torque
    # the torsion curve is monotone: more torque, more twist
    up = r.te[:8]
    assert np.all(np.diff(up) > 0)


def test_linear_dominated_factor_doubles_te(te_design):
    """Pin tooth-space deviation R_jk ('linear-dominated strong influence', doc 000 §4): Δθ_er(2e) = 2 Δθ_er(e)
    within 3 % — the elastic deflections at the light test load (~0.1 µm) are small against e = 2 µm."""
    m = TransmissionErrorModel(te_design, ["R_pin"])
    Y, status = m.evaluate_with_status(np.array([[0.002], [0.004]]))
    assert np.all(status == 0)
    assert Y[1, 0] / Y[0, 0] == pytest.approx(2.0, rel=0.03)
    assert Y[0, 0] / ARCSEC > 1.0           # and it is a strong factor: > 0.5 arcsec/µm


def test_failures_are_reported_per_sample_never_as_numbers(te_design):
    m = TransmissionErrorModel(te_design, ["delta_b", "delta_pin", "E_c"])
    X = np.array([[0.003, 0.0, 0.001],       # fine
                  [-0.001, 0.0, 0.0],        # negative clearance: refused
                  [0.0, 1.5, 0.0],           # every pin 1.5 mm away: no equilibrium within the model's range
                  [0.002, 0.0, np.nan]])     # not a number
    ev = evaluate(m, X, progress=False)
    assert list(ev.status) == [0, L.ST_BAD_CLEARANCE, L.ST_DIVERGED, 1]
    assert np.all(np.isfinite(ev.Y[0])) and np.all(np.isnan(ev.Y[1:]))
    for s in ev.status[1:]:
        assert m.status_reasons[int(s)]
    few = TransmissionErrorModel(te_design, ["E_c"], maxit=1)      # Newton starved of iterations
    Y, st = few.evaluate_with_status(np.array([[0.003]]))
    assert st[0] == L.ST_MAXITER and np.isnan(Y[0, 0])


def test_rows_are_independent_and_model_pickles(te_design):
    import pickle

    m = TransmissionErrorModel(te_design, ["E_c", "R_cyc"], per_crank_rev=12)
    X = np.array([[0.001, 0.0], [0.0, 0.002], [0.002, 0.001]])
    Y, _ = m.evaluate_with_status(X)
    Y1, _ = m.evaluate_with_status(X[2:])
    np.testing.assert_array_equal(Y[2], Y1[0])
    m2 = pickle.loads(pickle.dumps(m))
    np.testing.assert_array_equal(m2.evaluate(X[:1]), Y[:1])


def test_order_spectrum_recovers_sinusoids():
    th = 2 * np.pi * np.arange(1440) / 1440
    y = 3.0 + 2.0 * np.sin(40 * th + 0.3) + 0.5 * np.cos(78 * th)
    k, a = order_spectrum(y)
    assert a[0] == pytest.approx(3.0) and a[40] == pytest.approx(2.0) and a[78] == pytest.approx(0.5)
    assert np.delete(a, [0, 40, 78]).max() < 1e-12


def test_run_gives_curve_spectrum_and_forces(te_design):
    m = TransmissionErrorModel(te_design, ["E_c"], per_crank_rev=12)
    r = m.run({"E_c": 0.002})
    assert r.ok and r.te.size == 12 * 40
    top = r.top_orders(1)
    assert int(top.iloc[0, 0]) == 40     # the cam error turns with the crank: 40 per output revolution
    f = r.to_frame()
    assert (f["loaded pins disc 1"] > 0).all() and (f["max pin force [N]"] > 0).all()
    with pytest.raises(InputError):
        m.run({"E_x": 1.0})


def test_model_options_are_validated(te_design):
    with pytest.raises(InputError, match="mode"):
        TransmissionErrorModel(te_design, ["E_c"], mode="explicit")
    with pytest.raises(InputError, match="per_crank_rev"):
        TransmissionErrorModel(te_design, ["E_c"], per_crank_rev=2)
