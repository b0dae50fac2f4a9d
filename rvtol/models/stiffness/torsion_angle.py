"""Elastic torsion angle of the RV reducer at the output, input locked (doc 004).

``θ_Σ = θ1 + θ2 + θ3 + θ4 + θ5``: involute stage, cycloid–pin stage,
turning-arm (crank) bearings, crankshafts, planet carrier.

**Statics** (doc 004's equilibrium and deformation-coordination conditions).
An output torque ``T`` on the carrier is reacted by the pins and, through the
involute stage, by the locked sun (``T/i``, ``i = 1 + z_p z2/z1``).  The
pins' forces all pass through the pitch point, at ``r_p' = a z_p`` from the
axis and ``r_c' = a z_c`` from the cycloid centre, so each of the two discs
carries the torque ``T_c = T (1 - 1/i) z_c / (2 z_p)`` about its own centre
(:mod:`.cycloid_contact` solves its pins).  The three planets share the sun
equally (``δ_sp1 = δ_sp2 = δ_sp3``); the three turning-arm bearings of a disc
take equal thirds of the pins' net force and equal tangential forces
``T_c / (3 a_0)`` for the moment (a rigid disc on three equal isotropic
bearings 120° apart: translation and rotation uncouple), ``a_0 = m (z1+z2)/2``
the crank circle.  Each crank is a beam on its two support bearings loaded by
its two turning-arm bearings and its planet gear; the carrier's input-side
end plate passes its share of the crank reactions to the output flange
through the pillars.

**Torsion angles.**  Every component's contribution is its deformation
times the kinematic ratio from that deformation to the output rotation.  For
these statically determined load paths the ratio equals the element force
per unit output torque (virtual work, unit-load method), so rvtol computes::

    θ_c = Σ_e f_e · δ_e / T      over the elements e of component c

(``f_e`` force, ``δ_e`` deformation of element e).  This reproduces the
document's formulas with their ratios made explicit:

* ``θ1 = 3 F_n (F_n / k_X) / T`` with ``F_n = T/(3 i r_b1)``, i.e. the sun's
  rotation under ``T/i`` on ``3 K_X`` (``K_X = k_X r_b²``, :mod:`.involute`)
  divided by ``i`` — doc 004's ``θ1 = F_t/(k_X r_1 i_z)`` with ``i_z = i``
  (the document's form drops a ``cos² α``; rvtol uses the base radius as in
  ``K_X = k_X r_s²``);
* ``θ2 = i_b Δθ_b`` with ``Δθ_b = β`` the cycloid's elastic rotation and
  ``i_b = 2 T_c / T = (1 - 1/i) z_c / z_p``;
* ``θ3 = Σ |f_s| δ_s(|f_s|) / T`` over the six turning-arm bearings
  (:func:`rvtol.elements.rolling_bearings.radial_deflection`, Palmgren).  ``bearing_kinematics = "tangential"``
  instead counts only the rotation of the disc relative to the carrier,
  ``Σ (T_c/(3 a_0)) δ_s / T`` — doc 004's ``θ3 = z_c Δδ_s i_b / (z_p a_0)``
  with the same ``i_b``; equal when the bearing forces are purely tangential;
* ``θ4`` bending + shear (:mod:`.crankshaft`) and torsion of the three cranks;
* ``θ5 = T_B² / (K_5 T)`` with ``T_B`` the torque the cranks deliver to the
  input-side end plate and ``K_5`` the pillars' stiffness (:mod:`.carrier`).

Negative torques load the other flanks: rvtol mirrors the pin phase and the
crank angle and returns negative angles.

**Further components** (issue 12), present only when the design gives their data
(:mod:`rvtol.elements.reducer_chain`, the same elements the 20-DOF model reduces to
its contacts), each by virtual work under doc 004's statics:

* ``crank_support_bearings``: the preloaded tapered roller pair of each crank under
  the crank's three loads (gear, two eccentrics) as a 5-component load
  (:meth:`~rvtol.elements.rolling_bearings.BearingPair.solve`), ``Σ P·u(z) / T``;
* ``pin_groove``: the pin in its housing groove in series with the disc–pin
  contact — the contact solution uses the summed approach ``w(F) = w_pin(F) +
  w_groove(F)`` (more pins share the load), and ``θ2 = i_b w(F_max)/r_c'`` splits
  into ``i_b w_pin/r_c'`` (cycloid–pin) and ``i_b w_groove/r_c'`` (groove);
* ``disc_web``: ``2 T_c² / (K_web T)`` with ``T_c = T i_b/2`` (statics);
* ``input_shaft``: ``T / (K_in i²)`` (the sun carries ``T/i``).

With the crank layout (``crank.journal_diameter``, ``crank.eccentric_diameter``)
θ4 uses the stepped shaft instead of doc 004's uniform beam, and with the carrier
plates (``carrier.flange_thickness``, ``end_plate_thickness``, ``plate_clamp_radius``)
θ5 the pillars with flexible end plates (:mod:`rvtol.elements.carrier_structure`).
A family's ``compliance_scale.<family>`` multiplies its compliance (the cycloid–pin
and groove approaches inside the contact solution).  Not modelled: pin bending,
housing and flange deformation beyond the pillar roots.

**Keys.**  The stiffness model reads doc 004's keys and, where a design spells the
same quantity as the 20-DOF model does (the RV-80E product), falls back to those:
``first_stage.module`` → ``sun.module``, ``first_stage.pressure_angle`` →
``sun.pressure_angle``, ``first_stage.face_width`` → ``sun.face_width``,
``first_stage.profile_shift_sun`` / ``_planet`` → ``sun.profile_shift`` /
``planet.profile_shift``, ``cycloid.width`` → ``cycloid.face_width``; the crank
circle is ``crank_bearing.centre_radius`` where given (the operating centre
distance of shifted gears), else doc 004's ``a_0 = m (z1 + z2)/2``.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from ... import units
from ...errors import SpecError
from ...elements import carrier, crankshaft, involute, rolling_bearings
from ...elements.reducer_chain import ChainElements
from .cycloid_contact import ContactSolution, PinGear, angular_backlash, design_number, first_key, solve_contact

COMPONENTS = ("involute", "cycloid_pin", "crank_bearings", "crankshafts", "carrier")
LABELS = {
    "involute": "Involute gear stage (θ1)",
    "cycloid_pin": "Cycloid–pin stage (θ2)",
    "crank_bearings": "Turning-arm bearings (θ3)",
    "crankshafts": "Crankshafts (θ4)",
    "carrier": "Planet carrier (θ5)",
}
#: components beyond doc 004's five, present when the design gives their data (module doc)
EXTRA_COMPONENTS = ("crank_support_bearings", "pin_groove", "disc_web", "input_shaft")
LABELS.update({
    "crank_support_bearings": "Crank support bearings (tapered pair)",
    "pin_groove": "Pins in housing grooves",
    "disc_web": "Cycloid disc webs",
    "input_shaft": "Input-shaft twist",
})
#: compliance family (rvtol.elements.reducer_chain.FAMILIES) of each component; θ4 is split into two
FAMILY_OF = {"involute": "sun_planet_mesh", "cycloid_pin": "cycloid_pin", "crank_bearings": "turning_arm_bearings",
             "carrier": "carrier", **{c: c for c in EXTRA_COMPONENTS}}
BEARING_KINEMATICS = ("virtual_work", "tangential")


@dataclass(frozen=True)
class ReducerStiffness:
    """Everything the torsion-angle model needs, in base units (mm, N, MPa, rad)."""

    pins: PinGear
    z1: int
    z2: int
    cranks: int
    discs: int
    module: float
    pressure_angle: float
    gear_width: float
    shift_sun: float
    shift_planet: float
    crank_diameter: float
    support_span: float
    disc_pitch: float
    gear_overhang: float
    bearing_rollers: int
    bearing_length: float
    pillars: int
    pillar_radius: float
    pillar_width: float
    pillar_thickness: float
    pillar_length: float
    bearing_kinematics: str = "virtual_work"
    crank_circle: float | None = None      # crank_bearing.centre_radius (None: a_0 = m (z1 + z2)/2)
    chain: ChainElements | None = None     # the design's compliance elements (module doc)

    @classmethod
    def from_design(cls, design, **override) -> "ReducerStiffness":
        """The design's reducer; bad numbers raise :class:`SpecError` naming the design file and key."""
        d = design

        def num(name, **kw):
            return design_number(d, name, **kw)

        def whole(name):
            return design_number(d, name, integer=True)

        for name, want in (("reducer.cranks", 3), ("reducer.discs", 2)):
            if whole(name) != want:
                raise SpecError(f"the torsion-angle model is written for 3 cranks and 2 discs, got {d[name]:g}",
                                file=d.file, key=name)
        span = num("crank.support_span")
        z1, z2 = whole("sun.teeth"), whole("planet.teeth")
        module = num(first_key(d, "first_stage.module", "sun.module"))
        circle = num("crank_bearing.centre_radius") if "crank_bearing.centre_radius" in d else None
        chain = ChainElements.from_design(d, circle if circle is not None else module * (z1 + z2) / 2.0)
        if "pin.groove_radius" in d and chain.groove is not None:
            pins = PinGear.from_design(d, groove=chain.groove, approach_scale=chain.scale("cycloid_pin"),
                                       groove_scale=chain.scale("pin_groove"))
        else:
            pins = PinGear.from_design(d, approach_scale=chain.scale("cycloid_pin"))
        vals = dict(
            pins=pins, z1=z1, z2=z2, cranks=3, discs=2, module=module,
            pressure_angle=num(first_key(d, "first_stage.pressure_angle", "sun.pressure_angle"), upper=0.5 * np.pi),
            gear_width=num(first_key(d, "first_stage.face_width", "sun.face_width")),
            shift_sun=float(d[first_key(d, "first_stage.profile_shift_sun", "sun.profile_shift")]),
            shift_planet=float(d[first_key(d, "first_stage.profile_shift_planet", "planet.profile_shift")]),
            crank_diameter=num("crank.shaft_diameter"), crank_circle=circle, chain=chain,
            support_span=span, disc_pitch=num("crank.disc_pitch", nonnegative=True, upper=span),
            gear_overhang=num("crank.gear_overhang", nonnegative=True), bearing_rollers=whole("crank_bearing.rollers"),
            bearing_length=num("crank_bearing.roller_length"), pillars=whole("carrier.pillars"),
            pillar_radius=num("carrier.pillar_radius"), pillar_width=num("carrier.pillar_width"),
            pillar_thickness=num("carrier.pillar_thickness"), pillar_length=num("carrier.pillar_length"))
        vals.update(override)
        return cls(**vals)

    def with_pins(self, **kw) -> "ReducerStiffness":
        """A copy with pin-gear parameters replaced (``R_p``, ``a``, ``b``, ...)."""
        return replace(self, pins=replace(self.pins, **kw))

    # -- derived geometry --------------------------------------------------
    @property
    def ratio(self) -> float:
        """Total ratio, input locked, output on the carrier: ``1 + z_p z2 / z1``."""
        return 1.0 + self.pins.z_p * self.z2 / self.z1

    @property
    def crank_radius(self) -> float:
        """The crank circle: the design's ``crank_bearing.centre_radius`` (the operating centre distance of
        shifted gears) where given, else doc 004's ``a_0 = m (z1 + z2) / 2`` (unshifted)."""
        if self.crank_circle is not None:
            return self.crank_circle
        return self.module * (self.z1 + self.z2) / 2.0

    @property
    def components(self) -> tuple[str, ...]:
        """Doc 004's five components and the further ones the design provides (module doc)."""
        el = self.chain
        if el is None:
            return COMPONENTS
        return COMPONENTS + tuple(c for c in EXTRA_COMPONENTS if c in el.present)

    def scale(self, family: str) -> float:
        return 1.0 if self.chain is None else self.chain.scale(family)

    @property
    def i_b(self) -> float:
        """Output rotation per elastic cycloid rotation, ``(1 - 1/i) z_c / z_p``."""
        return (1.0 - 1.0 / self.ratio) * self.pins.z_c / self.pins.z_p

    def disc_torque(self, T):
        """``T_c`` per disc for output torque ``T`` (N·mm)."""
        return np.asarray(T, float) * (1.0 - 1.0 / self.ratio) * self.pins.z_c / (self.discs * self.pins.z_p)

    @property
    def K_carrier(self) -> float:
        """Pillars with flexible end plates where the design gives the plates, else doc 004's pillars."""
        if self.chain is not None and self.chain.carrier_stiffness is not None:
            return self.chain.carrier_stiffness
        p = self.pins
        return carrier.torsional_stiffness(self.pillars, self.pillar_radius, self.pillar_width,
                                           self.pillar_thickness, self.pillar_length, p.E, p.nu)

    # -- evaluation ----------------------------------------------------------
    def evaluate(self, torque, equidistance_mod=None, moved_distance_mod=None, pin_circle_error=0.0,
                 pin_radius_error=0.0, pin_phase: float = 0.0, crank_angle: float = 0.0,
                 nominal_mods: tuple[float, float] | None = None) -> "TorsionAngles":
        """Torsion angles at output torque ``torque`` (N·mm, any sign), vectorised over samples.

        Modifications default to ``nominal_mods`` (the design's ``(Δr_p, ΔR_p)``) when not given.
        """
        if self.discs != 2 or self.cranks != 3:
            raise ValueError("the torsion-angle model is written for 2 discs and 3 cranks")
        if nominal_mods is None and (equidistance_mod is None or moved_distance_mod is None):
            raise ValueError("give the modifications or nominal_mods")
        dr = nominal_mods[0] if equidistance_mod is None else equidistance_mod
        dR = nominal_mods[1] if moved_distance_mod is None else moved_distance_mod
        T, dr, dR, eR, er = np.broadcast_arrays(
            *(np.atleast_1d(np.asarray(v, float)) for v in (torque, dr, dR, pin_circle_error, pin_radius_error)))
        neg = T < 0
        theta = np.zeros((len(T), len(self.components)))
        extra = {k: np.zeros(len(T)) for k in ("max_pin_force", "contact_pairs", "K_B", "beta", "F_ref",
                                               "beta_rigid", "interference", "crank_bending", "crank_torsion")}
        contacts: list[tuple[np.ndarray, ContactSolution]] = []
        for rows, sign in ((~neg, 1.0), (neg, -1.0)):
            if not rows.any():
                continue
            th, ex, cs = self._evaluate_positive(np.abs(T[rows]), dr[rows], dR[rows], eR[rows], er[rows],
                                                 sign * pin_phase, sign * crank_angle)
            theta[rows] = sign * th
            for k in extra:
                extra[k][rows] = sign * ex[k] if k in ("crank_bending", "crank_torsion") else ex[k]
            contacts.append((np.flatnonzero(rows), cs))
        # flank to flank: twice (rotation to close n0 at φ0 + the discrete-pin remainder to first contact)
        backlash = self.i_b * (angular_backlash(self.pins, dr, dR, eR, er) + 2.0 * extra["beta_rigid"])
        return TorsionAngles(T, theta, extra, backlash, contacts, self.components)

    def _evaluate_positive(self, T, dr, dR, eR, er, phase, crank_angle):
        p = self.pins
        Tc = self.disc_torque(T)
        cs = solve_contact(p, Tc, dr, dR, eR, er, phase)
        Tsafe = np.where(T > 0, T, 1.0)

        # θ1: involute stage (three equal meshes, sun torque T/i)
        rb1 = self.module * self.z1 / 2.0 * np.cos(self.pressure_angle)
        Fn = T / (self.ratio * self.cranks * rb1)
        Ft = Fn * np.cos(self.pressure_angle)
        kX = involute.mesh_stiffness(self.z1, self.z2, self.module, self.pressure_angle, self.gear_width, Ft,
                                     self.shift_sun, self.shift_planet)
        th1 = np.where(kX > 0, self.cranks * Fn ** 2 / np.where(kX > 0, kX, 1.0), 0.0) / Tsafe

        th1 = th1 * self.scale("sun_planet_mesh")

        # θ2: cycloid–pin stage (with the pin grooves in series: split at the largest arm, module doc)
        th2 = self.i_b * cs.beta
        th_groove = np.zeros_like(th2)
        if p.groove is not None:
            w_total = np.where(cs.F_ref > 0, cs.approach_ref, 1.0)
            th_groove = np.where(cs.F_ref > 0, th2 * p.groove_approach(cs.F_ref) / w_total, 0.0)
            th2 = th2 - th_groove

        ld = self.crank_loads(cs, crank_angle)
        delta = rolling_bearings.radial_deflection(ld.bearing_force, self.bearing_rollers, self.bearing_length)
        if self.bearing_kinematics == "tangential":
            th3 = (ld.tangential[:, None] * delta).sum(axis=1) / Tsafe
        else:
            th3 = (ld.bearing_force * delta).sum(axis=1) / Tsafe
        th3 = th3 * self.scale("turning_arm_bearings")

        # θ4: crankshafts, bending + shear of the beam, torsion of its two segments
        t1, t2 = ld.torque
        crank = self.chain.crank if self.chain is not None else None
        if crank is None:
            A = crankshaft.influence_matrix(ld.z, self.support_span, self.crank_diameter, p.E, p.nu)
            cJ = crankshaft.torsional_compliance(self.crank_diameter, p.E, p.nu)
            c01, c12 = cJ * (ld.z[1] - ld.z[0]), cJ * (ld.z[2] - ld.z[1])
        else:                           # the stepped shaft, frame centred between the supports
            zc = ld.z - 0.5 * self.support_span
            A = crank.bending_flexibility(zc)
            c01, c12 = crank.twist(zc[0], zc[1]), crank.twist(zc[1], zc[2])
        defl = np.einsum("jk,nikd->nijd", A, ld.loads)
        bend = (ld.loads * defl).sum(axis=(1, 2, 3)) / Tsafe * self.scale("crank_bending")
        twist = ((t1 + t2) ** 2 * c01 + t2 ** 2 * c12).sum(axis=1) / Tsafe * self.scale("crank_torsion")
        th4 = bend + twist

        # θ5: carrier, torque the cranks deliver to the input-side end plate (support at z = 0)
        TB = ld.support_torque(self.crank_radius, self.support_span)[0]
        th5 = TB ** 2 / self.K_carrier / Tsafe * self.scale("carrier")

        cols = [th1, th2, th3, th4, th5]
        el = self.chain
        for c in self.components[len(COMPONENTS):]:
            if c == "crank_support_bearings":
                cols.append(self._support_pair(ld) / Tsafe * el.scale(c))
            elif c == "pin_groove":
                cols.append(th_groove)
            elif c == "disc_web":
                cols.append(2.0 * self.disc_torque(T) ** 2 / el.web_stiffness / Tsafe * el.scale(c))
            elif c == "input_shaft":
                cols.append(T / (el.input_shaft_stiffness * self.ratio ** 2) * el.scale(c))
        pos = (T > 0)
        theta = np.stack(cols, axis=1) * pos[:, None]
        extra = dict(max_pin_force=cs.max_force, contact_pairs=cs.contacts.astype(float), K_B=cs.K_B,
                     beta=cs.beta, F_ref=cs.F_ref, beta_rigid=cs.beta_rigid, interference=cs.interference.astype(float),
                     crank_bending=bend * pos, crank_torsion=twist * pos)
        return theta, extra, cs

    def _support_pair(self, ld: "CrankLoads") -> np.ndarray:
        """Work ``Σ P·u(z)`` (N·mm) of every crank's loads on its support pair (rigid crank), per sample."""
        pair = self.chain.pair
        z = ld.z - 0.5 * self.support_span                      # the pair's frame: centred between the supports
        P = ld.loads                                            # (n, cranks, points, 2)
        f = np.stack([P[..., 0].sum(-1), P[..., 1].sum(-1), np.zeros(P.shape[:2]),
                      -(z * P[..., 1]).sum(-1), (z * P[..., 0]).sum(-1)], axis=-1).reshape(-1, 5)
        q = pair.solve(f, tol=1e-8).q.reshape(P.shape[0], P.shape[1], 5)
        u = np.stack([q[..., None, 0] + q[..., None, 4] * z, q[..., None, 1] - q[..., None, 3] * z], axis=-1)
        return (P * u).sum(axis=(1, 2, 3))


    def crank_loads(self, cs: ContactSolution, crank_angle: float = 0.0) -> "CrankLoads":
        """Turning-arm bearing and crank loads for a solved contact (frame ``e_r, e_t`` of disc 1).

        Disc 2 is disc 1 turned by 180°: the pins' net force reverses, the
        moment (and so the tangential bearing forces) does not.
        """
        p = self.pins
        gam = crank_angle + 2.0 * np.pi * np.arange(self.cranks) / self.cranks
        rhat = np.stack([np.cos(gam), np.sin(gam)], axis=1)          # (3, 2) crank directions from the axis
        that = np.stack([-np.sin(gam), np.cos(gam)], axis=1)         # (3, 2) tangential
        FR = cs.resultant()                                          # (n, 2) pins on disc 1
        c = cs.torque / (self.cranks * self.crank_radius)           # (n,) tangential share for the moment
        f1 = -FR[:, None, :] / self.cranks + c[:, None, None] * that[None]   # (n, 3, 2) on disc 1
        f2 = +FR[:, None, :] / self.cranks + c[:, None, None] * that[None]   # on disc 2
        P1, P2 = -f1, -f2                                            # the same forces on the cranks
        tau1 = p.a * P1[..., 1]                                      # torque of P1 on the crank (e_1 = +e_r)
        tau2 = -p.a * P2[..., 1]                                     # (e_2 = -e_r)
        Fg_t = (tau1 + tau2) / (self.module * self.z2 / 2.0)         # planet gear tangential force
        Fg = Fg_t[..., None] * that[None] + (np.abs(Fg_t) * np.tan(self.pressure_angle))[..., None] * rhat[None]
        L = self.support_span
        z = np.array([-self.gear_overhang, (L - self.disc_pitch) / 2.0, (L + self.disc_pitch) / 2.0])
        return CrankLoads(np.stack([Fg, P1, P2], axis=2), z, rhat,
                          np.sqrt(np.concatenate([(f1 ** 2).sum(-1), (f2 ** 2).sum(-1)], axis=1)), c,
                          (tau1, tau2))


