"""Quasi-static equilibria of the 20-DOF model: rotation sweeps (TE) and locked-input torsion.

Two ways to load the reducer, one solver (:func:`._kernels.qs_sequence`):

* **prescribed input angle, output load torque** — the test-rig TE measurement:
  ``solver.rotation(load_torque=T)`` steps the sun through one output
  revolution (nominal carrier angle θ_c = θ_s / i) with a resisting torque T on
  the carrier; ``q[:, THCA]`` is the transmission error Δθ_ca = θ_ca − θ_c;
* **locked input, prescribed output torque** — the torsion/hysteresis test:
  ``solver.torsion(torques, theta_c=θ0)`` keeps the input at its nominal angle
  for θ0 and applies each carrier torque in turn (warm start from the previous
  one, so a 0 → +T → −T → 0 list gives the hysteresis loop); ``q[:, THCA]`` is
  the output torsion angle.

Torques are about +z in N·mm (base units), positive in the direction of
forward output rotation: a load that resists forward motion is negative.  At
exactly zero torque a reducer with clearances has no unique equilibrium; the
solver then returns some position inside the clearance (status OK only if it
converged) — sweep through small non-zero torques to trace the lost motion.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ...errors import InputError
from ...options import option
from . import _kernels as K
from . import layout as L
from .compliance import family_work
from .contacts import pin_cos_sin, static_table
from .factors import ErrorState
from .friction import friction_table
from .geometry import RVGeometry

#: fewest positions per crank revolution a sweep takes (the models' lower bound on ``per_crank_rev``)
MIN_PER_CRANK_REV = 8


@dataclass
class SweepResult:
    """Equilibria along a sequence (base units: rad, N, N·mm)."""

    theta_c: np.ndarray      # nominal carrier angle per position
    torque: np.ndarray       # external carrier torque per position
    q: np.ndarray            # [n, 20] coordinates
    status: np.ndarray       # [n] kernel status (−1: not reached)
    iterations: np.ndarray   # [n] Newton iterations
    rec: np.ndarray          # [n, NREC] per-position forces (see _kernels.R_*)
    failed_at: int           # first failing position or −1

    @property
    def ok(self) -> bool:
        return self.failed_at < 0

    @property
    def failure(self) -> int:
        """Status code of the first failure (0 if none)."""
        return 0 if self.ok else int(self.status[self.failed_at])

    @property
    def te(self) -> np.ndarray:
        """Δθ_ca (rad): transmission error, or torsion angle in a locked-input sweep."""
        return self.q[:, L.THCA]

    @property
    def input_torque(self) -> np.ndarray:
        return self.rec[:, K.R_TORQUE_IN]

    def to_frame(self) -> pd.DataFrame:
        r = self.rec
        return pd.DataFrame({
            "theta_c [deg]": np.degrees(self.theta_c),
            "carrier torque [N*m]": self.torque / 1e3,
            "TE [arcsec]": np.degrees(self.te) * 3600.0,
            "max pin force [N]": r[:, K.R_PIN_MAX],
            "loaded pins disc 1": r[:, K.R_NPIN0].astype(int),
            "loaded pins disc 2": r[:, K.R_NPIN1].astype(int),
            "max cycloid-crank bearing force [N]": r[:, K.R_CAM_MAX],
            "max crank-carrier bearing force [N]": r[:, K.R_CRANK_MAX],
            "carrier-housing bearing force [N]": r[:, K.R_HOUSING],
            "input torque [N*m]": r[:, K.R_TORQUE_IN] / 1e3,
            "status": self.status,
        })


@dataclass
class ContactSolveOptions:
    """The ``[model]`` keys every 20-DOF model kind shares: the error patterns' order and the static contact solve
    (:class:`QuasiStaticSolver`)."""

    harmonic: int = option(2, "the largest harmonic of the profile and pin error patterns (the Table 3 factors)",
                           min=1, max=L.NH - 1)
    tol_force: float = option(1e-5, "N: the largest residual force at convergence, and the force above which a pin "
                                    "counts as loaded (keep it far below the pin forces)", positive=True)
    max_iterations: int = option(200, "Newton iterations per position", min=2)
    compliance_chain: bool = option(True, "the design's compliance elements in series with the contacts (false: "
                                          "doc 000's rigid chain)")


class QuasiStaticSolver:
    """Static equilibria of one reducer (geometry + errors).

    ``tol_f`` (N): largest residual force (torques divided by their arc
    radius) at convergence, and the force above which a pin counts as loaded
    (:func:`._kernels.record`; keep it far below the pin forces: with a
    large ``tol_f`` near zero torque no pin may count, ``ST_LOST_CONTACT``);
    ``maxit``: Newton iterations per position;
    ``maxstep`` (mm): longest Newton step (arc length);
    ``friction``: the geometry's Coulomb friction for :meth:`friction_torques` (:mod:`.friction`; False or a
    geometry without it: none).  The equilibria themselves are frictionless.
    """

    #: the kernel module the sweep runs on (the benchmarks set an earlier commit's to compare)
    kernels = K

    def __init__(self, geometry: RVGeometry, errors: ErrorState | None = None, *, tol_f: float = 1e-5,
                 maxit: int = 200, maxstep: float = 0.02, friction: bool = True):
        self.g = geometry
        self.errors = errors if errors is not None else ErrorState.zero(geometry.z_b)
        if self.errors.pin_err.shape != (3, L.N_DISC, geometry.z_b):
            raise InputError(f"pin error array has shape {self.errors.pin_err.shape}, "
                             f"expected {(3, L.N_DISC, geometry.z_b)}")
        self.tol_f, self.maxit, self.maxstep = float(tol_f), int(maxit), float(maxstep)
        self.prm = geometry.prm()
        self.table = static_table(geometry, self.errors.err, self.errors.preload)
        self.pin_cs = pin_cos_sin(geometry)
        self.xs = geometry.arc_radii()
        self.friction = friction_table(geometry.friction, geometry.z_b, self.errors.preload) if friction else None

    # -- the general entry point --------------------------------------------------------------
    def sweep(self, theta_c, torque, dth_s=0.0, q_start=None, load=None, period: int = 0) -> SweepResult:
        """Equilibria at each ``theta_c[n]`` (rad) under carrier torque ``torque[n]`` (N·mm).

        ``dth_s``: deviation of the input angle from nominal (rad), scalar or per position.
        ``q_start``: warm start for the first position (else a cold start).
        ``load``: further constant generalised forces (20 values, base units), e.g. centrifugal.
        ``period``: positions after which the contact pattern repeats (one crank revolution of a rotation
        sweep), for the predictor (:func:`._kernels.qs_sequence`); 0: none.  The equilibria do not depend on
        it — only the Newton iterations to them.
        """
        theta_c = np.ascontiguousarray(np.atleast_1d(np.asarray(theta_c, dtype=float)))
        n = theta_c.size
        torque = np.ascontiguousarray(np.broadcast_to(np.asarray(torque, dtype=float), (n,)))
        dth = np.ascontiguousarray(np.broadcast_to(np.asarray(dth_s, dtype=float), (n,)))
        if not (np.all(np.isfinite(theta_c)) and np.all(np.isfinite(torque)) and np.all(np.isfinite(dth))):
            raise InputError("angles and torques must be finite")
        cold = q_start is None
        q0 = np.zeros(L.NDOF) if cold else np.array(q_start, dtype=float).reshape(L.NDOF)
        out_q = np.zeros((n, L.NDOF))
        out_status = np.full(n, -1, np.int64)
        out_iter = np.zeros(n, np.int64)
        out_rec = np.zeros((n, K.NREC))
        e = self.errors
        t = self.table
        load = np.zeros(L.NDOF) if load is None else np.ascontiguousarray(load, dtype=float).reshape(L.NDOF)
        failed = self.kernels.qs_sequence(theta_c, dth, torque, load, self.prm, e.err, e.pin_err, e.disc_h,
                                          self.pin_cs, t.kind, t.idx, t.k0, t.pw, t.gap, t.ser, t.tab, self.xs, q0,
                                          cold, self.tol_f, self.maxit, self.maxstep, int(period), out_q,
                                          out_status, out_iter, out_rec)
        return SweepResult(theta_c, torque, out_q, out_status, out_iter, out_rec, int(failed))

    def friction_torques(self, sweep: SweepResult) -> tuple[np.ndarray, np.ndarray]:
        """``(T_f, parts)``: the friction torque at the output (N·mm) of every equilibrium of ``sweep``
        (:func:`._kernels.friction_torques`, :mod:`.friction`) and its share per group ``[n, 3]`` (pins, needle
        rows, crank-support pairs); zeros without friction."""
        n = sweep.theta_c.size
        tf, parts = np.zeros(n), np.zeros((n, 3))
        if self.friction is None:
            return tf, parts
        e, t = self.errors, self.table
        dth = np.zeros(n)
        K.friction_torques(np.ascontiguousarray(sweep.theta_c), dth, np.ascontiguousarray(sweep.q), self.prm, e.err,
                           e.pin_err, e.disc_h, self.pin_cs, t.kind, t.idx, t.k0, t.pw, t.gap, t.ser, t.tab,
                           self.friction, self.xs, tf, parts)
        return tf, parts

    def equilibrium(self, theta_c: float, torque: float, dth_s: float = 0.0, q_start=None) -> SweepResult:
        return self.sweep([theta_c], [torque], dth_s, q_start)

    def contact_work(self, theta_c: float, q, dth_s: float = 0.0) -> dict[str, float]:
        """Work ``Σ_c f_c·(G_c q)`` of the contacts' forces over the motion part of their deflections, by
        compliance family (:data:`rvtol.elements.reducer_chain.FAMILIES`).

        The contact table of the production kernels at ``theta_c`` (:func:`._kernels.update_table`),
        forces by :func:`._kernels.contact_forces` at the coordinates ``q``; a bearing's force acts
        along its total relative displacement ``G q + h``.  A contact with elements in series
        (:mod:`.compliance`) splits its work: each element ``f·δ_i(f)``, the contact's own law the rest.
        Divided by the output torque, the families are the virtual-work breakdown of the output angle at
        an equilibrium (N·mm): doc 000's six contact laws (``sun_support``, ``sun_planet_mesh``,
        ``turning_arm_bearings``, ``crank_support_bearings``, ``carrier_housing_bearing``, ``cycloid_pin``)
        and the chain's families.
        """
        q = np.ascontiguousarray(q, dtype=float).reshape(L.NDOF)
        t, e = self.table, self.errors
        nc = t.kind.size
        coef = np.zeros((nc, 2, t.idx.shape[2]))
        off = np.zeros((nc, 2))
        K.update_table(float(theta_c), float(dth_s), self.prm, e.err, e.pin_err, e.disc_h, self.pin_cs, coef, off)
        F, fc, kt = np.zeros(L.NDOF), np.zeros(nc), np.zeros((nc, 3))
        K.contact_forces(q, t.kind, t.idx, coef, off, t.k0, t.pw, t.gap, t.ser, t.tab, F, fc, kt)
        used = t.idx >= 0
        motion = np.where(used, coef * q[np.where(used, t.idx, 0)], 0.0).sum(axis=2)   # [nc, 2]: G q
        total = motion + off
        radial = t.kind == L.RADIAL
        r = np.hypot(total[:, 0], total[:, 1])
        unit = np.where(r[:, None] > 0, total / np.where(r > 0, r, 1.0)[:, None], 0.0)
        work = np.where(radial, fc * (unit * motion).sum(axis=1), fc * motion[:, 0])
        return family_work(self.g.chain, work, fc)

    # -- the two test-rig set-ups --------------------------------------------------------------
    def positions(self, per_crank_rev: int = 36, revolutions: float = 1.0) -> np.ndarray:
        """Nominal carrier angles of a sweep: ``per_crank_rev`` positions per crank revolution
        (relative to the carrier; z_b crank revolutions per output revolution)."""
        if per_crank_rev < 1:
            raise InputError(f"positions per crank revolution must be >= 1, got {per_crank_rev}")
        n = int(round(per_crank_rev * self.g.z_b * revolutions))
        return 2.0 * np.pi * revolutions * np.arange(n) / n

    def rotation(self, load_torque: float | None = None, per_crank_rev: int = 36,
                 revolutions: float = 1.0) -> SweepResult:
        """Prescribed input angle over ``revolutions`` output revolutions, resisting load torque
        ``load_torque`` (N·mm, ≥ 0; default 3 % of rated)."""
        T = 0.03 * self.g.rated_torque if load_torque is None else float(load_torque)
        theta = self.positions(per_crank_rev, revolutions)
        # the contact pattern repeats every per_crank_rev positions only if they are one crank revolution
        # apart exactly (a whole number of positions over the sweep); else the plain predictor
        exact = (float(per_crank_rev).is_integer()
                 and abs(theta.size - per_crank_rev * self.g.z_b * revolutions) <= 1e-9 * theta.size)
        return self.sweep(theta, -T, period=int(per_crank_rev) if exact else 0)

    def torsion(self, torques, theta_c: float = 0.0, q_start=None) -> SweepResult:
        """Input locked at the nominal position of ``theta_c``; carrier torques applied in turn (frictionless: the
        friction of a hysteresis loop is referred to the output afterwards, :meth:`friction_torques`)."""
        torques = np.asarray(torques, dtype=float).ravel()
        return self.sweep(np.full(torques.size, float(theta_c)), torques, 0.0, q_start)
