"""Compliance of the thin seats and rings the closed forms leave out, by plane-stress finite elements
(:mod:`.plane_fe`, scikit-fem): the cycloid disc around its crank-bearing holes, the carrier plates around
their bearing cups, the housing ring behind the pin grooves.

Each model is loaded by the element's **statics at the given output torque** and returns the work
``W = Σ F·u`` of its loads (twice the strain energy, N·mm) and ``Σ|F|²`` of the loads the 20-DOF model
puts the element in series with, so that the **energy-equivalent compliance** ``c = W / Σ|F|²`` (mm/N)
stores the same energy there (:mod:`rvtol.models.reducer_20dof.compliance`).  The loads are averaged over
the crank angle (``angles`` positions over one third of a crank turn: the three cranks repeat after 120°).

**Disc** (:func:`disc_work`).  The disc (root circle ``r_o``, centre bore, three crank holes on the crank
circle, three pillar clearance holes between them) in plane stress, thickness = disc width.  Pins: the
classical load sharing of a rigid, unmodified cycloid disc (Blanche & Yang, *Mech. Mach. Theory* 24 (1989)
281; Yang & Blanche, *J. Mech. Des.* 112 (1990) 41): every pin on the loaded half pushes the disc along its
common normal, which passes through the pitch point ``I`` (distance ``e z_p`` from the housing centre on the
line of centres), with a force proportional to its lever arm ``l_k`` about the disc centre (the normal
approach of a rigidly rotated disc), scaled to the disc torque ``T_c = T i_b / 2``; each force is spread
over one pin pitch of the root circle (:func:`.plane_fe.patch_load`).  Crank holes: the needle rows push
the hole walls with the statics of doc 004 (``F_i = −F_R/3 + T_c/(3 a) t̂_i``, exactly balancing the pins),
as the roller-load distribution ``cos^(10/9)`` over ±90° (:func:`.plane_fe.arc_load`).  The element
reduced to the 20-DOF is the part **beyond the axisymmetric web** (:mod:`.disc_web`, which stays its own
element): ``W − T_c²/K_web``.

**Carrier plate** (:func:`carrier_plate_work`).  End plate or flange (outer radius ``r_o``, centre bore, three
cup seats on the crank circle) in plane stress, thickness = plate thickness, clamped at the three pillar
roots (each the circle of the pillar section's area, :func:`.carrier_structure.equivalent_boss_radius`: the
pillars' own compliance is the ``carrier`` element); each cup seat is pushed by its bearing's share of the
crank resultant, tangential ``ρ T/(3 a)`` (the two discs' radial resultants cancel on a crank), as the
``cos^(10/9)`` roller-load distribution over ±90°.

**Housing ring** (:func:`housing_ring_work`).  The annulus from the groove contact's reference depth
(``R_p + r_p + r_g``: the groove contact, :mod:`.pin_groove`, carries the approach down to one groove
radius behind the contact) to the radius where the housing is held (``r_o``, its bolt circle: clamped), in
plane stress, thickness = pin length, loaded by both discs' pin forces (the classical sharing above, the two
discs half a turn apart), each spread over one pin pitch.

All three leave out: the axial (3-D) spreading of the load beyond the plate's own thickness, which makes the
2-D plate a **soft** bound for a plate joined to thicker neighbours; stress concentrations at the roller
ends; friction.  Units: mm, N, MPa.

The three seats are kept on disk by their inputs and this code (:mod:`.fe_cache`) and memoised per process: a design
computes each once, whatever the number of processes and runs.
"""
from __future__ import annotations

import math
import sys
from dataclasses import dataclass

import numpy as np

from ..errors import SpecError
from . import _checks, disc_web, fe_cache, plane_fe
from .plane_fe import Circle, PlateModel, annulus_mesh, arc_load, patch_load, perforated_disc_mesh

#: default mesh sizes (mm): global and at the holes; crank-angle positions averaged over
MESH_H, MESH_H_FINE, ANGLES = 4.0, 0.8, 4


@dataclass(frozen=True)
class SeatResult:
    """Work ``W`` (N·mm) of the loads at each crank angle, ``Σ|F|²`` (N²) of the loads the element is in
    series with, and the energy-equivalent compliance ``c = mean W / mean Σ|F|²`` (mm/N)."""

    work: tuple
    force_sq: tuple

    @property
    def compliance(self) -> float:
        return float(np.mean(self.work) / np.mean(self.force_sq))

    def to_value(self) -> dict:
        """The result as JSON (:mod:`.fe_cache`): its two tuples as lists of floats."""
        return {"work": [float(w) for w in self.work], "force_sq": [float(f) for f in self.force_sq]}

    @classmethod
    def from_value(cls, value: dict) -> "SeatResult":
        """The inverse of :meth:`to_value`."""
        return cls(tuple(float(w) for w in value["work"]), tuple(float(f) for f in value["force_sq"]))


