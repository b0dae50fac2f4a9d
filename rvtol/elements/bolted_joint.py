"""The bolted joint between the carrier's end plate and a pillar: resiliences after VDI 2230 and the tilt
stiffness of the closed joint.

Source: VDI 2230 Blatt 1 (2015), *Systematic calculation of highly stressed bolted joints — joints with one
cylindrical bolt*, §5.1 (resilience of the bolt and of the clamped parts), §5.3.2 (eccentric clamping and
loading: bending resiliences, opening), §5.4.1 (assembly preload).  The pillar's end moment ``M`` (the
pillar is a fixed–guided beam, ``M = F_Q h/2``) and its shear ``F_Q`` cross the joint.

**Bolt** (tapped thread joint, ESV: the bolt screwed into the pillar; hexagon head), VDI 2230 eqs. (5.1/…)::

    δ_S = δ_SK + δ_Gew + δ_G + δ_M,   δ_SK = 0.5 d/(E A_N),  δ_Gew = l_Gew/(E A_d3),
    δ_G = 0.5 d/(E A_d3),  δ_M = 0.33 d/(E A_N)            (A_N = π d²/4, A_d3 = π d_3²/4)

**Clamped parts** (deformation cone of the ESV, ``w = 2``)::

    tan φ_E = 0.348 + 0.013 ln β_L + 0.193 ln y,   β_L = l_K/d_W,  y = D'_A/d_W
    D_A,Gr = d_W + w l_K tan φ
    cone only (D'_A ≥ D_A,Gr):
      δ_P = 2 ln[(d_W + d_h)(d_W + w l_K tan φ − d_h) / ((d_W − d_h)(d_W + w l_K tan φ + d_h))] / (w E π d_h tan φ)
    cone + sleeve (D'_A < D_A,Gr):
      δ_P = [2/(w d_h tan φ) ln((d_W + d_h)(D'_A − d_h)/((d_W − d_h)(D'_A + d_h)))
             + 4/(D'_A² − d_h²) (l_K − (D'_A − d_W)/(w tan φ))] / (E π)

**Bending** (§5.3.2): VDI 2230's bending resiliences ``β_S = l_K/(E I_3)`` (thread core,
``I_3 = π d_3⁴/64``) and ``β_P = l_K/(E I_Bers)`` (``I_Bers``: the interface's second moment about the
bending axis, less the bolt hole; prismatic clamped parts no wider than the cone) describe the bolt and the
clamped solids themselves; here the clamped solids are the end plate and the pillar, whose bending the
``carrier`` element already has (Kirchhoff plate, Timoshenko pillar).  What the **joint** adds while it
stays closed is its **interface**: a rough layer (:mod:`.roughness`, Greenwood–Williamson) of normal
stiffness ``k_n`` per unit area at the clamping pressure ``n F_V/A``; under a moment a Winkler layer of
rotational stiffness ``k_n I_Bers``, under the shear (stuck) Mindlin's tangential ratio of it::

    c_tilt = 1/(k_n I_Bers),      c_shear = 1/(2(1 − ν)/(2 − ν) · k_n A)

If the joint opened, the bolt (``δ_S``, ``β_S``) would carry the moment's tension and the tilt grow by an
order of magnitude; if it slipped, the dowel pin would carry the shear.  :func:`BoltedJoint.opening_and_slip`
checks both at the load; the chain refuses a design whose joint opens or slips at rated torque.

The **assembly preload** of a torque-controlled bolt at utilisation ``ν`` of its yield strength (VDI 2230
eq. (R7/…), §5.4.1)::

    F_M = ν R_p0.2 A_0 / √(1 + 3 [3/2 · d_2/d_0 · (P/(π d_2) + 1.155 μ_G)]²),    A_0 = π d_0²/4, d_0 = (d_2 + d_3)/2

and the smallest preload after tightening scatter ``α_A`` and embedding ``f_Z``: ``F_V = F_M/α_A − f_Z/(δ_S + δ_P)``.
The joint **stays closed** under ``M`` while ``F_V/A − M (c/2)/I_Bers ≥ 0`` and does **not slip** under the
shear ``F_Q`` while ``F_Q ≤ μ_T F_V`` (else the dowel (taper) pin carries the shear: :func:`opening_and_slip`
says which, the caller states it).

Units: mm, N, MPa.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import SpecError
from . import _checks

#: ISO 261/724 coarse threads: d -> (pitch P, d_2, d_3) (mm)
METRIC_COARSE = {
    5.0: (0.8, 4.480, 4.019), 6.0: (1.0, 5.350, 4.773), 8.0: (1.25, 7.188, 6.466), 10.0: (1.5, 9.026, 8.160),
    12.0: (1.75, 10.863, 9.853),
}


@dataclass(frozen=True)
class BoltedJoint:
    """One bolt (nominal ⌀ ``d``, ISO coarse thread) clamping a prismatic interface ``width × depth``
    (``width`` along the shear, across the bending axis) through the clamped length ``l_K``; head bearing
    diameter ``d_W``, hole ``d_h``; ``E``; assembly utilisation ``utilisation`` of ``yield_strength`` with
    thread friction ``mu_thread``, tightening factor ``alpha_A``, embedding ``f_Z``."""

    d: float
    l_K: float
    width: float
    depth: float
    E: float
    bolts: int = 1
    d_W: float | None = None
    d_h: float | None = None
    yield_strength: float = 940.0           # property class 10.9, ISO 898-1
    utilisation: float = 0.9
    mu_thread: float = 0.12
    alpha_A: float = 1.6
    f_Z: float = 0.0

    def __post_init__(self):
        if float(self.d) not in METRIC_COARSE:
            raise SpecError(f"must be one of the ISO coarse sizes {sorted(METRIC_COARSE)}, got {self.d!r}", key="d")
        for k in ("l_K", "width", "depth", "E"):
            _checks.positive(k, getattr(self, k))
        if self.d_W is None:
            object.__setattr__(self, "d_W", 1.5 * self.d)        # hexagon head bearing face ≈ 1.5 d
        if self.d_h is None:
            object.__setattr__(self, "d_h", 1.1 * self.d)        # ISO 273 medium clearance hole ≈ 1.1 d
        if not self.d_h < self.d_W:
            raise SpecError("the hole must be smaller than the head's bearing face", key="d_h")

    @property
    def thread(self):
        return METRIC_COARSE[float(self.d)]

    def bolt_resilience(self) -> float:
        """``δ_S`` (mm/N), ESV with hexagon head, the whole clamped length threaded (module doc)."""
        P, d2, d3 = self.thread
        A_N, A_3 = math.pi * self.d ** 2 / 4, math.pi * d3 ** 2 / 4
        return (0.5 * self.d / A_N + self.l_K / A_3 + 0.5 * self.d / A_3 + 0.33 * self.d / A_N) / self.E

    def clamped_resilience(self) -> float:
        """``δ_P`` (mm/N) of the deformation cone (ESV, ``w = 2``), limited by the interface (module doc)."""
        dW, dh, lK, w = self.d_W, self.d_h, self.l_K, 2.0
        DA = min(self.width, self.depth)                         # substitute outside diameter D'_A
        tphi = 0.348 + 0.013 * math.log(lK / dW) + 0.193 * math.log(max(DA / dW, 1.0))
        DAgr = dW + w * lK * tphi
        if DA >= DAgr:
            num = (dW + dh) * (dW + w * lK * tphi - dh)
            den = (dW - dh) * (dW + w * lK * tphi + dh)
            return 2.0 * math.log(num / den) / (w * self.E * math.pi * dh * tphi)
        cone = 2.0 / (w * dh * tphi) * math.log((dW + dh) * (DA - dh) / ((dW - dh) * (DA + dh)))
        sleeve = 4.0 / (DA ** 2 - dh ** 2) * (lK - (DA - dW) / (w * tphi))
        return (cone + sleeve) / (self.E * math.pi)

    def assembly_preload(self) -> float:
        """``F_M`` (N) at the utilisation of the yield strength (module doc)."""
        P, d2, d3 = self.thread
        d0 = 0.5 * (d2 + d3)
        A0 = math.pi * d0 ** 2 / 4
        t = 1.5 * d2 / d0 * (P / (math.pi * d2) + 1.155 * self.mu_thread)
        return self.utilisation * self.yield_strength * A0 / math.sqrt(1.0 + 3.0 * t * t)

    def preload(self) -> float:
        """Smallest preload of all the joint's bolts, ``n (F_M/α_A − f_Z/(δ_S + δ_P))`` (N)."""
        return self.bolts * (self.assembly_preload() / self.alpha_A
                             - self.f_Z / (self.bolt_resilience() + self.clamped_resilience()))

    @property
    def interface_area(self) -> float:
        return self.width * self.depth - self.bolts * math.pi * self.d_h ** 2 / 4

    @property
    def interface_inertia(self) -> float:
        """``I_Bers`` (mm⁴): the interface about the bending axis (across ``width``), less the holes (on the
        axis)."""
        return self.depth * self.width ** 3 / 12.0 - self.bolts * math.pi * self.d_h ** 4 / 64.0

    def bending_resiliences(self) -> tuple[float, float]:
        """VDI 2230's ``(β_S, β_P)`` (rad/(N·mm)) of the bolt(s) and the clamped solids (module doc)."""
        P, d2, d3 = self.thread
        return (self.l_K / (self.E * self.bolts * math.pi * d3 ** 4 / 64.0),
                self.l_K / (self.E * self.interface_inertia))

    def tilt_compliance(self, roughness) -> float:
        """Rotation per moment (rad/(N·mm)) of the closed joint's rough interface (module doc)."""
        kn = roughness.stiffness_at_pressure(self.preload() / self.interface_area)
        return 1.0 / (kn * self.interface_inertia)

    def shear_compliance(self, roughness, poisson: float = 0.3) -> float:
        """Displacement per shear force (mm/N) of the stuck interface: Mindlin's ratio of tangential to normal
        stiffness ``2(1 − ν)/(2 − ν)`` (Johnson 1985 §7.2) applied to the rough layer's normal stiffness."""
        kn = roughness.stiffness_at_pressure(self.preload() / self.interface_area) * self.interface_area
        return 1.0 / (2.0 * (1.0 - poisson) / (2.0 - poisson) * kn)

    def opening_and_slip(self, moment: float, shear: float, mu_interface: float = 0.15) -> dict:
        """``{"opens": bool, "slips": bool, "margin_open", "margin_slip"}`` under ``moment`` (N·mm) and ``shear``
        (N): edge pressure ``F_V/A − M (w/2)/I`` and friction ``μ_T F_V − F_Q`` (module doc)."""
        FV = self.preload()
        edge = FV / self.interface_area - abs(moment) * 0.5 * self.width / self.interface_inertia
        grip = mu_interface * FV - abs(shear)
        return {"opens": edge < 0, "slips": grip < 0, "margin_open": edge, "margin_slip": grip}
