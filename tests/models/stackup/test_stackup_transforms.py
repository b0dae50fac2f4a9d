"""Transforms of 6-DOF deviations: conventions, round trips, small-angle error ∝ angle², numba = NumPy."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from rvtol.models.stackup import transforms as tr
from rvtol.models.stackup.program import Program, chain_program, run_numba, run_numpy

RNG = np.random.default_rng(20261121)


def random_E(n, lin=0.1, ang=0.2, shape=()):
    E = np.empty(shape + (n, 6))
    E[..., :3] = RNG.normal(0, lin, shape + (n, 3))
    E[..., 3:] = RNG.uniform(-ang, ang, shape + (n, 3))
    return E


def test_exact_rotation_is_fixed_axis_xyz():
    """R = Rz(γ)·Ry(β)·Rx(α): SciPy's extrinsic 'xyz' Euler angles (an independent implementation)."""
    w = RNG.uniform(-1.2, 1.2, (50, 3))
    R = tr.rotation_exact(w)
    ref = Rotation.from_euler("xyz", w).as_matrix()
    np.testing.assert_allclose(R, ref, atol=1e-15)
    np.testing.assert_allclose(R @ np.swapaxes(R, -1, -2), np.broadcast_to(np.eye(3), R.shape), atol=1e-15)


def test_small_angle_matrix_is_the_documents():
    a, b, g = 0.01, -0.02, 0.03
    T = tr.small_angle([1.0, 2.0, 3.0, a, b, g])
    expected = np.array([[1, -g, b, 1.0], [g, 1, -a, 2.0], [-b, a, 1, 3.0], [0, 0, 0, 1]])
    np.testing.assert_array_equal(T, expected)
    # Trans × Rot: translation applied after the rotation
    p = np.array([0.3, -0.2, 0.5, 1.0])
    np.testing.assert_allclose(T @ p, np.r_[expected[:3, :3] @ p[:3] + [1, 2, 3], 1.0])


@pytest.mark.parametrize("mode", tr.MODES)
def test_extract_inverts_transform(mode):
    E = random_E(200, ang=1.0 if mode == "exact" else 5.0)
    np.testing.assert_allclose(tr.extract(tr.transform(E, mode), mode), E, atol=1e-14, rtol=1e-14)


@pytest.mark.parametrize("mode", tr.MODES)
def test_inverse_of_products(mode):
    Ts = tr.transform(random_E(30, shape=(4,)), mode)  # (4, 30, 4, 4): 4 links
    T = tr.compose(np.moveaxis(Ts, 0, -3))
    np.testing.assert_allclose(tr.inverse(T, mode) @ T, np.broadcast_to(np.eye(4), T.shape), atol=1e-13)
    np.testing.assert_allclose(tr.inverse3(T[..., :3, :3]), np.linalg.inv(T[..., :3, :3]), atol=1e-13)


def test_compose_matches_loop_reference_and_is_row_independent():
    E = random_E(25, shape=(5,))
    Ts = tr.exact(np.moveaxis(E, 0, 1))  # (25, 5, 4, 4)
    out = tr.compose(Ts)
    for i in range(25):
        np.testing.assert_allclose(out[i], np.linalg.multi_dot(list(Ts[i])), atol=1e-15)
    np.testing.assert_array_equal(tr.compose(Ts[7:9]), out[7:9])


def test_small_angle_error_scales_with_angle_squared():
    """‖T_exact − T_small‖ and the chain-deviation difference both shrink 100× when angles shrink 10×."""
    direction = random_E(100, lin=1.0, ang=1.0, shape=(4,))  # 4-link chains, 100 of them
    errs, chain_errs = [], []
    for theta in (1e-2, 1e-3, 1e-4):
        E = direction.copy()
        E[..., 3:] *= theta
        errs.append(np.abs(tr.exact(E) - tr.small_angle(E)).max())
        Ec = np.moveaxis(E, 0, 1)
        chain_errs.append(np.abs(tr.chain_deviation(Ec, "exact") - tr.chain_deviation(Ec, "small")).max())
    for e in (errs, chain_errs):
        r1, r2 = e[0] / e[1], e[1] / e[2]
        assert 95 < r1 < 105 and 95 < r2 < 105, e  # O(θ²): a factor 100 per decade


