"""Calibration against measurements: fit named parameters of the 20-DOF model to measured curves.

A measured hysteresis (torsion) curve and/or a measured transmission-error curve (CSV,
:mod:`.measurements`) is compared with the 20-DOF model evaluated at the measured torques/angles
(:mod:`.curves`); a small named set of parameters (:mod:`.parameters`: a compliance scale per
element family, effective clearances, error factors, an angle offset per measurement) is fitted by
weighted least squares with its uncertainty — covariance, t-based confidence intervals,
correlations and an identifiability check that names what the measurement cannot separate
(:mod:`.fit`); the calibrated design is written as a new design file whose changed entries carry
their provenance (:mod:`.design_file`).  Calibration is a result with its own uncertainty, never a
hidden factor: the design file says which numbers were fitted, to what, when, and how well.

::

    from rvtol.models.calibration import calibrate, load_measurement
    cal = calibrate(design, [load_measurement(csv)], ["compliance.all", "clearance.crank_bearing"])
    cal.fit.to_frame(); cal.fit.identifiability.messages; cal.write_design(path)

The study analysis is ``[[analysis]] kind = "calibration"`` (:mod:`.analyses`); synthetic test
curves from known parameters: ``tests/synthetic_curves.py`` (outside the package).  Notes: ``studies/calibration.md``.
"""
from .calibrate import Calibration, CurveComparison, calibrate, reproduce
from .design_file import calibrated_factors, design_toml, write_design
from .fit import FitResult, Identifiability, least_squares_fit
from .measurements import Measurement, load_measurement
from .parameters import CLEARANCES, FAMILIES, Parameter, make_parameter

__all__ = ["Calibration", "CurveComparison", "calibrate", "reproduce", "calibrated_factors", "design_toml",
           "write_design", "FitResult", "Identifiability", "least_squares_fit", "Measurement", "load_measurement",
           "CLEARANCES", "FAMILIES", "Parameter", "make_parameter"]
