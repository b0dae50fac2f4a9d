"""Finite-horizon LQR gains and Kalman-filter gains for a time-varying linear system.

The system (doc 002) is ``x(k+1) = A(k) x(k) + B(k) u(k) + F(k) w(k)``,
``y(k) = C(k) x(k) + v(k)``, with the cost
``J = x(N)ᵀ Q(N) x(N) + Σ_k [x(k)ᵀ Q(k) x(k) + u(k)ᵀ R(k) u(k)]`` (doc 002 has
only the terminal term: Q(k) = 0 for k < N).  The optimal control is
``u(k) = -K(k) x(k)`` with the backward recursion written in doc 002::

    K(k) = [R(k) + Bᵀ P(k+1) B]⁻¹ Bᵀ P(k+1) A
    P(k) = Q(k) + Aᵀ P(k+1) [I + B R(k)⁻¹ Bᵀ P(k+1)]⁻¹ A,     P(N) = Q(N)

:func:`terminal_constraint_gains` is the limit Q(N) → ∞ (final observation
forced to zero with the least weighted effort), computed in closed form
rather than with a huge Q.  With measurement noise the control acts on the
Kalman estimate of the state (certainty equivalence — the LQG separation
principle); :func:`kalman_gains` gives the time-varying filter gains, which
do not depend on the data, so the whole adjusted assembly is a fixed linear
map of part errors and noise.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import ModelError


@dataclass(frozen=True)
class LQRGains:
    K: tuple[np.ndarray, ...]  # K(0..N-1)
    P: tuple[np.ndarray, ...] | None  # P(0..N) (None for the terminal-constraint limit)


def riccati_gains(A, B, R, Q_final, Q_stage=None) -> LQRGains:
    """Backward Riccati recursion of doc 002 (lists of per-step matrices, length N)."""
    N = len(A)
    if not (len(B) == len(R) == N):
        raise ModelError("A, B and R need one matrix per step")
    n = A[0].shape[0]
    P = [None] * (N + 1)
    K = [None] * N
    P[N] = np.asarray(Q_final, float)
    for k in range(N - 1, -1, -1):
        Pn, Ak, Bk, Rk = P[k + 1], A[k], B[k], R[k]
        K[k] = np.linalg.solve(Rk + Bk.T @ Pn @ Bk, Bk.T @ Pn @ Ak)
        M = np.eye(n) + Bk @ np.linalg.solve(Rk, Bk.T) @ Pn
        Pk = Ak.T @ Pn @ np.linalg.solve(M, Ak)
        if Q_stage is not None:
            Pk = Pk + Q_stage[k]
        P[k] = 0.5 * (Pk + Pk.T)
    return LQRGains(tuple(K), tuple(P))


def terminal_constraint_gains(A, B, R, C_final) -> LQRGains:
    """The Q(N) → ∞ limit: drive ``C_final x(N)`` to zero with least Σ uᵀRu (no stage cost).

    From ``x(k)`` the remaining controls ``u(k..N-1)`` minimise ``Σ uⱼᵀRⱼuⱼ``
    subject to ``C Φ(N,k) x(k) + C Σⱼ Φ(N,j+1) Bⱼ uⱼ = 0``; the first of them is
    ``u(k) = -Rₖ⁻¹ Bₖᵀ Φ(N,k+1)ᵀ Cᵀ (C Gₖ Cᵀ)⁺ C Φ(N,k) x(k)`` with the weighted
    reachability Gramian ``Gₖ = Σⱼ≥ₖ Φ(N,j+1) Bⱼ Rⱼ⁻¹ Bⱼᵀ Φ(N,j+1)ᵀ``.  Where
    ``C Gₖ Cᵀ`` is singular (not every final direction is reachable from step
    k) the pseudo-inverse gives the least-squares limit.
    """
    N = len(A)
    n = A[0].shape[0]
    C = np.asarray(C_final, float)
    Phi = [None] * (N + 1)  # Phi[k] = Φ(N, k) = A(N-1)···A(k)
    Phi[N] = np.eye(n)
    for k in range(N - 1, -1, -1):
        Phi[k] = Phi[k + 1] @ A[k]
    K = [None] * N
    G = np.zeros((n, n))
    for k in range(N - 1, -1, -1):
        PB = Phi[k + 1] @ B[k]
        G = G + PB @ np.linalg.solve(R[k], PB.T)
        CGC = C @ G @ C.T
        K[k] = np.linalg.solve(R[k], PB.T) @ C.T @ np.linalg.pinv(CGC, rcond=1e-12) @ C @ Phi[k]
    return LQRGains(tuple(K), None)


@dataclass(frozen=True)
class KalmanGains:
    L: tuple[np.ndarray, ...]  # L(k): x̂ += L(k) (y(k) − C(k) x̂⁻)
    Sigma: tuple[np.ndarray, ...]  # posterior covariance after the measurement of step k


def kalman_gains(A, F, C, W, V) -> KalmanGains:
    """Time-varying Kalman filter gains for ``x(0) = F(0) w(0)`` (a perfect datum before step 0).

    Before step k's measurement the prior covariance is
    ``A(k-1) Σ(k-1) A(k-1)ᵀ + F(k) W(k) F(k)ᵀ`` (the adjustments are known, so
    they move the estimate, not its covariance).
    """
    N = len(F)
    n = F[0].shape[0]
    Sigma = np.zeros((n, n))
    Ls, Ss = [], []
    for k in range(N):
        prior = F[k] @ W[k] @ F[k].T
        if k > 0:
            prior = A[k - 1] @ Sigma @ A[k - 1].T + prior
        S = C[k] @ prior @ C[k].T + V[k]
        L = prior @ C[k].T @ np.linalg.pinv(S, rcond=1e-12, hermitian=True)
        Sigma = (np.eye(n) - L @ C[k]) @ prior
        Sigma = 0.5 * (Sigma + Sigma.T)
        Ls.append(L)
        Ss.append(Sigma)
    return KalmanGains(tuple(Ls), tuple(Ss))
