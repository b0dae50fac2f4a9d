"""Shafts: Timoshenko beam (stepped, hollow) on two elastic supports, and torsion of stepped shafts.

**Beam.**  A straight shaft along ``z`` made of segments of constant circular
section (outer diameter ``d_o``, inner ``d_i``), resting on two supports at
``z_A < z_B`` with radial spring stiffnesses ``k_A``, ``k_B`` (``inf`` = rigid),
loaded in one plane by point forces (N, along the deflection ``w``) and point
couples (N·mm, work-conjugate to the section rotation ``φ``) anywhere on the
shaft, overhangs included.  The flexibility matrix follows from the unit-load
(Maxwell–Mohr) integrals of Timoshenko beam theory::

    C_jk = ∫ m_j m_k / (E I) dz + ∫ v_j v_k / (κ G A) dz + r_Aj r_Ak / k_A + r_Bj r_Bk / k_B

where ``m_j``, ``v_j``, ``r_sj`` are the bending moment, shear force and
support reactions of the statically determinate beam under a unit load ``j``
(Timoshenko & Gere, *Mechanics of Materials*, energy methods; Roark's
*Formulas for Stress and Strain*, 7th ed., ch. 8, Table 8.1 for the
Euler–Bernoulli closed forms the tests check).  ``m`` is piecewise linear and
``v`` piecewise constant between knots, so Simpson's rule on each piece is
exact.  The response to a force is the deflection ``w`` (mm), to a couple the
rotation of the cross-section ``φ`` (rad) — with shear deformation this is not
the slope ``dw/dz`` (they differ by the shear strain ``V/(κ G A)``); a ring
mounted on the shaft (a bearing, an eccentric) tilts by ``φ``.  ``C`` is
symmetric (Maxwell–Betti).

Shear coefficient of a circular tube, ``m = d_i/d_o`` (Cowper, "The shear
coefficient in Timoshenko's beam theory", *J. Appl. Mech.* 33 (1966) 335–340,
Table 1)::

    κ = 6 (1 + ν)(1 + m²)² / [ (7 + 6ν)(1 + m²)² + (20 + 12ν) m² ]

which is ``6(1+ν)/(7+6ν)`` for a solid circle.  Sections: ``A = π(d_o² − d_i²)/4``,
``I = π(d_o⁴ − d_i⁴)/64``, ``J = 2I``.

**Torsion** of a stepped shaft, segment ``i`` of length ``L_i`` carrying the
torque ``T_i`` (Saint-Venant, circular sections)::

    θ = Σ T_i L_i / (G J_i),     G = E / (2(1 + ν))

Neglected: stress concentration and the local flexibility at shoulders and
fillets, the eccentricity of the eccentrics (treated as coaxial cylinders),
axial load and shear-centre effects.  Units: mm, N, N·mm, MPa, rad.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import SpecError
from . import _checks

FORCE = "force"
MOMENT = "moment"


def circle_section(d_outer, d_inner=0.0):
    """``(A, I, J)`` of a circular tube (mm², mm⁴, mm⁴); ``d_inner = 0`` for a solid shaft."""
    do = _checks.positive("d_outer", d_outer)
    di = _checks.nonnegative("d_inner", d_inner)
    if np.any(di >= do):
        raise SpecError(f"must be smaller than d_outer, got d_inner {di} >= d_outer {do}", key="d_inner")
    A = np.pi * (do ** 2 - di ** 2) / 4.0
    I = np.pi * (do ** 4 - di ** 4) / 64.0
    return A, I, 2.0 * I


def cowper_circle(nu, d_outer=1.0, d_inner=0.0):
    """Timoshenko shear coefficient ``κ`` of a circular tube (Cowper 1966, Table 1); solid: ``6(1+ν)/(7+6ν)``."""
    nu = _checks.poisson("nu", nu)
    do = _checks.positive("d_outer", d_outer)
    di = _checks.nonnegative("d_inner", d_inner)
    m2 = (di / do) ** 2
    return 6.0 * (1.0 + nu) * (1.0 + m2) ** 2 / ((7.0 + 6.0 * nu) * (1.0 + m2) ** 2 + (20.0 + 12.0 * nu) * m2)


def twist(torque, length, d_outer, d_inner=0.0, *, G):
    """``θ = Σ T_i L_i / (G J_i)`` (rad) of a stepped shaft; arrays over segments ``i`` (last axis).

    ``torque`` (N·mm) per segment, ``length`` (mm), diameters (mm), shear modulus ``G`` (MPa).
    """
    L = _checks.nonnegative("length", length)
    _, _, J = circle_section(d_outer, d_inner)
    T = _checks.finite("torque", torque)
    G = _checks.positive("G", G)
    return np.sum(T * L / (G * J), axis=-1)


@dataclass(frozen=True)
class SteppedShaft:
    """A shaft of circular segments: segment ``i`` spans ``stations[i] .. stations[i+1]``.

    ``stations`` (mm, increasing), ``d_outer``/``d_inner`` (mm, one per segment), ``E`` (MPa), ``nu``;
    ``shear=False`` gives Euler–Bernoulli beam theory.
    """

    stations: tuple
    d_outer: tuple
    d_inner: tuple
    E: float
    nu: float
    shear: bool = True

    def __post_init__(self):
        z = _checks.finite("stations", self.stations)
        if z.ndim != 1 or len(z) < 2 or np.any(np.diff(z) <= 0):
            raise SpecError(f"must be at least two increasing positions, got {self.stations!r}", key="stations")
        n = len(z) - 1
        do = np.broadcast_to(_checks.positive("d_outer", self.d_outer), (n,)).copy()
        di = np.broadcast_to(_checks.nonnegative("d_inner", self.d_inner), (n,)).copy()
        circle_section(do, di)
        _checks.positive("E", self.E)
        _checks.poisson("nu", self.nu)
        object.__setattr__(self, "stations", tuple(float(v) for v in z))
        object.__setattr__(self, "d_outer", tuple(float(v) for v in do))
        object.__setattr__(self, "d_inner", tuple(float(v) for v in di))

    @classmethod
    def uniform(cls, length: float, d_outer: float, E: float, nu: float, *, d_inner: float = 0.0,
                start: float = 0.0, shear: bool = True) -> "SteppedShaft":
        _checks.positive("length", length)
        return cls((start, start + length), (d_outer,), (d_inner,), E, nu, shear)

    @property
    def G(self) -> float:
        return float(_checks.shear_modulus(self.E, self.nu))

    def _segment_index(self, z):
        return np.clip(np.searchsorted(self.stations, z, side="right") - 1, 0, len(self.d_outer) - 1)

    def _check_inside(self, name, z):
        z = _checks.finite(name, z)
        lo, hi = self.stations[0], self.stations[-1]
        if np.any((z < lo) | (z > hi)):
            raise SpecError(f"must lie on the shaft [{lo:g}, {hi:g}] mm, got {z}", key=name)
        return z

    # -- bending ---------------------------------------------------------------------------------
    def flexibility(self, points, kinds=None, *, supports, support_stiffness=(np.inf, np.inf)) -> np.ndarray:
        """Flexibility matrix ``C[j, k]``: response at ``points[j]`` to a unit load at ``points[k]``.

        ``kinds[j]`` is ``"force"`` (load N, response deflection mm) or ``"moment"`` (load N·mm,
        response section rotation rad); default all forces.  ``supports = (z_A, z_B)``,
        ``support_stiffness = (k_A, k_B)`` in N/mm (``inf`` = rigid).
        """
        z = np.atleast_1d(self._check_inside("points", points))
        kinds = [FORCE] * len(z) if kinds is None else list(kinds)
        if len(kinds) != len(z) or any(k not in (FORCE, MOMENT) for k in kinds):
            raise SpecError(f"must be one of 'force'/'moment' per point, got {kinds!r}", key="kinds")
        zA, zB = (float(v) for v in self._check_inside("supports", supports))
        if not zB > zA:
            raise SpecError(f"must be two positions z_A < z_B, got {supports!r}", key="supports")
        kA, kB = (float(v) for v in _checks.positive("support_stiffness", support_stiffness, allow_inf=True))
        L = zB - zA

        # unit-load systems: positions, forces and couples (couples enter M with a minus sign)
        systems = []
        for p, kind in zip(z, kinds):
            if kind == FORCE:
                RA, RB = -(zB - p) / L, -(p - zA) / L
                systems.append((np.array([zA, zB, p]), np.array([RA, RB, 1.0]), p, 0.0, (RA, RB)))
            else:
                RA, RB = 1.0 / L, -1.0 / L
                systems.append((np.array([zA, zB]), np.array([RA, RB]), p, 1.0, (RA, RB)))

        knots = np.unique(np.concatenate([self.stations, z, [zA, zB]]))
        a, b = knots[:-1], knots[1:]
        h = b - a
        seg = self._segment_index(0.5 * (a + b))
        do, di = np.asarray(self.d_outer)[seg], np.asarray(self.d_inner)[seg]
        A, I, _ = circle_section(do, di)
        EI = self.E * I
        kGA = cowper_circle(self.nu, do, di) * self.G * A

        mA, mB, v = [], [], []
        for pos, F, pc, C, _ in systems:
            left = pos[None, :] <= a[:, None]                       # loads at or left of each piece
            ma = (F[None, :] * (a[:, None] - pos[None, :]) * left).sum(axis=1) - C * (pc <= a)
            mb = (F[None, :] * (b[:, None] - pos[None, :]) * left).sum(axis=1) - C * (pc <= a)
            mA.append(ma)
            mB.append(mb)
            v.append((F[None, :] * left).sum(axis=1))
        mA, mB, v = np.array(mA), np.array(mB), np.array(v)
        mM = 0.5 * (mA + mB)
        w = h / (6.0 * EI)
        bend = (mA * w) @ mA.T + 4.0 * (mM * w) @ mM.T + (mB * w) @ mB.T
        out = bend
        if self.shear:
            out = out + (v * (h / kGA)) @ v.T
        R = np.array([s[4] for s in systems])                       # (n, 2) reactions
        for s, k in enumerate((kA, kB)):
            if np.isfinite(k):
                out = out + np.outer(R[:, s], R[:, s]) / k
        return out

    def reactions(self, points, loads, kinds=None, *, supports) -> np.ndarray:
        """Support reactions ``(R_A, R_B)`` (N, on the shaft, same sign convention as the loads)."""
        z = np.atleast_1d(self._check_inside("points", points))
        kinds = [FORCE] * len(z) if kinds is None else list(kinds)
        P = np.atleast_1d(_checks.finite("loads", loads))
        zA, zB = (float(v) for v in supports)
        L = zB - zA
        RA = sum(-(zB - p) / L * q if k == FORCE else q / L for p, q, k in zip(z, P, kinds))
        RB = sum(-(p - zA) / L * q if k == FORCE else -q / L for p, q, k in zip(z, P, kinds))
        return np.array([RA, RB])

    # -- torsion ---------------------------------------------------------------------------------
    def torsional_compliance(self, z_from: float, z_to: float) -> float:
        """``∫ dz / (G J(z))`` between two positions (rad per N·mm of torque carried there)."""
        z0, z1 = sorted(float(v) for v in self._check_inside("z", [z_from, z_to]))
        st = np.asarray(self.stations)
        lo = np.clip(st[:-1], z0, z1)
        hi = np.clip(st[1:], z0, z1)
        _, _, J = circle_section(np.asarray(self.d_outer), np.asarray(self.d_inner))
        return float(np.sum((hi - lo) / (self.G * J)))
