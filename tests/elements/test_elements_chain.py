"""rvtol.elements.chain: series/parallel, transforms, virtual-work breakdown on hand-solvable structures."""
import math

import numpy as np
import pytest
from scipy.optimize import root

from rvtol.elements import chain
from rvtol.errors import SpecError


def test_series_parallel_closed_forms():
    assert chain.series(2.0, 2.0) == pytest.approx(1.0, rel=1e-15)
    assert chain.series(3.0, math.inf) == pytest.approx(3.0, rel=1e-15)
    assert chain.parallel(2.0, 3.0, 0.0) == pytest.approx(5.0, rel=1e-15)
    k = chain.series(np.array([1.0, 2.0]), 4.0)
    np.testing.assert_allclose(k, [0.8, 4.0 / 3.0], rtol=1e-15)
    with pytest.raises(SpecError):
        chain.series(1.0, -1.0)
    with pytest.raises(ValueError):
        chain.parallel(1.0, float("nan"))


def test_radius_and_ratio_transforms():
    assert chain.torsional_from_translational(1000.0, 40.0) == pytest.approx(1.6e6, rel=1e-15)
    assert chain.translational_from_torsional(1.6e6, 40.0) == pytest.approx(1000.0, rel=1e-15)
    # an input shaft of stiffness K under T/i twists T/(i K); the output turns 1/i of it
    K, i, T = 5.0e6, 81.0, 7.84e5
    twist = (T / i) / K
    theta_out = twist / i
    assert T / chain.reflected_to_output(K, i) == pytest.approx(theta_out, rel=1e-14)
    # the same by virtual work: element torque T/i, element deformation = twist
    assert chain.virtual_work(T, T / i, twist) == pytest.approx(theta_out, rel=1e-14)
    assert chain.arcsec(math.pi / 648000.0) == pytest.approx(1.0, rel=1e-14)
    assert chain.arcsec(chain.output_angle(1.0, 1.0)) == pytest.approx(206264.806, rel=1e-8)


def test_breakdown_series_parallel_structure_sums_to_direct_solution():
    # ground --K1-- node φ --(k2 tangential at r)-- output θ ; ground --K3-- output θ ; torque T on θ
    K1, k2, r, K3, T = 3.0e7, 2.0e4, 35.0, 1.5e7, 7.84e5
    Kt = k2 * r * r
    S = np.array([[K1 + Kt, -Kt], [-Kt, Kt + K3]])
    phi, theta = np.linalg.solve(S, [0.0, T])
    # closed form of the chain
    K_chain = chain.parallel(chain.series(K1, chain.torsional_from_translational(k2, r)), K3)
    assert theta == pytest.approx(T / K_chain, rel=1e-12)
    M1, f2, M3 = K1 * phi, k2 * r * (theta - phi), K3 * theta
    bd = chain.Breakdown.from_contributions(T, {
        "K1": chain.linear_contribution(T, M1, K1),
        "k2": chain.linear_contribution(T, f2, k2),
        "K3": chain.linear_contribution(T, M3, K3)})
    assert bd.total[0] == pytest.approx(theta, rel=1e-12)
    assert bd.stiffness[0] == pytest.approx(K_chain, rel=1e-12)
    # the same from (force, deformation) pairs
    bd2 = chain.Breakdown.from_elements(T, {"K1": (M1, phi), "k2": (f2, r * (theta - phi)), "K3": (M3, theta)})
    np.testing.assert_allclose(bd2.theta, bd.theta, rtol=1e-12)
    df = bd.to_frame()
    assert df["share (%)"].iloc[:-1].sum() == pytest.approx(100.0, rel=1e-12)
    assert df["θ (arcsec)"].iloc[-1] == pytest.approx(chain.arcsec(theta), rel=1e-12)


# A rigid disc (x, y, rotation φ) held by three springs at points p_i acting along n_i (statically
# indeterminate), loaded by a torque T only.
P = np.array([[40.0, 0.0], [-20.0, 34.64], [-20.0, -34.64]])
N = np.array([[0.2, 1.0], [-0.9, -0.3], [0.8, -0.6]])
N = N / np.linalg.norm(N, axis=1, keepdims=True)
KS = np.array([1.0e4, 2.5e4, 0.6e4])


def _B():
    # spring elongation e_i = n_i · (u + φ ẑ × p_i) = B_i · (u_x, u_y, φ)
    return np.column_stack([N[:, 0], N[:, 1], N[:, 1] * P[:, 0] - N[:, 0] * P[:, 1]])


def test_breakdown_statically_indeterminate_linear_structure():
    B, T = _B(), 5.0e5
    S = B.T @ (KS[:, None] * B)
    q = np.linalg.solve(S, [0.0, 0.0, T])
    e = B @ q
    f = KS * e
    # equilibrium with the external torque (reactions of the springs on the disc are -f B)
    np.testing.assert_allclose(B.T @ f, [0.0, 0.0, T], rtol=0, atol=1e-7 * T)
    theta = chain.linear_contribution(T, f, KS)
    assert theta.sum() == pytest.approx(q[2], rel=1e-12)
    # vectorised over load cases: contributions scale with T (linear structure)
    Ts = np.array([1.0e5, -2.0e5])
    qs = np.linalg.solve(S, np.stack([np.zeros(2), np.zeros(2), Ts]))
    fs = KS[None, :] * (B @ qs).T
    np.testing.assert_allclose(chain.virtual_work(Ts, fs, (B @ qs).T), qs[2], rtol=1e-12)


