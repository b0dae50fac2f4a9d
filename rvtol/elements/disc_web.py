"""In-plane torsion of the cycloid disc body ("web") between its crank-bearing holes and its tooth ring.

**Model.**  The disc is a flat annulus of thickness ``t`` between radii ``r_i``
(where the torque leaves the web: the outer edge of the crank-bearing holes,
``a_0 + r_hole``) and ``r_o`` (where it enters: the tooth root circle,
``R_p − r_p − a``).  A torque ``T`` transmitted across every circle ``r`` is
carried by the in-plane shear stress (plane stress, axisymmetric; the stress
function ``φ = C θ`` of Timoshenko & Goodier, *Theory of Elasticity*, 3rd ed.,
ch. 4, two-dimensional problems in polar coordinates)::

    τ_rθ(r) = T / (2π r² t)

The displacement is purely tangential, ``u_θ = r β(r)``, with shear strain
``γ_rθ = r dβ/dr = τ_rθ / G``; integrating from ``r_i`` to ``r_o``::

    β = T / (4π G t) · (1/r_i² − 1/r_o²),      K_web = 4π G t / (1/r_i² − 1/r_o²)

(rad, N·mm/rad; ``G`` MPa, lengths mm, ``T`` N·mm).  For a web of stepped
thickness the annuli add in series (:func:`stepped_web_rotation`).

**What it neglects.**  The three crank holes (and the pillar clearance
holes) cut the annulus inside ``r_i`` — there the torque is already handed to
the bearings, which is why the web starts at the holes' outer edge; the load
is not axisymmetric (the pins load ~ a quarter of the circumference of each
disc, the holes take it at three points), so the real shear field
concentrates between the loaded teeth and the nearest hole — the formula is
the axisymmetric average, a lower bound of the compliance; tooth bending and
the local contact deformation belong to the cycloid–pin contact;
out-of-plane effects (the disc is loaded in its plane) are absent.

Transfer to the output: a disc rotation ``β`` turns the output by
``i_b β`` with ``i_b = (1 − 1/i) z_c / z_p`` (locked input); each disc carries
``T_c = T i_b / 2`` so the two webs contribute ``θ = 2 T_c β / T = i_b² T / (2 K_web)``
(virtual work, :mod:`rvtol.elements.chain`).
"""
from __future__ import annotations

import numpy as np

from ..errors import SpecError
from . import _checks


def web_shear_stress(torque, r, thickness):
    """``τ_rθ = T / (2π r² t)`` (MPa) at radius ``r`` (mm) of a web of thickness ``t`` (mm) carrying ``T`` (N·mm)."""
    return _checks.finite("torque", torque) / (
        2.0 * np.pi * _checks.positive("r", r) ** 2 * _checks.positive("thickness", thickness))


def annular_web_stiffness(r_inner, r_outer, thickness, G):
    """``K_web = 4π G t / (1/r_i² − 1/r_o²)`` (N·mm/rad) of an annular web in in-plane torsion."""
    ri = _checks.positive("r_inner", r_inner)
    ro = _checks.positive("r_outer", r_outer)
    if np.any(ro <= ri):
        raise SpecError(f"must be larger than r_inner, got r_outer {ro} <= r_inner {ri}", key="r_outer")
    return 4.0 * np.pi * _checks.positive("G", G) * _checks.positive("thickness", thickness) / (ri ** -2 - ro ** -2)


def annular_web_rotation(torque, r_inner, r_outer, thickness, G):
    """``β = T / (4π G t) · (1/r_i² − 1/r_o²)`` (rad): relative rotation of the web's two edges."""
    return _checks.finite("torque", torque) / annular_web_stiffness(r_inner, r_outer, thickness, G)


def stepped_web_rotation(torque, radii, thickness, G):
    """Rotation (rad) across a web of piecewise constant thickness: ``radii`` r_0 < … < r_m (mm),
    ``thickness[j]`` (mm) between ``radii[j]`` and ``radii[j+1]``; the annuli are in series."""
    r = _checks.positive("radii", radii)
    t = _checks.positive("thickness", thickness)
    if r.ndim != 1 or len(r) < 2 or np.any(np.diff(r) <= 0) or t.shape != (len(r) - 1,):
        raise SpecError("radii must increase and thickness must have one value per annulus", key="radii")
    T = _checks.finite("torque", torque)
    return T * np.sum((r[:-1] ** -2 - r[1:] ** -2) / (4.0 * np.pi * G * t))
