"""Torsion (hysteresis) curve of the 20-DOF model: input locked, output torque swept.

The test-rig hysteresis measurement, simulated on doc 000's 20-DOF model
(:mod:`rvtol.models.transmission`, :meth:`QuasiStaticSolver.torsion`): the
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

Doc 000's model has no friction, so away from zero torque the branches
coincide (``hysteresis_width`` reports the largest width, ~0) and at zero
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
design's compliance chain, :mod:`rvtol.models.transmission.compliance`),
exact at equilibrium — the 20-DOF counterpart of doc 004's θ1 … θ5.

``[model] kind = "torsion_curve"`` (design: a 20-DOF design such as
``data/designs/rv80e_te.toml``; factors: those of the transmission-error
model, :mod:`rvtol.models.transmission.factors`)::

    percent = 3.0          # lost motion within ±percent % of rated torque
    points = 20            # torque steps per quarter cycle
    torque = 784           # N·m (default: the design's rated torque)
    harmonic = 2           # of the Table 3 tooth patterns
    tol_force = 1e-6       # N
    max_iterations = 200
    compliance_chain = true   # the design's compliance elements in series (false: doc 000's rigid chain)
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ... import units
from ...errors import InputError
from ...model import STATUS_NONFINITE, Model, Quantity
from ..transmission import layout as L
from ..transmission.factors import ErrorFactors, ErrorState
from ..transmission.geometry import RVGeometry, geometry_from_design
from ..transmission.model import ST_BAD_CLEARANCE
from ..transmission.quasistatic import QuasiStaticSolver

EPSILON = 1e-4           # fraction of rated torque at which the branches are read around zero
BRANCHES = ("loading 0 → +T", "descending +T → −T", "ascending −T → 0")
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

    def as_row(self) -> np.ndarray:
        return np.array([self.lost_motion, self.rigidity, self.backlash, self.angle_at_rated,
                         self.hysteresis_width, self.rigidity_50_100, self.rigidity_clearance_free])

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
        """Ascending branch: ``−T → 0`` below zero, the first loading ``0 → +T`` above."""
        return self._branch_at(2 if tau < 0 else 0, tau)

    def midline(self, tau: float) -> float:
        return 0.5 * (self.descending(tau) + self.ascending(tau))

    def metrics(self, percent: float = 3.0, epsilon: float = EPSILON) -> CurveMetrics:
        T, p, e = self.rated, percent / 100.0 * self.rated, epsilon * self.rated
        lm = self.midline(p) - self.midline(-p)
        span = self.midline(T) - self.midline(-T)
        backlash = self.descending(e) - self.ascending(-e)
        taus = self.torque[(np.abs(self.torque) >= 2 * e)]
        width = max((abs(self.descending(t) - self.ascending(t)) for t in np.unique(taus)), default=0.0)
        upper = (self.midline(T) - self.midline(0.5 * T)) + (self.midline(-0.5 * T) - self.midline(-T))
        free = span - backlash
        return CurveMetrics(lm, 2.0 * T / span if span > 0 else math.nan, backlash, self.midline(T), width,
                            T / upper if upper > 0 else math.nan, 2.0 * T / free if free > 0 else math.nan)

    def to_frame(self) -> pd.DataFrame:
        return pd.DataFrame({"branch": [BRANCHES[b] for b in self.branch], "torque (N·m)": self.torque_Nm,
                             "torsion angle (arcmin)": self.angle_arcmin})

    def plot(self, ax=None, percent: float | None = 3.0):
        from ...plotting.stiffness import plot_torsion_curve

        return plot_torsion_curve(self, ax=ax, percent=percent)


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
                 compliance_chain: bool = True):
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
        self.status_reasons = {**Model.status_reasons, **L.STATUS_REASONS,
                               ST_BAD_CLEARANCE: "negative bearing clearance in the sample (clearances must be >= 0)"}

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
            return TorsionCurve(torque, empty, branch, self.torque, ST_BAD_CLEARANCE,
                                self.status_reasons[ST_BAD_CLEARANCE])
        r = QuasiStaticSolver(self.geometry, st, **self.solver_options).torsion(torque)
        if not r.ok:
            return TorsionCurve(torque, empty, branch, self.torque, r.failure,
                                self.status_reasons.get(r.failure, "solver failure"))
        return TorsionCurve(torque, r.te.copy(), branch, self.torque, 0, "", r.q.copy())

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


def from_study(params, design, spec) -> TorsionCurveModel:
    if design is None:
        raise params.error("kind", "the torsion_curve model needs a 20-DOF design ([study] design = ...)")
    percent = params.float("percent", 3.0, min=0.01, max=50.0)
    points = params.int("points", 20, min=4, max=1000)
    torque = params.quantity("torque", "N*m", None, positive=True)
    harmonic = params.int("harmonic", 2, min=1, max=L.NH - 1)
    tol = params.float("tol_force", 1e-6, positive=True)
    maxit = params.int("max_iterations", 200, min=2)
    chain = params.bool("compliance_chain", True)
    params.finish()
    return TorsionCurveModel(design, spec.names, percent=percent, points=points, torque=torque,
                             harmonic=harmonic, tol_f=tol, maxit=maxit, compliance_chain=chain)
