"""The plane-stress finite-element elements (rvtol.elements.plane_fe, fe_seats) and the conforming pin-in-groove
contact (rvtol.elements.pin_groove), each against a closed form or a mesh-convergence study."""
import math

import numpy as np
import pytest

from rvtol.elements import disc_web, fe_seats, pin_groove
from rvtol.elements import plane_fe as P
from rvtol.errors import SpecError

E, NU = 206000.0, 0.3
G = E / (2 * (1 + NU))


def test_thick_ring_under_internal_pressure_is_lame():
    """Lamé, plane stress: u(r_i) = p r_i/E [(r_o² + r_i²)/(r_o² − r_i²) + ν]; the work of a uniform pressure
    (self-equilibrated) is 2π r_i t p u(r_i).  Error falls with the mesh (O(h²) of the polygonal boundary)."""
    ri, ro, t, p = 20.0, 50.0, 10.0, 100.0
    exact = p * ri / E * ((ro ** 2 + ri ** 2) / (ro ** 2 - ri ** 2) + NU)
    err = []
    for n in (2, 4):
        sol = P.solve_plane_stress(P.annulus_mesh(ri, ro, n, 12 * n), E, NU, t,
                                   [P.Traction(P.Circle(0, 0, ri), radial=lambda s: p + 0 * s)])
        err.append(abs(sol.work / (2 * math.pi * ri * t * p * exact) - 1))
    assert err[1] < 3e-3 and err[1] < 0.25 * err[0]


def test_perforated_mesh_reproduces_the_annular_web_in_torsion():
    """Torque T by uniform shear on the bore and the rim of the Delaunay mesh: work T²/K_web with
    K_web = 4πGt/(1/r_i² − 1/r_o²) (Timoshenko & Goodier ch. 4, rvtol.elements.disc_web)."""
    ri, ro, t, T = 20.0, 72.0, 12.0, 1e6
    m = P.perforated_disc_mesh(ro, [], bore=ri, h=4.0, h_fine=1.0)
    sol = P.solve_plane_stress(m, E, NU, t, [
        P.Traction(P.Circle(0, 0, ri), tangential=lambda s: -T / (2 * math.pi * ri ** 2 * t) + 0 * s),
        P.Traction(P.Circle(0, 0, ro), tangential=lambda s: T / (2 * math.pi * ro ** 2 * t) + 0 * s)])
    assert sol.work == pytest.approx(T ** 2 / disc_web.annular_web_stiffness(ri, ro, t, G), rel=1e-3)


def test_arc_and_patch_loads_have_their_resultant():
    """The assembled load vector of an arc load (cos^(10/9) over ±90°) and of a patch load sums to the force."""
    m = P.perforated_disc_mesh(30.0, [(10.0, 0.0, 5.0)], h=3.0, h_fine=0.6)
    model = P.PlateModel(m, E, NU, 8.0, fixed=lambda x: np.hypot(*x) > 29.0)
    R = P.rigid_modes(model.basis)
    for ld, F in ((P.arc_load(P.Circle(10.0, 0.0, 5.0), (300.0, -400.0), 8.0), (300.0, -400.0)),
                  (P.patch_load(P.Circle(0.0, 0.0, 30.0), 1.0, (-200.0, 50.0), 8.0, 0.3), (-200.0, 50.0))):
        f = model.load_vector([ld])
        np.testing.assert_allclose(R[:, :2].T @ f, F, rtol=2e-3)


def test_pin_forces_carry_the_disc_torque():
    phi, F = fe_seats.pin_forces(1e5, 40, 39, 76.5, 1.5, 0.3)
    centre = 1.5 * np.array([math.cos(0.3), math.sin(0.3)])
    r = 76.5 * np.vstack([np.cos(phi), np.sin(phi)]).T - centre
    assert np.sum(r[:, 0] * F[:, 1] - r[:, 1] * F[:, 0]) == pytest.approx(1e5, rel=1e-12)
    assert np.count_nonzero(np.hypot(*F.T)) == 20                   # the loaded half


