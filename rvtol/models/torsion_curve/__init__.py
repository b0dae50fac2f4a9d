"""The hysteresis (torsion) curve of the 20-DOF model: input locked, output torque swept.

* :mod:`.model` — :class:`TorsionCurve` (one curve and its metrics: rigidity,
  lost motion at ±p % of rated, backlash) and :class:`TorsionCurveModel`
  (``MODELS["torsion_curve"]``);
* :mod:`.analyses` — curve, clearance sweeps and the comparison with the
  analytical models (``ANALYSES["torsion_curve"]``).
"""