#: a seat computed once per design, kept on disk by its inputs and this code (:mod:`.fe_cache`) and memoised per
#: process
_by_content = fe_cache.content_cached(to_value=SeatResult.to_value, from_value=SeatResult.from_value,
                                      modules=(sys.modules[__name__], plane_fe, _checks, fe_cache))


def pin_forces(torque: float, z_p: int, z_c: int, R_p: float, ecc: float, phase: float = 0.0):
    """Classical pin forces on one disc (module doc): ``(angles φ_k, forces (n, 2))`` in the housing frame
    with the eccentricity along ``phase``; the disc centre is at ``e (cos phase, sin phase)``; the forces
    turn the disc by ``+torque`` (N·mm, counter-clockwise) about its centre."""
    phi = 2.0 * np.pi * np.arange(z_p) / z_p
    pin = R_p * np.vstack([np.cos(phi), np.sin(phi)])
    u = np.array([math.cos(phase), math.sin(phase)])
    centre = ecc * u
    pitch = ecc * z_p * u
    d = pitch[:, None] - pin
    d /= np.hypot(*d)
    r = pin - centre[:, None]
    lever = r[0] * d[1] - r[1] * d[0]                 # moment of a unit force about the disc centre
    w = np.where(lever > 1e-12 * R_p, lever, 0.0)     # pins that can push the disc counter-clockwise
    F = w / float(np.sum(w * lever)) * float(torque)
    return phi, (d * F).T


def _crank_holes(a, n=3, start=0.0):
    return [start + 2.0 * np.pi * i / n for i in range(n)]


@_by_content
def disc_work(torque: float, *, r_root: float, bore: float, crank_radius: float, crank_hole: float,
              pillar_radius: float, pillar_hole: float, thickness: float, z_p: int, z_c: int, R_p: float,
              ecc: float, E: float, nu: float, angles: int = ANGLES, h: float = MESH_H,
              h_fine: float = MESH_H_FINE) -> SeatResult:
    """The disc under its pins and crank holes (module doc); ``Σ|F|²`` over the three crank-hole forces.
    Cached by its inputs, on disk and per process (:mod:`.fe_cache`)."""
    beta = _crank_holes(crank_radius)
    holes = [Circle(crank_radius * math.cos(b), crank_radius * math.sin(b), 0.5 * crank_hole) for b in beta]
    holes += [Circle(pillar_radius * math.cos(b + math.pi / 3), pillar_radius * math.sin(b + math.pi / 3),
                     0.5 * pillar_hole) for b in beta]
    mesh = perforated_disc_mesh(r_root, holes, bore=0.5 * bore, h=h, h_fine=h_fine)
    model = PlateModel(mesh, E, nu, thickness)
    rim = Circle(0.0, 0.0, r_root)
    half = math.pi / z_p
    works, fsq = [], []
    for k in range(int(angles)):
        phase = 2.0 * np.pi / 3.0 * k / angles
        phi, F = pin_forces(torque, z_p, z_c, R_p, ecc, phase)
        centre = ecc * np.array([math.cos(phase), math.sin(phase)])
        loads = []
        for ang, f in zip(phi, F):
            if np.hypot(*f) > 0:
                c = R_p * np.array([math.cos(ang), math.sin(ang)]) - centre      # pin seen from the disc centre
                loads.append(patch_load(rim, math.atan2(c[1], c[0]), f, thickness, half))
        FR = F.sum(axis=0)
        Fh = [-FR / 3.0 - torque / (3.0 * crank_radius) * np.array([-math.sin(b), math.cos(b)]) for b in beta]
        loads += [arc_load(hc, fh, thickness) for hc, fh in zip(holes[:3], Fh)]
        works.append(model.solve(loads).work)
        fsq.append(float(sum(np.dot(f, f) for f in Fh)))
    return SeatResult(tuple(works), tuple(fsq))


def disc_seat_compliance(result: SeatResult, torque: float, web_stiffness: float) -> float:
    """Compliance per crank hole (mm/N) of the disc beyond its axisymmetric web: ``(W − T_c²/K_web)/Σ|F|²``;
    raises :class:`SpecError` if the finite-element disc is stiffer than the web's closed form (the web is
    a lower bound of the disc's compliance: :mod:`.disc_web`)."""
    extra = float(np.mean(result.work)) - float(torque) ** 2 / float(web_stiffness)
    if not extra > 0:
        raise SpecError(f"the finite-element disc stores less than its axisymmetric web (work {np.mean(result.work):.4g}"
                        f" against {float(torque) ** 2 / float(web_stiffness):.4g} N·mm): mesh too coarse",
                        key="cycloid.crank_hole_diameter")
    return extra / float(np.mean(result.force_sq))