def test_disc_seat_element_converges_with_the_mesh():
    """Mesh convergence of the RV-80E disc (work at rated, one crank angle): the default mesh within 0.5 %
    of a twice finer one; the finite-element disc stores more than its axisymmetric web (a lower bound)."""
    kw = dict(r_root=72.0, bore=40.0, crank_radius=41.937, crank_hole=34.0, pillar_radius=42.0, pillar_hole=28.0,
              thickness=12.0, z_p=40, z_c=39, R_p=76.5, ecc=1.5, E=E, nu=NU, angles=1)
    Tc = 784e3 * (1 - 1 / 81) * 39 / 40 / 2
    coarse = fe_seats.disc_work(Tc, **kw)
    fine = fe_seats.disc_work(Tc, h=2.0, h_fine=0.4, **kw)
    assert coarse.work[0] == pytest.approx(fine.work[0], rel=5e-3)
    K_web = disc_web.annular_web_stiffness(41.937 + 17.0, 72.0, 12.0, G)
    assert fe_seats.disc_seat_compliance(coarse, Tc, K_web) > 0


def test_housing_ring_converges_and_refuses_a_clamp_inside_the_grooves():
    kw = dict(thickness=24.0, z_p=40, z_c=39, R_p=76.5, ecc=1.5, E=E, nu=NU, angles=1)
    a = fe_seats.housing_ring_work(3e5, r_inner=82.5, r_outer=90.0, n_r=4, per_pitch=4, **kw)
    b = fe_seats.housing_ring_work(3e5, r_inner=82.5, r_outer=90.0, n_r=8, per_pitch=8, **kw)
    assert a.compliance == pytest.approx(b.compliance, rel=1e-2)
    with pytest.raises(SpecError, match="clamp radius"):
        fe_seats.housing_ring_work(3e5, r_inner=82.5, r_outer=80.0, **kw)


# ---------------------------------------------------------------------------------------------- conforming contact
@pytest.mark.parametrize("n", [0, 2, 3])
def test_fourier_kernels_against_finite_elements(n):
    """The disk's and the hole's boundary displacement under p cos nθ (plane strain) against scikit-fem: a disk,
    and an annulus clamped at 40 a with radially graded elements (n ≥ 2: the hole's field decays, measured
    0.3 % from the infinite plate at 40 a, 0.08 % at 80 a; n = 0: Lamé's annulus clamped outside,
    u(a) = B (1/a − a/r_o²), B = p / (2μ/a² + 2(λ+μ)/r_o²))."""
    a, p, ro = 3.0, 10.0, 120.0
    Eps, nups = E / (1 - NU ** 2), NU / (1 - NU)          # plane strain as plane stress
    disk = P.PlateModel(P.perforated_disc_mesh(a, [], h=0.25, h_fine=0.25), Eps, nups, 1.0)
    ring = P.PlateModel(P.annulus_mesh(a, ro, 48, 128, geometric=True), Eps, nups, 1.0,
                        fixed=lambda x: np.hypot(*x) > 0.5 * (a + ro))
    hole = P.Circle(0, 0, a)
    arc = 2 * math.pi * a * p if n == 0 else math.pi * a * p     # work = arc × amplitude of u_r
    u_disk = disk.solve([P.Traction(hole, radial=lambda s: -p * np.cos(n * s))]).work / arc
    u_hole = ring.solve([P.Traction(hole, radial=lambda s: p * np.cos(n * s))]).work / arc
    assert u_disk == pytest.approx(p * pin_groove.kernel_pin(n, a, G, NU), rel=1e-3)
    if n == 0:
        B = p / (2 * G / a ** 2 + 2 * G / (1 - 2 * NU) / ro ** 2)
        assert u_hole == pytest.approx(B * (1 / a - a / ro ** 2), rel=1e-3)
        assert p * pin_groove.kernel_hole(0, a, G, NU) == pytest.approx(B * (1 / a - a / ro ** 2), rel=3e-3)
    else:
        assert u_hole == pytest.approx(p * pin_groove.kernel_hole(n, a, G, NU), rel=5e-3)


