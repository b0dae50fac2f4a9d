"""Line contacts for the pin path: a pin in its housing groove, in series with the disc–pin contact.

**Formula (the same as the disc–pin contact of** :mod:`rvtol.models.stiffness.hertz` **).**  Two
parallel cylinders of contact length ``b`` (mm) pressed by ``F`` (N) approach by::

    w = 2F/(π b) · Σ_i (1 − ν_i²)/E_i · (1/3 + ln(4 d_i / L))

    L = √(4 F R_e / (π b E*)),   1/R_e = 1/R_1 + 1/R_2,   1/E* = Σ (1 − ν_i²)/E_i

with signed radii (convex > 0, concave < 0).  This is doc 004's formula; the
bracket is the classical plane-strain approach of a cylinder's reference
point to its Hertz contact (Roark's *Formulas for Stress and Strain*, 7th ed.,
Table 14.1, cylinder between two plates: ``ΔD = 4p(1−ν²)/(πE) (1/3 + ln(2D/b_w))``,
``b_w`` the full contact width).  ``d_i`` is the **reference depth** of body
``i``: the distance behind its contact surface of the point whose approach is
measured.  rvtol's disc–pin contact takes ``d_i = |R_i|`` (the pin's centre,
the centre of curvature of the cycloid flank) and ``L`` = the Hertz
**half-width** (``hertz.py``); the groove contact here uses the same
conventions by default, so the two approaches add along the pin's force:

* disc–pin: pin term ``(1/3 + ln(4 r_p / L_1))`` + disc term;
* pin–groove: pin term ``(1/3 + ln(4 r_p / L_2))`` + housing term
  ``(1/3 + ln(4 d_h / L_2))``, ``d_h = r_g`` by default (a point one groove
  radius deep in the housing).

The two pin terms together are the pin's compression between its two line
loads (centre to each contact).  Note: with ``L`` the **full** width ``2a``
(``width="full"``) the bracket is Roark's; the half-width convention of
``hertz.py`` adds ``ln 2`` to every body's bracket (≈ 10 % more approach).
Both are offered; keep one convention along a series chain.

**Pin in a groove.**  Pin radius ``r_p`` (convex), groove radius
``r_g > r_p`` (concave): ``1/R_e = 1/r_p − 1/r_g``, i.e. ``R_e = r_p r_g / (r_g − r_p)``
— a conforming contact.  Hertz theory needs the contact arc to be small: the
half-angle ``a / r_p`` is returned by :func:`groove_half_angle`; beyond
~0.3 rad the contact is conformal (Persson's pin-in-hole solution, Johnson,
*Contact Mechanics*, 1985, §5.6) and this formula over-estimates the approach.
A zero clearance is outside the formula and raises :class:`SpecError`.
The limit ``r_g → ∞`` (with a fixed housing depth) is the cylinder-on-flat
contact.

**Series.**  Disc–pin and pin–groove carry the same pin force, so their
approaches add (:func:`pin_path_approach`); the force for a given total
approach is found numerically (:func:`rvtol.elements.chain.series_force`).

Units: N, mm, MPa.  All functions broadcast over the force.
"""
from __future__ import annotations

import numpy as np

from ..errors import SpecError
from . import _checks, chain

WIDTHS = ("half", "full")


def reduced_modulus(E1, nu1, E2=None, nu2=None):
    """``E*`` (MPa) with ``1/E* = (1−ν1²)/E1 + (1−ν2²)/E2`` (second body defaults to the first)."""
    E1 = _checks.positive("E1", E1)
    nu1 = _checks.poisson("nu1", nu1)
    E2 = E1 if E2 is None else _checks.positive("E2", E2)
    nu2 = nu1 if nu2 is None else _checks.poisson("nu2", nu2)
    return 1.0 / ((1.0 - nu1 ** 2) / E1 + (1.0 - nu2 ** 2) / E2)


def effective_radius(R1, R2):
    """``R_e`` (mm) from signed radii (``inf`` = flat); must be positive (the bodies touch on a line)."""
    R1 = _checks.array("R1", R1)
    R2 = _checks.array("R2", R2)
    if np.any(R1 == 0) or np.any(R2 == 0):
        raise SpecError("radii must be non-zero (use inf for a flat)", key="R1" if np.any(R1 == 0) else "R2")
    curv = 1.0 / R1 + 1.0 / R2
    if np.any(curv <= 0):
        raise SpecError("1/R1 + 1/R2 must be > 0: a concave body must be larger than the convex one it holds "
                        "(zero clearance is a conforming contact outside Hertz theory)", key="R2")
    return 1.0 / curv


def half_width(F, b, R1, R2, E1, nu1, E2=None, nu2=None):
    """Hertz half-width ``a = √(4 F R_e / (π b E*))`` (mm) of a line contact."""
    F = _checks.nonnegative("F", F)
    b = _checks.positive("b", b)
    return np.sqrt(4.0 * F * effective_radius(R1, R2) / (np.pi * b * reduced_modulus(E1, nu1, E2, nu2)))


