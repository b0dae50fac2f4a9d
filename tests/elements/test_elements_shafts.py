"""rvtol.elements.shafts against Roark/Euler–Bernoulli closed forms, the Timoshenko shear term, an
independent Timoshenko finite-element model (exact for nodal loads) and Saint-Venant torsion."""
import math

import numpy as np
import pytest

from rvtol.elements import shafts
from rvtol.elements.shafts import SteppedShaft, circle_section, cowper_circle
from rvtol.errors import SpecError

E, NU = 206000.0, 0.3
G = E / (2 * (1 + NU))


def test_cowper_coefficients():
    assert cowper_circle(0.3) == pytest.approx(6 * 1.3 / (7 + 1.8), rel=1e-15)        # 0.886
    # thin-walled tube limit of Cowper's formula: 2(1+ν)/(4+3ν)
    assert cowper_circle(0.3, 1.0, 1.0 - 1e-9) == pytest.approx(2 * 1.3 / (4 + 0.9), rel=1e-8)
    A, I, J = circle_section(20.0, 10.0)
    assert A == pytest.approx(math.pi * (400 - 100) / 4, rel=1e-15)
    assert I == pytest.approx(math.pi * (20 ** 4 - 10 ** 4) / 64, rel=1e-15)
    assert J == pytest.approx(2 * I, rel=1e-15)
    with pytest.raises(SpecError):
        circle_section(10.0, 12.0)


def test_midspan_load_euler_bernoulli_plus_timoshenko_shear():
    L, d, P = 38.0, 22.0, 1.0
    s = SteppedShaft.uniform(L, d, E, NU)
    A, I, _ = circle_section(d)
    k = cowper_circle(NU)
    got = s.flexibility([L / 2], supports=(0, L))[0, 0]
    assert got == pytest.approx(P * L ** 3 / (48 * E * I) + P * L / (4 * k * G * A), rel=1e-13)
    eb = SteppedShaft.uniform(L, d, E, NU, shear=False).flexibility([L / 2], supports=(0, L))[0, 0]
    assert eb == pytest.approx(L ** 3 / (48 * E * I), rel=1e-13)


def test_off_centre_load_roark_table_8_1():
    # Roark 7th ed. Table 8.1 case 1e (simply supported, load W at a from the left end, b = L - a):
    # y(x) = W b x (L² - b² - x²) / (6 E I L) for x <= a; shear part W b x / (κ G A L)
    L, d, a = 60.0, 20.0, 15.0
    b = L - a
    s = SteppedShaft.uniform(L, d, E, NU)
    A, I, _ = circle_section(d)
    k = cowper_circle(NU)
    x = 7.0
    C = s.flexibility([x, a], supports=(0, L))
    assert C[0, 1] == pytest.approx(b * x * (L ** 2 - b ** 2 - x ** 2) / (6 * E * I * L) + b * x / (k * G * A * L),
                                    rel=1e-13)
    assert C[1, 1] == pytest.approx(a ** 2 * b ** 2 / (3 * E * I * L) + a * b / (k * G * A * L), rel=1e-13)
    # section rotation at the left support under the load: Roark's θ_A = W a b (2L - a)/(6 E I L) with no
    # shear term — E I φ' = M as in Euler–Bernoulli, and the shear strain integrates to M(L) - M(0) = 0
    # over the span, so the simply supported section rotation is the Euler–Bernoulli one
    C = s.flexibility([0.0, a], ["moment", "force"], supports=(0, L))
    bend = a * b * (2 * L - a) / (6 * E * I * L)
    # sign: a load along +w makes dw/dz > 0 at the left support
    assert C[0, 1] == pytest.approx(bend, rel=1e-13)
    assert C[0, 1] == pytest.approx(C[1, 0], rel=1e-15)                     # Maxwell–Betti


def test_overhang_tip_load_and_elastic_supports():
    # load P at the tip of an overhang c beyond support B of a span L (Roark Table 8.1, overhang case):
    # y_tip = P c² (L + c) / (3 E I); shear: P c (L + c) / (κ G A L); springs: rigid-body part
    L, c, d = 40.0, 12.0, 18.0
    s = SteppedShaft.uniform(L + c, d, E, NU)
    A, I, _ = circle_section(d)
    k = cowper_circle(NU)
    rigid = s.flexibility([L + c], supports=(0, L))[0, 0]
    assert rigid == pytest.approx(c * c * (L + c) / (3 * E * I) + c * (L + c) / (k * G * A * L), rel=1e-13)
    kA, kB = 2.0e5, 5.0e5
    el = s.flexibility([L + c], supports=(0, L), support_stiffness=(kA, kB))[0, 0]
    RA, RB = c / L, (L + c) / L                                                   # reaction magnitudes
    assert el - rigid == pytest.approx(RA ** 2 / kA + RB ** 2 / kB, rel=1e-12)


