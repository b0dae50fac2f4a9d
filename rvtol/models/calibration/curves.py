"""The 20-DOF model's prediction of measured curves, as a Model over the calibration parameters.

:class:`CurveModel` turns one row of physical parameters (compliance scales, clearances, error
factors; :mod:`.parameters`) into the 20-DOF model's values **at the measured abscissae**:

* **torsion curve** — the input locked at its nominal position, the output torque set to each
  measured torque (:meth:`QuasiStaticSolver.torsion`, doc 000's 20-DOF model).  Without friction the
  angle away from zero torque depends on the torque alone, not on the branch
  (:mod:`rvtol.models.torsion_curve.model`): the positive torques are solved in increasing order
  from zero and the negative ones in decreasing order, each equilibrium warm-started from the
  previous one, and the results put back in the file's order.  **With friction** (the design's
  ``[friction]`` coefficients, :mod:`rvtol.models.reducer_20dof.friction`) the file's order is the
  test's loading path: each point's branch moves the way the torque moved to it (d = ±1), and the model's
  angle there is the frictionless angle at the elastic torque ``T_e`` with ``T_e + d T_f(T_e) = T``
  (passes of the fixed point, each a frictionless solve of all points, until ``T_e`` moves by less than 1e-9
  of the largest torque: three or four); after a turning point of
  the load the angle keeps the turning point's until the branch reaches it (the contacts stick).  So a
  fit sees the loop's width where the measured loop has it and does not read it as clearance.
* **TE curve** — the input turned to each measured position under the measurement's resisting
  load torque (:meth:`QuasiStaticSolver.sweep`, the quasi-static TE of
  :mod:`rvtol.models.reducer_20dof`), positions solved in increasing order.

Why the model goes to the measured points and not the reverse: interpolating a noisy measured curve
onto model points would smooth and correlate its noise, change its weights and hide how many
independent points there are; evaluating the model at the measured abscissae leaves every measured
point and its uncertainty as it is, and the solver takes any torque or angle list at the cost of one
equilibrium per point.  (The measured torques/angles are taken as exact; their uncertainty is not
propagated — a rig's torque is usually far more precise, relatively, than its angle.)

The outputs are the predicted angles (rad) at the points each measurement uses
(:attr:`Measurement.used`), measurements one after the other; rows are independent (picklable,
row-deterministic), so the fit's finite-difference Jacobian runs through :class:`rvtol.mc.Evaluator`
on the study's executor.
"""
from __future__ import annotations

from dataclasses import replace
from types import MappingProxyType

import numpy as np

from ...design import Design
from ...errors import InputError
from ...model import STATUS_NONFINITE, Model, Quantity
from ..reducer_20dof import layout as L
from ..reducer_20dof.factors import ErrorFactors
from ..reducer_20dof.friction import friction_from_design
from ..reducer_20dof.geometry import geometry_from_design
from ..reducer_20dof.quasistatic import QuasiStaticSolver
from .measurements import TORSION, Measurement
from ...elements.reducer_chain import SCALE_PREFIX, with_compliance_scales
from .parameters import factor_values, scaled_design_values

LOAD_FRACTION = 0.03     # default resisting torque of a TE measurement (× rated): as TransmissionErrorModel


