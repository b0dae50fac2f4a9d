"""rvtol.elements.rolling_bearings against Palmgren's law, Harris' load integrals, roller statics,
a 3-D force balance computed independently, a scalar closed form for axial preload, and symmetry."""
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from rvtol.elements import rolling_bearings as rb
from rvtol.elements.rolling_bearings import BearingPair, NeedleRollerBearing, TaperedRollerBearing
from rvtol.errors import SpecError

# 32004 X-sized bearing (d 20, D 42, T 15; α = 14°): internal geometry estimated (see studies/compliance_elements.md)
TRB = TaperedRollerBearing(rollers=16, alpha=math.radians(14.0), length=10.0, pitch_diameter=31.0,
                           alpha_inner=math.radians(10.0))


def test_palmgren_single_contact_and_roller_between_two_raceways():
    Q, l = 1000.0, 10.0
    assert rb.palmgren_approach(Q, l) == pytest.approx(3.84e-5 * Q ** 0.9 / l ** 0.8, rel=1e-15)
    # a roller between two raceways of equal length: 7.68e-5 Q^0.9 / l^0.8 (both contacts)
    K = rb.roller_constant(l)
    delta = 7.68e-5 * Q ** 0.9 / l ** 0.8
    assert K * delta ** (10 / 9) == pytest.approx(Q, rel=1e-12)
    # per-contact constant as the classical K_l = 8.06e4 l^(8/9) N/mm^(10/9) of one line contact
    assert (3.84e-5) ** (-10 / 9) == pytest.approx(8.06e4, rel=2e-3)
    # a single roller (Z = 1, at ψ = 0) of a needle bearing follows Palmgren's law exactly
    one = NeedleRollerBearing(rollers=1, length=l)
    assert one.solve(Q).u[0, 0] == pytest.approx(delta, rel=1e-10)


def test_load_integrals_against_harris_table_and_catalogue_constants():
    # Harris' tables use n = 1.1 for line contact: J_r(0.5) = 0.2453, Q_max = 4.08 F_r/(Z cos α);
    # NSK (catalogue, "bearing internal load distribution"): F_a = 1.260 F_r tan α (line), 1.216 (point)
    Jr, Ja = rb.load_integrals(0.5, 1.1)
    assert Jr == pytest.approx(0.2453, abs=5e-5)
    assert 1 / Jr == pytest.approx(4.08, abs=5e-3)
    assert Ja / Jr == pytest.approx(1.260, abs=1e-3)
    Jr, Ja = rb.load_integrals(0.5, 1.5)
    assert Jr == pytest.approx(0.2288, abs=5e-5)
    assert 1 / Jr == pytest.approx(4.37, abs=5e-3)
    assert Ja / Jr == pytest.approx(1.216, abs=1e-3)
    # ε → ∞ (uniform load): J_r → 0, J_a → 1 ; ε = 1: J_a = (1/2π)∫((1+cosψ)/2)^n dψ
    Jr, Ja = rb.load_integrals(1e9, 10 / 9)
    assert Ja == pytest.approx(1.0, rel=1e-8) and abs(Jr) < 1e-8
    from scipy.special import gamma
    n = 10 / 9
    # ∫_{-π}^{π} cos^{2n}(ψ/2) dψ = 2√π Γ(n+½)/Γ(n+1)
    assert rb.load_integrals(1.0, n)[1] == pytest.approx(math.sqrt(math.pi) * gamma(n + 0.5) / gamma(n + 1) / math.pi,
                                                         rel=1e-10)


def test_needle_bearing_many_rollers_zero_clearance_matches_stribeck_integral():
    Z, l, F = 720, 8.0, 3000.0
    brg = NeedleRollerBearing(rollers=Z, length=l)
    sol = brg.solve(F)
    Jr, _ = rb.load_integrals(0.5)                     # n = 10/9, the model's exponent
    assert sol.max_roller_load[0] * Z / F == pytest.approx(1 / Jr, rel=2e-4)
    assert sol.u[0, 0] == pytest.approx(7.68e-5 * (F / (Z * Jr)) ** 0.9 / l ** 0.8, rel=2e-4)
    assert abs(sol.u[0, 1]) < 1e-12


