"""The hysteresis (torsion) curve of the 20-DOF model: input locked, output torque swept.

* :mod:`.model` — :class:`TorsionCurve` (one curve and its metrics: rigidity,
  lost motion at ±p % of rated, backlash) and :class:`TorsionCurveModel`
  (``MODELS["torsion_curve"]``);
* :mod:`.screening` — the bridge between doc 001's factors and the 20-DOF's, and
  the 20-DOF backlash rates per doc-001 factor (used by ``lost_motion_screening``);
* :mod:`.analyses` — curve, clearance sweeps and the comparison with the
  analytical models (``ANALYSES["torsion_curve"]``).
"""
