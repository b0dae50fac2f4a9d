"""The 20-DOF model's prediction of measured curves, as a Model over the calibration parameters.

:class:`CurveModel` turns one row of physical parameters (compliance scales, clearances, error
factors; :mod:`.parameters`) into the 20-DOF model's values **at the measured abscissae**:

* **torsion curve** — the input locked at its nominal position, the output torque set to each
  measured torque (:meth:`QuasiStaticSolver.torsion`, doc 000's 20-DOF model).  Doc 000's model has
  no friction, so away from zero torque its angle depends on the torque alone, not on the branch
  (:mod:`rvtol.models.torsion_curve.model`): the positive torques are solved in increasing order
  from zero and the negative ones in decreasing order, each equilibrium warm-started from the
  previous one, and the results put back in the file's order.
* **TE curve** — the input turned to each measured position under the measurement's resisting
  load torque (:meth:`QuasiStaticSolver.sweep`, the quasi-static TE of
  :mod:`rvtol.models.transmission`), positions solved in increasing order.

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

from types import MappingProxyType

import numpy as np

from ....design import Design
from ....errors import InputError
from ....model import STATUS_NONFINITE, Model, Quantity
from .. import layout as L
from ..factors import ErrorFactors
from ..geometry import geometry_from_design
from ..model import ST_BAD_CLEARANCE
from ..quasistatic import QuasiStaticSolver
from .measurements import TORSION, Measurement
from ....elements.reducer_chain import SCALE_PREFIX, with_compliance_scales
from .parameters import factor_values, scaled_design_values

LOAD_FRACTION = 0.03     # default resisting torque of a TE measurement (× rated): as TransmissionErrorModel


class CurveModel(Model):
    """Predicted measured curves of one reducer per row of physical calibration parameters.

    ``fixed_factors``: error factors held at known values (base units; e.g. measured part errors,
    or a calibrated design's clearances, :func:`rvtol.models.transmission.calibration.calibrated_factors`).
    """

    status_reasons = {**Model.status_reasons, **L.STATUS_REASONS,
                      ST_BAD_CLEARANCE: "negative bearing clearance (clearances must be >= 0)"}

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
            return nan, ST_BAD_CLEARANCE
        has_scale = any(p.kind == "compliance" for p in self.parameters)
        g = geometry_from_design(self.design_at(x)) if has_scale else self.geometry
        solver = QuasiStaticSolver(g, st, **self.solver_options)
        out = []
        for m in self.measurements:
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


def _torsion_runs(m: Measurement) -> list[np.ndarray]:
    """Indices of the positive torques in increasing order and of the negative ones in decreasing order."""
    pos = np.flatnonzero(m.x > 0)
    neg = np.flatnonzero(m.x < 0)
    return [a for a in (pos[np.argsort(m.x[pos], kind="stable")], neg[np.argsort(-m.x[neg], kind="stable")])
            if a.size]
