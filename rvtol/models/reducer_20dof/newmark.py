"""Dynamic transmission error: implicit Newmark-β (γ = 1/2, β = 1/4) at constant input speed.

``M q̈ + C q̇ + F(q, t) = Q``: the sun turns at constant speed (its angle is
prescribed through the contact table), the carrier carries a resisting load
torque; the run starts from the static equilibrium at θ_c = 0, settles, then
records one full output revolution (doc 000 §1.4 and §2).

Modelling choices (the document gives none of these):

* **mass matrix** diagonal in the document's coordinates: sun m_s; planet/crank
  m_p, I_p; disc m_d for η, m_d e² for θ_do (its centre moves e·θ_do), I_d for
  θ_d; carrier m_ca, I_ca (design ``mass.*``, estimated from the geometry);
* **damping**: modal, ratio ζ (design ``damping.modal_ratio``) on every mode of
  the model linearised at the loaded static equilibrium,
  ``C = M Φ diag(2 ζ ω) Φᵀ M`` (Φ mass-normalised);
* **inertial loads of the nominal motion**: the disc centre orbits at radius e
  with the crank speed ω_p = (1 − z_b) ω_c, so each disc carries the constant
  centrifugal force m_d e ω_p² on η (rotating-frame coordinates); Coriolis and
  ω²-stiffness terms of the small deviations are neglected (m ω_p² ≈ 10² N/mm
  against contact stiffnesses of 10⁵ N/mm);
* **time step**: ``steps_per_crank_rev`` if given, else the finer of 36 steps
  per crank revolution and a tenth of the period of the lowest natural mode
  (error-free RV-80E: 2–14 kHz; with the spec's bearing clearances the lowest
  linearised mode drops to about 0.4–0.9 kHz, near the 390 Hz pin-mesh
  frequency at 15 rpm; resolving the lowest one is what makes the response
  dynamic rather than quasi-static);
* **settling**: ``settle_periods`` periods of the lowest mode (transients decay
  as exp(−ζ ω t)) before the recorded revolution.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sl

from ...errors import InputError
from . import _kernels as K
from . import layout as L
from .contacts import pin_cos_sin, static_table
from .factors import ErrorState
from .geometry import RVGeometry
from .quasistatic import QuasiStaticSolver, SweepResult


@dataclass
class DynamicResult(SweepResult):
    """A :class:`SweepResult` over time, with velocities and the time axis."""

    t: np.ndarray = None
    v: np.ndarray = None
    frequencies: np.ndarray = None   # natural frequencies of the linearised model (Hz)
    time_step: float = 0.0


def modal_damping(M: np.ndarray, Kt: np.ndarray, zeta: float) -> tuple[np.ndarray, np.ndarray]:
    """``(C, ω)``: damping matrix with ratio ``zeta`` on every mode of (Kt, M), circular frequencies."""
    w2, phi = sl.eigh(Kt, M)
    w = np.sqrt(np.clip(w2, 0.0, None))
    Mphi = M @ phi
    return Mphi @ np.diag(2.0 * zeta * w) @ Mphi.T, w


class NewmarkSolver:
    """Constant-speed dynamic run of one reducer.

    ``output_speed`` (rad/s, default 15 rpm), ``load_torque`` (N·mm, default
    3 % of rated), ``steps_per_crank_rev`` (None: automatic, see module notes),
    ``settle_periods`` of the lowest mode before recording, ``centrifugal``
    loads on/off.
    """

    #: the kernel module the run uses (the benchmarks set an earlier commit's to compare)
    kernels = K

    def __init__(self, geometry: RVGeometry, errors: ErrorState | None = None, *,
                 output_speed: float = 15 * 2 * math.pi / 60, load_torque: float | None = None,
                 steps_per_crank_rev: int | None = None, settle_periods: float = 50.0, centrifugal: bool = True,
                 tol_f: float = 1e-5, maxit: int = 200, maxstep: float = 0.02):
        if not output_speed > 0:
            raise InputError(f"output speed must be > 0, got {output_speed}", key="output_speed")
        if steps_per_crank_rev is not None and steps_per_crank_rev < 4:
            raise InputError(f"steps per crank revolution must be >= 4, got {steps_per_crank_rev}",
                             key="steps_per_crank_rev")
        self.g = geometry
        self.M = geometry.mass_matrix()
        self.errors = errors if errors is not None else ErrorState.zero(geometry.z_b)
        self.omega_c = float(output_speed)
        self.load_torque = 0.03 * geometry.rated_torque if load_torque is None else float(load_torque)
        self.steps_per_crank_rev = steps_per_crank_rev
        self.settle_periods = float(settle_periods)
        self.centrifugal = centrifugal
        self.tol_f, self.maxit, self.maxstep = float(tol_f), int(maxit), float(maxstep)
        self.static = QuasiStaticSolver(geometry, self.errors, tol_f=tol_f, maxit=maxit, maxstep=maxstep)

    def loads(self) -> np.ndarray:
        """Constant generalised forces: the load torque and the discs' centrifugal forces."""
        Q = np.zeros(L.NDOF)
        Q[L.THCA] = -self.load_torque
        if self.centrifugal:
            w_p = (1 - self.g.z_b) * self.omega_c
            for j in range(L.N_DISC):
                Q[L.disc(j)] = self.g.m_disc * self.g.ecc * w_p ** 2
        return Q

    def tangent(self, theta_c: float, q: np.ndarray) -> np.ndarray:
        g, e = self.g, self.errors
        tab = static_table(g, e.err, e.preload)
        coef = np.zeros((tab.n, 2, L.NZ))
        off = np.zeros((tab.n, 2))
        K.update_table(theta_c, 0.0, g.prm(), e.err, e.pin_err, e.disc_h, pin_cos_sin(g), coef, off)
        F, fc, kt, Kt = np.zeros(L.NDOF), np.zeros(tab.n), np.zeros((tab.n, 3)), np.zeros((L.NDOF, L.NDOF))
        K.contact_forces(q, tab.kind, tab.idx, coef, off, tab.k0, tab.pw, tab.gap, tab.ser, tab.tab, F, fc, kt)
        K.tangent_matrix(tab.kind, tab.idx, coef, kt, Kt)
        return Kt

    def run(self, revolutions: float = 1.0) -> DynamicResult:
        g = self.g
        Q0 = self.loads()
        eq = self.static.sweep([0.0], [0.0], load=Q0)
        n_rec = 0
        if not eq.ok:
            return self._failed(eq)
        q0 = eq.q[0]
        C, w = modal_damping(self.M, self.tangent(0.0, q0), self.g.zeta)
        w1 = w[w > 0].min()
        t_crank = 2 * math.pi / (self.omega_c * g.z_b)          # crank revolution relative to the carrier
        if self.steps_per_crank_rev is not None:
            per = self.steps_per_crank_rev
        else:
            per = max(36, int(math.ceil(t_crank / (0.1 * 2 * math.pi / w1))))
        h = t_crank / per
        n_rec = int(round(per * g.z_b * revolutions))
        nskip = int(math.ceil(self.settle_periods * 2 * math.pi / w1 / h))
        nsteps = nskip + n_rec - 1
        tab = self.static.table
        e = self.errors
        out_q = np.zeros((n_rec, L.NDOF))
        out_v = np.zeros((n_rec, L.NDOF))
        out_status = np.full(n_rec, -1, np.int64)
        out_iter = np.zeros(n_rec, np.int64)
        out_rec = np.zeros((n_rec, K.NREC))
        coef = np.zeros((tab.n, 2, L.NZ))
        off = np.zeros((tab.n, 2))
        failed = self.kernels.newmark_run(0.0, self.omega_c, h, nsteps, nskip, True, self.static.prm, e.err,
                                          e.pin_err, e.disc_h, self.static.pin_cs, tab.kind, tab.idx, coef, off,
                                          tab.k0, tab.pw, tab.gap, tab.ser, tab.tab, self.static.xs, self.M, C, Q0,
                                          np.zeros(L.NDOF), 0.0, q0, np.zeros(L.NDOF), self.tol_f, self.maxit,
                                          self.maxstep, out_q, out_v, out_status, out_iter, out_rec)
        t = (nskip + np.arange(n_rec)) * h
        theta_c = self.omega_c * t
        return DynamicResult(theta_c, np.full(n_rec, -self.load_torque), out_q, out_status, out_iter, out_rec,
                             int(failed), t=t, v=out_v, frequencies=w / (2 * math.pi), time_step=h)

    def _failed(self, eq: SweepResult) -> DynamicResult:
        return DynamicResult(eq.theta_c, eq.torque, eq.q, eq.status, eq.iterations, eq.rec, 0,
                             t=np.zeros(1), v=np.zeros((1, L.NDOF)), frequencies=np.zeros(0), time_step=0.0)


