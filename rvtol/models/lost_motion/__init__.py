"""Geometric lost motion per stage (doc 001): rvtol's fast screening estimate.

* :mod:`.model` — the formulas in two modes (``document``: as printed; ``consistent``, the
  default: every coefficient from the kinematics), :class:`LostMotionModel`
  (``MODELS["lost_motion"]``), the analytic mean ± T/2 (:func:`analytic`);
* :mod:`.breakdown` — the stage breakdown, analytic beside Monte Carlo;
* :mod:`.analyses` — ``ANALYSES["lost_motion_breakdown"]``, laid out by :mod:`.texts`.

The screening estimate beside the maker's lost motion on the 20-DOF torsion curve
(``ANALYSES["lost_motion_screening"]``) is the package :mod:`rvtol.models.screening`.
"""
from .model import MODES, LostMotionGeometry, LostMotionModel, analytic, factor_moments

__all__ = ["MODES", "LostMotionGeometry", "LostMotionModel", "analytic", "factor_moments"]
