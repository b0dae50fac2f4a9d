"""The optimal in-process adjuster: LQR gains, state estimation and assembly simulation.

Timing of one assembly step k (0-based, N steps): the part of step k is
installed (its error ``w(k)`` enters through ``F(k)``), the KCs of step k
are measured (``y(k) = C(k) x(k) + v(k)``), the state is estimated (Kalman
filter; exact when the noise is zero and the measured KCs identify the
state), and the adjustment ``u(k) = -K(k) x̂(k)`` is applied
(``x ← x + B(k) u(k)``); then ``A(k)`` carries the state to the next step.
The final state ``x(N)`` is the state after the last adjustment.

Every operation is linear, so an adjusted assembly is a fixed linear map of
part errors and measurement noise (:meth:`Adjuster.linear_map`).  The
arithmetic is done row by row (no BLAS), so a row's result never depends on
the other rows of the batch.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import ModelError
from .description import AssemblyDescription
from .lqr import kalman_gains, riccati_gains, terminal_constraint_gains


def _mv(M: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``x @ M.T`` row by row: ``x[n, c]``, ``M[r, c]`` -> ``[n, r]``.

    ``np.einsum`` without ``optimize`` runs its own loops (no BLAS), so each
    row's sum is taken in the same order whatever the batch size
    (tests/models/adjustment/test_adjustment.py checks chunk invariance bit for bit).
    """
    return np.einsum("nc,rc->nr", x, M)


@dataclass
class AssemblyRun:
    """State trajectories of a batch of simulated assemblies (base units, rad).

    ``x_installed[:, k]``: state after installing (and before adjusting) step k;
    ``x_adjusted[:, k]``: after the adjustment of step k; ``u[:, k]``: the
    adjustment; ``final``: ``C_final x(N)``; ``effort``: ``sqrt(Σ_k |u(k)|²)``.
    """

    x_installed: np.ndarray
    x_adjusted: np.ndarray
    u: np.ndarray
    x_estimate: np.ndarray
    final: np.ndarray
    effort: np.ndarray
    quadratic_cost: np.ndarray  # J = x̃ᵀQx̃ + Σ uᵀRu (nan when Q = ∞)
    state_names: tuple[str, ...] = ()

    def to_frame(self, row: int = 0, unit: str = "mrad"):
        """One assembly as a table: per step and KC, error before/after adjustment and the adjustment."""
        import pandas as pd

        from ... import units

        names = self.state_names or tuple(f"x{i}" for i in range(self.x_installed.shape[2]))
        recs = []
        for k in range(self.x_installed.shape[1]):
            for i, nm in enumerate(names):
                recs.append({"step": k + 1, "KC": nm,
                             f"before adjustment [{unit}]": units.from_base(self.x_installed[row, k, i], unit),
                             f"adjustment u [{unit}]": units.from_base(self.u[row, k, i], unit)
                             if i < self.u.shape[2] else np.nan,
                             f"after adjustment [{unit}]": units.from_base(self.x_adjusted[row, k, i], unit)})
        return pd.DataFrame(recs)

    def plot(self, row: int = 0, ax=None, unit: str = "mrad"):
        from ...plotting.adjustment import kc_steps

        return kc_steps(self, row=row, ax=ax, unit=unit)