def test_needle_bearing_with_clearance_matches_load_integral_at_its_epsilon():
    Z, l, Pd, F = 720, 8.0, 0.004, 2000.0
    sol = NeedleRollerBearing(rollers=Z, length=l, clearance=Pd).solve(F)
    dr = sol.u[0, 0]
    eps = 0.5 * (1 - Pd / (2 * dr))                   # Harris: ε = ½ (1 − P_d/(2 δ_r))
    Jr, _ = rb.load_integrals(eps)
    Qmax = rb.roller_constant(l) * (dr - Pd / 2) ** (10 / 9)
    assert F == pytest.approx(Z * Qmax * Jr, rel=5e-4)
    assert 0 < eps < 0.5
    # clearance softens: more deflection, higher peak roller load than at zero clearance
    zero = NeedleRollerBearing(rollers=Z, length=l).solve(F)
    assert dr > zero.u[0, 0] and sol.max_roller_load[0] > zero.max_roller_load[0]


def test_needle_bearing_any_direction_and_tangent_stiffness():
    brg = NeedleRollerBearing(rollers=17, length=8.0, clearance=0.003, phase=0.3)
    beta = 0.7
    sol = brg.solve(1500.0, direction=beta)
    Q = sol.roller_load[0]
    psi = brg.azimuths
    np.testing.assert_allclose([Q @ np.cos(psi), Q @ np.sin(psi)], 1500.0 * np.array([np.cos(beta), np.sin(beta)]),
                               rtol=1e-9)
    # tangent stiffness against a finite difference of the solution
    h = 1e-3
    up = brg.solve(1500.0 + h, direction=beta).u[0]
    dn = brg.solve(1500.0 - h, direction=beta).u[0]
    du = (up - dn) / (2 * h)
    np.testing.assert_allclose(sol.stiffness[0] @ du, [np.cos(beta), np.sin(beta)], rtol=1e-5, atol=1e-5)


def test_tapered_roller_statics_force_balance():
    ao, ai = math.radians(14.0), math.radians(10.0)
    for bf in (None, math.radians(11.0), math.radians(13.0)):
        rho, fr = rb.tapered_force_ratios(ao, ai, bf)
        b = 0.5 * (ao + ai) if bf is None else bf
        # forces on the roller (axial, radial): cup, cone, rib; solve the 2×2 balance independently
        A = np.array([[math.sin(ai), math.cos(b)], [math.cos(ai), -math.sin(b)]])
        Qi, Qf = np.linalg.solve(A, [math.sin(ao), math.cos(ao)])
        assert rho == pytest.approx(Qi, rel=1e-12) and fr == pytest.approx(Qf, rel=1e-12)
    rho, fr = rb.tapered_force_ratios(ao, ai)
    assert rho == pytest.approx(1.0, rel=1e-12)        # rib normal along the roller axis: Q_i = Q_o
    assert fr == pytest.approx(math.sin(ao - ai) / math.cos(0.5 * (ao - ai)), rel=1e-12)


def _independent_wrench(pair, sol):
    """Sum of roller force vectors and their moments about the origin, from 3-D geometry."""
    total = np.zeros(5)
    for j, (brg, z, s) in enumerate(zip((pair.bearing_a, pair.bearing_b), pair.positions, pair.signs)):
        R, a = 0.5 * brg.pitch_diameter, brg.alpha
        for Q, psi in zip(sol.roller_load[0, j], brg.azimuths):
            n = np.array([-math.cos(a) * math.cos(psi), -math.cos(a) * math.sin(psi), s * math.sin(a)])
            p = np.array([R * math.cos(psi), R * math.sin(psi), z])
            F = Q * n                                       # force of the roller on the shaft
            M = np.cross(p, F)
            total += np.array([F[0], F[1], F[2], M[0], M[1]])
    return total


@pytest.mark.parametrize("arrangement", ["X", "O"])
def test_pair_equilibrium_checked_with_independent_3d_force_balance(arrangement):
    pair = BearingPair(TRB, TRB, (0.0, 38.0), arrangement, interference=0.004)
    f = np.array([2500.0, -1200.0, 300.0, 8000.0, -20000.0])
    sol = pair.solve(f)
    # the bearings push the shaft with -f
    np.testing.assert_allclose(_independent_wrench(pair, sol), -f, rtol=1e-9, atol=1e-7)
    np.testing.assert_allclose(sol.bearing_force[0].sum(axis=0), -f, rtol=1e-9, atol=1e-7)