@dataclass
class CrankLoads:
    """Loads on the three cranks (N, N·mm), frame of disc 1."""

    loads: np.ndarray          # (n, 3 cranks, 3 points [gear, disc 1, disc 2], 2)
    z: np.ndarray              # (3,) axial positions of the points, supports at 0 and L
    rhat: np.ndarray           # (3, 2) crank directions from the axis
    bearing_force: np.ndarray  # (n, 6) turning-arm bearing force magnitudes (disc 1 cranks, disc 2 cranks)
    tangential: np.ndarray     # (n,) tangential bearing force T_c / (3 a_0)
    torque: tuple              # crank torques from disc 1 and disc 2, each (n, 3)

    def support_torque(self, crank_radius: float, span: float) -> np.ndarray:
        """Torque about the axis (N·mm) the cranks put on the carrier at each support, ``(2, n)``."""
        R = np.einsum("sk,nikd->snid", crankshaft.support_reactions(self.z, span), self.loads)
        return crank_radius * (self.rhat[None, None, :, 0] * R[..., 1]
                               - self.rhat[None, None, :, 1] * R[..., 0]).sum(axis=2)


@dataclass
class TorsionAngles:
    """Result of :meth:`ReducerStiffness.evaluate` (angles in rad, torque in N·mm)."""

    torque: np.ndarray            # (n,)
    theta: np.ndarray             # (n, 5) per component, signed like the torque
    extra: dict                   # max_pin_force, contact_pairs, K_B, beta, F_ref, interference (n,)
    pin_backlash: np.ndarray      # (n,) output angle from flank to flank of the pin stage, rad (< 0: preload)
    contacts: list                # [(rows, ContactSolution)]
    components: tuple = COMPONENTS   # names of the columns of theta

    @property
    def total(self) -> np.ndarray:
        return self.theta.sum(axis=1)

    @property
    def rigidity(self) -> np.ndarray:
        """Secant torsional rigidity ``T / θ_Σ`` (N·mm/rad)."""
        tot = self.total
        return np.where(tot != 0, self.torque / np.where(tot != 0, tot, 1.0), np.nan)

    def component(self, name: str) -> np.ndarray:
        return self.theta[:, self.components.index(name)]

    def families(self) -> dict[str, np.ndarray]:
        """Angles (rad) by compliance family (:data:`rvtol.elements.reducer_chain.FAMILIES`): the components,
        θ4 split into crankshaft bending and torsion."""
        out = {}
        for c in self.components:
            if c == "crankshafts":
                out["crank_bending"] = self.extra["crank_bending"]
                out["crank_torsion"] = self.extra["crank_torsion"]
            else:
                out[FAMILY_OF[c]] = self.component(c)
        return out

    def to_frame(self, row: int = 0) -> pd.DataFrame:
        arcsec = units.from_base(self.theta[row], "arcsec")
        total = float(arcsec.sum())
        df = pd.DataFrame({"component": [LABELS[c] for c in self.components], "θ (arcsec)": arcsec,
                           "share (%)": 100.0 * arcsec / total if total else np.nan})
        return pd.concat([df, pd.DataFrame({"component": ["Total θ_Σ"], "θ (arcsec)": [total],
                                            "share (%)": [100.0]})], ignore_index=True)

    def plot(self, row: int = 0, ax=None):
        from ...plotting.stiffness import plot_breakdown

        return plot_breakdown(self.to_frame(row), ax=ax)
