"""Torsion (hysteresis) curve of the 20-DOF model: input locked, output torque swept.

The test-rig hysteresis measurement, simulated on doc 000's 20-DOF model
(:mod:`rvtol.models.reducer_20dof`, :meth:`QuasiStaticSolver.torsion`): the
input is locked at its nominal position and the carrier torque runs
``0 → +T_r → −T_r → 0`` quasi-statically (each equilibrium warm-started from
the previous one), with the clearances and errors of the sample.  From the
curve, by the maker's definitions (``../shared/REFERENCE.md``):

* **torsional rigidity** ``b/a``: the torque span ``b = 2 T_r`` over the
  angle span ``a`` between the rated-torque end points of the mid-line
  (REFERENCE's reading, output ``torsional_rigidity``).  The maker's figure
  leaves room for two other readings, both reported beside it:
  ``rigidity_50_100``, the mid-line's slope between 50 % and 100 % of rated
  torque (both signs: ``T_r / [(θ(T_r) − θ(T_r/2)) + (θ(−T_r/2) − θ(−T_r))]``,
  the range where the clearances are closed and the contact laws nearly
  linear), and ``rigidity_clearance_free``, ``b/a`` with the free play taken
  out of ``a`` (``2 T_r / (a − backlash)``: the curve of the same reducer
  without its dead band at zero torque);
* **lost motion**: angle between the mid-points of the hysteresis width at
  ``+p %`` and ``−p %`` of rated torque (``p = 3`` by default, a parameter);
* **backlash**: the hysteresis width at zero torque, ``θ_desc(0) − θ_asc(0)`` (REFERENCE's
  "torsion angle at zero torque": the angle between the two branches' zero-torque points).

**Friction** (issue 23; :mod:`rvtol.models.reducer_20dof.friction`).  Where the design gives friction
coefficients (``[friction]``: pins sliding in their grooves, needle rows, tapered crank-support pairs) the
loop has a friction width beside its free play: each contact's Coulomb friction, from the normal force the
model solves, is referred to the output through the reducer's kinematics as the friction torque ``T_f``
(:func:`rvtol.models.reducer_20dof._kernels.friction_torque`), opposing the motion of the branch — rising
torque on the loading branches, falling on the unloading one.  The frictionless curve θ₀ is solved as before;
a point of a branch moving in direction d (+1, −1) at elastic torque ``T_e`` lies at output torque
``T = T_e + d T_f(T_e)`` (:func:`friction_loop`: first order, the friction forces' redistribution of the
contact loads left out), and the points the maker's figures are read at are solved exactly (``T_e`` found by
fixed point, a few equilibria).  At the tips every contact sticks until the torque has turned by 2 T_f (the
loop's vertical segments).  How the maker's definitions read a loop with friction:

* **lost motion** — the mid-points of the loop's width at ±p %: friction shifts the two branches nearly
  symmetrically and cancels in the mid-points to first order; it stays only through the load dependence of
  friction and stiffness (second order);
* **backlash** — the loop's width at zero torque (read at ±ε): the free play plus the width the
  load-independent friction holds there (the tapered pairs' preload: the reducer crosses its free play at
  ``T = ∓T_f(0)``, not at 0); the pins' and needles' friction, proportional to their loads, vanishes with
  the torque;
* **rigidity b/a** — ``a`` between the loop's tips at ±T_r, which lie on the loading branches (at a turning
  point every contact sticks: the loop closes there), so friction makes the end-point reading stiffer by
  about its own share of the torque; the 50–100 % reading is taken on the loading branches (as a maker reads
  spring constants on the loading curve; on the mid-line its upper point would be a tip and its lower one
  the loop's middle); the clearance-free reading is the end-point one less the backlash;
* **friction width** (output ``friction_width``) — the loop's width at ±p %, mean of the two signs: with the
  clearances closed there, the friction's own figure beside the free play (``backlash``);
  ``hysteresis_width`` is the largest width away from zero torque.

Doc 000's model has no friction, so away from zero torque the branches
coincide (``hysteresis_width`` and ``friction_width`` ~0) and at zero
torque the curve jumps across the clearances; the equilibrium at exactly zero
is not unique, so the branches are read at ``±ε`` (``ε = 1e-4 T_r``): the
descending branch just above zero, the ascending one just below.  For
``τ > 0`` the ascending branch is the first loading ``0 → +T_r`` (the same
equilibria without friction).

``compliance_breakdown`` splits the angle at any torque into its compliance
families by virtual work: ``T θ = Σ_c f_c · (G_c q)`` over the contacts (sun
support, sun–planet meshes, pins, cycloid–crank bearings, crank–carrier
bearings, carrier–housing bearing), a contact with elements in series split
into ``f·δ_i(f)`` per element (crankshaft bending and torsion, the tapered
crank-support pair, carrier, pin grooves, disc webs, input shaft: the
design's compliance chain, :mod:`rvtol.models.reducer_20dof.compliance`),
exact at equilibrium — the 20-DOF counterpart of doc 004's θ1 … θ5.

``[model] kind = "torsion_curve"`` (design: a 20-DOF design such as
``data/designs/rv80e_te.toml``; factors: those of the transmission-error
model, :mod:`rvtol.models.reducer_20dof.factors`)::

    percent = 3.0          # lost motion within ±percent % of rated torque
    points = 20            # torque steps per quarter cycle
    torque = 784           # N·m (default: the design's rated torque)
    harmonic = 2           # of the Table 3 tooth patterns
    tol_force = 1e-6       # N
    max_iterations = 200
    compliance_chain = true   # the design's compliance elements in series (false: doc 000's rigid chain)
    friction = true        # the design's Coulomb friction where it gives coefficients (false: frictionless)
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import optimize

from ... import units
from ...errors import InputError
from ...model import STATUS_NONFINITE, Model, Quantity
from ...model_kind import ModelKind, require_design
from ...options import option
from ..reducer_20dof import layout as L
from ..reducer_20dof.factors import ErrorFactors, ErrorState
from ..reducer_20dof.geometry import RVGeometry, geometry_from_design
from ..reducer_20dof.quasistatic import ContactSolveOptions, QuasiStaticSolver

EPSILON = 1e-4           # fraction of rated torque at which the branches are read around zero
#: fixed-point steps and tolerance (fraction of rated torque) of a reading point on a loop with friction; the elastic
#: torque at which a reading stuck at the edge of the free play is solved (fraction of rated torque)
MAX_READING_STEPS, READING_TOL, EDGE = 12, 1e-9, 1e-9
BRANCHES = ("loading 0 → +T", "descending +T → −T", "ascending −T → 0")
#: the direction each branch moves in (+1: torque rising, −1: falling)
DIRECTION = (1.0, -1.0, 1.0)
#: the six cycloid–crank bearing clearances δ_b (disc j, crank i) of the 20-DOF model
CAMS = tuple(f"delta_b[{j},{i}]" for j in (1, 2) for i in (1, 2, 3))

OUTPUTS = (
    Quantity("lost_motion", "rad", "arcmin", "angle between the hysteresis mid-points at ±p % rated torque"),
    Quantity("torsional_rigidity", "N*mm/rad", "N*m/arcmin", "b/a between the rated-torque end points"),
    Quantity("backlash", "rad", "arcmin", "hysteresis width at zero torque"),
    Quantity("angle_at_rated", "rad", "arcmin", "mid-line torsion angle at +rated torque"),
    Quantity("hysteresis_width", "rad", "arcsec", "largest hysteresis width away from zero torque"),
    Quantity("rigidity_50_100", "N*mm/rad", "N*m/arcmin", "mid-line slope between 50 % and 100 % rated torque"),
    Quantity("rigidity_clearance_free", "N*mm/rad", "N*m/arcmin", "b/a with the backlash taken out of a"),
    Quantity("friction_width", "rad", "arcsec", "loop width at ±p % rated torque (friction), mean of both signs"),
)
#: the readings of the maker's rigidity b/a (module doc): output name -> reading
RIGIDITY_READINGS = {
    "torsional_rigidity": "b/a between the rated-torque end points of the mid-line (REFERENCE)",
    "rigidity_50_100": "mid-line slope between 50 % and 100 % of rated torque",
    "rigidity_clearance_free": "b/a with the backlash (free play at zero torque) taken out of a",
}


def torque_schedule(rated: float, points: int = 20, percent: float = 3.0,
                    epsilon: float = EPSILON) -> tuple[np.ndarray, np.ndarray]:
    """``(torque, branch)``: 0 → +T → −T → 0 with ``points`` steps per quarter, plus ±ε and ±p %."""
    T = float(rated)
    quarter = np.concatenate([np.linspace(0.0, T, points + 1), [epsilon * T, percent / 100.0 * T, 0.5 * T]])
    quarter = np.unique(quarter)                                    # 0 … T, increasing
    pos = quarter[1:]
    up = quarter
    down = np.concatenate([pos[::-1], -pos])                        # T … ε, −ε … −T
    back = np.concatenate([-pos[::-1][1:], [0.0]])                  # … −ε, 0
    torque = np.concatenate([up, down[1:], back])
    branch = np.concatenate([np.zeros(up.size), np.ones(down.size - 1), np.full(back.size, 2)]).astype(int)
    return torque, branch


@dataclass
class CurveMetrics:
    """Maker's figures of one torsion curve (base units: rad, N·mm/rad)."""

    lost_motion: float
    rigidity: float
    backlash: float
    angle_at_rated: float
    hysteresis_width: float
    rigidity_50_100: float = math.nan
    rigidity_clearance_free: float = math.nan
    friction_width: float = math.nan

    def as_row(self) -> np.ndarray:
        return np.array([self.lost_motion, self.rigidity, self.backlash, self.angle_at_rated,
                         self.hysteresis_width, self.rigidity_50_100, self.rigidity_clearance_free,
                         self.friction_width])

    def readings(self) -> dict:
        """The rigidity under each reading (:data:`RIGIDITY_READINGS`), N·mm/rad."""
        return {"torsional_rigidity": self.rigidity, "rigidity_50_100": self.rigidity_50_100,
                "rigidity_clearance_free": self.rigidity_clearance_free}