def test_first_order_composition_uses_the_adjoint():
    """D(ξ)·T = T·D(Ad ξ) + O(ξ²): the transport the analytic Jacobian relies on."""
    T = tr.exact([3.0, -1.0, 2.0, 0.3, -0.2, 0.5])
    xi = random_E(20, lin=1.0, ang=1.0)
    for eps in (1e-4, 1e-5):
        lhs = tr.extract(tr.inverse(T) @ tr.exact(eps * xi) @ T, "exact")
        rhs = eps * xi @ tr.adjoint(T).T
        err = np.abs(lhs - rhs).max()
        assert err < 50 * eps**2


@pytest.mark.parametrize("mode", tr.MODES)
def test_numba_chain_equals_numpy_chain(mode):
    for m in (1, 3, 8):
        E = random_E(500, shape=(m,))
        E = np.ascontiguousarray(np.moveaxis(E, 0, 1))  # (500, m, 6)
        p = chain_program(m)
        a, sa = run_numba(p, E, mode)
        b, sb = run_numpy(p, E, mode)
        np.testing.assert_allclose(a[:, 0], b[:, 0], atol=1e-13)
        np.testing.assert_allclose(a[:, 0], tr.chain_deviation(E, mode), atol=1e-13)
        assert not sa.any() and not sb.any()


@pytest.mark.parametrize("mode", tr.MODES)
def test_program_with_every_operation_numba_equals_numpy(mode):
    p = Program(n_slots=3)
    r0, r1, r2 = p.register(), p.register(), p.register()
    C1, C2 = tr.exact([10.0, 0, 5, 0, 0, 0.7]), tr.exact([0, -3.0, 1, 0.1, 0, 0])
    p.set(r0)
    p.mul_const(r0, C1)
    p.mul_dev(r0, 0)
    p.mul_dev(r0, 1, inverse=True)
    p.copy(r1, r0)
    p.mul_const(r1, C2)
    p.mul_dev(r1, 2)
    p.set(r2, C2)
    p.mul_dev(r2, 0)
    p.left_inv(r1, r0)
    p.left_inv(r2, r1)
    p.out(r1)
    p.out(r2)
    E = np.ascontiguousarray(np.moveaxis(random_E(300, shape=(3,)), 0, 1))
    a, sa = run_numba(p, E, mode)
    b, sb = run_numpy(p, E, mode)
    np.testing.assert_allclose(a, b, atol=1e-12)
    # reference for out 0: (T0)^-1 · T0·C2·T(E2) with T0 = C1·T(E0)·T(E1)^-1
    ref = tr.extract(C2 @ tr.transform(E[:, 2], mode), mode)
    np.testing.assert_allclose(a[:, 0], ref, atol=1e-12)


def test_status_codes_for_bad_rows():
    p = chain_program(2)
    E = np.zeros((4, 2, 6))
    E[1, 0, 3] = np.nan
    E[2, 1, 0] = np.inf
    for run in (run_numba, run_numpy):
        out, st = run(p, E, "exact")
        assert list(st) == [0, 1, 1, 0]
        assert np.isnan(out[1:3]).all() and np.isfinite(out[[0, 3]]).all()
    q = Program(n_slots=1)  # a singular register inverted in the small-angle mode
    r, s = q.register(), q.register()
    q.set(r, np.diag([1.0, 0.0, 1.0, 1.0]))
    q.set(s)
    q.left_inv(s, r)
    q.out(s)
    for run in (run_numba, run_numpy):
        out, st = run(q, np.zeros((2, 1, 6)), "small")
        assert list(st) == [2, 2] and np.isnan(out).all()
