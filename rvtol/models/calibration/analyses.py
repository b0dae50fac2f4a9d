"""``[[analysis]] kind = "calibration"``: fit the study's 20-DOF design to measured curves.

A thin adapter (:mod:`rvtol.analysis`): its options, one call of
:func:`rvtol.models.calibration.calibrate.calibrate_study`, the layout in
:mod:`rvtol.models.calibration.texts`; ``rvtol kinds calibration`` lists every key.

::

    [[analysis]]
    kind = "calibration"
    name = "torsion"                  # optional: section key calibration_<name> (default: calibration)
    output = "../reports/calibrated_designs/rv80e_te_calibrated.toml"   # optional: the calibrated design
    confidence = 0.95                 # of the t-based intervals
    max_correlation = 0.95            # identifiability: pairs of estimates with |ρ| above this
    max_condition_index = 30          # identifiability: collinear groups (Belsley's condition index)
    allow_unidentifiable = false      # write the design even when parameters are not separable
    fixed_factors = { E_c = 5.0 }     # error factors held at known values (µm / deg, or {value, unit})
    tol_force = 1e-6                  # N, equilibrium tolerance of the 20-DOF solver

    [[analysis.measurement]]          # one or more measured curves (rvtol.models.calibration.measurements)
    file = "../data/measurements/synthetic_rv80e_torsion_curve.csv"
    name = "tc"                       # optional (default: the file's stem)
    units = { angle = "arcsec" }      # units of columns whose header has none
    sigma = 0.5                       # arcsec (or {value, unit}): when the file has no sigma column
    exclude_below = 1.0               # % of the largest |torque| left out of the fit (torsion curve)
    load_torque = 23.52               # N·m (or {value, unit}), TE curve; default 3 % of rated
    offset = true                     # fit an angle offset for this curve

    [[analysis.parameter]]            # the fitted parameters (rvtol.models.calibration.parameters)
    name = "compliance.crank_support_bearings"
    start = 1.0                       # default: 1 (scales), 1 µm (clearances), 0 (factors, offsets)
    bounds = [0.2, 5.0]               # default: [0.1, 10], [0, 50] µm, [−50, 50] µm, [−3600, 3600] arcsec
    unit = "1"                        # of start and bounds (default: 1, um, um or deg, arcsec)

Everything is read and checked when the study loads (the CSV files included: a bad file gives
``FILE: line N, column 'x': reason``).  The section shows the fitted parameters with their
intervals, the correlation matrix, the identifiability verdict, the fit statistics and, per curve,
the measured points beside the calibrated model with the residuals.  The calibrated design is
written only after a successful fit, and (unless ``allow_unidentifiable``) only when every
parameter is separable; an existing ``output`` is replaced only if it is an earlier calibrated
design.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from ... import units
from ...analysis import Analysis, CommonOptions
from ...errors import InputError
from ...options import REQUIRED, option
from ...params import Params, read_toml
from . import texts
from .calibrate import calibrate_study
from .measurements import TORSION, load_measurement
from .parameters import check_parameters, make_parameter

CALIBRATED_SOURCE = "rvtol calibration"


@dataclass
class MeasurementOptions:
    file: Path = option(REQUIRED, "the measured curve (CSV: torque and angle, or output/input angle and te)")
    name: str | None = option(None, "its name (default: the file's stem)")
    units: dict[str, str] = option({}, "units of columns whose header has none ({angle = \"arcsec\"})")
    sigma: float | None = option(None, "one standard uncertainty of every point when the file has no sigma column",
                                 unit="arcsec", positive=True)
    exclude_below: float = option(1.0, "% of the largest |torque| left out of the fit (torsion curve)", min=0.0,
                                  max=99.0)
    load_torque: float | None = option(None, "the resisting output torque of a TE curve (default 3 % of rated)",
                                       unit="N*m", positive=True)
    offset: bool = option(True, "fit an angle offset for this curve")


def load_curve(m: MeasurementOptions, design, error):
    """The measured curve of one ``[[analysis.measurement]]`` table ``m`` (``error``: located in that table)."""
    ratio = float(design["reducer.ratio"]) if design is not None and "reducer.ratio" in design else None
    curve = load_measurement(m.file, column_units=m.units, sigma=m.sigma, exclude_below=m.exclude_below,
                             load_torque=m.load_torque, ratio=ratio, name=m.name)
    if curve.kind == TORSION and m.load_torque is not None:
        raise error("load_torque", "a torsion curve has no load torque (its torques are in the file)")
    return curve


@dataclass
class ParameterOptions:
    name: str = option(REQUIRED, "compliance.<family>, clearance.<name>, factor.<factor> or offset.<measurement>")
    start: float | None = option(None, "start value (default: 1 for scales, 1 µm clearances, 0 factors and offsets)")
    bounds: list[float] | None = option(None, "[low, high] (default: [0.1, 10], [0, 50] µm, [−50, 50] µm, "
                                              "[−3600, 3600] arcsec)", min_length=2)
    unit: str | None = option(None, "unit of start and bounds (default: 1, um, um or deg, arcsec)")

    def complete(self, study, error):
        if self.bounds is not None and len(self.bounds) != 2:
            raise error("bounds", f"expected 2 numbers, got {len(self.bounds)}")
        if self.unit is not None:
            try:
                self.unit = units.canonical(self.unit)
            except InputError as exc:
                raise error("unit", exc.reason) from None


class CalibrationAnalysis(Analysis):
    kind, title = "calibration", "Calibration against measured curves"
    layout = texts.calibration

    @dataclass
    class Options(CommonOptions):
        name: str = option("", "section key calibration_<name> (give one to run the kind twice)")
        output: Path | None = option(None, "where the calibrated design is written (a new file, or an earlier "
                                           "calibrated design)")
        confidence: float = option(0.95, "level of the t-based intervals", min=0.5, max=0.9999)
        max_correlation: float = option(0.95, "identifiability: pairs of estimates with |ρ| above this", min=0.5,
                                        max=0.99999)
        max_condition_index: float = option(30.0, "identifiability: collinear groups (Belsley's condition index)",
                                            min=1.0)
        allow_unidentifiable: bool = option(False, "write the design even when parameters are not separable")
        tol_force: float = option(1e-6, "equilibrium tolerance of the 20-DOF solver (N)", positive=True)
        fixed_factors: Params | None = option(None, "error factors held at known values (µm / deg, or {value, unit})")
        measurement: list[MeasurementOptions] = option(REQUIRED, "[[analysis.measurement]]: the measured curves",
                                                       min_length=1)
        parameter: list[ParameterOptions] = option(REQUIRED, "[[analysis.parameter]]: the fitted parameters",
                                                   min_length=1)

        def complete(self, study, error):
            if study.design is None:
                raise error("kind", "calibration needs a 20-DOF design ([study] design = ...)")
            self.key = self.key or (f"calibration_{self.name}" if self.name else "calibration")
            self.title = self.title or (f"{CalibrationAnalysis.title}: {self.name}" if self.name else None)
            if any(getattr(a, "key", None) == self.key for a in study.analyses):
                raise error("name", f"two calibration analyses with the key {self.key!r}: give each a name")
            if self.output is not None:
                self.output = Path(os.path.normpath(self.output))

    def prepare(self, o, study, error) -> CalibrationPlan:
        return calibration_plan(o, study, error)

    def compute(self, ctx):
        o, p = self.options, self.plan
        return calibrate_study(p.design, p.curves, p.parameters, output=o.output,
                               allow_unidentifiable=o.allow_unidentifiable, fixed_factors=p.fixed or None,
                               offsets=p.offsets, confidence=o.confidence, max_correlation=o.max_correlation,
                               max_condition_index=o.max_condition_index, evaluator=ctx.evaluator, tol_f=o.tol_force)


@dataclass(frozen=True)
class CalibrationPlan:
    """What a calibration reads when the study loads: the design, the measured curves, which of them get an
    angle offset, the error factors held fixed (base units) and the fitted parameters."""

    design: object
    curves: list
    offsets: dict[str, bool]
    fixed: dict[str, float]
    parameters: list


def calibration_plan(o, study, error) -> CalibrationPlan:
    """The :class:`CalibrationPlan` of a ``calibration`` table ``o``: every file read and every parameter checked
    against the design and the curves (the output checked to be new or an earlier calibrated design)."""
    design = study.design
    if o.output is not None:
        _check_output(o.output, study, error)
    curves = [load_curve(m, design, lambda key, reason, i=i: error(f"measurement[{i}].{key}", reason))
              for i, m in enumerate(o.measurement)]
    offsets = {m_curve.name: m.offset for m, m_curve in zip(o.measurement, curves)}
    names = [c.name for c in curves]
    if len(set(names)) != len(names):
        raise error("measurement", "two measurements have the same name: give each a name")
    if len(curves) > 1 and any(c.sigma is None for c in curves):
        raise error("measurement", "a joint fit of several curves needs each curve's uncertainty (a sigma "
                                   "column or key)")
    fixed = _fixed(o.fixed_factors, design) if o.fixed_factors is not None else {}
    parameters = [_parameter(i, t, design, curves, error) for i, t in enumerate(o.parameter)]
    _check_parameters(parameters, curves, offsets, fixed, design, error)
    return CalibrationPlan(design, curves, offsets, fixed, parameters)


def _parameter(i, t, design, curves, error):
    try:
        return make_parameter(t.name, design, start=t.start, bounds=t.bounds, unit=t.unit, measurements=curves)
    except InputError as exc:
        if exc.file is not None:
            raise
        key = exc.key if exc.key in ("name", "unit", "start", "bounds") else "name"
        raise error(f"parameter[{i}].{key}", exc.reason) from None


def _check_parameters(parameters, curves, offsets, fixed, design, error) -> None:
    """Parameters the curves can separate: no two of one thing, more points than parameters (offsets included),
    no factor both fixed and fitted."""
    fitted = {p.name for p in parameters}
    extra = [make_parameter(f"offset.{c.name}", design, measurements=curves)
             for c in curves if offsets[c.name] and f"offset.{c.name}" not in fitted]
    try:
        check_parameters(parameters + extra, int(design.get("pin.count", 40)))
    except InputError as exc:
        raise error("parameter", exc.reason) from None
    n_used = sum(int(c.used.sum()) for c in curves)
    n_par = len(parameters) + len(extra)
    if n_used <= n_par:
        raise error("parameter", f"{n_par} parameters (offsets included) for {n_used} measured points: need "
                                 "more points than parameters")
    clash = sorted(set(fixed) & {f for p in parameters if p.kind in ("clearance", "factor") for f in p.targets})
    if clash:
        raise error("fixed_factors", f"factor {clash[0]!r} is both fixed and fitted")


def _check_output(path: Path, study, error) -> None:
    if study.design is not None and study.design.file and Path(study.design.file).resolve() == path.resolve():
        raise error("output", "would overwrite the study's design: name a new file")
    if path.exists():
        if path.is_dir():
            raise error("output", f"{path} is a folder, expected a file name")
        try:
            data, _ = read_toml(path)
            ok = str(data.get("design", {}).get("source", "")).startswith(CALIBRATED_SOURCE)
        except InputError:
            ok = False
        if not ok:
            raise error("output", f"{path} exists and is not a calibrated design written by rvtol: name a new file")


def _fixed(p: Params, design) -> dict[str, float]:
    """The error factors a ``fixed_factors`` table holds at known values (base units)."""
    from ..reducer_20dof.factors import ErrorFactors

    out = {}
    names = list(p.keys())
    try:
        ef = ErrorFactors(names, int(design.get("pin.count", 40)))
    except InputError as exc:
        raise p.error(None, exc.reason) from None
    for n, bu in zip(names, ef.units):
        out[n] = p.quantity(n, "deg" if bu == "rad" else "um")
    p.finish()
    return out