class CurveModel(Model):
    """Predicted measured curves of one reducer per row of physical calibration parameters.

    ``fixed_factors``: error factors held at known values (base units; e.g. measured part errors,
    or a calibrated design's clearances, :func:`rvtol.models.calibration.calibrated_factors`).
    """

    status_reasons = {**Model.status_reasons, **L.STATUS_REASONS,
                      L.ST_BAD_CLEARANCE: "negative bearing clearance (clearances must be >= 0)"}

    def __init__(self, design: Design, measurements, parameters=(), fixed_factors: dict | None = None, *,
                 tol_f: float = 1e-6, maxit: int = 200):
        self.parameters = tuple(p for p in parameters)
        if any(p.kind == "offset" for p in self.parameters):
            raise InputError("offsets are added by the fit, not by the 20-DOF model", key="parameter")
        self._design_params = dict(design.params)
        self._design_head = (design.name, design.description, design.file)
        self.geometry = geometry_from_design(design)
        self.measurements = tuple(measurements)
        if not self.measurements:
            raise InputError("no measurement", key="measurement")
        self.fixed = dict(fixed_factors or {})
        targets = [t for p in self.parameters if p.kind in ("clearance", "factor") for t in p.targets]
        both = sorted(set(targets) & set(self.fixed))
        if both:
            raise InputError(f"factor {both[0]!r} is both fixed and fitted", key="fixed_factors")
        self.factors = ErrorFactors(list(self.fixed) + targets, self.geometry.z_b)
        self.inputs = tuple(p.name for p in self.parameters)
        self.input_units = self._input_units()
        self.outputs = tuple(Quantity(f"{m.name}[{int(line)}]", "rad", m.y_unit)
                             for m in self.measurements for line in m.lines[m.used])
        self.solver_options = dict(tol_f=float(tol_f), maxit=int(maxit))
        st = self.factors.state(self._factor_row(np.array([p.start for p in self.parameters])))
        if np.any(self._clearances(st) < 0):
            raise InputError("a fixed clearance is negative", key="fixed_factors")

    def _input_units(self) -> tuple[str, ...]:
        unit = dict(zip(self.factors.names, self.factors.units))
        return tuple(unit[p.targets[0]] if p.kind in ("clearance", "factor") else "1" for p in self.parameters)

    # -- one row ---------------------------------------------------------------------------------
    @property
    def design(self) -> Design:
        name, desc, file = self._design_head
        return Design(name, MappingProxyType(dict(self._design_params)), desc, file)

    def design_at(self, x) -> Design:
        """The design with the compliance scales of ``x`` applied (other parameters do not touch it)."""
        d = self.design
        changed = scaled_design_values(d, list(self.parameters), x)
        present = {k: v for k, v in changed.items() if k in d}
        added = {k[len(SCALE_PREFIX):]: v for k, v in changed.items() if k not in d}   # scales left at 1
        d = d.with_values(**present) if present else d
        return with_compliance_scales(d, added, "calibration trial value") if added else d

    def _factor_row(self, x) -> np.ndarray:
        vals = {**self.fixed, **factor_values(list(self.parameters), x)}
        return np.array([vals[n] for n in self.factors.names], dtype=float)

    @staticmethod
    def _clearances(st) -> np.ndarray:
        return np.concatenate([st.err[L.DELTA_B:L.DELTA_B + 6], st.err[L.DELTA_OC:L.DELTA_OC + 3],
                               st.err[L.DELTA_CA:L.DELTA_CA + 1]])

    def predict(self, x) -> tuple[list[np.ndarray], int]:
        """``(curves, status)``: per measurement the model value (rad) at every measured point (NaN at
        exactly zero torque, where the frictionless model has no unique equilibrium)."""
        x = np.asarray(x, dtype=float).reshape(len(self.inputs))
        nan = [np.full(m.n, np.nan) for m in self.measurements]
        if not np.all(np.isfinite(x)):
            return nan, STATUS_NONFINITE
        st = self.factors.state(self._factor_row(x))
        if np.any(self._clearances(st) < 0):
            return nan, L.ST_BAD_CLEARANCE
        has_scale = any(p.kind == "compliance" for p in self.parameters)
        g = geometry_from_design(self.design_at(x)) if has_scale else self.geometry
        if not has_scale and any(p.kind == "friction" for p in self.parameters):
            g = replace(g, friction=friction_from_design(self.design_at(x)))
        solver = QuasiStaticSolver(g, st, **self.solver_options)
        out = []
        for m in self.measurements:
            if m.kind == TORSION and solver.friction is not None:
                y, status = _torsion_with_friction(solver, m)
                if status:
                    return nan, status
                out.append(y)
                continue
            y = np.full(m.n, np.nan)
            runs = _torsion_runs(m) if m.kind == TORSION else [np.argsort(m.x, kind="stable")]
            for idx in runs:
                if m.kind == TORSION:
                    r = solver.torsion(np.concatenate([[0.0], m.x[idx]]))
                    val = r.te[1:]
                else:
                    load = m.load_torque if m.load_torque is not None else LOAD_FRACTION * g.rated_torque
                    r = solver.sweep(m.x[idx], -load)
                    val = r.te
                if not r.ok:
                    return nan, r.failure
                y[idx] = val
            out.append(y)
        return out, 0

    def evaluate_with_status(self, X):
        X = self.check_input(X)
        Y = np.full((X.shape[0], len(self.outputs)), np.nan)
        status = np.zeros(X.shape[0], np.int16)
        for n, x in enumerate(X):
            curves, status[n] = self.predict(x)
            if status[n] == 0:
                Y[n] = np.concatenate([c[m.used] for c, m in zip(curves, self.measurements)])
                if not np.all(np.isfinite(Y[n])):
                    Y[n], status[n] = np.nan, STATUS_NONFINITE
        return Y, status

    def evaluate(self, X):
        return self.evaluate_with_status(X)[0]