def test_pair_tangent_stiffness_matches_finite_differences():
    pair = BearingPair(TRB, TRB, (0.0, 38.0), "X", interference=0.003)
    f = np.array([3000.0, 500.0, 0.0, 0.0, 40000.0])
    K = pair.solve(f).stiffness[0]
    h = np.array([1.0, 1.0, 1.0, 10.0, 10.0])
    cols = []
    for i in range(5):
        e = np.zeros(5)
        e[i] = h[i]
        cols.append((pair.solve(f + e).q[0] - pair.solve(f - e).q[0]) / (2 * h[i]))
    C = np.column_stack(cols)
    np.testing.assert_allclose(K @ C, np.eye(5), atol=2e-5)


def test_pair_axial_preload_closed_form_and_preload_loss():
    # pure axial load on an X pair of identical bearings (interference Δ): with x = u_z,
    # F_a = Z K sin α [((Δ/2 − x) sin α)^n − ((Δ/2 + x) sin α)^n], each term only while positive;
    # bearing B unloads at F_a = 2^n F_pre (line contact: 2.16 F_pre)
    n, a, Z, K = 10 / 9, TRB.alpha, TRB.rollers, TRB.K
    pair = BearingPair(TRB, TRB, (0.0, 38.0), "X").with_preload_force(800.0)
    D = pair.interference
    assert 800.0 == pytest.approx(Z * K * (0.5 * D * math.sin(a)) ** n * math.sin(a), rel=1e-10)

    def Fa(x):
        A = max((0.5 * D - x) * math.sin(a), 0.0)
        B = max((0.5 * D + x) * math.sin(a), 0.0)
        return Z * K * math.sin(a) * (A ** n - B ** n)

    for load in (300.0, 1200.0, 2 ** n * 800.0, 2500.0):
        x = brentq(lambda x, load=load: Fa(x) + load, -D, 10 * D)   # bearing A pushes +z: load along -z
        sol = pair.solve(np.array([0.0, 0.0, -load, 0.0, 0.0]))
        assert sol.q[0, 2] == pytest.approx(-x, rel=1e-8, abs=1e-12)
    lost = pair.solve(np.array([0.0, 0.0, -2 ** n * 800.0, 0.0, 0.0]))
    assert lost.axial_force(1, a)[0] == pytest.approx(0.0, abs=1e-6)


def test_pair_symmetry():
    pair = BearingPair(TRB, TRB, (0.0, 38.0), "X", interference=0.002)
    s1 = pair.solve(np.array([3000.0, 0.0, 0.0, 0.0, 3000.0 * 19.0]))   # radial force at mid-span
    assert abs(s1.q[0, 2]) < 1e-12 and abs(s1.q[0, 4]) < 1e-12
    np.testing.assert_allclose(s1.roller_load[0, 0], s1.roller_load[0, 1], rtol=1e-9)
    # the same force along y: same magnitude of deflection (roller positions differ by the rotation only
    # when Z is a multiple of 4)
    s2 = pair.solve(np.array([0.0, 3000.0, 0.0, -3000.0 * 19.0, 0.0]))
    assert s2.q[0, 1] == pytest.approx(s1.q[0, 0], rel=1e-9)


def test_preload_stiffens_and_linearises_small_loads():
    z = 19.0
    F = np.array([20.0, 200.0, 2000.0])
    bare = BearingPair(TRB, TRB, (0.0, 38.0), "X")
    pre = bare.with_preload_force(1000.0)
    kb = bare.radial_stiffness(F, z)
    kp = pre.radial_stiffness(F, z)
    assert np.all(kp > kb)
    assert kp[0] > 1.5 * kb[0]
    # nonlinearity: stiffness change over two decades of load is much smaller with preload
    assert kp.max() / kp.min() < 1.1 < kb.max() / kb.min()
    # zero preload and zero clearance: radial stiffness grows like F^(1/10) (Q ∝ δ^(10/9), similar distribution)
    assert kb[1] / kb[0] == pytest.approx(10 ** 0.1, rel=1e-6)
    # secant ≥ tangent⁻¹ ordering for a stiffening law (secant is softer than tangent)
    ks = bare.radial_stiffness(F, z, kind="secant")
    np.testing.assert_array_less(ks, kb)
    # end play softens further than zero clearance
    loose = BearingPair(TRB, TRB, (0.0, 38.0), "X", interference=-0.01)
    assert loose.radial_stiffness(200.0, z, "secant")[0] < ks[1]


