"""Doc 004 cycloid–pin contact: Hertz approach, clearance formula, loaded-contact solution."""
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from rvtol.elements import hertz
from rvtol.models.stiffness.cycloid_contact import (PinGear, angular_backlash, arm, equidistance_term,
                                                    initial_clearance, moved_distance_term, pin_angles,
                                                    reference_approach, solve_contact)

RV80E = PinGear(z_p=40, z_c=39, R_p=75.0, r_p=3.5, a=1.5, b=10.0, E=206000.0, nu=0.3)


def test_hertz_approach_against_hand_computation():
    # pin r = 3.5 mm on a convex cycloid flank ρ = 41.5 mm, b = 10 mm, F = 1000 N, steel.
    # By hand: E* = 206000 / (2 * 0.91) = 113186.8 MPa; R_e = 3.5 * 41.5 / 45 = 3.22778 mm;
    # L = sqrt(4 * 1000 * 3.22778 / (pi * 10 * 113186.8)) = 0.0602572 mm;
    # ln(4 * 3.5 / L) = 5.44819, ln(4 * 41.5 / L) = 7.92111, bracket = 2/3 + both = 14.03597;
    # 2F/(pi b) * (1 - nu^2)/E = 63.6620 * 4.41748e-6 = 2.81226e-4 -> w = 3.94727e-3 mm.
    L = hertz.half_width(1000.0, 10.0, 3.5, 41.5, 206000.0, 0.3)
    assert L == pytest.approx(0.0602572, rel=1e-5)
    w = hertz.approach(1000.0, 10.0, 3.5, 41.5, 206000.0, 0.3)
    assert w == pytest.approx(3.94727e-3, rel=1e-5)


def test_hertz_scaling_and_zero_force():
    # L² ∝ F, so the bracket X loses ln 2 when F doubles: w(2F) = 2 w(F) (X - ln 2)/X
    F = 1500.0
    w1 = hertz.approach(F, 10.0, 3.5, 41.5, 206000.0, 0.3)
    pre = 2 * F / (math.pi * 10.0) * 0.91 / 206000.0
    X = w1 / pre
    w2 = hertz.approach(2 * F, 10.0, 3.5, 41.5, 206000.0, 0.3)
    assert w2 == pytest.approx(2 * w1 * (X - math.log(2)) / X, rel=1e-12)
    assert hertz.approach(0.0, 10.0, 3.5, 41.5, 206000.0, 0.3) == 0.0


def test_clearance_formula_is_normal_clearance_minus_rigid_rotation():
    # Independent decomposition: n(φ) = Δr - ΔR (1 - K cos φ)/√S, rotation β0 = n(φ0)/r_c' closes φ0:
    # Δ(φ) must equal n(φ) - l(φ) β0 for any modifications (doc 004's Δ1, written differently).
    phi = np.linspace(0.05, math.pi - 0.05, 50)
    for dr, dR in ((0.02, 0.0), (0.0, -0.02), (-0.015, -0.03), (0.03, 0.01)):
        K = RV80E.a * RV80E.z_p / (RV80E.R_p + dR)
        S = 1 + K * K - 2 * K * np.cos(phi)
        n = dr - dR * (1 - K * np.cos(phi)) / np.sqrt(S)
        n0 = dr - dR * math.sqrt(1 - K * K)
        l_over_rc = np.sin(phi) / np.sqrt(S)
        expected = n - l_over_rc * n0
        got = initial_clearance(RV80E, phi, dr, dR)[0]
        np.testing.assert_allclose(got, expected, rtol=0, atol=1e-15)


def test_clearance_terms_vanish_at_largest_arm_and_arm_is_largest_there():
    K = RV80E.K1
    phi0 = RV80E.phi0
    assert equidistance_term(phi0, K) == pytest.approx(0.0, abs=1e-12)
    assert moved_distance_term(phi0, K) == pytest.approx(0.0, abs=1e-12)
    assert arm(RV80E, phi0) == pytest.approx(RV80E.a * RV80E.z_c, rel=1e-12)
    phi = np.linspace(0.01, math.pi - 0.01, 2001)
    assert arm(RV80E, phi).max() <= RV80E.a * RV80E.z_c * (1 + 1e-12)