class Adjuster:
    """Finite-horizon LQR adjustment policy (doc 002) with a Kalman state estimate.

    Parameters (per-step lists of length N): ``A``, ``B``, ``F``, ``C``
    (measurement), ``R`` (effort weights), the final observation
    ``C_final`` with the accuracy weight ``accuracy`` (Q(N) = accuracy·I on
    ``C_final x``; ``math.inf`` = terminal constraint), and for the
    estimator the prior covariance ``W`` of each step's part error and the
    measurement-noise covariance ``V``.  :meth:`fit` computes the gains.
    """

    def __init__(self, A, B, F, C, R, C_final, accuracy: float, W=None, V=None, state_names=()):
        self.A = [np.asarray(a, float) for a in A]
        self.B = [np.asarray(b, float) for b in B]
        self.F = [np.asarray(f, float) for f in F]
        self.C = [np.asarray(c, float) for c in C]
        self.R = [np.asarray(r, float) for r in R]
        self.C_final = np.asarray(C_final, float)
        self.accuracy = float(accuracy)
        self.W = [np.eye(f.shape[1]) for f in self.F] if W is None else [np.asarray(w, float) for w in W]
        self.V = [np.zeros((c.shape[0],) * 2) for c in self.C] if V is None else [np.asarray(v, float) for v in V]
        self.state_names = tuple(state_names)
        N = len(self.A)
        if not all(len(x) == N for x in (self.B, self.F, self.C, self.R, self.W, self.V)):
            raise ModelError("A, B, F, C, R, W and V need one matrix per step")
        if not self.accuracy >= 0:
            raise ModelError("accuracy weight must be >= 0")
        self.lqr = None
        self.kalman = None

    @classmethod
    def from_assembly(cls, desc: AssemblyDescription, accuracy: float | None = None) -> "Adjuster":
        """The adjuster of an assembly description (its weights, or ``accuracy`` instead of its Q)."""
        N = desc.n_steps
        return cls(A=[np.eye(desc.n_state)] * N, B=[desc.B_step(k) for k in range(N)],
                   F=[desc.F_step(k) for k in range(N)], C=[desc.C_step(k) for k in range(N)],
                   R=[desc.R_step(k) for k in range(N)], C_final=desc.C_final(),
                   accuracy=desc.accuracy if accuracy is None else accuracy,
                   W=[desc.prior_cov(k) for k in range(N)], V=[desc.noise_cov(k) for k in range(N)],
                   state_names=desc.state_names())

    # -- sizes -------------------------------------------------------------------
    @property
    def n_steps(self) -> int:
        return len(self.A)

    @property
    def n_state(self) -> int:
        return self.A[0].shape[0]

    @property
    def n_w(self) -> int:
        return sum(f.shape[1] for f in self.F)

    @property
    def n_v(self) -> int:
        return sum(c.shape[0] for c in self.C)

    # -- gains -------------------------------------------------------------------
    def fit(self) -> "Adjuster":
        A, B = self.control_system()
        if math.isinf(self.accuracy):
            self.lqr = terminal_constraint_gains(A, B, self.R, self.C_final)
        else:
            Qf = self.accuracy * self.C_final.T @ self.C_final
            self.lqr = riccati_gains(A, B, self.R, Qf)
        self.kalman = kalman_gains(self.A, self.F, self.C, self.W, self.V)
        return self

    def control_system(self) -> tuple[list[np.ndarray], list[np.ndarray]]:
        """``(A', B')`` of the state the adjustment acts on, in :meth:`simulate`'s timing.

        The controlled state ``s(k)`` is the state after installing and
        measuring part k; the adjustment acts before ``A(k)`` carries the state
        on, and the final state is the one after the last adjustment, so
        ``s(k+1) = A(k) s(k) + A(k) B(k) u(k) + F(k+1) w(k+1)`` for k < N−1 and
        ``x(N) = s(N−1) + B(N−1) u(N−1)``: ``A'(k) = A(k)``, ``B'(k) = A(k) B(k)``,
        ``A'(N−1) = I``, ``B'(N−1) = B(N−1)`` (``A(N−1)`` acts after the end).
        For doc 002's rigid assembly (A = I) this is the document's recursion unchanged.
        """
        N = self.n_steps
        A = [self.A[k] if k < N - 1 else np.eye(self.n_state) for k in range(N)]
        B = [self.A[k] @ self.B[k] if k < N - 1 else self.B[k] for k in range(N)]
        return A, B

    @property
    def K(self) -> tuple[np.ndarray, ...]:
        self._check_fitted()
        return self.lqr.K

    def _check_fitted(self):
        if self.lqr is None:
            raise ModelError("Adjuster.fit() has not been called")

    # -- simulation ----------------------------------------------------------------
    def simulate(self, w, v=None, adjust: bool = True) -> AssemblyRun:
        """Simulate assemblies: ``w[n, n_w]`` part errors and ``v[n, n_v]`` noise, step order (rad).

        A 1-D ``w`` is one assembly.  ``adjust=False`` gives the unadjusted assembly.
        """
        self._check_fitted()
        w = np.atleast_2d(np.asarray(w, float))
        n = w.shape[0]
        if w.shape[1] != self.n_w:
            raise ModelError(f"w needs {self.n_w} columns, got {w.shape[1]}")
        v = np.zeros((n, self.n_v)) if v is None else np.atleast_2d(np.asarray(v, float))
        if v.shape != (n, self.n_v):
            raise ModelError(f"v needs shape {(n, self.n_v)}, got {v.shape}")
        N, nx = self.n_steps, self.n_state
        nu = self.B[0].shape[1]
        X_in = np.empty((n, N, nx))
        X_ad = np.empty((n, N, nx))
        U = np.zeros((n, N, nu))
        XH = np.empty((n, N, nx))
        x = np.zeros((n, nx))
        xh = np.zeros((n, nx))
        iw = iv = 0
        for k in range(N):
            if k > 0:
                x = _mv(self.A[k - 1], x)
                xh = _mv(self.A[k - 1], xh)
            dw = self.F[k].shape[1]
            x = x + _mv(self.F[k], w[:, iw:iw + dw])
            iw += dw
            X_in[:, k] = x
            m = self.C[k].shape[0]
            y = _mv(self.C[k], x) + v[:, iv:iv + m]
            iv += m
            xh = xh + _mv(self.kalman.L[k], y - _mv(self.C[k], xh))
            XH[:, k] = xh
            if adjust:
                U[:, k] = -_mv(self.lqr.K[k], xh)
                du = _mv(self.B[k], U[:, k])
                x = x + du
                xh = xh + du
            X_ad[:, k] = x
        final = _mv(self.C_final, x)
        effort = np.sqrt((U * U).sum(axis=(1, 2)))
        if math.isinf(self.accuracy):
            J = np.full(n, np.nan)
        else:
            J = self.accuracy * (final * final).sum(axis=1)
            for k in range(N):
                J = J + (U[:, k] * _mv(self.R[k], U[:, k])).sum(axis=1)
        return AssemblyRun(X_in, X_ad, U, XH, final, effort, J, self.state_names)

    def linear_map(self) -> tuple[np.ndarray, np.ndarray]:
        """``(M_w, M_v)`` with ``final = M_w w + M_v v`` (exact: the adjusted assembly is linear)."""
        Iw, Iv = np.eye(self.n_w), np.eye(self.n_v)
        M_w = self.simulate(Iw, np.zeros((self.n_w, self.n_v))).final.T
        M_v = self.simulate(np.zeros((self.n_v, self.n_w)), Iv).final.T if self.n_v else np.zeros((len(self.C_final), 0))
        return M_w, M_v