def integrate_small_system(M, C, kind, idx, coef, off, k0, pw, gap, Q0, Q1, omega_f, q0, v0, h, nsteps,
                           tol_f: float = 1e-8, maxit: int = 60, maxstep: float = 1e300, ser=None, tab=None):
    """The same Newmark-β loop on a small system given directly as a contact table (no reducer
    geometry): ``M q̈ + C q̇ + Σ Gᵀ f(G q + off) = Q0 + Q1 sin(omega_f t)``.  For the tests (1-DOF
    oscillators against closed forms and SciPy).  Returns ``(t, q, v, status)`` for steps 1..nsteps."""
    nd = len(q0)
    rows = np.asarray(idx)
    if np.any((rows[..., 1:] >= 0) & (rows[..., :-1] < 0)):
        raise InputError("contact table: idx rows must be filled from the left (the first -1 ends a row)", key="idx")
    f = lambda a, dt=float: np.ascontiguousarray(a, dtype=dt)  # noqa: E731
    out_q, out_v = np.zeros((nsteps, nd)), np.zeros((nsteps, nd))
    out_status, out_iter, out_rec = np.full(nsteps, -1, np.int64), np.zeros(nsteps, np.int64), np.zeros((nsteps, K.NREC))
    ser = np.zeros((len(kind), L.NSER)) if ser is None else ser
    tab = np.zeros((1, 4, 2)) if tab is None else tab
    failed = K.newmark_run(0.0, 0.0, float(h), int(nsteps), 1, False, np.zeros(L.NPRM), np.zeros(L.NERR),
                           np.zeros((3, L.N_DISC, 1)), np.zeros((L.N_DISC, 2, L.NH, 2)), np.zeros((2, 1)),
                           f(kind, np.int64), f(idx, np.int64), f(coef), f(off), f(k0), f(pw), f(gap), f(ser), f(tab),
                           np.ones(nd),
                           f(M), f(C), f(Q0), f(Q1), float(omega_f), f(q0), f(v0), float(tol_f), int(maxit),
                           float(maxstep), out_q, out_v, out_status, out_iter, out_rec)
    if failed >= 0:
        raise RuntimeError(f"Newmark failed at step {failed + 1}: status {out_status[failed]}")
    return h * np.arange(1, nsteps + 1), out_q, out_v, out_status
