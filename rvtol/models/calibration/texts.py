"""What the calibration section says: its prose and the layout of a
:class:`~rvtol.models.calibration.calibrate.CalibrationRun` as report blocks.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ... import units
from ...blocks import Figure, Table, Text, figure_png
from .measurements import TORSION

FAILED = "The fit failed: {why}. No calibrated design was written."

METHOD = ("Weighted least squares (scipy.optimize.least_squares, trust-region reflective, bounded) of the 20-DOF model "
          "evaluated at the measured torques/angles (the measured curve is not interpolated: each point keeps its own "
          "noise and weight). Uncertainty from the Jacobian at the estimate: C = s²(JᵀJ)⁻¹ with s² the residual "
          "variance over ν = n − p degrees of freedom; intervals θ ± t(ν)·√C_jj at {confidence:.0%}. Linearised: "
          "valid when the model is near-linear over the interval and the residuals look like independent noise "
          "(plots below). Notes: studies/calibration.md.")

CURVE = ("{file} (sha256 {sha}…): {what}, {n} points, {used} fitted, σ {sigma}; residual RMS {rms:.3g} {unit}.{notes}")
TORSION_CURVE = "torsion curve (input locked)"
TE_UNDER = "TE curve under {torque:g} N·m"
TE_RATED = "TE curve under 3 % of rated torque"

SEPARABLE = ("Identifiability: every parameter is separable by these measurements (largest |ρ| {rho:.3f} ≤ "
             "{max_rho:g}; largest condition index {eta:.3g} ≤ {max_eta:g}).")
NOT_SEPARABLE = "IDENTIFIABILITY WARNING — "

NOT_CONVERGED = "The optimiser did not converge ({message}): no design written."
NOT_WRITTEN = ("No design written to {output}: some parameters are not separable (above). Fix them or add a measurement "
               "that separates them, or set allow_unidentifiable = true (the notes of the written entries then carry "
               "the warning).")
WRITTEN = ("Calibrated design written to {output}: every changed entry has source = \"{source}\" and its estimate ± "
           "interval in its note.")


def calibration(run, o) -> list:
    if run.calibration is None:
        return [Text(FAILED.format(why=run.failed))]
    cal, f = run.calibration, run.fit
    ident = f.identifiability
    lines = []
    for m, c in zip(cal.measurements, run.comparisons()):
        what = TORSION_CURVE if m.kind == TORSION else (
            TE_UNDER.format(torque=units.from_base(m.load_torque, "N*m")) if m.load_torque is not None else TE_RATED)
        lines.append(CURVE.format(file=Path(m.file).name, sha=m.sha256[:12], what=what, n=m.n, used=int(m.used.sum()),
                                  sigma="from the file" if m.sigma is not None else "not given (unit weights)",
                                  rms=c.rms, unit=m.y_unit, notes=(" " + " ".join(m.notes)) if m.notes else ""))
    blocks = [Text(METHOD.format(confidence=o.confidence)), Text("\n\n".join(lines)),
              Table(f.to_frame(), "Fitted parameters (display units)", "{:.5g}"),
              Table(run.statistics(), f"Fit statistics ({f.message})", "{:.4g}"),
              Table(f.correlation_frame().reset_index(names="ρ"), "Correlation of the estimates", "{:+.3f}")]
    if len(f.parameters) > 1:
        blocks.append(Figure(figure_png(run.plot("correlation")), "Correlation of the estimates", width="60%"))
    if ident.ok:
        eta = float(np.nanmax(ident.condition_indices)) if ident.condition_indices.size else 1.0
        blocks.append(Text(SEPARABLE.format(rho=f.largest_correlation, max_rho=o.max_correlation, eta=eta,
                                            max_eta=o.max_condition_index)))
    else:
        blocks.append(Text(NOT_SEPARABLE + "\n\n".join(ident.messages)))
    blocks += [Figure(figure_png(run.plot("curve", i)), f"{c.measurement.name}: measured and calibrated model; "
                                                        "residuals") for i, c in enumerate(run.comparisons())]
    if run.not_written == "not converged":
        blocks.append(Text(NOT_CONVERGED.format(message=f.message)))
    elif run.not_written == "not separable":
        blocks.append(Text(NOT_WRITTEN.format(output=run.output)))
    elif run.written is not None:
        blocks.append(Text(WRITTEN.format(output=run.output, source=cal.source)))
    return blocks
