"""Geometric lost motion per stage (doc 001).

* :mod:`.model` — the formulas, :class:`LostMotionModel` (``MODELS["lost_motion"]``),
  the document's analytic mean ± T/2 (:func:`analytic`);
* :mod:`.analyses` — the stage breakdown, analytic beside Monte Carlo
  (``ANALYSES["lost_motion_breakdown"]``).
"""
from .model import LostMotionGeometry, LostMotionModel, analytic, factor_moments

__all__ = ["LostMotionGeometry", "LostMotionModel", "analytic", "factor_moments"]
