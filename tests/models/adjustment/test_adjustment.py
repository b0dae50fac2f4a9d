"""Finite-horizon LQR adjustment (doc 002): recursion, limits, estimator, simulation, Model."""
import math

import numpy as np
import pytest
from scipy import linalg

from rvtol.models.adjustment import AdjustedAssemblyModel, Adjuster, load_assembly
from rvtol.models.adjustment.lqr import kalman_gains, riccati_gains, terminal_constraint_gains
from rvtol.mc import evaluate
from rvtol.sampling import rng

BX2 = "data/assemblies/bx40e_2d.toml"
BX3 = "data/assemblies/bx40e_3d.toml"
EXAMPLE = np.array([-1.6, 5.3, 5.8, 3.2]) * 1e-3  # doc 002 Table 3, rad


@pytest.fixture
def bx2(root):
    return load_assembly(root / BX2)


# --------------------------------------------------------------------------- the recursion
def test_riccati_scalar_closed_form():
    """a = b = 1, terminal weight q, effort r: 1/P(k) = 1/q + (N−k)/r and K(k) = P(k+1)/(r + P(k+1))."""
    N, q, r = 6, 7.0, 2.5
    I = [np.eye(1)] * N
    g = riccati_gains(I, I, [r * np.eye(1)] * N, q * np.eye(1))
    for k in range(N + 1):
        assert g.P[k][0, 0] == pytest.approx(1.0 / (1.0 / q + (N - k) / r), rel=1e-13)
    for k in range(N):
        p1 = 1.0 / (1.0 / q + (N - k - 1) / r)
        assert g.K[k][0, 0] == pytest.approx(p1 / (r + p1), rel=1e-13)


def test_riccati_long_horizon_matches_scipy_dare():
    """With a stage cost Q(k) = Q and many steps, P(0) and K(0) converge to the DARE solution."""
    g0 = rng(5)
    A = np.array([[1.1, 0.3, 0.0], [0.0, 0.9, 0.2], [0.1, 0.0, 0.7]])
    B = g0.normal(size=(3, 2))
    Q = np.diag([2.0, 1.0, 0.5])
    R = np.array([[1.5, 0.2], [0.2, 0.8]])
    N = 400
    g = riccati_gains([A] * N, [B] * N, [R] * N, Q, Q_stage=[Q] * N)
    X = linalg.solve_discrete_are(A, B, Q, R)
    K = np.linalg.solve(R + B.T @ X @ B, B.T @ X @ A)
    np.testing.assert_allclose(g.P[0], X, rtol=1e-9)
    np.testing.assert_allclose(g.K[0], K, rtol=1e-9)


def test_gain_is_the_open_loop_least_squares_optimum(bx2):
    """u(k) = −K(k)x(k) equals the first move of min Σ_{j≥k} uⱼᵀRⱼuⱼ + Q|x(N)|² (future w = 0), by least squares."""
    Q = 10.0
    adj = Adjuster.from_assembly(bx2, Q).fit()
    x = np.array([0.7, -1.1, 2.0, 0.4])
    n = 4
    for k in range(bx2.n_steps):
        steps = range(k, bx2.n_steps)
        # residual r = [sqrt(Q)(x + Σ B uⱼ); sqrt(Rⱼ) uⱼ]
        M = np.zeros((n + n * len(steps), n * len(steps)))
        rhs = np.zeros(n + n * len(steps))
        rhs[:n] = -math.sqrt(Q) * x
        for c, j in enumerate(steps):
            M[:n, c * n:(c + 1) * n] = math.sqrt(Q) * bx2.B_step(j)
            M[n + c * n:n + (c + 1) * n, c * n:(c + 1) * n] = np.sqrt(bx2.R_step(j))
        u = np.linalg.lstsq(M, rhs, rcond=None)[0]
        np.testing.assert_allclose(-adj.K[k] @ x, u[:n], rtol=1e-10, atol=1e-14)