def defined(m: Measurement) -> np.ndarray:
    """Points where the model has a value: all but exactly zero torque on a torsion curve."""
    return m.x != 0.0 if m.kind == TORSION else np.ones(m.n, bool)


def _torsion_runs(m: Measurement, x=None) -> list[np.ndarray]:
    """Indices of the positive torques in increasing order and of the negative ones in decreasing order
    (of ``x``, default the measured torques)."""
    x = m.x if x is None else x
    pos = np.flatnonzero(x > 0)
    neg = np.flatnonzero(x < 0)
    return [a for a in (pos[np.argsort(x[pos], kind="stable")], neg[np.argsort(-x[neg], kind="stable")])
            if a.size]


#: fixed-point passes of the elastic torques of a torsion curve with friction, at most, and their tolerance (fraction
#: of the largest measured torque), as the torsion-curve model's reading points
FRICTION_PASSES, FRICTION_TOL = 12, 1e-9


def path_directions(x) -> np.ndarray:
    """Per point of a measured loading path, the direction the torque moved to it: +1 rising, −1 falling (the
    first point from zero, or towards the second where it is zero; a repeated torque keeps the one before)."""
    x = np.asarray(x, dtype=float)
    d = np.sign(np.diff(x, prepend=0.0))
    if d.size > 1 and d[0] == 0.0:
        d[0] = np.sign(x[1] - x[0])
    for k in range(d.size):
        if d[k] == 0.0:
            d[k] = d[k - 1] if k else 1.0
    return d


def _torsion_with_friction(solver: QuasiStaticSolver, m: Measurement) -> tuple[np.ndarray, int]:
    """The model's angles at a measured torsion path with friction (module doc): ``(angles, status)``."""
    x = m.x
    d = path_directions(x)
    te = x.copy()
    y = np.full(m.n, np.nan)
    scale = float(np.max(np.abs(x))) if x.size else 0.0
    for _ in range(FRICTION_PASSES):
        tf = np.zeros(m.n)
        for idx in _torsion_runs(m, te):
            r = solver.torsion(np.concatenate([[0.0], te[idx]]))
            if not r.ok:
                return y, r.failure
            y[idx] = r.te[1:]
            tf[idx] = solver.friction_torques(r)[0][1:]
        if not np.all(np.isfinite(tf)):
            return y, STATUS_NONFINITE
        new = np.where(x != 0.0, x - d * tf, 0.0)
        done = np.max(np.abs(new - te)) <= FRICTION_TOL * scale
        te = new
        if done:
            break
    # stick after a turning point: the angle stays the turning point's until the branch reaches it
    for k in range(1, m.n):
        if d[k] != d[k - 1]:
            tip = y[k - 1]
            j = k
            while j < m.n and d[j] == d[k]:
                y[j] = np.fmin(y[j], tip) if d[k] < 0 else np.fmax(y[j], tip)
                j += 1
    return y, 0