@dataclass
class TorsionCurve:
    """One simulated hysteresis curve (base units: N·mm, rad)."""

    torque: np.ndarray
    angle: np.ndarray
    branch: np.ndarray
    rated: float
    status: int = 0
    reason: str = ""
    q: np.ndarray | None = None       # [n, 20] equilibria (20-DOF coordinates)
    friction: np.ndarray | None = None   # [n] friction torque at the output (N·mm) of each point; None: frictionless
    elastic: np.ndarray | None = None    # [n] elastic torque T_e of each point (= torque without friction)

    @property
    def ok(self) -> bool:
        return self.status == 0

    @property
    def torque_Nm(self) -> np.ndarray:
        return units.from_base(self.torque, "N*m")

    @property
    def angle_arcmin(self) -> np.ndarray:
        return units.from_base(self.angle, "arcmin")

    @property
    def rated_Nm(self) -> float:
        return float(units.from_base(self.rated, "N*m"))

    def _branch_at(self, b: int, tau: float) -> float:
        idx = np.flatnonzero(self.branch == b)
        if idx[0] > 0:                      # a branch starts where the previous one ended
            idx = np.concatenate([[idx[0] - 1], idx])
        t, a = self.torque[idx], self.angle[idx]
        o = np.argsort(t)
        t, a = t[o], a[o]
        if not t[0] - 1e-9 * self.rated <= tau <= t[-1] + 1e-9 * self.rated:
            return math.nan
        return float(np.interp(tau, t, a))

    def descending(self, tau: float) -> float:
        return self._branch_at(1, tau)

    def ascending(self, tau: float) -> float:
        """Ascending branch: ``−T → 0`` up to zero, the first loading ``0 → +T`` above (the same elastic states as
        the loop's closing leg: the frictionless curve does not depend on the path, and the friction torque
        of a rising torque is the same)."""
        return self._branch_at(2 if tau <= 0 else 0, tau)

    def loading(self, tau: float) -> float:
        """The branch that loads towards ``tau``: ascending above zero, descending below (the branch a stiffness
        is read on where the loop has friction width)."""
        return self.ascending(tau) if tau > 0 else self.descending(tau)

    def midline(self, tau: float) -> float:
        return 0.5 * (self.descending(tau) + self.ascending(tau))

    def metrics(self, percent: float = 3.0, epsilon: float = EPSILON) -> CurveMetrics:
        T, p, e = self.rated, percent / 100.0 * self.rated, epsilon * self.rated
        lm = self.midline(p) - self.midline(-p)
        span = self.midline(T) - self.midline(-T)
        backlash = self.descending(e) - self.ascending(-e)
        taus = self.torque[(np.abs(self.torque) >= 2 * e)]
        width = max((abs(self.descending(t) - self.ascending(t)) for t in np.unique(taus)), default=0.0)
        line = self.loading if self.friction is not None else self.midline
        upper = (line(T) - line(0.5 * T)) + (line(-0.5 * T) - line(-T))
        free = span - backlash
        friction = 0.5 * ((self.descending(p) - self.ascending(p)) + (self.descending(-p) - self.ascending(-p)))
        return CurveMetrics(lm, 2.0 * T / span if span > 0 else math.nan, backlash, self.midline(T), width,
                            T / upper if upper > 0 else math.nan, 2.0 * T / free if free > 0 else math.nan,
                            friction)

    def to_frame(self) -> pd.DataFrame:
        return pd.DataFrame({"branch": [BRANCHES[b] for b in self.branch], "torque (N·m)": self.torque_Nm,
                             "torsion angle (arcmin)": self.angle_arcmin})

    def plot(self, ax=None, percent: float | None = 3.0):
        from ...plotting.stiffness import plot_torsion_curve

        return plot_torsion_curve(self, ax=ax, percent=percent)


