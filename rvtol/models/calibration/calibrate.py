"""``calibrate``: measured curves + a design + named parameters -> estimates with intervals, a new design.

::

    from rvtol.models.calibration import calibrate, load_measurement
    from rvtol.design import load_design

    design = load_design("data/designs/rv80e_te.toml")
    m = load_measurement("data/measurements/synthetic_rv80e_torsion_curve.csv")
    cal = calibrate(design, [m], ["compliance.crank_support_bearings", "clearance.crank_bearing"])
    print(cal.fit.to_frame())                 # estimates, standard errors, t-based intervals
    print(cal.fit.identifiability.messages)   # what the measurement cannot separate, and why
    cal.write_design("reports/calibrated_designs/rv80e_te_calibrated.toml")

Every measurement gets an angle offset ``offset.<name>`` unless ``offsets=False`` (a rig's angle
zero is arbitrary).  A joint fit of several measurements needs each one's uncertainty (a ``sigma``
column or key): weights then follow the stated uncertainties, never a hidden re-weighting.
"""
from __future__ import annotations

import datetime as _dt
import os
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType

import numpy as np

from ... import units
from ...design import Design, DesignParam
from ...errors import InputError, SolverError
from ...mc import Evaluator
from ...model import Model, Quantity
from ...records import frame_records
from .curves import CurveModel, defined
from .design_file import CALIBRATION, calibrated_factors, write_design
from .fit import FitResult, least_squares_fit
from .measurements import TORSION, Measurement
from .parameters import STIFFNESS, Parameter, check_parameters, make_parameter


class _AllPoints(Model):
    """The curve model at every measured point (NaN at exactly zero torque), for the plots."""

    def __init__(self, model: CurveModel):
        self.model = model
        self.inputs, self.input_units = model.inputs, model.input_units
        self.outputs = tuple(Quantity(f"{m.name}[{int(line)}]", "rad", m.y_unit)
                             for m in model.measurements for line in m.lines[defined(m)])

    def evaluate_with_status(self, X):
        X = self.check_input(X)
        Y = np.full((X.shape[0], len(self.outputs)), np.nan)
        status = np.zeros(X.shape[0], np.int16)
        for n, x in enumerate(X):
            curves, status[n] = self.model.predict(x)
            if status[n] == 0:
                Y[n] = np.concatenate([c[defined(m)] for c, m in zip(curves, self.model.measurements)])
        return Y, status

    def evaluate(self, X):
        return self.evaluate_with_status(X)[0]


@dataclass
class CurveComparison:
    """One measurement beside the calibrated model (display units)."""

    measurement: Measurement
    x: np.ndarray
    measured: np.ndarray
    model: np.ndarray            # model + offset at every point (NaN where undefined: zero torque)
    used: np.ndarray

    @property
    def residual(self) -> np.ndarray:
        return self.model - self.measured

    @property
    def rms(self) -> float:
        r = self.residual[self.used]
        return float(np.sqrt(np.mean(r ** 2)))


