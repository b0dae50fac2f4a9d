"""Newmark-β loop (the numba kernel the reducer uses) on 1-DOF oscillators, and on the reducer."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rvtol import units
from rvtol.design import load_design
from rvtol.models.reducer_20dof import layout as L
from rvtol.models.reducer_20dof.factors import ErrorFactors
from rvtol.models.reducer_20dof.geometry import geometry_from_design
from rvtol.models.reducer_20dof.newmark import NewmarkSolver, integrate_small_system
from rvtol.models.reducer_20dof.quasistatic import QuasiStaticSolver

from conftest import ROOT

# 1 kg, 1000 N/mm: ω = 1000 rad/s; base units t, N, mm, s
M_, K_, ZETA = 1e-3, 1e3, 0.02
W = np.sqrt(K_ / M_)
C_ = 2 * ZETA * np.sqrt(K_ * M_)


def table(contacts):
    """A contact table for one DOF: [(kind, coefficient, offset, stiffness)]."""
    n = len(contacts)
    kind = np.array([c[0] for c in contacts])
    idx = np.full((n, 2, L.NZ), -1)
    idx[:, 0, 0] = 0
    coef = np.zeros((n, 2, L.NZ))
    coef[:, 0, 0] = [c[1] for c in contacts]
    off = np.zeros((n, 2))
    off[:, 0] = [c[2] for c in contacts]
    return kind, idx, coef, off, np.array([c[3] for c in contacts], float), np.ones(n), np.zeros(n)


def run(contacts, F0, omega_f, x0, v0, h, n):
    return integrate_small_system([[M_]], [[C_]], *table(contacts), [0.0], [F0], omega_f, [x0], [v0], h, n)


def test_free_damped_oscillator_matches_closed_form_to_second_order():
    x0, v0 = 0.01, 3.0
    T = 2 * np.pi / W
    wd = W * np.sqrt(1 - ZETA ** 2)

    def exact(t):
        return np.exp(-ZETA * W * t) * (x0 * np.cos(wd * t) + (v0 + ZETA * W * x0) / wd * np.sin(wd * t))

    errs = []
    for per in (100, 200):
        t, q, v, _ = run([(L.LINEAR, 1.0, 0.0, K_)], 0.0, 0.0, x0, v0, T / per, 5 * per)
        errs.append(np.max(np.abs(q[:, 0] - exact(t))))
    amp = np.hypot(x0, v0 / W)
    # trapezoidal period error (ωh)²/12 per radian: 5 periods at h = T/100 -> 2.6e-3 of the amplitude
    assert errs[0] < 2 * 5 * 2 * np.pi * (2 * np.pi / 100) ** 2 / 12 * amp
    assert 3.5 < errs[0] / errs[1] < 4.5                      # second order


def test_forced_oscillator_transient_plus_steady_state():
    F0, Om = 5.0, 0.6 * W
    X = F0 / np.hypot(K_ - M_ * Om ** 2, C_ * Om)
    phi = np.arctan2(C_ * Om, K_ - M_ * Om ** 2)
    wd = W * np.sqrt(1 - ZETA ** 2)
    A = X * np.sin(phi)
    B = (ZETA * W * A - X * Om * np.cos(phi)) / wd

    def exact(t):
        return X * np.sin(Om * t - phi) + np.exp(-ZETA * W * t) * (A * np.cos(wd * t) + B * np.sin(wd * t))

    T = 2 * np.pi / W
    t, q, _, _ = run([(L.LINEAR, 1.0, 0.0, K_)], F0, Om, 0.0, 0.0, T / 400, 4000)
    assert np.max(np.abs(q[:, 0] - exact(t))) < 2e-3 * X


def test_clearance_oscillator_matches_fine_scipy_solution():
    """Dead zone ±δ (two one-sided linear contacts, as the reducer's pins and bearings)."""
    delta, F0, Om = 0.002, 8.0, 0.5 * W

    def rhs(t, y):
        x, v = y
        f = K_ * (x - delta) if x > delta else (K_ * (x + delta) if x < -delta else 0.0)
        return [v, (F0 * np.sin(Om * t) - C_ * v - f) / M_]

    T = 2 * np.pi / Om
    tend = 6 * T
    contacts = [(L.UNILATERAL, 1.0, -delta, K_), (L.UNILATERAL, -1.0, -delta, K_)]
    errs = []
    for per in (2000, 4000):
        h = T / per
        t, q, _, _ = run(contacts, F0, Om, 0.0, 0.0, h, int(round(tend / h)))
        ref = solve_ivp(rhs, (0, tend), [0.0, 0.0], method="DOP853", rtol=1e-11, atol=1e-14, max_step=h,
                        dense_output=True)
        errs.append(np.max(np.abs(q[:, 0] - ref.sol(t)[0])))
    amp = np.max(np.abs(q[:, 0]))
    assert amp > 3 * delta                                    # it crosses the dead zone every cycle
    assert errs[1] < 1e-4 * amp
    assert 3.0 < errs[0] / errs[1] < 5.0                      # still second order across the kinks


@pytest.fixture(scope="module")
def geom():
    return geometry_from_design(load_design(ROOT / "data/designs/rv80e_te.toml"))


def test_reducer_newmark_error_free_and_against_quasi_static(geom):
    arcsec = units.to_base(1.0, "arcsec")
    r = NewmarkSolver(geom).run()
    assert r.ok
    assert r.time_step < 0.1 / r.frequencies[r.frequencies > 0].min()     # lowest mode resolved
    assert (r.te.max() - r.te.min()) / arcsec < 0.01
    # at 15 rpm the pin-mesh frequency (390 Hz) is far below the lowest mode (2 kHz): Newmark TE ≈ static TE
    st = ErrorFactors(["E_c"], geom.z_b).state([0.002])
    dyn = NewmarkSolver(geom, st).run()
    sta = QuasiStaticSolver(geom, st).rotation()
    pp_d, pp_s = np.ptp(dyn.te), np.ptp(sta.te)
    assert pp_d == pytest.approx(pp_s, rel=0.01)