def test_breakdown_nonlinear_structure_is_exact_with_actual_forces():
    # Hertz-like springs f = c |e|^1.5 sign(e): the unit-load theorem with f/T as virtual system
    B, T = _B(), 5.0e5
    c = KS * 30.0

    def res(q):
        e = B @ q
        f = c * np.abs(e) ** 1.5 * np.sign(e)
        J = B.T @ ((1.5 * c * np.abs(e) ** 0.5)[:, None] * B)
        return B.T @ f - np.array([0.0, 0.0, T]), J

    sol = root(res, np.array([0.0, 0.0, 1e-3]), jac=True, method="hybr", options={"xtol": 1e-14})
    assert sol.success
    e = B @ sol.x
    f = c * np.abs(e) ** 1.5 * np.sign(e)
    assert chain.virtual_work(T, f, e) == pytest.approx(sol.x[2], rel=1e-9)
    # …whereas f²/k with a secant or tangent stiffness would not be the contribution in general
    assert chain.Breakdown.from_elements(T, {f"s{i}": (f[i], e[i]) for i in range(3)}).total[0] == \
        pytest.approx(sol.x[2], rel=1e-9)


def test_series_force_inverts_nonlinear_series_and_small_load_compliance_adds():
    laws = [lambda F: 2.0e-5 * np.asarray(F) ** 0.9, lambda F: 1.0e-6 * np.asarray(F)]
    F = np.array([0.0, 1.0, 250.0, 3000.0])
    d = chain.series_deflection(F, laws)
    np.testing.assert_allclose(chain.series_force(d, laws), F, rtol=1e-10, atol=0)
    F0 = 1e-3
    ct = chain.tangent_compliance(F0, lambda F: chain.series_deflection(F, laws))
    parts = sum(chain.tangent_compliance(F0, law) for law in laws)
    assert ct == pytest.approx(parts, rel=1e-8)
    assert chain.tangent_compliance(100.0, laws[1]) == pytest.approx(1e-6, rel=1e-8)
    with pytest.raises(SpecError):
        chain.series_force(-1.0, laws)


def test_virtual_work_rejects_zero_torque():
    with pytest.raises(SpecError, match="non-zero"):
        chain.virtual_work(0.0, 1.0, 1.0)


def test_linearised_disc_to_carrier_chain_of_real_elements():
    # One disc's torque path, linearised at a load: tooth ring --web--> disc hub --3 × [needle bearing,
    # crank bending at the eccentric, support pair]--> carrier (ground).  Assembled as a stiffness matrix
    # with the interface displacements as unknowns and solved directly; compared with the series/parallel
    # closed form and with the virtual-work breakdown.
    from rvtol.elements import disc_web, shafts
    from rvtol.elements.rolling_bearings import BearingPair, NeedleRollerBearing, TaperedRollerBearing

    E, nu, a0 = 206000.0, 0.3, 39.375
    G = E / (2 * (1 + nu))
    K_web = float(disc_web.annular_web_stiffness(56.4, 70.0, 10.0, G))
    k_needle = float(NeedleRollerBearing(rollers=18, length=8.0).solve(3000.0).stiffness[0, 0, 0])
    C = shafts.SteppedShaft((0.0, 7.5, 30.5, 38.0), (20.0, 26.0, 20.0), (0.0, 0.0, 0.0), E, nu).flexibility(
        [13.5], supports=(0.0, 38.0))[0, 0]
    k_crank = 1.0 / C
    trb = TaperedRollerBearing(rollers=16, alpha=math.radians(13.85), length=10.0, pitch_diameter=31.0)
    k_pair = float(BearingPair(trb, trb, (0.0, 38.0), "X").with_preload_force(1000.0).radial_stiffness(
        3000.0, 13.5)[0])
    ks = [k_needle, k_crank, k_pair]
    # DOFs: β_o, β_h, then per crank two interface displacements (needle|crank, crank|pair)
    n = 2 + 3 * 2
    S = np.zeros((n, n))

    def spring(i, j, k, ci=1.0, cj=1.0):        # spring between generalized displacements ci·q_i and cj·q_j
        idx, c = [i, j], np.array([ci, -cj])
        keep = [m for m, ii in enumerate(idx) if ii is not None]
        for a in keep:
            for b in keep:
                S[idx[a], idx[b]] += k * c[a] * c[b]

    spring(0, 1, K_web)
    for c in range(3):
        u1, u2 = 2 + 2 * c, 3 + 2 * c
        spring(1, u1, k_needle, ci=a0)          # hub rotation seen at the crank radius
        spring(u1, u2, k_crank)
        spring(u2, None, k_pair)
    T = 3.775e5
    F = np.zeros(n)
    F[0] = T
    q = np.linalg.solve(S, F)
    K_chain = chain.series(K_web, chain.parallel(*[chain.torsional_from_translational(chain.series(*ks), a0)] * 3))
    assert q[0] == pytest.approx(T / K_chain, rel=1e-12)
    f_bearing = T / (3 * a0)                    # each path carries a third, tangentially
    contrib = {"web": chain.linear_contribution(T, T, K_web)}
    for name, k in zip(("needle", "crank", "pair"), ks):
        contrib[name] = 3 * chain.linear_contribution(T, f_bearing, k)
    bd = chain.Breakdown.from_contributions(T, contrib)
    assert bd.total[0] == pytest.approx(q[0], rel=1e-12)