@dataclass
class Calibration:
    design: Design
    measurements: tuple[Measurement, ...]
    model: CurveModel
    fit: FitResult
    date: str
    evaluator: Evaluator | None = None
    _comparisons: list | None = None

    # -- the fitted curves ---------------------------------------------------------------------
    def comparisons(self) -> list[CurveComparison]:
        """Per measurement, the measured curve beside the model at the estimate (every point, the ones left
        out of the fit included; one more model evaluation, made once)."""
        if self._comparisons is not None:
            return self._comparisons
        k = len(self.model.inputs)
        ev = (self.evaluator or Evaluator())(_AllPoints(self.model), self.fit.x[None, :k], "calibration: curves")
        if ev.status[0] != 0:
            raise SolverError(f"the model fails at the estimate ({self.model.status_reasons.get(int(ev.status[0]))})")
        parts = np.split(ev.Y[0], np.cumsum([int(defined(m).sum()) for m in self.measurements])[:-1])
        curves = []
        for m, part in zip(self.measurements, parts):
            c = np.full(m.n, np.nan)
            c[defined(m)] = part
            curves.append(c)
        out = []
        for m, c in zip(self.measurements, curves):
            off = next((self.fit.x[j] for j, p in enumerate(self.fit.parameters)
                        if p.kind == "offset" and p.targets[0] == m.name), 0.0)
            out.append(CurveComparison(m, m.x_display, m.y_display, units.from_base(c + off, m.y_unit), m.used))
        self._comparisons = out
        return out

    # -- provenance ----------------------------------------------------------------------------
    @property
    def source(self) -> str:
        shas = " + ".join(m.sha256 for m in self.measurements)
        return f"calibrated: {shas}, {self.date}, fit of {', '.join(self.fit.names)}"

    def _note(self, j: int, prefix: str = "") -> str:
        f, p = self.fit, self.fit.parameters[j]
        d = p.display
        u = "" if p.unit == "1" else f" {p.unit}"
        bits = [f"{prefix}{p.name} = {d(f.x[j]):.5g}{u} ± {d(f.t * f.se[j]):.3g}{u} "
                f"({f.confidence:.0%} CI [{d(f.ci[j, 0]):.5g}, {d(f.ci[j, 1]):.5g}]{u}, t with {f.dof} dof; "
                f"residual s = {np.sqrt(f.s2):.3g}{' (reduced χ²: ' + format(f.s2, '.3g') + ')' if f.weighted else ''})"]
        if f.at_bound[j]:
            bits.append("at a bound: the interval is not valid")
        if p.name in f.identifiability.flagged:
            bits.append("NOT SEPARABLE from this measurement: " + "; ".join(
                m for m in f.identifiability.messages if p.name in m))
        return "; ".join(bits)

    def calibrated_design(self) -> Design:
        """The design with the fitted compliance scales applied and the fitted clearances/factors stored
        under ``[calibration.*]``; every changed entry says where it came from (``source``, ``note``)."""
        f = self.fit
        params = dict(self.design.params)
        for j, p in enumerate(f.parameters):
            if p.kind in ("compliance", "friction"):
                c = f.x[j]
                for key, acts in zip(p.targets, p.acts):
                    old = params.get(key) or DesignParam(key, 1.0, "1", "as derived from first principles (scale 1)")
                    stiff = acts == STIFFNESS
                    value = (tuple(v / c for v in old.value) if isinstance(old.value, tuple) else old.value / c) \
                        if stiff else (tuple(v * c for v in old.value) if isinstance(old.value, tuple)
                                       else old.value * c)
                    note = (self._note(j, f"{p.kind} scale ") + f"; applied to the design value {old.value!r} "
                            f"{old.unit} ({'÷' if stiff else '×'} c), whose source was: {old.source}"
                            + (f" — {old.note}" if old.note else ""))
                    params[key] = DesignParam(key, value, old.unit, self.source, note)
            elif p.kind in ("clearance", "factor"):
                key = f"{CALIBRATION}.{p.kind}.{p.name.partition('.')[2]}"
                params[key] = DesignParam(key, float(p.display(f.x[j])), p.unit, self.source,
                                          self._note(j) + f"; acts on {p.acts_on()}")
        held = calibrated_factors(self.design)
        for name, v in self.model.fixed.items():
            key = f"{CALIBRATION}.factor.{name}"
            if name in held and held[name] == v:
                continue                    # stored by an earlier calibration: keep its provenance
            unit = "deg" if dict(zip(self.model.factors.names, self.model.factors.units))[name] == "rad" else "um"
            params[key] = DesignParam(key, float(units.from_base(v, unit)), unit,
                                      f"held fixed in the calibration of {self.date} (given, not fitted)",
                                      f"the fitted parameters ({', '.join(f.names)}) hold for this value of {name}")
        desc = (self.design.description + " " if self.design.description else "") + \
            f"Calibrated against {', '.join(Path(m.file).name for m in self.measurements)}."
        return Design(f"{self.design.name} (calibrated)", MappingProxyType(params), desc, None)

    def write_design(self, path: str | Path) -> Design:
        """Write :meth:`calibrated_design` to ``path`` (atomically; read back and checked)."""
        src = os.path.normpath(self.design.file) if self.design.file else "<design>"
        comments = [f"Calibrated design written by rvtol.models.calibration on {self.date}.",
                    f"From {src} (sha256 {self.design.sha256 or 'unknown'})",
                    *[f"against {os.path.normpath(m.file)} (sha256 {m.sha256})" for m in self.measurements],
                    f"Fitted: {', '.join(self.fit.names)}. Changed entries carry source = \"calibrated: ...\".",
                    "Fitted clearances/factors are under [calibration.*]: "
                    "rvtol.models.calibration.calibrated_factors(design)."]
        return write_design(self.calibrated_design(), path, comments=comments,
                            source=f"rvtol calibration of {src} against "
                                   f"{', '.join(Path(m.file).name for m in self.measurements)}")

    def summary(self) -> dict:
        """JSON-able (NaN and ±inf as None)."""
        f = self.fit
        num = lambda v: float(v) if np.isfinite(v) else None  # noqa: E731
        return {"parameters": frame_records(f.to_frame()),
                "correlation": {a: {b: num(f.corr[i, j]) for j, b in enumerate(f.names)}
                                for i, a in enumerate(f.names)},
                "n": f.n, "dof": f.dof, "s2": num(f.s2), "weighted": f.weighted, "t": num(f.t), "nfev": f.nfev,
                "model_evaluations": f.evaluations,
                "success": f.success, "message": f.message, "rejected_trial_points": len(f.rejected),
                "identifiable": f.identifiability.ok, "identifiability": f.identifiability.messages,
                "condition_number": num(f.identifiability.condition),
                "multiple_correlation": {k: num(v) for k, v in f.identifiability.multiple.items()},
                "residual_rms": {c.measurement.name: {"value": num(c.rms), "unit": c.measurement.y_unit}
                                 for c in self.comparisons()},
                "measurements": [{"file": m.file, "sha256": m.sha256, "kind": m.kind, "points": m.n,
                                  "used": int(m.used.sum())} for m in self.measurements],
                "source": self.source}