@_by_content
def carrier_plate_work(torque: float, *, r_outer: float, bore: float, crank_radius: float, cup_diameter: float,
                       pillar_radius: float, pillar_root_radius: float, thickness: float, share: float,
                       E: float, nu: float, h: float = MESH_H, h_fine: float = MESH_H_FINE) -> SeatResult:
    """A carrier plate under its three cup seats, clamped at the pillar roots (module doc): each cup carries
    ``share · torque / (3 a)`` tangentially.  ``Σ|F|²`` over the three cups."""
    beta = _crank_holes(crank_radius)
    cups = [Circle(crank_radius * math.cos(b), crank_radius * math.sin(b), 0.5 * cup_diameter) for b in beta]
    roots = [Circle(pillar_radius * math.cos(b + math.pi / 3), pillar_radius * math.sin(b + math.pi / 3),
                    pillar_root_radius) for b in beta]
    mesh = perforated_disc_mesh(r_outer, cups + roots, bore=0.5 * bore, h=h, h_fine=h_fine)

    def clamped(x):
        return np.any([np.abs(c.distance(x)) < 1e-3 * c.r + 0.05 * h_fine for c in roots], axis=0)

    model = PlateModel(mesh, E, nu, thickness, fixed=clamped)
    f = float(share) * float(torque) / (3.0 * crank_radius)
    Fc = [f * np.array([-math.sin(b), math.cos(b)]) for b in beta]
    sol = model.solve([arc_load(c, fc, thickness) for c, fc in zip(cups, Fc)])
    return SeatResult((sol.work,), (float(sum(np.dot(v, v) for v in Fc)),))


@_by_content
def housing_ring_work(torque: float, *, r_inner: float, r_outer: float, thickness: float, z_p: int, z_c: int,
                      R_p: float, ecc: float, E: float, nu: float, angles: int = ANGLES, n_r: int = 8,
                      per_pitch: int = 8) -> SeatResult:
    """The housing ring under both discs' pins (module doc), clamped at ``r_outer``; ``torque`` = one disc's
    torque ``T_c``.  ``Σ|F|²`` over the pin forces of both discs."""
    ri = float(_checks.positive("r_inner", r_inner))
    ro = float(_checks.positive("r_outer", r_outer))
    if not ro > ri:
        raise SpecError(f"the housing's clamp radius {ro:g} mm must exceed the groove contact's reference radius "
                        f"{ri:g} mm", key="housing.clamp_radius")
    n_r = max(int(n_r), int(math.ceil(n_r * (ro - ri) / (2.0 * math.pi * ri / z_p))))
    mesh = annulus_mesh(ri, ro, n_r, z_p * int(per_pitch))
    model = PlateModel(mesh, E, nu, thickness, fixed=lambda x: np.hypot(*x) > 0.5 * (ri + ro))
    ring = Circle(0.0, 0.0, ri)
    half = math.pi / z_p
    works, fsq = [], []
    for k in range(int(angles)):
        phase = 2.0 * np.pi / z_p * k / angles
        loads, s2 = [], 0.0
        for disc in range(2):
            phi, F = pin_forces(torque, z_p, z_c, R_p, ecc, phase + math.pi * disc)
            for ang, f in zip(phi, F):
                if np.hypot(*f) > 0:
                    loads.append(patch_load(ring, ang, -f, thickness, half))     # the pin pushes the housing
                    s2 += float(np.dot(f, f))
        works.append(model.solve(loads).work)
        fsq.append(s2)
    return SeatResult(tuple(works), tuple(fsq))


def log_sensitivity(fn, params: dict, names, rel_step: float = 0.02) -> dict:
    """``d ln c / d ln x`` of ``fn(**params) -> c`` for each name, by central differences (the linearised
    model of :mod:`studies/compliance_chain.md` §7: a per-sample dimension ``x`` changes ``c`` by
    ``c (1 + s Δx/x)``)."""
    out = {}
    for n in names:
        lo, hi = dict(params), dict(params)
        lo[n] = params[n] * (1.0 - rel_step)
        hi[n] = params[n] * (1.0 + rel_step)
        out[n] = (math.log(fn(**hi)) - math.log(fn(**lo))) / (math.log(1 + rel_step) - math.log(1 - rel_step))
    return out


__all__ = ["SeatResult", "pin_forces", "disc_work", "disc_seat_compliance", "carrier_plate_work",
           "housing_ring_work", "log_sensitivity", "disc_web"]
