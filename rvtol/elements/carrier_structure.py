"""Carrier structure: pillars between the two carrier flanges, the end plate's flexibility at a pillar
root, and the carrier's torsional stiffness between its flanges.

**Load path.**  The crank support bearings deliver the output torque to the
carrier at both flanges: the output flange directly, the input-side end plate
through the pillars.  A relative rotation ``Δφ`` of the two flanges about the
reducer axis displaces the ends of a pillar at radius ``R`` tangentially by
``R Δφ`` relative to each other and twists it by ``Δφ`` about its own axis.

**Pillar** (length ``h`` between the flanges; section area ``A``, second moment
``I`` about the radial axis — bending in the tangential direction — shear
coefficient ``κ``, torsion constant ``J``).  Both ends are held against
rotation by the flanges through rotational springs ``k_1``, ``k_2`` (N·mm/rad;
``inf`` = rigid flange, the fixed–guided beam).  With the end moment ``M_1``
as redundant (Castigliano; the shear force ``F`` is constant along the pillar,
``M(x) = M_1 − F x``, ``M_2 = M_1 − F h``)::

    M_1 (h/EI + 1/k_1 + 1/k_2) = F (h²/(2EI) + h/k_2)
    Δ/F = h³/(3EI) − (M_1/F) h²/(2EI) + h/(κ G A) + (h − M_1/F) h / k_2

which is ``h³/(12 E I) + h/(κ G A)`` for rigid flanges (Roark's *Formulas for
Stress and Strain*, 7th ed., Table 8.1, fixed–guided case, plus the
Timoshenko shear term) and ``h³/(12EI) + h/(κGA) + h²/(2k)`` for equal springs.
Shear coefficients (Cowper 1966): rectangle ``10(1+ν)/(12+11ν)``, circle
``6(1+ν)/(7+6ν)``.  Torsion constant of a rectangle ``2a × 2b`` (``a ≥ b``),
Roark 7th ed. Table 10.1 case 4: ``J = a b³ [16/3 − 3.36 (b/a)(1 − b⁴/(12 a⁴))]``.

**End plate at a pillar root.**  The pillar's end moment ``M`` (about the
radial axis) tilts the flange locally.  The root is idealised as a rigid
circular boss of radius ``b`` (the pillar footprint, equal area) in an annular
Kirchhoff plate of thickness ``t`` that is clamped (or simply supported) at a
radius ``a`` (the distance to the nearest stiff feature: flange rim, hub,
bearing seat).  Loaded by a couple, the deflection is the ``cos θ`` harmonic
``w = f(r) cos θ`` with (Timoshenko & Woinowsky-Krieger, *Theory of Plates and
Shells*, 2nd ed., ch. 9, unsymmetrical bending of circular plates, ``n = 1``)::

    f(r) = A r³ + B r + C/r + D r ln r

and boundary conditions ``f(b) = ψ b``, ``f'(b) = ψ`` (the boss turns by ``ψ``),
``f(a) = f'(a) = 0`` (clamped) or ``f(a) = 0``, ``f'' + ν(f'/r − f/r²) = 0``
(simply supported).  The couple is ``M = 2U/ψ`` with the strain energy::

    U = (π D/2) ∫_b^a [ f''² + g² + 2ν f'' g + 2(1−ν) g² ] r dr,   g = f'/r − f/r²,
    D = E t³ / (12 (1 − ν²))

so the root's rotational stiffness is ``k_φ = 2U/ψ²``.  This is the problem
Roark tabulates for a couple on a rigid central boss (Table 11.2 in the 7th
ed.; the coefficients here come from the general solution, not from the
table).  Kirchhoff theory neglects transverse shear — the flanges are thick
(``t`` ≈ ``a − b``), so ``k_φ`` is an upper bound — and the idealisation
replaces the real flange (holes, pockets, bolt joint) by an axisymmetric
annulus around each pillar; ``k_φ`` depends only logarithmically on ``a/b``.

**Carrier torsion** between the flanges (``n`` pillars at radius ``R``)::

    K_carrier = n (k_pillar R² + G J / h)

and the carrier's share of the output rotation is ``θ = T_B² / (K_carrier T)``
with ``T_B`` the torque the cranks deliver to the end plate.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import SpecError
from . import _checks


@dataclass(frozen=True)
class Section:
    """Beam cross-section: ``area`` (mm²), ``inertia`` about the bending axis (mm⁴), Timoshenko shear
    coefficient ``kappa``, St-Venant torsion constant ``torsion`` (mm⁴, None if unknown)."""

    area: float
    inertia: float
    kappa: float
    torsion: float | None = None
    name: str = ""

    def __post_init__(self):
        _checks.positive("area", self.area)
        _checks.positive("inertia", self.inertia)
        k = float(_checks.positive("kappa", self.kappa))
        if k > 1.0:
            raise SpecError(f"a shear coefficient is at most 1, got {k:g}", key="kappa")
        if self.torsion is not None:
            _checks.positive("torsion", self.torsion)


def rectangle(width: float, depth: float, nu: float) -> Section:
    """Rectangle ``width`` (along the deflection, tangential) × ``depth`` (radial), mm.

    ``I = depth width³ / 12``; ``κ = 10(1+ν)/(12+11ν)`` (Cowper); ``J`` after Roark Table 10.1 case 4.
    """
    w = float(_checks.positive("width", width))
    d = float(_checks.positive("depth", depth))
    nu = float(_checks.poisson("nu", nu))
    a, b = 0.5 * max(w, d), 0.5 * min(w, d)
    J = a * b ** 3 * (16.0 / 3.0 - 3.36 * (b / a) * (1.0 - b ** 4 / (12.0 * a ** 4)))
    return Section(w * d, d * w ** 3 / 12.0, 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu), J, "rectangle")


def circle(diameter: float, nu: float) -> Section:
    """Solid circle: ``I = π d⁴/64``, ``J = π d⁴/32``, ``κ = 6(1+ν)/(7+6ν)`` (Cowper)."""
    d = float(_checks.positive("diameter", diameter))
    nu = float(_checks.poisson("nu", nu))
    return Section(np.pi * d * d / 4.0, np.pi * d ** 4 / 64.0, 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu),
                   np.pi * d ** 4 / 32.0, "circle")


def polygon(vertices, nu: float, kappa: float | None = None) -> Section:
    """Simple polygon ``vertices`` = [(x, y), ...] in mm, ``x`` along the deflection (tangential).

    Area and ``I = ∫ (x − x_c)² dA`` by Green's theorem; ``κ`` defaults to Cowper's rectangle value
    (an approximation for compact sections); the torsion constant is left unknown.
    """
    P = _checks.finite("vertices", vertices)
    if P.ndim != 2 or P.shape[1] != 2 or len(P) < 3:
        raise SpecError("must be at least three (x, y) points", key="vertices")
    x, y = P[:, 0], P[:, 1]
    x1, y1 = np.roll(x, -1), np.roll(y, -1)
    cr = x * y1 - x1 * y
    A = 0.5 * cr.sum()
    if A < 0:                                 # clockwise: flip
        cr, A = -cr, -A
    if not A > 0:
        raise SpecError("the polygon has no area", key="vertices")
    xc = ((x + x1) * cr).sum() / (6.0 * A)
    Iyy = ((x * x + x * x1 + x1 * x1) * cr).sum() / 12.0
    k = 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu) if kappa is None else kappa
    return Section(float(A), float(Iyy - A * xc * xc), float(k), None, "polygon")


def pillar_compliance(section: Section, length: float, E: float, nu: float,
                      end_rotation_stiffness=(np.inf, np.inf)) -> float:
    """Tangential compliance ``Δ/F`` (mm/N) of a pillar between two flanges (see the module doc)."""
    h = float(_checks.positive("length", length))
    E = float(_checks.positive("E", E))
    G = float(_checks.shear_modulus(E, _checks.poisson("nu", nu)))
    k1, k2 = (float(v) for v in _checks.positive("end_rotation_stiffness", end_rotation_stiffness, allow_inf=True))
    c1, c2 = 1.0 / k1, 1.0 / k2
    EI = E * section.inertia
    S = h / EI + c1 + c2
    m1 = (h * h / (2.0 * EI) + h * c2) / S                      # M_1 / F
    rest = (h * h / (2.0 * EI) + h * c1) / S                    # (h − M_1/F), without cancellation
    return h ** 3 / (3.0 * EI) - m1 * h * h / (2.0 * EI) + h / (section.kappa * G * section.area) + rest * h * c2


def pillar_stiffness(section: Section, length: float, E: float, nu: float,
                     end_rotation_stiffness=(np.inf, np.inf)) -> float:
    """Tangential stiffness ``F/Δ`` (N/mm) of a pillar, see :func:`pillar_compliance`."""
    return 1.0 / pillar_compliance(section, length, E, nu, end_rotation_stiffness)


def boss_coefficients(boss_radius: float, outer_radius: float, nu: float, edge: str = "clamped") -> np.ndarray:
    """``(A, B, C, D)`` of ``f(r) = A r³ + B r + C/r + D r ln r`` for a unit boss rotation ``ψ = 1``."""
    b = float(_checks.positive("boss_radius", boss_radius))
    a = float(_checks.positive("outer_radius", outer_radius))
    nu = float(_checks.poisson("nu", nu))
    if not a > b:
        raise SpecError(f"must be larger than the boss radius {b:g} mm, got {a:g}", key="outer_radius")
    if a - b < 1e-3 * b:
        raise SpecError(f"annulus too narrow for the plate solution ((a − b)/b = {(a - b) / b:.2g} < 1e-3, the 4×4 "
                        "system loses its digits): it is a clamped strip, k = π D b (12b² + 12bh + 4h²)/h³",
                        key="outer_radius")
    if edge not in ("clamped", "simply_supported"):
        raise SpecError(f"must be 'clamped' or 'simply_supported', got {edge!r}", key="edge")

    def row_f(r):
        return [r ** 3, r, 1.0 / r, r * np.log(r)]

    def row_df(r):
        return [3.0 * r * r, 1.0, -1.0 / (r * r), np.log(r) + 1.0]

    def row_mr(r):                # f'' + ν (f'/r − f/r²)
        d2 = np.array([6.0 * r, 0.0, 2.0 / r ** 3, 1.0 / r])
        g = (np.array(row_df(r)) - np.array(row_f(r)) / r) / r
        return list(d2 + nu * g)

    M = np.array([row_f(b), row_df(b), row_f(a), row_df(a) if edge == "clamped" else row_mr(a)])
    return np.linalg.solve(M, [b, 1.0, 0.0, 0.0])


def boss_rotational_stiffness(boss_radius: float, outer_radius: float, thickness: float, E: float, nu: float,
                              edge: str = "clamped", *, nodes: int = 64) -> float:
    """``k_φ = M/ψ`` (N·mm/rad) of a rigid boss in an annular Kirchhoff plate under a couple (module doc).

    The energy integral is evaluated with ``nodes``-point Gauss–Legendre quadrature in ``ln r``
    (the integrand is smooth; 64 points give machine precision for ``a/b`` up to ~100).
    """
    A, B, C, Dc = boss_coefficients(boss_radius, outer_radius, nu, edge)
    t = float(_checks.positive("thickness", thickness))
    E = float(_checks.positive("E", E))
    D = E * t ** 3 / (12.0 * (1.0 - nu * nu))
    b, a = float(boss_radius), float(outer_radius)
    x, w = np.polynomial.legendre.leggauss(nodes)
    s = 0.5 * (np.log(a) - np.log(b)) * x + 0.5 * (np.log(a) + np.log(b))
    r = np.exp(s)
    f = A * r ** 3 + B * r + C / r + Dc * r * np.log(r)
    df = 3.0 * A * r * r + B - C / (r * r) + Dc * (np.log(r) + 1.0)
    d2f = 6.0 * A * r + 2.0 * C / r ** 3 + Dc / r
    g = df / r - f / (r * r)
    dens = (d2f ** 2 + g ** 2 + 2.0 * nu * d2f * g + 2.0 * (1.0 - nu) * g ** 2) * r
    U = 0.5 * np.pi * D * np.sum(w * dens * r) * 0.5 * (np.log(a) - np.log(b))     # dr = r ds
    return 2.0 * U


def equivalent_boss_radius(section: Section) -> float:
    """Radius of the circle with the section's area (mm): the boss of a pillar root."""
    return float(np.sqrt(section.area / np.pi))


def carrier_torsional_stiffness(pillars: int, radius: float, k_pillar: float, *, section: Section | None = None,
                                length: float | None = None, G: float | None = None) -> float:
    """``K = n (k R² + G J / h)`` (N·mm/rad) between the carrier flanges; the twist term needs
    ``section`` (with a torsion constant), ``length`` and ``G`` and is left out otherwise."""
    n = _checks.whole("pillars", pillars)
    R = float(_checks.positive("radius", radius))
    k = float(_checks.positive("k_pillar", k_pillar))
    twist = 0.0
    if section is not None and section.torsion is not None:
        if length is None or G is None:
            raise SpecError("the pillar twist term needs the pillar length and G", key="length")
        twist = float(_checks.positive("G", G)) * section.torsion / float(_checks.positive("length", length))
    return n * (k * R * R + twist)
