"""rvtol.elements.carrier_structure: sections (closed forms), pillars (Roark fixed–guided, cantilever limit,
Timoshenko FE with end springs), rigid boss in a plate (ODE solved by scipy, Cartesian energy, strip limit)."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_bvp

from rvtol.elements import carrier_structure as cs
from rvtol.errors import SpecError

from rvtol.elements import carrier as old_carrier

E, NU = 206000.0, 0.3
G = E / (2 * (1 + NU))


def test_sections():
    r = cs.rectangle(20.0, 14.0, NU)
    assert r.area == 280.0 and r.inertia == pytest.approx(14 * 20 ** 3 / 12, rel=1e-15)
    assert r.kappa == pytest.approx(10 * 1.3 / (12 + 3.3), rel=1e-15)
    p = cs.polygon([(0, 0), (20, 0), (20, 14), (0, 14)], NU)
    assert p.area == pytest.approx(280.0, rel=1e-14) and p.inertia == pytest.approx(r.inertia, rel=1e-14)
    # isosceles triangle, base w along x: I about the vertical centroidal axis = h w³ / 48
    t = cs.polygon([(0, 0), (12, 0), (6, 9)], NU)
    assert t.inertia == pytest.approx(9 * 12 ** 3 / 48, rel=1e-13)
    # a fine polygon of a circle (clockwise on purpose)
    phi = -np.linspace(0, 2 * np.pi, 4000, endpoint=False)
    c = cs.polygon(np.column_stack([5 * np.cos(phi), 5 * np.sin(phi)]), NU)
    assert c.inertia == pytest.approx(math.pi * 10 ** 4 / 64, rel=1e-5)
    # torsion constant of a square of side s: 0.1406 s⁴ (exact series value 0.140577)
    assert cs.rectangle(10.0, 10.0, NU).torsion == pytest.approx(0.140577 * 1e4, rel=2e-3)
    # thin strip: J → w t³ / 3
    assert cs.rectangle(100.0, 1.0, NU).torsion == pytest.approx(100 / 3 * (1 - 0.63 / 100), rel=1e-3)
    assert cs.circle(10.0, NU).torsion == pytest.approx(math.pi * 1e4 / 32, rel=1e-15)
    with pytest.raises(SpecError):
        cs.polygon([(0, 0), (1, 1), (2, 2)], NU)


def test_pillar_rigid_flanges_roark_fixed_guided_and_existing_carrier_model():
    sec = cs.rectangle(20.0, 14.0, NU)
    h = 24.0
    c = cs.pillar_compliance(sec, h, E, NU)
    assert c == pytest.approx(h ** 3 / (12 * E * sec.inertia) + h / (sec.kappa * G * sec.area), rel=1e-14)
    # same as rvtol.elements.carrier with its κ = 5/6
    s56 = cs.Section(sec.area, sec.inertia, 5 / 6)
    assert cs.pillar_stiffness(s56, h, E, NU) == pytest.approx(old_carrier.pillar_stiffness(20.0, 14.0, h, E, NU),
                                                               rel=1e-14)
    # equal end springs: + h²/(2k)
    k = 3.0e9
    assert cs.pillar_compliance(sec, h, E, NU, (k, k)) == pytest.approx(c + h * h / (2 * k), rel=1e-13)
    # one end free to rotate (k2 → 0): a cantilever
    canti = cs.pillar_compliance(sec, h, E, NU, (math.inf, 1e-9))
    assert canti == pytest.approx(h ** 3 / (3 * E * sec.inertia) + h / (sec.kappa * G * sec.area), rel=1e-9)


def test_pillar_unequal_end_springs_against_timoshenko_fe():
    sec = cs.rectangle(18.0, 12.0, NU)
    h, k1, k2 = 30.0, 1.5e9, 6.0e8
    EI, kGA = E * sec.inertia, sec.kappa * G * sec.area
    phi = 12 * EI / (kGA * h * h)
    K = EI / ((1 + phi) * h ** 3) * np.array([
        [12, 6 * h, -12, 6 * h], [6 * h, (4 + phi) * h * h, -6 * h, (2 - phi) * h * h],
        [-12, -6 * h, 12, -6 * h], [6 * h, (2 - phi) * h * h, -6 * h, (4 + phi) * h * h]])
    K[1, 1] += k1
    K[3, 3] += k2
    free = [1, 2, 3]                                  # w1 = 0
    u = np.linalg.solve(K[np.ix_(free, free)], [0.0, 1.0, 0.0])
    assert cs.pillar_compliance(sec, h, E, NU, (k1, k2)) == pytest.approx(u[1], rel=1e-12)
    # symmetric in the two ends
    assert cs.pillar_compliance(sec, h, E, NU, (k2, k1)) == pytest.approx(u[1], rel=1e-12)


def _f(coef, r):
    A, B, C, D = coef
    return A * r ** 3 + B * r + C / r + D * r * np.log(r)


@pytest.mark.parametrize("edge", ["clamped", "simply_supported"])
def test_boss_plate_shape_against_scipy_bvp(edge):
    b, a = 9.0, 25.0
    coef = cs.boss_coefficients(b, a, NU, edge)

    # w = f cos θ, ∇⁴ w = 0 → L(L f) = 0 with L f = f'' + f'/r − f/r²; state y = (f, f', f'', f''')
    def rhs(r, y):
        f, f1, f2, f3 = y
        # expand L(Lf) = 0 for f'''' : f'''' = −2f'''/r + 3f''/r² − 3f'/r³ + 3f/r⁴
        return np.vstack([f1, f2, f3, -2 * f3 / r + 3 * f2 / r ** 2 - 3 * f1 / r ** 3 + 3 * f / r ** 4])

    def bc(ya, yb):
        out = [ya[0] - b, ya[1] - 1.0, yb[0]]
        out.append(yb[1] if edge == "clamped" else yb[2] + NU * (yb[1] / a - yb[0] / a ** 2))
        return np.array(out)

    r = np.linspace(b, a, 50)
    sol = solve_bvp(rhs, bc, r, np.vstack([b * (a - r) / (a - b), -np.ones_like(r) * b / (a - b),
                                           np.zeros_like(r), np.zeros_like(r)]), tol=1e-10, max_nodes=100000)
    assert sol.success
    rr = np.linspace(b, a, 17)
    np.testing.assert_allclose(sol.sol(rr)[0], _f(coef, rr), rtol=0, atol=1e-7 * b)


def test_boss_stiffness_equals_cartesian_bending_energy():
    # independent of the polar curvature formulas: w(x, y) = f(r) x / r, second derivatives by central
    # differences, U = D/2 ∫ [(w_xx + w_yy)² − 2(1−ν)(w_xx w_yy − w_xy²)] dA, k = 2U (ψ = 1)
    b, a, t = 9.0, 25.0, 12.0
    coef = cs.boss_coefficients(b, a, NU)
    D = E * t ** 3 / (12 * (1 - NU ** 2))

    def w(x, y):
        r = np.hypot(x, y)
        return _f(coef, r) * x / r

    xr, wr = np.polynomial.legendre.leggauss(80)
    r = 0.5 * (a - b) * xr + 0.5 * (a + b)
    wr = 0.5 * (a - b) * wr
    th = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    R, TH = np.meshgrid(r, th, indexing="ij")
    X, Y = R * np.cos(TH), R * np.sin(TH)
    h = 1e-3
    wxx = (w(X + h, Y) - 2 * w(X, Y) + w(X - h, Y)) / h ** 2
    wyy = (w(X, Y + h) - 2 * w(X, Y) + w(X, Y - h)) / h ** 2
    wxy = (w(X + h, Y + h) - w(X + h, Y - h) - w(X - h, Y + h) + w(X - h, Y - h)) / (4 * h * h)
    dens = (wxx + wyy) ** 2 - 2 * (1 - NU) * (wxx * wyy - wxy ** 2)
    U = 0.5 * D * np.sum(wr[:, None] * R * dens) * (2 * np.pi / len(th))
    assert cs.boss_rotational_stiffness(b, a, t, E, NU) == pytest.approx(2 * U, rel=1e-5)


def test_boss_narrow_annulus_is_a_clamped_strip():
    # a ≈ b + h, h ≪ b: each radial strip is a beam (rigidity D per unit length) of length h clamped at the
    # outer edge with end deflection ψ b cos θ and slope ψ cos θ: k = π D b (12 b² + 12 b h + 4 h²) / h³
    b, t = 10.0, 8.0
    D = E * t ** 3 / (12 * (1 - NU ** 2))
    for h in (1.0, 0.1):           # the plate's extra (hoop, twist) terms are O(h/b): ≈ 0.5 h/b
        k = cs.boss_rotational_stiffness(b, b + h, t, E, NU)
        strip = math.pi * D * b * (12 * b * b + 12 * b * h + 4 * h * h) / h ** 3
        assert 0 < k / strip - 1 < 0.6 * h / b
    with pytest.raises(SpecError, match="too narrow"):
        cs.boss_rotational_stiffness(b, b + 1e-3, t, E, NU)


def test_boss_monotonic_and_simply_supported_softer():
    ks = [cs.boss_rotational_stiffness(9.0, a, 12.0, E, NU) for a in (15.0, 20.0, 30.0)]
    assert ks[0] > ks[1] > ks[2]
    assert cs.boss_rotational_stiffness(9.0, 20.0, 12.0, E, NU, "simply_supported") < ks[1]
    # plate stiffness ∝ t³
    assert cs.boss_rotational_stiffness(9.0, 20.0, 6.0, E, NU) == pytest.approx(ks[1] / 8, rel=1e-12)
    with pytest.raises(SpecError, match="larger than the boss"):
        cs.boss_rotational_stiffness(9.0, 8.0, 12.0, E, NU)


def test_carrier_torsional_stiffness():
    sec = cs.rectangle(20.0, 14.0, NU)
    k = cs.pillar_stiffness(sec, 24.0, E, NU)
    assert cs.carrier_torsional_stiffness(3, 40.0, k) == pytest.approx(3 * k * 1600.0, rel=1e-15)
    K = cs.carrier_torsional_stiffness(3, 40.0, k, section=sec, length=24.0, G=G)
    assert K == pytest.approx(3 * (k * 1600.0 + G * sec.torsion / 24.0), rel=1e-15)
    with pytest.raises(SpecError):
        cs.carrier_torsional_stiffness(3, 40.0, k, section=sec)