def test_o_arrangement_is_stiffer_in_tilt_than_x():
    M = np.array([0.0, 0.0, 0.0, 0.0, 30000.0])
    x = BearingPair(TRB, TRB, (0.0, 38.0), "X", interference=0.004).solve(M).q[0, 4]
    o = BearingPair(TRB, TRB, (0.0, 38.0), "O", interference=0.004).solve(M).q[0, 4]
    assert 0 < o < x


def test_bad_input():
    with pytest.raises(SpecError, match="whole number"):
        TaperedRollerBearing(rollers=15.5, alpha=0.2, length=10.0, pitch_diameter=31.0)
    with pytest.raises(SpecError, match="angle"):
        TaperedRollerBearing(rollers=15, alpha=2.0, length=10.0, pitch_diameter=31.0)
    with pytest.raises(SpecError, match="'X'"):
        BearingPair(TRB, TRB, (0.0, 38.0), "Y")
    with pytest.raises(SpecError, match="z_A < z_B"):
        BearingPair(TRB, TRB, (38.0, 0.0))
    with pytest.raises(SpecError, match="5 components"):
        BearingPair(TRB, TRB, (0.0, 38.0)).solve(np.zeros(3))
    with pytest.raises(ValueError):
        NeedleRollerBearing(rollers=18, length=-8.0)


@pytest.mark.parametrize("length", [8.0, 9.0, 10.0, 12.0])
def test_needle_row_converges_below_the_energy_rounding(length):
    """Issue 39 item 5: an 8-mm needle row did not build (the 20-DOF chain tabulates the row over a load sequence,
    each solve warm-started from the last). Armijo's test on the potential energy stalls once a step's decrease is
    below Π's rounding: the residual stopped near 1e-7 N, above the 1e-10 × load the solver asks. Checked against
    the roller statics solved independently: the load on the ψ = 0 axis of 18 rollers (symmetric, one unknown)."""
    from rvtol.models.reducer_20dof.compliance import _knots

    brg = NeedleRollerBearing(rollers=18, length=length)
    f = _knots(1528.69311904)       # the chain's load sequence for the product's row at rated (8-mm design)
    sol = brg.solve(f)
    c, K = np.cos(brg.azimuths), brg.K
    for F, u in zip(f[1:], sol.u[1:]):
        ux = brentq(lambda x: K * np.sum(np.maximum(x * c, 0.0) ** (10 / 9) * c) - F, 0.0, 1.0, xtol=1e-16,
                    rtol=1e-14)
        assert u[0] == pytest.approx(ux, rel=1e-9)
        assert abs(u[1]) < 1e-12
        Q = sol.roller_load[list(f).index(F)]         # the solver's criterion: residual ≤ 1e-10 max(F, ΣQ)
        assert np.hypot(Q @ c - F, Q @ np.sin(brg.azimuths)) <= 1e-10 * np.sqrt(2) * max(F, Q.sum())


def test_step_acceptance_reads_the_slope_only_below_the_energy_rounding():
    """Hager–Zhang's approximate Wolfe conditions apply only where Π's change is within its rounding error; above
    it a step must decrease Π (Armijo)."""
    slope = -1.0
    assert rb._step_accepted(0.0, -1e-3, slope, -0.5, 1.0, 1e-12)            # Armijo
    assert not rb._step_accepted(0.0, 1e-6, slope, 0.0, 1.0, 1e-12)          # an increase Π resolves
    assert rb._step_accepted(0.0, 1e-13, slope, 0.0, 1.0, 1e-12)             # below rounding: the slope decides
    assert not rb._step_accepted(0.0, 1e-13, slope, -0.95, 1.0, 1e-12)       # the slope barely changed: too short
    assert not rb._step_accepted(0.0, 1e-13, slope, 0.99999, 1.0, 1e-12)    # overshot to the other side
    assert rb._energy_rounding(2.0, 18) == pytest.approx(19 * np.finfo(float).eps * 2.0)
