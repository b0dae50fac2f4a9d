"""Line (cylinder–cylinder) contact after Hertz: half-width and normal approach.

The approach ``w`` of two parallel cylinders of length ``b`` pressed by ``F``
is doc 004's formula::

    w = 2F/(π b) · [ (1-μ1²)/E1 · (1/3 + ln(4|R1|/L)) + (1-μ2²)/E2 · (1/3 + ln(4|R2|/L)) ]

The document leaves ``L`` undefined; rvtol takes the Hertz contact
**half-width** (Johnson, *Contact Mechanics*, ch. 4, line contact)::

    L = sqrt(4 F R_e / (π b E*)),   1/R_e = 1/R1 + 1/R2,   1/E* = (1-μ1²)/E1 + (1-μ2²)/E2

Radii are signed: positive convex, negative concave (a concave body enters
``R_e`` with its sign and the logarithm with its magnitude).  All functions
broadcast over NumPy arrays; units are the base units (N, mm, MPa).
"""
from __future__ import annotations

import numpy as np


def reduced_modulus(E1, nu1, E2=None, nu2=None):
    """``E*`` with ``1/E* = (1-ν1²)/E1 + (1-ν2²)/E2`` (second body defaults to the first)."""
    E2 = E1 if E2 is None else E2
    nu2 = nu1 if nu2 is None else nu2
    return 1.0 / ((1.0 - nu1 ** 2) / E1 + (1.0 - nu2 ** 2) / E2)


def equivalent_radius(R1, R2):
    """``R_e = R1 R2 / (R1 + R2)`` for signed radii (convex > 0, concave < 0)."""
    R1 = np.asarray(R1, dtype=float)
    R2 = np.asarray(R2, dtype=float)
    return R1 * R2 / (R1 + R2)


def half_width(F, b, R1, R2, E1, nu1, E2=None, nu2=None):
    """Hertz half-width of the contact band of two cylinders (mm)."""
    Re = equivalent_radius(R1, R2)
    return np.sqrt(4.0 * np.asarray(F, dtype=float) * Re / (np.pi * b * reduced_modulus(E1, nu1, E2, nu2)))


def approach(F, b, R1, R2, E1, nu1, E2=None, nu2=None):
    """Normal approach ``w`` (mm) of two cylinders under force ``F`` (N), doc 004's formula.

    ``F = 0`` gives ``w = 0`` (the limit of ``F ln F``).
    """
    E2 = E1 if E2 is None else E2
    nu2 = nu1 if nu2 is None else nu2
    F = np.asarray(F, dtype=float)
    Fpos = np.where(F > 0, F, 1.0)
    L = half_width(Fpos, b, R1, R2, E1, nu1, E2, nu2)
    c1 = (1.0 - nu1 ** 2) / E1 * (1.0 / 3.0 + np.log(4.0 * np.abs(R1) / L))
    c2 = (1.0 - nu2 ** 2) / E2 * (1.0 / 3.0 + np.log(4.0 * np.abs(R2) / L))
    return np.where(F > 0, 2.0 * Fpos / (np.pi * b) * (c1 + c2), 0.0)