class _Failed(Exception):
    """An equilibrium of a reading point failed (its status)."""

    def __init__(self, status: int):
        super().__init__(status)
        self.status = int(status)


def _sorted(x, y):
    """``(x, y)`` sorted by ``x`` (for :func:`numpy.interp`)."""
    o = np.argsort(x, kind="stable")
    return x[o], y[o]


def reading_points(rated: float, percent: float = 3.0, epsilon: float = EPSILON) -> list[tuple[int, float]]:
    """``(branch, torque)`` of every point the maker's figures read on a loop with friction (:meth:`TorsionCurve.metrics`):
    both branches at ±p %, the descending at +ε and the ascending at −ε, the tips, the loading branches at ±½T_r."""
    T, p, e = float(rated), percent / 100.0 * rated, epsilon * rated
    return [(0, p), (1, p), (1, -p), (2, -p), (1, e), (2, -e), (0, T), (1, -T), (0, 0.5 * T), (1, -0.5 * T)]


def friction_loop(torque, branch, angle, friction, rated: float, readings=(), q=None):
    """The hysteresis loop with friction from a frictionless torsion curve (module doc).

    ``torque``, ``branch``, ``angle``: the frictionless curve (its torques are the elastic torques ``T_e``);
    ``friction``: the friction torque at the output ``T_f(T_e)`` of each of its points; ``readings``: exact points
    ``(branch, T, angle, T_e, T_f[, q])`` (solved at ``T = T_e + d T_f(T_e)``) inserted where the figures are
    read, the tips ``(0, +T_r)`` and ``(1, −T_r)`` among them.  Every point of a branch moving in direction ``d``
    (:data:`DIRECTION`) moves to ``T = T_e + d T_f``; points beyond ±T_r are dropped; after a tip the unloading
    branch keeps the tip's angle until it reaches it at ``T_r − 2 T_f`` (the contacts stick while the torque
    turns by 2 T_f: the tip's elastic state seen from the other side).
    Returns ``(torque, angle, branch, elastic, friction, q)`` ordered branch by branch along the path."""
    torque, angle, friction = (np.asarray(a, dtype=float) for a in (torque, angle, friction))
    branch = np.asarray(branch, dtype=int)
    d = np.asarray(DIRECTION)[branch]
    nq = None if q is None else np.asarray(q, dtype=float)
    rows = [(int(b), float(t + dd * f), float(a), float(t), float(f), None if nq is None else nq[k])
            for k, (b, t, a, f, dd) in enumerate(zip(branch, torque, angle, friction, d))]
    exact = [(int(r[0]), float(r[1]), float(r[2]), float(r[3]), float(r[4]), r[5] if len(r) > 5 else None)
             for r in readings]
    T = float(rated)
    tips = {r[0]: r[2] for r in exact if abs(abs(r[1]) - T) <= 1e-12 * T}
    # where the unloading branch leaves a tip's angle: the tip's elastic state at T_e − d T_f, d the next branch's
    corners = [(b + 1, r[3] + DIRECTION[b + 1] * r[4], r[2], r[3], r[4], r[5])
               for r in exact for b in (r[0],) if abs(abs(r[1]) - T) <= 1e-12 * T]
    keep = [r for r in rows if abs(r[1]) <= T * (1.0 + 1e-12)] + exact + corners
    out = []
    for b in range(len(BRANCHES)):
        part = [r for r in keep if r[0] == b]
        part.sort(key=lambda r: DIRECTION[b] * r[1])
        for r in part:
            a = r[2]
            if b == 1 and 0 in tips:
                a = min(a, tips[0])
            if b == 2 and 1 in tips:
                a = max(a, tips[1])
            out.append((b, r[1], a, r[3], r[4], r[5]))
    arr = lambda k: np.array([r[k] for r in out], dtype=float if k else int)  # noqa: E731
    qs = None if nq is None else np.array([r[5] for r in out])
    return arr(1), arr(2), arr(0), arr(3), arr(4), qs


