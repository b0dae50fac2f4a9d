"""Synthetic measured curves from known parameters plus seeded noise — to test the calibration (a test
oracle, kept out of the package; ``studies/calibration_synthetic_data.py`` makes the repository's synthetic files
with it).

``synthetic_measurement`` evaluates the 20-DOF model
(:class:`rvtol.models.calibration.curves.CurveModel`) with the true parameter values, adds an angle
offset and independent normal noise of standard deviation ``sigma`` drawn from the named sub-stream
``"calibration_noise"`` of ``seed`` (:func:`rvtol.sampling.substream`), and returns it as a :class:`Measurement`;
``write_synthetic_csv`` writes the same as a CSV file whose header says, in words, that it is
synthetic and which parameters made it.

A synthetic torsion curve runs 0 → +T → −T → 0 in ``points`` torque steps per quarter (without the
points at exactly zero torque, where the frictionless model has no unique equilibrium); a synthetic TE curve has ``points``
output angles evenly spaced over one revolution under the load torque.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from rvtol import units
from rvtol.design import Design
from rvtol.models.calibration.curves import LOAD_FRACTION, CurveModel
from rvtol.models.calibration.measurements import TE, TORSION, Measurement
from rvtol.models.calibration.parameters import make_parameter
from rvtol.sampling import substream


def torque_cycle(rated: float, points: int) -> np.ndarray:
    """0 → +T → −T → 0 with ``points`` steps per quarter (base units)."""
    q = int(points)
    return np.concatenate([np.linspace(0.0, rated, q + 1), np.linspace(rated, -rated, 2 * q + 1)[1:],
                           np.linspace(-rated, 0.0, q + 1)[1:]])


def _grid(kind: str, design: Design, points: int, name: str, load_torque: float | None) -> Measurement:
    if kind == TORSION:
        x = torque_cycle(float(design["reducer.rated_torque"]), points)
        x = x[x != 0.0]          # no unique equilibrium at exactly zero torque: no point there
        labels = ("torque [N*m]", "angle [arcsec]", "N*m", "arcsec")
        include = np.ones(x.size, bool)
    else:
        x = 2.0 * np.pi * np.arange(points) / points
        labels = ("output_angle [deg]", "te [arcsec]", "deg", "arcsec")
        include = np.ones(x.size, bool)
    return Measurement(kind, name, "<synthetic>", "", x, np.zeros(x.size), None, *labels,
                       np.arange(x.size) + 1, (), include, load_torque if kind == TE else None)


def synthetic_measurement(design: Design, kind: str, truth: dict, *, sigma: float, seed: int, points: int = 40,
                          offset: float = 0.0, load_torque: float | None = None, name: str = "synthetic",
                          fixed_factors: dict | None = None) -> Measurement:
    """A measured curve made by the model from ``truth`` (``{parameter name: value in its display unit}``),
    plus ``offset`` and noise ``sigma`` (both base units: rad)."""
    if kind == TE and load_torque is None:
        load_torque = LOAD_FRACTION * float(design["reducer.rated_torque"])
    grid = _grid(kind, design, points, name, load_torque)
    params = [make_parameter(n, design) for n in truth]
    x = np.array([float(units.to_base(v, p.unit)) for p, v in zip(params, truth.values())])
    curves, status = CurveModel(design, [grid], params, fixed_factors).predict(x)
    if status:
        raise ValueError(f"the 20-DOF model fails on the true parameters (status {status})")
    noise = substream(seed, "calibration_noise").normal(0.0, sigma, grid.n)
    y = curves[0] + offset + noise
    return Measurement(kind, name, "<synthetic>", "", grid.x, y, np.full(grid.n, float(sigma)), grid.x_label,
                       grid.y_label, grid.x_unit, grid.y_unit, grid.lines, (), grid.include, grid.load_torque)


def write_synthetic_csv(path: str | Path, m: Measurement, comments=()) -> Path:
    """Write a synthetic measurement as CSV (``x``, ``y`` and ``sigma`` in the measurement's display units)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    sig = m.sigma if m.sigma is not None else np.full(m.n, np.nan)
    lines = ["# SYNTHETIC DATA — made by the rvtol 20-DOF model from known parameters plus seeded noise;",
             "# NOT a measurement of any reducer.", *[f"# {c}" for c in comments],
             f"{m.x_label}, {m.y_label}, sigma [{m.y_unit}]"]
    for x, y, s in zip(m.x_display, m.y_display, units.from_base(sig, m.y_unit)):
        lines.append(f"{x:.10g}, {y:.10g}, {s:.6g}")
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path