def calibrate(design: Design, measurements, parameters, *, fixed_factors: dict | None = None,
              offsets: bool | dict = True, confidence: float = 0.95, max_correlation: float = 0.95,
              max_condition_index: float = 30.0, evaluator: Evaluator | None = None, date: str | None = None, tol_f: float = 1e-6) -> Calibration:
    """Fit ``parameters`` (names, or :class:`Parameter`) of ``design`` to ``measurements`` (module docstring).

    ``fixed_factors``: ``{factor: base value}`` held fixed (known part errors), on top of the clearances
    and factors a previous calibration stored in ``design`` (those refitted here excepted); ``offsets``: add ``offset.<name>`` per measurement (``True``), none
    (``False``) or per measurement name (``{name: bool}``); ``evaluator``: where the model runs (a
    study's ``ctx.evaluator``; default serial).
    """
    measurements = tuple(measurements)
    names = [m.name for m in measurements]
    if len(set(names)) != len(names):
        raise InputError(f"two measurements are named {sorted(n for n in names if names.count(n) > 1)[0]!r}",
                         key="measurement.name")
    if len(measurements) > 1 and any(m.sigma is None for m in measurements):
        bad = next(m for m in measurements if m.sigma is None)
        raise InputError("a joint fit of several measurements needs each one's uncertainty (a sigma column or "
                         "key): their weights cannot be guessed", file=bad.file, key="sigma")
    params = [p if isinstance(p, Parameter) else make_parameter(p, design, measurements=measurements)
              for p in parameters]
    for m in measurements:
        want = offsets.get(m.name, True) if isinstance(offsets, dict) else bool(offsets)
        if want and not any(p.kind == "offset" and p.targets[0] == m.name for p in params):
            params.append(make_parameter(f"offset.{m.name}", design, measurements=measurements))
    check_parameters(params, int(design.get("pin.count", 40)))
    physical = [p for p in params if p.kind != "offset"]
    offs = [p for p in params if p.kind == "offset"]
    fitted = {t for p in physical if p.kind in ("clearance", "factor") for t in p.targets}
    stored = {k: v for k, v in calibrated_factors(design).items() if k not in fitted}
    fixed = {**stored, **(fixed_factors or {})}
    model = CurveModel(design, measurements, physical, fixed, tol_f=tol_f)
    y = np.concatenate([m.y[m.used] for m in measurements])
    which = np.concatenate([np.full(int(m.used.sum()), i) for i, m in enumerate(measurements)])
    weighted = all(m.sigma is not None for m in measurements)
    sigma = np.concatenate([m.sigma[m.used] if m.sigma is not None
                            else np.full(int(m.used.sum()), float(units.to_base(1.0, m.y_unit)))
                            for m in measurements])
    masks = [(p, which == names.index(p.targets[0])) for p in offs]
    fit = least_squares_fit(model, physical, masks, y, 1.0 / sigma, weighted=weighted, evaluator=evaluator,
                            confidence=confidence, max_correlation=max_correlation,
                            max_condition_index=max_condition_index, kinds=tuple(sorted({m.kind for m in measurements})))
    return Calibration(design, measurements, model, fit, date or _dt.date.today().isoformat(), evaluator)