def test_conforming_contact_has_hertz_limit_and_a_load_free_neat_fit_angle():
    """Small load: the contact half-angle is Hertz's a/r (Johnson 1985 ch. 4); the conformity correction to doc
    004's approach vanishes in Hertz's range and lowers the approach of the tight product groove (−5 % at
    1 kN over 12 mm).  Neat fit (ΔR = 0): no length scale, so the angle does not depend on the load nor on ν
    (the kernels are ∝ (κ+1)/G)."""
    m = pin_groove.PinInHole(3.0, 0.002, E, NU, nodes=241, modes=2000)
    hz = pin_groove.half_width(10.0, 12.0, 3.0, -3.002, E, NU) / 3.0
    assert m.solve(10.0 / 12.0).angle == pytest.approx(hz, rel=0.02)
    corr = pin_groove.conforming_correction(np.array([5.0, 1000.0]), 12.0, 3.0, 3.002, E, NU)
    hertz = pin_groove.groove_approach(np.array([5.0, 1000.0]), 12.0, 3.0, 3.002, E, NU)
    assert corr[0] == 0.0
    assert -0.10 < corr[1] / hertz[1] < -0.02
    angles = [pin_groove.PinInHole(3.0, 0.0, E, nu, nodes=161, modes=1200).solve(P_).angle
              for nu, P_ in ((0.3, 1.0), (0.3, 300.0), (0.45, 30.0))]
    assert max(angles) - min(angles) < 1e-6
    assert 1.3 < angles[0] < 0.5 * math.pi


def test_tabulated_needle_row_is_palmgren_and_softer_than_doc_000_law_only_by_its_distribution():
    """The needle row of the product by Palmgren (rvtol.elements.rolling_bearings) at 1 kN: the Stribeck
    closed form Q_max = 4.08 F/Z (zero clearance) with 7.68e-5 Q^0.9/l^0.8 per roller, within the tabulation;
    doc 000's k0 P^0.1 law deflects 1.6× more (the review's finding)."""
    from rvtol.elements.rolling_bearings import NeedleRollerBearing

    nb = NeedleRollerBearing(18, 10.0)
    u = float(np.hypot(*nb.solve(1000.0).u[0]))
    stribeck = 7.68e-5 * (4.08 * 1000.0 / 18) ** 0.9 / 10.0 ** 0.8
    assert u == pytest.approx(stribeck, rel=0.01)
    doc000 = 1000.0 ** 0.9 / 1.93e5                           # k = k0 P^0.1: δ = P^0.9/k0
    assert doc000 / u == pytest.approx(1.6, abs=0.05)


def test_linearised_dimension_model_predicts_a_resolved_element():
    """The linearised model of a per-sample dimension (``fe_seats.log_sensitivity``: c (1 + s Δx/x)) against
    the element solved again at the changed dimension: within the quadratic remainder at 1 % (the ring's
    compliance grows about as the 10th power of its clamp radius: a 7.5-mm wall)."""
    kw = dict(thickness=24.0, z_p=40, z_c=39, R_p=76.5, ecc=1.5, E=E, nu=NU, angles=1, n_r=4, per_pitch=4)

    def c(r_outer):
        return fe_seats.housing_ring_work(3e5, r_inner=82.5, r_outer=r_outer, **kw).compliance

    s = fe_seats.log_sensitivity(c, {"r_outer": 90.0}, ["r_outer"])["r_outer"]
    assert s > 0                                        # a wider wall is softer in this clamped ring
    # the linear prediction misses by the second-order term s(s − 1)/2 (Δx/x)² of c ∝ x^s
    assert abs(c(90.9) / c(90.0) - (1 + 0.01 * s)) < 0.5 * s * s * 1e-4
