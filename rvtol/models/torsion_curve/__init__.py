"""The hysteresis (torsion) curve of the 20-DOF model: input locked, output torque swept.

* :mod:`.model` — :class:`TorsionCurve` (one curve and its metrics: rigidity,
  lost motion at ±p % of rated, backlash) and :class:`TorsionCurveModel`
  (``MODELS["torsion_curve"]``);
* :mod:`.beside_analytical_models` — curves, clearance sweeps, rigidity and compliance: the 20-DOF
  curve beside the analytical models;
* :mod:`.analyses` — ``ANALYSES["torsion_curve"]`` and ``["compliance_breakdown"]``, laid out
  by :mod:`.texts`.

The bridge between doc 001's factors and the 20-DOF's (``lost_motion_screening``) is the package
:mod:`rvtol.models.screening`.
"""