@dataclass
class CalibrationRun:
    """A study's calibration: the fit (None when it failed, ``failed`` saying why), the curves beside the
    calibrated model, and the calibrated design written to ``output`` — or why not (``not_written``:
    ``"not converged"``, ``"not separable"``)."""

    calibration: Calibration | None
    failed: str | None = None
    output: Path | None = None
    written: str | None = None
    not_written: str | None = None

    @property
    def fit(self) -> FitResult:
        return self.calibration.fit

    def comparisons(self) -> list[CurveComparison]:
        return self.calibration.comparisons()

    def to_frame(self):
        """The fitted parameters (display units)."""
        return self.fit.to_frame()

    def statistics(self):
        """One row: points, parameters, degrees of freedom, residual SD, reduced χ², condition, evaluations."""
        import pandas as pd

        f = self.fit
        return pd.DataFrame([{"points fitted n": f.n, "parameters p": len(f.parameters), "dof ν": f.dof,
                              "s (weighted residual SD)": np.sqrt(f.s2),
                              "reduced χ²": f.s2 if f.weighted else np.nan, f"t({f.dof})": f.t,
                              "condition number (unit columns)": f.identifiability.condition,
                              "optimiser steps": f.nfev, "model evaluations": f.evaluations,
                              "rejected trial points": len(f.rejected)}])

    def plot(self, which: str = "correlation", i: int = 0):
        """``correlation`` of the estimates, or ``curve`` ``i``: the measured curve beside the calibrated model
        with its residuals."""
        from ...plotting.calibration import plot_correlation, plot_overlay

        if which == "correlation":
            return plot_correlation(self.fit.correlation_frame())
        c = self.comparisons()[i]
        m = c.measurement
        return plot_overlay(c.x, c.measured, c.model, c.used, xlabel=m.x_label, ylabel=m.y_label,
                            title=Path(m.file).name, split_at_zero=m.kind == TORSION, unit=m.y_unit)

    def summary(self) -> dict:
        if self.calibration is None:
            return {"failed": self.failed}
        return {**self.calibration.summary(), "design_written": self.written}


def calibrate_study(design: Design, measurements, parameters, *, output: str | Path | None = None,
                    allow_unidentifiable: bool = False, **kw) -> CalibrationRun:
    """:func:`calibrate` as a study runs it: a fit the solver cannot finish is a result that says so; the
    curves beside the calibrated model are computed; the calibrated design is written to ``output`` only
    after a converged fit, and (unless ``allow_unidentifiable``) only when every parameter is separable."""
    try:
        cal = calibrate(design, measurements, parameters, **kw)
    except SolverError as exc:
        return CalibrationRun(None, str(exc), output)
    cal.comparisons()
    run = CalibrationRun(cal, None, output)
    if output is None:
        return run
    if not cal.fit.success:
        run.not_written = "not converged"
    elif not cal.fit.identifiability.ok and not allow_unidentifiable:
        run.not_written = "not separable"
    else:
        cal.write_design(output)
        run.written = str(output)
    return run


def reproduce(design: Design, measurements, *, offsets: dict | None = None) -> list[np.ndarray]:
    """The curves (base units) a (calibrated) design gives at the measured points, with its stored
    clearances (:func:`calibrated_factors`) and ``offsets`` (``{measurement name: base value}``) added."""
    model = CurveModel(design, measurements, (), calibrated_factors(design))
    curves, status = model.predict(np.zeros(0))
    if status:
        raise InputError(f"the 20-DOF model fails on this design ({model.status_reasons.get(status, status)})",
                         file=design.file, key="-")
    return [c + (offsets or {}).get(m.name, 0.0) for m, c in zip(measurements, curves)]

