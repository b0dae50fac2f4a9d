"""A measured hysteresis curve read by the maker's definitions, as the 20-DOF model's own curve is read.

The end-of-line test of a reducer records its hysteresis curve (torque, angle); :func:`hysteresis_figures` reads
lost motion, backlash and rigidity off it with :meth:`TorsionCurve.metrics <.model.TorsionCurve.metrics>` and
propagates each angle's uncertainty to them.  The per-serial update (:mod:`rvtol.production.per_serial`) reaches it
through :func:`rvtol.registry.curve_reader`.
"""
from __future__ import annotations

import numpy as np

from ...errors import InputError
from ..calibration.measurements import TORSION, load_measurement
from .model import TorsionCurve

#: the figures, in the order :func:`hysteresis_figures` reads them
CURVE_FIGURES = ("lost_motion", "backlash", "rigidity", "rigidity_50_100")
CURVE_DRAWS = 400


def curve_branches(torque: np.ndarray) -> np.ndarray:
    """The branch of each point of a hysteresis test in its order: 0 loading 0 → +T, 1 descending +T → −T, 2
    ascending −T → 0 (the monotone runs of the torque; a turning point belongs to the run it ends; a repeated torque
    — a pause, two readings at zero — continues the run it is in)."""
    step = np.sign(np.diff(torque))
    moving = np.flatnonzero(step)
    if moving.size:                      # a repeated torque takes the direction of the last move (the first, at start)
        last = np.maximum.accumulate(np.where(step != 0, np.arange(step.size), -1))
        step = np.where(last >= 0, step[np.maximum(last, 0)], step[moving[0]])
    change = np.concatenate([[False], step[1:] != step[:-1]])
    return np.concatenate([[0], np.cumsum(change)])


def hysteresis_figures(path, percent: float = 3.0, draws: int = CURVE_DRAWS,
                       seed: int = 0) -> tuple[dict[str, float], dict[str, float]]:
    """The maker's figures (:data:`CURVE_FIGURES`, base units) of a measured hysteresis curve — the calibration's
    file format (:func:`rvtol.models.calibration.measurements.load_measurement`: ``torque``, ``angle``,
    ``sigma``), the torque in the test's order 0 → +T → −T → 0, T the largest |torque| — read as the 20-DOF model's
    curve is (:meth:`TorsionCurve.metrics <rvtol.models.torsion_curve.model.TorsionCurve.metrics>`: the mid-line),
    the backlash at zero torque itself (a measured loop crosses its play at a finite slope; the model's frictionless
    curve jumps there and is read at ±ε) and their standard uncertainties by Monte Carlo propagation of each angle's ``sigma``
    (GUM Supplement 1: ``draws`` copies of the curve with independent normal errors, the figures' standard
    deviation).  The torque is taken as exact."""
    m = load_measurement(path, exclude_below=0.0)
    if m.kind != TORSION:
        raise InputError("an end-of-line curve must be a hysteresis curve (columns torque, angle, sigma)", file=m.file)
    if m.sigma is None:
        raise InputError("no 'sigma' column: give each angle's standard uncertainty (k = 1)", file=m.file)
    branch = curve_branches(m.x)
    if branch.max() != 2 or m.x[branch == 0].max() <= 0 or m.x[branch == 1].min() >= 0:
        raise InputError(f"the torque must run 0 → +T → −T → 0 once (found {branch.max() + 1} monotone runs)",
                         file=m.file)
    rated = float(np.abs(m.x).max())

    def figures(angle):
        c = TorsionCurve(m.x, angle, branch, rated).metrics(percent, epsilon=0.0)
        return np.array([c.lost_motion, c.backlash, c.rigidity, c.rigidity_50_100])

    value = figures(m.y)
    if not np.all(np.isfinite(value)):
        missing = [f for f, v in zip(CURVE_FIGURES, value) if not np.isfinite(v)]
        raise InputError(f"the curve does not reach the points its {', '.join(missing)} is read at (±{percent:g} % "
                         "and ±T on both branches; zero torque on the descending and the ascending one)", file=m.file)
    rng = np.random.default_rng(seed)
    sims = np.array([figures(m.y + m.sigma * rng.standard_normal(m.n)) for _ in range(draws)])
    return dict(zip(CURVE_FIGURES, value)), dict(zip(CURVE_FIGURES, sims.std(axis=0, ddof=1)))
