"""``[[analysis]] kind = "calibration"``: fit the study's 20-DOF design to measured curves.

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

    [[analysis.measurement]]          # one or more measured curves (rvtol.calibration.measurements)
    file = "../data/measurements/synthetic_rv80e_torsion_curve.csv"
    name = "tc"                       # optional (default: the file's stem)
    units = { angle = "arcsec" }      # units of columns whose header has none
    sigma = 0.5                       # arcsec (or {value, unit}): when the file has no sigma column
    exclude_below = 1.0               # % of the largest |torque| left out of the fit (torsion curve)
    load_torque = 23.52               # N·m (or {value, unit}), TE curve; default 3 % of rated
    offset = true                     # fit an angle offset for this curve

    [[analysis.parameter]]            # the fitted parameters (rvtol.calibration.parameters)
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
from pathlib import Path

import numpy as np
import pandas as pd

from .. import units
from ..analysis import Analysis
from ..errors import InputError, SolverError
from ..params import Params, read_toml
from ..report.sections import Section
from .calibrate import calibrate
from .measurements import TORSION, load_measurement
from .parameters import check_parameters, make_parameter

CALIBRATED_SOURCE = "rvtol calibration"


def _check_output(path: Path, study, params: Params) -> None:
    if study.design is not None and study.design.file and Path(study.design.file).resolve() == path.resolve():
        raise params.error("output", "would overwrite the study's design: name a new file")
    if path.exists():
        if path.is_dir():
            raise params.error("output", f"{path} is a folder, expected a file name")
        try:
            data, _ = read_toml(path)
            ok = str(data.get("design", {}).get("source", "")).startswith(CALIBRATED_SOURCE)
        except InputError:
            ok = False
        if not ok:
            raise params.error("output", f"{path} exists and is not a calibrated design written by rvtol: "
                                         "name a new file")


class CalibrationAnalysis(Analysis):
    def setup(self, params, study):
        if study.design is None:
            raise params.error("kind", "calibration needs a 20-DOF design ([study] design = ...)")
        self.design = study.design
        self.name = params.str("name", "")
        self.key = f"calibration_{self.name}" if self.name else "calibration"
        if any(getattr(a, "key", None) == self.key for a in study.analyses):
            raise params.error("name", f"two calibration analyses with the key {self.key!r}: give each a name")
        out = params.path_value("output", study.base_dir, None)
        if out is not None:
            out = Path(os.path.normpath(out))
            _check_output(out, study, params)
        self.output = out
        self.confidence = params.float("confidence", 0.95, min=0.5, max=0.9999)
        self.max_correlation = params.float("max_correlation", 0.95, min=0.5, max=0.99999)
        self.max_condition_index = params.float("max_condition_index", 30.0, min=1.0)
        self.allow_unidentifiable = params.bool("allow_unidentifiable", False)
        self.tol_f = params.float("tol_force", 1e-6, positive=True)
        self.ratio = float(self.design["reducer.ratio"]) if "reducer.ratio" in self.design else None
        self.measurements, self.offsets = [], {}
        tables = params.tables("measurement")
        if not tables:
            raise params.error("measurement", "give at least one [[analysis.measurement]] table with a file")
        for t in tables:
            self._measurement(t, study)
        names = [m.name for m in self.measurements]
        if len(set(names)) != len(names):
            raise params.error("measurement", "two measurements have the same name: give each a name")
        if len(self.measurements) > 1 and any(m.sigma is None for m in self.measurements):
            raise params.error("measurement", "a joint fit of several curves needs each one's uncertainty "
                                              "(a sigma column or a sigma key per measurement)")
        self.fixed = self._fixed(params.sub("fixed_factors", {}))
        ptables = params.tables("parameter")
        if not ptables:
            raise params.error("parameter", "give at least one [[analysis.parameter]] table with a name")
        self.parameters = []
        for t in ptables:
            self.parameters.append(self._parameter(t))
        try:
            check_parameters(self.parameters + [make_parameter(f"offset.{m.name}", self.design,
                                                               measurements=self.measurements)
                                                for m in self.measurements
                                                if self.offsets[m.name] and not any(
                                                    p.name == f"offset.{m.name}" for p in self.parameters)],
                             int(self.design.get("pin.count", 40)))
        except InputError as exc:
            raise params.error("parameter", exc.reason) from None
        n_used = sum(int(m.used.sum()) for m in self.measurements)
        n_par = len(self.parameters) + sum(1 for m in self.measurements if self.offsets[m.name] and not any(
            p.name == f"offset.{m.name}" for p in self.parameters))
        if n_used <= n_par:
            raise params.error("parameter", f"{n_par} parameters (offsets included) for {n_used} measured points: "
                                            "need more points than parameters")
        clash = sorted(set(self.fixed) & {f for p in self.parameters if p.kind in ("clearance", "factor")
                                          for f in p.targets})
        if clash:
            raise params.error("fixed_factors", f"factor {clash[0]!r} is both fixed and fitted")
        params.finish()

    def _measurement(self, t: Params, study) -> None:
        path = t.path_value("file", study.base_dir)
        name = t.str("name", None)
        col_units = {}
        u = t.sub("units", {})
        for k in list(u.keys()):
            col_units[k] = u.str(k)
        u.finish()
        sigma = t.quantity("sigma", "arcsec", None, positive=True)
        exclude = t.float("exclude_below", 1.0, min=0.0, max=99.0)
        load = t.quantity("load_torque", "N*m", None, positive=True)
        offset = t.bool("offset", True)
        t.finish()
        m = load_measurement(path, column_units=col_units, sigma=sigma, exclude_below=exclude, load_torque=load,
                             ratio=self.ratio, name=name)
        if m.kind == TORSION and "load_torque" in t:
            raise t.error("load_torque", "a torsion curve has no load torque (its torques are in the file)")
        self.measurements.append(m)
        self.offsets[m.name] = offset

    def _fixed(self, p: Params) -> dict[str, float]:
        from ..models.transmission.factors import ErrorFactors

        out = {}
        names = list(p.keys())
        try:
            ef = ErrorFactors(names, int(self.design.get("pin.count", 40)))
        except InputError as exc:
            raise p.error(None, exc.reason) from None
        for n, bu in zip(names, ef.units):
            out[n] = p.quantity(n, "deg" if bu == "rad" else "um")
        p.finish()
        return out

    def _parameter(self, t: Params):
        name = t.str("name")
        unit = t.unit("unit", None)
        start = t.float("start", None)
        bounds = t.floats("bounds", None, length=2)
        t.finish()
        try:
            return make_parameter(name, self.design, start=start, bounds=bounds, unit=unit,
                                  measurements=self.measurements)
        except InputError as exc:
            if exc.file is not None:
                raise
            raise t.error(exc.key if exc.key in ("name", "unit", "start", "bounds") else "name", exc.reason) from None

    # ------------------------------------------------------------------
    def run(self, ctx) -> Section:
        s = Section(self.key, "Calibration against measured curves" + (f": {self.name}" if self.name else ""))
        try:
            cal = calibrate(self.design, self.measurements, self.parameters, fixed_factors=self.fixed or None,
                            offsets=self.offsets, confidence=self.confidence, max_correlation=self.max_correlation,
                            max_condition_index=self.max_condition_index,
                            evaluator=ctx.evaluator, tol_f=self.tol_f)
        except SolverError as exc:
            s.add_text(f"The fit failed: {exc}. No calibrated design was written.")
            s.summary = {"failed": str(exc)}
            return s
        return self._section(s, cal)

    def _section(self, s: Section, cal) -> Section:
        from ..plotting.calibration import plot_correlation, plot_overlay

        f = cal.fit
        ident = f.identifiability
        comps = cal.comparisons()
        lines = []
        for m, c in zip(cal.measurements, comps):
            what = "torsion curve (input locked)" if m.kind == TORSION else (
                f"TE curve under {units.from_base(m.load_torque, 'N*m'):g} N·m" if m.load_torque is not None
                else "TE curve under 3 % of rated torque")
            lines.append(f"{Path(m.file).name} (sha256 {m.sha256[:12]}…): {what}, {m.n} points, {int(m.used.sum())} "
                         f"fitted, σ {'from the file' if m.sigma is not None else 'not given (unit weights)'}; "
                         f"residual RMS {c.rms:.3g} {m.y_unit}." + (" " + " ".join(m.notes) if m.notes else ""))
        s.add_text("Weighted least squares (scipy.optimize.least_squares, trust-region reflective, bounded) of the "
                   "20-DOF model evaluated at the measured torques/angles (the measured curve is not interpolated: "
                   "each point keeps its own noise and weight). Uncertainty from the Jacobian at the estimate: "
                   "C = s²(JᵀJ)⁻¹ with s² the residual variance over ν = n − p degrees of freedom; intervals "
                   f"θ ± t(ν)·√C_jj at {self.confidence:.0%}. Linearised: valid when the model is near-linear over "
                   "the interval and the residuals look like independent noise (plots below). Notes: "
                   "studies/calibration.md.")
        s.add_text("\n\n".join(lines))
        s.add_table(f.to_frame(), "Fitted parameters (display units)", "{:.5g}")
        stats = pd.DataFrame([{"points fitted n": f.n, "parameters p": len(f.parameters), "dof ν": f.dof,
                               "s (weighted residual SD)": np.sqrt(f.s2),
                               "reduced χ²": f.s2 if f.weighted else np.nan, f"t({f.dof})": f.t,
                               "condition number (unit columns)": ident.condition, "optimiser steps": f.nfev,
                               "model evaluations": f.evaluations,
                               "rejected trial points": len(f.rejected)}])
        s.add_table(stats, f"Fit statistics ({f.message})", "{:.4g}")
        corr = f.correlation_frame()
        s.add_table(corr.reset_index(names="ρ"), "Correlation of the estimates", "{:+.3f}")
        if len(f.parameters) > 1:
            s.add_figure(plot_correlation(corr), "Correlation of the estimates", width="60%")
        if ident.ok:
            eta = float(np.nanmax(ident.condition_indices)) if ident.condition_indices.size else 1.0
            s.add_text(f"Identifiability: every parameter is separable by these measurements (largest |ρ| "
                       f"{_max_offdiag(f.corr):.3f} ≤ {self.max_correlation:g}; largest condition index {eta:.3g} ≤ "
                       f"{self.max_condition_index:g}).")
        else:
            s.add_text("IDENTIFIABILITY WARNING — " + "\n\n".join(ident.messages))
        for c in comps:
            m = c.measurement
            fig = plot_overlay(c.x, c.measured, c.model, c.used, xlabel=m.x_label,
                               ylabel=m.y_label, title=Path(m.file).name, split_at_zero=m.kind == TORSION,
                               unit=m.y_unit)
            s.add_figure(fig, f"{m.name}: measured and calibrated model; residuals")
        written = None
        if self.output is not None:
            if not f.success:
                s.add_text(f"The optimiser did not converge ({f.message}): no design written.")
            elif not ident.ok and not self.allow_unidentifiable:
                s.add_text(f"No design written to {self.output}: some parameters are not separable (above). Fix "
                           "them or add a measurement that separates them, or set allow_unidentifiable = true "
                           "(the notes of the written entries then carry the warning).")
            else:
                cal.write_design(self.output)
                written = str(self.output)
                s.add_text(f"Calibrated design written to {self.output}: every changed entry has source = "
                           f"\"{cal.source}\" and its estimate ± interval in its note.")
        s.summary = {**cal.summary(), "design_written": written}
        return s


def _max_offdiag(c: np.ndarray) -> float:
    if c.shape[0] < 2:
        return 0.0
    off = np.abs(c[~np.eye(c.shape[0], dtype=bool)])
    return float(np.nanmax(off)) if np.isfinite(off).any() else float("nan")