@pytest.mark.parametrize("Q", [3.0, math.inf])
def test_gains_are_optimal_for_the_simulated_timing_with_a_general_A(Q):
    """Non-identity A: the closed-loop adjustments after one part error equal the open-loop optimum
    (batch least squares over u(0..N−1)) of the dynamics ``simulate`` runs: install, measure, adjust,
    then A(k) carries the state on; the final state is the one after the last adjustment."""
    g0 = rng(11)
    n, N = 3, 4
    A = [np.eye(n) + 0.3 * g0.normal(size=(n, n)) for _ in range(N)]
    B = [np.eye(n)[:, :2] + 0.1 * g0.normal(size=(n, 2)) for _ in range(N)]
    F = [np.eye(n)[:, [k % n]] for k in range(N)]
    R = [np.diag([2.0, 0.5]) * (k + 1) for k in range(N)]
    Cf = np.eye(n)[:2]
    adj = Adjuster(A, B, F, [np.eye(n)] * N, R, Cf, Q).fit()
    run = adj.simulate(np.array([1.0, 0.0, 0.0, 0.0]))
    # final = Cf (T(0) x0 + Σ_k T(k) B(k) u(k)), T(k) = A(N−2)···A(k) carries step k's adjusted state to the end
    def T(k):
        M = np.eye(n)
        for j in range(k, N - 1):
            M = A[j] @ M
        return M

    G = np.hstack([Cf @ T(k) @ B[k] for k in range(N)])
    c0 = Cf @ T(0) @ F[0][:, 0]
    Rh = linalg.block_diag(*[np.sqrt(r) for r in R])
    if math.isinf(Q):  # min Σ uᵀRu subject to c0 + G u = 0
        Ri = np.linalg.inv(Rh @ Rh)
        u = -Ri @ G.T @ np.linalg.solve(G @ Ri @ G.T, c0)
        assert np.max(np.abs(run.final)) < 1e-12
    else:  # min Q|c0 + G u|² + Σ uᵀRu
        M = np.vstack([math.sqrt(Q) * G, Rh])
        u = np.linalg.lstsq(M, np.concatenate([-math.sqrt(Q) * c0, np.zeros(2 * N)]), rcond=None)[0]
    np.testing.assert_allclose(run.u[0].ravel(), u, rtol=1e-9, atol=1e-12)


def test_terminal_constraint_is_the_limit_of_large_Q(bx2):
    """The closed-form Q = ∞ gains (Gramian) are the limit of the Riccati gains; the gap shrinks like R/Q."""
    inf = Adjuster.from_assembly(bx2, math.inf).fit().K
    gap = lambda q: max(np.max(np.abs(a - b)) for a, b in zip(Adjuster.from_assembly(bx2, q).fit().K, inf))  # noqa
    r_max = bx2.effort_locked
    for q in (1e6, 1e9):
        assert gap(q) <= 10 * r_max / q
    assert gap(1e6) / gap(1e9) == pytest.approx(1e3, rel=0.01)


# --------------------------------------------------------------------------- limits
def test_no_adjustment_when_effort_weights_go_to_infinity(bx2):
    d = bx2.with_weights(accuracy=10.0, effort_adjustable=1e15, effort_locked=1e15)
    adj = Adjuster.from_assembly(d).fit()
    w = rng(3).normal(size=(50, 4)) * 1e-3
    run = adj.simulate(w)
    assert np.max(run.effort) < 1e-12 * np.max(np.abs(w))
    # the adjustments are O(Q/R) = 1e-14 of the errors: the final state is the unadjusted F·w
    np.testing.assert_allclose(run.final, w @ bx2.F_full().T, rtol=0, atol=1e-12 * np.max(np.abs(w)))


def test_full_authority_and_infinite_Q_remove_the_final_error(bx2):
    w = rng(4).normal(size=(50, 4)) * 1e-3
    run = Adjuster.from_assembly(bx2, math.inf).fit().simulate(w)
    assert np.max(np.abs(run.final)) < 1e-12 * np.max(np.abs(w))
    # and finite Q approaches it like 1/Q
    e = [np.max(np.abs(Adjuster.from_assembly(bx2, q).fit().simulate(w).final)) for q in (1e2, 1e4, 1e6)]
    assert e[0] > 50 * e[1] > 2500 * e[2] > 0


def test_one_step_scalar_closed_loop_by_hand():
    """One KC, one step: u = −Q/(R+Q)·δ, final δ·R/(R+Q) (doc 002's cost with one adjustment)."""
    from rvtol.models.adjustment import assembly_from_table

    d = assembly_from_table({
        "assembly": {"name": "one"}, "weights": {"accuracy": 8.0, "effort_adjustable": 2.0, "effort_locked": 1e3},
        "chain": [{"name": "c", "kcs": ["K"]}], "kc": [{"name": "K", "error": "e"}],
        "step": [{"install": "K"}]})
    run = Adjuster.from_assembly(d).fit().simulate(np.array([[0.5]]))
    assert run.final[0, 0] == pytest.approx(0.5 * 2.0 / 10.0, rel=1e-14)
    assert run.effort[0] == pytest.approx(0.5 * 8.0 / 10.0, rel=1e-14)
    assert run.quadratic_cost[0] == pytest.approx(8.0 * 0.1**2 + 2.0 * 0.4**2, rel=1e-13)


# --------------------------------------------------------------------------- estimator
def test_noise_free_estimate_is_the_true_state(bx2):
    w = rng(6).normal(size=(20, 4)) * 1e-3
    run = Adjuster.from_assembly(bx2, 10.0).fit().simulate(w)
    np.testing.assert_allclose(run.x_estimate, run.x_installed, rtol=0, atol=1e-14 * np.max(np.abs(w)))