def test_backlash_angle_reproduces_doc004_table3_normal_clearances():
    # Doc 004 Table 3 prints j_C1 = 6.84e-4, 4.10e-4, 8.21e-4, 5.47e-4, 2.74e-4 "mm"; they are the
    # flank-to-flank angle 2 n0 / r_c' in rad with K1 = a z_p / R_p (the document's rounding).
    printed = [6.84e-4, 4.10e-4, 8.21e-4, 5.47e-4, 2.74e-4]
    combos = [(0.02, 0.0), (0.0, -0.02), (0.03, 0.01), (0.01, -0.01), (-0.01, -0.03)]
    for (dr, dR), p in zip(combos, printed):
        ours = 2 * (dr - math.sqrt(1 - RV80E.K1 ** 2) * dR) / RV80E.r_c
        assert round(ours, 6) == pytest.approx(p, abs=1e-12)
        # with K1' = a z_p/(R_p + ΔR_p) as in the clearance formula: within 0.5 %
        assert float(angular_backlash(RV80E, dr, dR)) == pytest.approx(p, rel=5e-3)
    # the clearance formula itself is nanometres at the first pin, not these values
    gaps = initial_clearance(RV80E, pin_angles(40)[1:20], 0.02, 0.0)[0]
    assert gaps.min() < 1e-5


def test_contact_equilibrium_to_1e9():
    rng = np.random.default_rng(4)
    n = 200
    torque = rng.uniform(1e3, 6e5, n)
    dr = rng.uniform(-0.015, 0.03, n)
    # no interference: -ΔR + q Δr ≥ 0 for q in [√(1-K1²), 1], with a margin for the errors
    dR = np.minimum(dr, 0.6 * dr) - 0.005 - rng.uniform(0.0, 0.03, n)
    eR = rng.uniform(-0.002, 0.002, n)
    er = rng.uniform(-0.002, 0.002, n)
    sol = solve_contact(RV80E, torque, dr, dR, eR, er, phase=0.3)
    assert not sol.interference.any()
    assert np.abs(sol.equilibrium_residual()).max() < 1e-9
    assert (sol.force >= 0).all()
    # every loaded pin's approach exceeds its gap, every unloaded one does not
    approach = sol.arm[None, :] * sol.beta[:, None]
    side = sol.arm > 0
    loaded = sol.force > 0
    assert np.all(approach[loaded] > sol.gap[loaded])
    assert np.all(approach[~loaded & side[None, :]] <= sol.gap[~loaded & side[None, :]] + 1e-15)


def test_contact_force_matches_scipy_root_of_the_same_equation():
    torque, dr, dR = 3.775e5, -0.015, -0.03
    sol = solve_contact(RV80E, torque, dr, dR)
    phi = pin_angles(40)
    l = arm(RV80E, phi)
    gap = initial_clearance(RV80E, phi, dr, dR)[0]
    side = l > 0
    gap = gap - l * np.min(gap[side] / l[side])

    def residual(F):
        w = float(reference_approach(RV80E, F))
        Fk = np.maximum(0.0, F * l / RV80E.r_c - gap * F / w)
        return float((Fk * l)[side].sum()) - torque

    F_ref = brentq(residual, 10.0, 1e5, xtol=1e-12, rtol=1e-14)
    assert sol.F_ref[0] == pytest.approx(F_ref, rel=1e-10)


def test_zero_modification_and_error_give_the_symmetric_textbook_distribution():
    # No modification, no error: every pin on the loaded side touches, F_k = F_max l_k / r_c'
    # with F_max = T_c r_c' / Σ l_k² (load proportional to the arm), and both flanks mirror.
    torque = 3.0e5
    sol = solve_contact(RV80E, torque, 0.0, 0.0, phase=0.0)
    l = sol.arm
    side = l > 1e-9
    assert sol.contacts[0] == side.sum() == 19
    F_max = torque * RV80E.r_c / (l[side] ** 2).sum()
    np.testing.assert_allclose(sol.force[0][side], F_max * l[side] / RV80E.r_c, rtol=1e-12)


def test_interference_is_flagged_and_zero_torque_is_unloaded():
    sol = solve_contact(RV80E, [1e5, 1e5, 0.0], [-0.015, -0.015, -0.015], [-0.03, 0.0, -0.03])
    assert list(sol.interference) == [False, True, False]
    assert sol.force[2].sum() == 0.0 and sol.beta[2] == 0.0