def compliance_breakdown(g: RVGeometry, errors: ErrorState | None, q, torque: float, theta_c: float = 0.0) -> dict:
    """Torsion angle (rad) per compliance family by virtual work, ``Σ_c f_c·(G_c q) / T`` (see module doc and
    :meth:`QuasiStaticSolver.contact_work`)."""
    work = QuasiStaticSolver(g, errors).contact_work(theta_c, q)
    return {k: w / torque for k, w in work.items()}


class TorsionCurveModel(Model):
    """Lost motion, rigidity and backlash of one reducer per row of error factors (module doc)."""

    outputs = OUTPUTS

    def __init__(self, design_or_geometry, inputs=(), *, percent: float = 3.0, points: int = 20,
                 torque: float | None = None, harmonic: int = 2, tol_f: float = 1e-6, maxit: int = 200,
                 compliance_chain: bool = True, friction: bool = True):
        g = design_or_geometry
        self.geometry = g if isinstance(g, RVGeometry) else geometry_from_design(g, compliance_chain)
        if not 0.0 < percent < 100.0:
            raise InputError(f"percent must lie in (0, 100), got {percent}", key="percent")
        if points < 4:
            raise InputError(f"points must be >= 4, got {points}", key="points")
        self.percent = float(percent)
        self.points = int(points)
        self.torque = float(self.geometry.rated_torque if torque is None else torque)
        if not self.torque > 0:
            raise InputError(f"torque must be > 0, got {self.torque}", key="torque")
        self.factors = ErrorFactors(list(inputs), self.geometry.z_b, harmonic)
        self.inputs = self.factors.names
        self.input_units = self.factors.units
        self.solver_options = dict(tol_f=float(tol_f), maxit=int(maxit))
        self.friction = bool(friction) and self.geometry.friction is not None and self.geometry.friction.active
        self.status_reasons = {**Model.status_reasons, **L.STATUS_REASONS,
                               L.ST_BAD_CLEARANCE: "negative bearing clearance in the sample (clearances must be >= 0)"}

    def state(self, x) -> ErrorState:
        return self.factors.state(np.asarray(x, dtype=float))

    def curve(self, x=None) -> TorsionCurve:
        """The torsion curve of one reducer (``x``: factor values in base units; default all zero)."""
        x = np.zeros(len(self.inputs)) if x is None else np.asarray(x, dtype=float).reshape(len(self.inputs))
        torque, branch = torque_schedule(self.torque, self.points, self.percent)
        empty = np.full(torque.size, np.nan)
        if not np.all(np.isfinite(x)):
            return TorsionCurve(torque, empty, branch, self.torque, STATUS_NONFINITE,
                                self.status_reasons[STATUS_NONFINITE])
        st = self.state(x)
        clear = np.concatenate([st.err[L.DELTA_B:L.DELTA_B + 6], st.err[L.DELTA_OC:L.DELTA_OC + 3],
                                st.err[L.DELTA_CA:L.DELTA_CA + 1]])
        if np.any(clear < 0):
            return TorsionCurve(torque, empty, branch, self.torque, L.ST_BAD_CLEARANCE,
                                self.status_reasons[L.ST_BAD_CLEARANCE])
        solver = QuasiStaticSolver(self.geometry, st, friction=self.friction, **self.solver_options)
        r = solver.torsion(torque)
        if not r.ok:
            return TorsionCurve(torque, empty, branch, self.torque, r.failure,
                                self.status_reasons.get(r.failure, "solver failure"))
        if not self.friction:
            return TorsionCurve(torque, r.te.copy(), branch, self.torque, 0, "", r.q.copy())
        tf, _ = solver.friction_torques(r)
        readings = []
        for b, tau in reading_points(self.torque, self.percent):
            got = self._reading(solver, r, tf, branch, b, tau)
            if isinstance(got, int):
                return TorsionCurve(torque, empty, branch, self.torque, got,
                                    self.status_reasons.get(got, "solver failure"))
            readings.append(got)
        if not np.all(np.isfinite(tf)):
            return TorsionCurve(torque, empty, branch, self.torque, STATUS_NONFINITE,
                                self.status_reasons[STATUS_NONFINITE])
        T, a, b, te, f, q = friction_loop(torque, branch, r.te, tf, self.torque, readings, r.q)
        return TorsionCurve(T, a, b, self.torque, 0, "", q, f, te)

    def _reading(self, solver, r, tf, branch, b: int, tau: float):
        """``(b, tau, angle, T_e, T_f, q)``: the point of branch ``b`` at output torque ``tau`` on the loop with
        friction, a root of ``h(T_e) = T_e + d T_f(T_e) = tau`` (``d`` the branch's direction), each
        equilibrium warm-started from the frictionless curve's nearest point on the same side of the free play;
        or a status code.

        Coulomb friction leaves the root path-dependent where the flank in contact changes ``T_f`` (a root can
        exist on both sides of the play): the branch keeps the side it comes from — the unloading branch (b = 1)
        stays on the positive flank, the reloading one (b = 2) on the negative, as long as a root exists there —
        and only then crosses the play to the side it moves to; the first loading (b = 0) starts inside the play
        and can only reach the side it moves to.  A fixed point first (``T_f`` changes with ``T_e`` by a fraction
        μ of it: a few steps), its root taken where it lies on the side the branch may be on; otherwise Brent's
        method on each side in that order; where no side has a root, the reducer has crossed the play and sticks
        at its far edge in the branch's direction, its friction holding what the contacts do not carry."""
        d = DIRECTION[b]
        T = self.torque
        cache: dict[float, tuple] = {}

        def point(te):
            if te not in cache:
                side = np.flatnonzero(np.sign(r.torque) == np.sign(te)) if te != 0 else np.arange(r.torque.size)
                k = int(side[np.argmin(np.abs(r.torque[side] - te))])
                s = solver.sweep([r.theta_c[k]], [te], 0.0, r.q[k])
                if not s.ok:
                    raise _Failed(s.failure)
                f = float(solver.friction_torques(s)[0][0])
                if not math.isfinite(f):
                    raise _Failed(STATUS_NONFINITE)
                cache[te] = (te + d * f, float(s.te[0]), f, s.q[0].copy())
            return cache[te]

        def found(te):
            _, angle, f, q = point(te)
            return b, tau, angle, te, f, q

        def edge(side):
            """The elastic torque just past the free play on ``side``: EDGE of rated, or EPSILON where no contact
            carries so small a load (a clearance-free reducer: its contact laws have no stiffness at zero load)."""
            for frac in (EDGE, EPSILON):
                try:
                    point(side * frac * T)
                    return side * frac * T
                except _Failed as exc:
                    failed = exc
            raise failed

        sides = (-d, d) if b > 0 else (d,)
        on = np.flatnonzero(branch == b)
        try:
            fixed = None
            te = tau - d * float(np.interp(tau, *_sorted(r.torque[on] + d * tf[on], tf[on])))
            for _ in range(MAX_READING_STEPS):
                new = tau - d * point(te)[2]
                if abs(new - te) <= READING_TOL * T:
                    fixed = te
                    break
                if new * te < 0.0:
                    break
                te = new
            reach = abs(tau) + 4.0 * float(np.max(np.abs(tf))) + 1e-3 * T
            for side in sides:
                if fixed is not None and np.sign(fixed) == side:
                    return found(fixed)
                lo, hi = sorted((edge(side), side * reach))
                glo, ghi = point(lo)[0] - tau, point(hi)[0] - tau
                if glo * ghi <= 0.0:
                    te = optimize.brentq(lambda t: point(t)[0] - tau, lo, hi, xtol=READING_TOL * T, rtol=1e-15,
                                         maxiter=200)
                    return found(te)
            return found(edge(d))
        except _Failed as exc:
            return exc.status

    def evaluate_with_status(self, X):
        X = self.check_input(X)
        Y = np.full((X.shape[0], len(self.outputs)), np.nan)
        status = np.zeros(X.shape[0], np.int16)
        for n, x in enumerate(X):
            c = self.curve(x)
            status[n] = c.status
            if c.ok:
                Y[n] = c.metrics(self.percent).as_row()
                if not np.all(np.isfinite(Y[n])):
                    Y[n], status[n] = np.nan, STATUS_NONFINITE
        return Y, status

    def evaluate(self, X):
        return self.evaluate_with_status(X)[0]


@dataclass
class Options(ContactSolveOptions):
    """The keys of ``[model] kind = "torsion_curve"``."""

    percent: float = option(3.0, "the maker's lost-motion torque band ±percent of rated torque", min=0.01, max=50.0)
    points: int = option(20, "load steps of each branch of the curve", min=4, max=1000)
    torque: float | None = option(None, "the curve's end torque (default: the design's rated torque)", unit="N*m",
                                  positive=True)
    tol_force: float = option(1e-6, "N: the largest residual force at convergence, and the force above which a pin "
                                    "counts as loaded (keep it far below the pin forces)", positive=True)
    friction: bool = option(True, "the design's contact friction: the loop's width (rvtol.models.reducer_20dof.friction)")


def build(o: Options, design, spec, error) -> TorsionCurveModel:
    require_design(design, error, "the torsion_curve model needs a 20-DOF design")
    return TorsionCurveModel(design, spec.names, percent=o.percent, points=o.points, torque=o.torque,
                             harmonic=o.harmonic, tol_f=o.tol_force, maxit=o.max_iterations,
                             compliance_chain=o.compliance_chain, friction=o.friction)


from_study = ModelKind(Options, build, "the 20-DOF torsion (hysteresis) curve: lost motion, backlash, rigidity")