def line_contact_approach(F, b, R1, R2, E1, nu1, E2=None, nu2=None, *, depth1=None, depth2=None,
                          width: str = "half"):
    """Approach ``w`` (mm) of two line-contacting bodies under ``F`` (N), see the module doc.

    ``R1``, ``R2`` signed radii (mm, ``inf`` flat); ``depth1``, ``depth2`` reference depths (mm,
    default ``|R_i|``; required for a flat body); ``width`` = ``"half"`` (``L = a``, as
    ``hertz.py``) or ``"full"`` (``L = 2a``, Roark).  ``w(0) = 0``.
    """
    if width not in WIDTHS:
        raise SpecError(f"must be 'half' (hertz.py) or 'full' (Roark), got {width!r}", key="width")
    E2v = E1 if E2 is None else E2
    nu2v = nu1 if nu2 is None else nu2
    F = _checks.nonnegative("F", F)
    d1 = _depth("depth1", depth1, R1)
    d2 = _depth("depth2", depth2, R2)
    Fpos = np.where(F > 0, F, 1.0)
    L = half_width(Fpos, b, R1, R2, E1, nu1, E2v, nu2v) * (2.0 if width == "full" else 1.0)
    c1 = (1.0 - np.asarray(nu1) ** 2) / np.asarray(E1) * (1.0 / 3.0 + np.log(4.0 * d1 / L))
    c2 = (1.0 - np.asarray(nu2v) ** 2) / np.asarray(E2v) * (1.0 / 3.0 + np.log(4.0 * d2 / L))
    return np.where(F > 0, 2.0 * Fpos / (np.pi * np.asarray(b, float)) * (c1 + c2), 0.0)


def _depth(name, depth, R):
    if depth is None:
        R = _checks.array(name.replace("depth", "R"), R)
        if np.any(~np.isfinite(R)):
            raise SpecError("a flat body (infinite radius) needs an explicit reference depth", key=name)
        return np.abs(R)
    return _checks.positive(name, depth)


def groove_approach(F, b, r_pin, r_groove, E_pin, nu_pin, E_housing=None, nu_housing=None, *,
                    housing_depth=None, width: str = "half"):
    """Approach (mm) of a pin (radius ``r_pin``) pressed by ``F`` (N) into a housing groove of radius
    ``r_groove > r_pin`` over the length ``b`` (mm): pin centre to the housing point at
    ``housing_depth`` (default ``r_groove``) behind the contact.
    """
    rp = _checks.positive("r_pin", r_pin)
    rg = _checks.positive("r_groove", r_groove, allow_inf=True)
    if np.any(rg <= rp):
        raise SpecError(f"must be larger than the pin radius ({rp} mm): zero clearance is a conforming contact "
                        "outside Hertz theory", key="r_groove")
    if np.any(np.isinf(rg)) and housing_depth is None:
        raise SpecError("a flat seat (r_groove = inf) needs housing_depth", key="housing_depth")
    return line_contact_approach(F, b, rp, -rg, E_pin, nu_pin, E_housing, nu_housing, depth1=rp,
                                 depth2=rg if housing_depth is None else housing_depth, width=width)


def groove_half_angle(F, b, r_pin, r_groove, E_pin, nu_pin, E_housing=None, nu_housing=None):
    """Half-angle ``a / r_pin`` (rad) of the pin's contact arc in the groove: Hertz needs it ≪ 1."""
    rp = _checks.positive("r_pin", r_pin)
    return half_width(F, b, rp, -_checks.positive("r_groove", r_groove, allow_inf=True), E_pin, nu_pin,
                      E_housing, nu_housing) / rp


def pin_path_approach(F, *, b_disc, r_pin, rho_disc, b_groove, r_groove, E, nu, E_housing=None,
                      nu_housing=None, housing_depth=None, width: str = "half"):
    """Approach (mm) of the disc's reference point to the housing's along the pin force ``F`` (N):
    disc–pin contact (flank curvature radius ``rho_disc``, signed, length ``b_disc``) in series with
    the pin–groove contact (length ``b_groove``).  Both with the same width convention.
    """
    w1 = line_contact_approach(F, b_disc, r_pin, rho_disc, E, nu, width=width)
    w2 = groove_approach(F, b_groove, r_pin, r_groove, E, nu, E_housing, nu_housing,
                         housing_depth=housing_depth, width=width)
    return w1 + w2


def pin_path_force(approach, **kw):
    """Inverse of :func:`pin_path_approach`: the pin force (N) at a given total approach (mm)."""
    return chain.series_force(approach, [lambda F: pin_path_approach(F, **kw)], force_scale=100.0)
