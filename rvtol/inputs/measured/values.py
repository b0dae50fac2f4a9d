"""Measured values as every method takes them: checked, and corrected for the gauge's uncertainty.

Measurement uncertainty.  With ``measurement_sigma`` u (the gauge's standard uncertainty,
in the data's unit; independent of the parts) the observed variance is the part variance
plus u².  The deconvolution used is the moment one: the values are shrunk about their mean,
x' = x̄ + (x − x̄)·√(1 − u²/s²) (s² the sample variance), which leaves the mean and gives
the part variance s² − u², and the method then runs on x'.  It is exact for normal parts
with a normal gauge error; for other shapes it keeps the observed shape (slightly smoother
than the parts').  u ≥ s is refused (the gauge cannot resolve the parts).
"""
from __future__ import annotations

import math

import numpy as np

from ...errors import InputError


def clean_values(values, what: str = "measured values", min_n: int = 2) -> np.ndarray:
    x = np.asarray(values, dtype=float).ravel()
    if x.size < min_n:
        raise InputError(f"{what}: need at least {min_n} values, got {x.size}")
    if not np.all(np.isfinite(x)):
        raise InputError(f"{what}: {int(np.sum(~np.isfinite(x)))} values are not finite numbers")
    if np.ptp(x) == 0.0:
        raise InputError(f"{what}: all values are equal ({x[0]:g}); no spread to describe")
    return x


def deconvolve(values, measurement_sigma: float | None) -> tuple[np.ndarray, float]:
    """``(x', u²/s²)``: the values shrunk about their mean to the part variance s² − u²."""
    x = clean_values(values)
    if not measurement_sigma:
        return x, 0.0
    u = float(measurement_sigma)
    if not (math.isfinite(u) and u > 0):
        raise InputError(f"measurement_sigma must be a positive number, got {measurement_sigma!r}")
    s2 = float(np.var(x, ddof=1))
    ratio = u * u / s2
    if ratio >= 1.0:
        raise InputError(f"the measurement uncertainty (σ = {u:g}) is not smaller than the spread of the "
                         f"measured values (s = {math.sqrt(s2):g}): the gauge cannot resolve these parts")
    m = float(np.mean(x))
    return m + (x - m) * math.sqrt(1.0 - ratio), ratio