def _timoshenko_fe(stations, do, di, supports, kS, nodes_extra):
    """Independent reference: Timoshenko beam elements (exact stiffness for nodal loads,
    Przemieniecki, Theory of Matrix Structural Analysis, §5.6), supports as springs or constraints."""
    x = np.unique(np.concatenate([stations, supports, nodes_extra]))
    n = len(x)
    K = np.zeros((2 * n, 2 * n))
    st = np.asarray(stations)
    for e in range(n - 1):
        L = x[e + 1] - x[e]
        seg = min(max(np.searchsorted(st, 0.5 * (x[e] + x[e + 1])) - 1, 0), len(do) - 1)
        A, I, _ = circle_section(do[seg], di[seg])
        kap = cowper_circle(NU, do[seg], di[seg])
        phi = 12 * E * I / (kap * G * A * L * L)
        k = E * I / ((1 + phi) * L ** 3) * np.array([
            [12, 6 * L, -12, 6 * L],
            [6 * L, (4 + phi) * L * L, -6 * L, (2 - phi) * L * L],
            [-12, -6 * L, 12, -6 * L],
            [6 * L, (2 - phi) * L * L, -6 * L, (4 + phi) * L * L]])
        idx = [2 * e, 2 * e + 1, 2 * e + 2, 2 * e + 3]
        K[np.ix_(idx, idx)] += k
    fixed = []
    for zs, ks in zip(supports, kS):
        i = int(np.flatnonzero(np.isclose(x, zs))[0])
        if np.isfinite(ks):
            K[2 * i, 2 * i] += ks
        else:
            fixed.append(2 * i)
    free = [i for i in range(2 * n) if i not in fixed]
    return x, K, free


def test_stepped_hollow_shaft_against_timoshenko_finite_elements():
    # crank-like shaft: journal Ø20 | eccentric Ø26 | eccentric Ø26 | journal Ø20 | gear seat hollow Ø24/10
    stations = [-10.0, 0.0, 7.0, 19.0, 31.0, 38.0]
    do = [24.0, 20.0, 26.0, 26.0, 20.0]
    di = [10.0, 0.0, 0.0, 0.0, 0.0]
    s = SteppedShaft(tuple(stations), tuple(do), tuple(di), E, NU)
    pts = np.array([-10.0, 13.5, 24.5, 13.5, 38.0])
    kinds = ["force", "force", "force", "moment", "moment"]
    for kS in ((np.inf, np.inf), (3.0e5, 8.0e5)):
        C = s.flexibility(pts, kinds, supports=(0.0, 38.0), support_stiffness=kS)
        np.testing.assert_allclose(C, C.T, rtol=1e-12, atol=0)               # Maxwell–Betti
        x, K, free = _timoshenko_fe(stations, do, di, (0.0, 38.0), kS, pts)
        dof = [2 * int(np.flatnonzero(np.isclose(x, p))[0]) + (k == "moment") for p, k in zip(pts, kinds)]
        Kf = K[np.ix_(free, free)]
        for j, dj in enumerate(dof):
            f = np.zeros(K.shape[0])
            f[dj] = 1.0
            u = np.zeros(K.shape[0])
            u[free] = np.linalg.solve(Kf, f[free])
            np.testing.assert_allclose(C[:, j], u[dof], rtol=1e-9, atol=1e-9 * np.abs(u[dof]).max())


def test_reactions_balance_the_loads():
    s = SteppedShaft.uniform(50.0, 20.0, E, NU, start=-10.0)
    pts, loads, kinds = [-10.0, 12.0, 30.0], [100.0, -300.0, 5000.0], ["force", "force", "moment"]
    RA, RB = s.reactions(pts, loads, kinds, supports=(0.0, 38.0))
    assert RA + RB + 100.0 - 300.0 == pytest.approx(0.0, abs=1e-10)
    # moment about z_A (a couple conjugate to +dw/dz counts +C, cf. the module's sign convention)
    assert RB * 38.0 + 100.0 * (-10.0) - 300.0 * 12.0 + 5000.0 == pytest.approx(0.0, abs=1e-9)


def test_torsion_of_stepped_shaft():
    T = 4.8e3
    th = shafts.twist([T, T, 0.5 * T], [10.0, 12.0, 8.0], [20.0, 26.0, 24.0], [0.0, 0.0, 10.0], G=G)
    J = [math.pi * 20 ** 4 / 32, math.pi * 26 ** 4 / 32, math.pi * (24 ** 4 - 10 ** 4) / 32]
    assert th == pytest.approx(T * 10 / (G * J[0]) + T * 12 / (G * J[1]) + 0.5 * T * 8 / (G * J[2]), rel=1e-14)
    s = SteppedShaft((-10.0, 0.0, 7.0, 31.0, 38.0), (24.0, 20.0, 26.0, 20.0), (10.0, 0.0, 0.0, 0.0), E, NU)
    c = s.torsional_compliance(-5.0, 13.5)
    assert c == pytest.approx(5.0 / (G * J[2]) + 7.0 / (G * J[0]) + 6.5 / (G * J[1]), rel=1e-14)
    assert s.torsional_compliance(13.5, -5.0) == c


def test_bad_input():
    with pytest.raises(SpecError, match="increasing"):
        SteppedShaft((0.0, 0.0), (10.0,), (0.0,), E, NU)
    s = SteppedShaft.uniform(10.0, 10.0, E, NU)
    with pytest.raises(SpecError, match="on the shaft"):
        s.flexibility([11.0], supports=(0.0, 10.0))
    with pytest.raises(SpecError, match="z_A < z_B"):
        s.flexibility([5.0], supports=(10.0, 0.0))
    with pytest.raises(ValueError):
        s.flexibility([5.0], ["torque"], supports=(0.0, 10.0))
    with pytest.raises(SpecError, match="Poisson"):
        SteppedShaft.uniform(10.0, 10.0, E, 0.5)


def test_uniform_shaft_reproduces_the_existing_crankshaft_influence_matrix():
    from rvtol.elements import crankshaft as old
    z = np.array([-10.0, 13.5, 24.5])
    s = SteppedShaft.uniform(48.0, 22.0, E, NU, start=-10.0)
    np.testing.assert_allclose(s.flexibility(z, supports=(0.0, 38.0)), old.influence_matrix(z, 38.0, 22.0, E, NU),
                               rtol=1e-9)
    assert s.torsional_compliance(0.0, 1.0) == pytest.approx(old.torsional_compliance(22.0, E, NU), rel=1e-14)
