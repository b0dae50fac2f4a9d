"""Planet carrier wind-up: pillars between the output flange and the input-side end plate.

The cranks deliver their tangential loads partly to the input-side end plate;
that share of the torque reaches the output flange through the ``n``
pillars, each a beam built in at both flanges whose ends are displaced
tangentially relative to each other (guided–fixed: bending ``h³/(12 E I)``
plus shear ``h/(κ G A)``, rectangular section, ``κ = 5/6``).  The
carrier's torsional stiffness between the flanges is ``K_5 = n k R²`` with
``R`` the pillar radius.  Flange bending is neglected (flanges are much
stiffer than the pillars).
"""
from __future__ import annotations


def pillar_stiffness(width: float, thickness: float, length: float, E: float, nu: float) -> float:
    """Tangential stiffness (N/mm) of one pillar, ``width`` tangential and ``thickness`` radial."""
    G = E / (2.0 * (1.0 + nu))
    inertia = thickness * width ** 3 / 12.0
    area = width * thickness
    return 1.0 / (length ** 3 / (12.0 * E * inertia) + length / (5.0 / 6.0 * G * area))


def torsional_stiffness(pillars: int, radius: float, width: float, thickness: float, length: float,
                        E: float, nu: float) -> float:
    """``K_5`` (N·mm/rad) between the input-side end plate and the output flange."""
    return pillars * pillar_stiffness(width, thickness, length, E, nu) * radius ** 2