def test_kalman_error_covariance_matches_monte_carlo(bx2):
    """With noise the estimation error after each measurement has the filter's covariance Σ(k)."""
    sv, sw = 0.3e-3, 1.0e-3
    d = bx2.with_weights(accuracy=10.0)
    from dataclasses import replace

    d = replace(d, noise_sigma=sv, kcs=tuple(replace(k, prior_sigma=sw) for k in d.kcs))
    adj = Adjuster.from_assembly(d).fit()
    n = 40000
    g = rng(7)
    run = adj.simulate(g.normal(size=(n, 4)) * sw, g.normal(size=(n, 4)) * sv)
    for k in range(4):
        e = run.x_estimate[:, k] - run.x_installed[:, k]
        S = adj.kalman.Sigma[k]
        emp = e.T @ e / n
        # variance estimates: relative standard error sqrt(2/n) ≈ 0.7 %; 5 standard errors
        tol = 5 * math.sqrt(2 / n)
        for i in range(4):
            if S[i, i] > 1e-20:
                assert emp[i, i] == pytest.approx(S[i, i], rel=tol)
    # a one-step scalar check of the gain: posterior gain σw²/(σw² + σv²)
    kg = kalman_gains([np.eye(1)], [np.eye(1)], [np.eye(1)], [np.eye(1) * sw**2], [np.eye(1) * sv**2])
    assert kg.L[0][0, 0] == pytest.approx(sw**2 / (sw**2 + sv**2), rel=1e-14)


# --------------------------------------------------------------------------- the Model
def test_model_is_the_linear_map_and_chunk_invariant(root):
    d = load_assembly(root / BX3)
    m = AdjustedAssemblyModel(d)
    X = rng(8).normal(size=(301, len(m.inputs))) * 1e-3
    Y = evaluate(m, X, progress=False).Y
    run = m.simulate(X)  # the step-by-step recursion, independent of the closed-loop map evaluate uses
    np.testing.assert_allclose(Y[:, :12], run.final, rtol=1e-10, atol=1e-16)
    np.testing.assert_allclose(Y[:, 12], np.linalg.norm(run.final, axis=1), rtol=1e-12)
    np.testing.assert_allclose(Y[:, 13], run.effort, rtol=1e-10)
    M_w, M_v = m.adjuster.linear_map()
    w, v = m.split(X)
    np.testing.assert_allclose(Y[:, :12], w @ M_w.T + v @ M_v.T, rtol=1e-10, atol=1e-16)
    free = m.with_accuracy(10.0, adjust=False)
    np.testing.assert_allclose(free.evaluate(X)[:, :12], m.adjuster.simulate(w, v, adjust=False).final, rtol=1e-12)
    assert np.all(free.evaluate(X)[:, 13] == 0.0)
    for cs in (1, 7, 64):
        assert np.array_equal(evaluate(m, X, chunk_size=cs, progress=False).Y, Y)


def test_missing_factors_stay_at_zero(root, bx2):
    full = AdjustedAssemblyModel(bx2)
    parts = AdjustedAssemblyModel(bx2, inputs=["dtheta_3", "dtheta_1"])
    X = np.array([[2e-3, -1e-3]])
    Xf = np.zeros((1, len(full.inputs)))
    Xf[0, full.inputs.index("dtheta_3")] = 2e-3
    Xf[0, full.inputs.index("dtheta_1")] = -1e-3
    np.testing.assert_array_equal(parts.evaluate(X), full.evaluate(Xf))


def test_3d_case_is_three_2d_cases_turned_by_W(root, bx2):
    """With isotropic weights each axis of the 3-D case is the 2-D case (KC3's frame turned 180° about z)."""
    m2 = Adjuster.from_assembly(bx2).fit().linear_map()[0]
    m3 = Adjuster.from_assembly(load_assembly(root / BX3)).fit().linear_map()[0]
    sign = {0: [1, 1, -1, 1], 1: [1, 1, -1, 1], 2: [1, 1, 1, 1]}  # x and y of part 3 flip under Rz(180°)
    for c in range(3):
        sub = m3[c::3, c::3]
        np.testing.assert_allclose(sub, m2 * np.array(sign[c])[None, :], rtol=1e-12, atol=1e-15)


def test_doc_example_unadjusted_is_F_times_w(bx2):
    run = Adjuster.from_assembly(bx2, 0.0).fit().simulate(EXAMPLE)
    np.testing.assert_allclose(run.final[0] * 1e3, [-1.6, 3.7, 5.8, 9.0], rtol=1e-14)
    assert run.effort[0] == 0.0


def test_effort_grows_and_final_error_falls_with_Q(bx2):
    Qs = [0.0, 1.0, 5.0, 10.0, 100.0, math.inf]
    runs = [Adjuster.from_assembly(bx2, q).fit().simulate(EXAMPLE) for q in Qs]
    fe = [np.linalg.norm(r.final) for r in runs]
    ef = [r.effort[0] for r in runs]
    assert all(a > b for a, b in zip(fe, fe[1:]))
    assert all(a < b for a, b in zip(ef, ef[1:]))
