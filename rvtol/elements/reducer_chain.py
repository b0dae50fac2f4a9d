"""The RV reducer's compliance chain from a design: element families, their design keys, each element built
from the closed-form elements of this package.  Both reducer models read it (the 20-DOF model of
:mod:`rvtol.models.reducer_20dof` reduces the elements to its contacts, the torsion-angle model of
:mod:`rvtol.models.stiffness` adds them as components), so the two see the same elements.

**Families.**  Every compliance of the torque path belongs to one family with a stable name
(:data:`FAMILIES`); a calibration scales a family's compliance through one optional design key,
``compliance_scale.<family>`` (dimensionless, default 1: as derived).  The first six are the contact
laws doc 000's 20-DOF model always has; the others are present only when the design gives their data:

* ``sun_support``, ``sun_planet_mesh``, ``cycloid_pin``, ``turning_arm_bearings``,
  ``carrier_housing_bearing``: doc 000's contact laws (Table 2, ``stiffness.*``); in doc 004's model the
  involute mesh (ISO 6336-1), the disc–pin Hertz contact and the needle bearings (Palmgren).  Where the
  design gives the needle row (``crank_bearing.rollers``, ``crank_bearing.roller_length``) the 20-DOF
  model's ``turning_arm_bearings`` is the needle row by Palmgren's line contact with its roller load
  distribution (:class:`.rolling_bearings.NeedleRollerBearing`) instead of doc 000's ``k0·P^0.1``;
* ``crank_support_bearings``: doc 000's one planar k0·P^0.1 law per crank, or the preloaded tapered
  roller pair (:mod:`.rolling_bearings`; ``crank_support_bearing.{rollers, roller_length,
  pitch_diameter, cup_angle, cone_angle, preload, arrangement}``);
* ``crank_bending``: bending + shear of the crank between its supports, Timoshenko beam of ⌀ journals
  and eccentrics (:class:`.shafts.SteppedShaft`; ``crank.*``);
* ``crank_torsion``: twist of the crank between the planet gear and an eccentric (:mod:`.shafts`);
* ``carrier``: pillars with flexible end plates (:mod:`.carrier_structure`; ``carrier.*`` with
  ``flange_thickness``, ``end_plate_thickness``, ``plate_clamp_radius``);
* ``pin_groove``: pin in its housing groove, in series with the disc–pin contact, a **conforming** contact
  (:func:`.pin_groove.conforming_groove_approach`: doc 004's Hertz approach corrected by the exact
  pin-in-hole solution; ``pin.groove_radius``, ``pin.groove_contact_length``);
* ``housing_ring``: the housing ring between the groove contacts' reference depth and its bolt circle,
  plane-stress finite elements (:func:`.fe_seats.housing_ring_work`; ``housing.clamp_radius``, ``pin.length``);
* ``disc_web``: in-plane torsion of the disc web (:mod:`.disc_web`; ``cycloid.crank_hole_diameter``);
* ``disc_seats``: the disc round its crank holes beyond the axisymmetric web — the 4.9-mm ligament to the
  centre bore, the ovalising hole — plane-stress finite elements (:func:`.fe_seats.disc_work`;
  ``cycloid.centre_bore_diameter``, ``cycloid.pillar_hole_diameter``);
* ``carrier_seats``: the end plate and the flange round their bearing cups, clamped at the pillar roots,
  plane-stress finite elements (:func:`.fe_seats.carrier_plate_work`; ``carrier.outer_radius``,
  ``carrier.bore_diameter``, ``crank_support_bearing.outside_diameter``);
* ``carrier_joints``: the bolted joints of the end plate on the pillars, VDI 2230 preload and
  Greenwood–Williamson interface (:mod:`.bolted_joint`; ``carrier.joint_bolts``,
  ``carrier.joint_bolt_diameter``, ``carrier.joint_roughness_ra``, ``roughness.summit_radius``): the
  interface's tilt compliance in series with the end plate's rotational spring, its shear compliance with
  each pillar — the carrier's compliance with the joints less without;
* ``edge_loading``: the needle rows bear on one end where the crank tilts under its loads (beam slope and
  the support pair's tilt at the eccentrics), slice model (:func:`.rolling_bearings.edge_loaded_approach`),
  the extra approach at rated as a linear term per cam;
* ``contact_roughness``: the rough layer of the pin–groove contact (:mod:`.roughness`;
  ``pin.roughness_ra``, ``pin.groove_roughness_ra``, ``roughness.summit_radius``), linear at the rated
  pin loads;
* ``input_shaft``: twist of the input shaft between the locked end and the sun (:mod:`.shafts`;
  ``input_shaft.diameter``, ``input_shaft.length``).

**Crank frame.**  ``z`` along the crank, positive towards the output flange, ``z = 0`` midway between
the two eccentrics (= midway between the support bearings: the discs sit symmetrically in the span):
support bearings at ``z = ∓L/2`` (A input side, B output side; ``L = crank.support_span``), eccentric of
disc 1 at ``+p/2`` and of disc 2 at ``−p/2`` (``p = crank.disc_pitch``), planet gear at ``−L/2 − c``
(``c = crank.gear_overhang``).  The shaft is ⌀``crank.journal_diameter`` from the gear to the
eccentrics and from the eccentrics to bearing B, ⌀``crank.eccentric_diameter`` over the two eccentrics
(each as long as the disc, ``cycloid.face_width``); the eccentrics are taken as coaxial cylinders
(:mod:`.shafts`).

All numbers in base units (mm, N, N·mm, MPa, rad).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import SpecError
from . import _checks, carrier_structure, disc_web, fe_seats, pin_groove, shafts
from .bolted_joint import BoltedJoint
from .roughness import GreenwoodWilliamson
from .rolling_bearings import BearingPair, NeedleRollerBearing, TaperedRollerBearing
from . import sources as S

#: stable family names of the torque path's compliances and their labels (module doc)
FAMILIES: dict[str, str] = {
    "sun_support": "sun support",
    "sun_planet_mesh": "sun–planet meshes",
    "input_shaft": "input-shaft twist",
    "crank_torsion": "crankshaft torsion",
    "cycloid_pin": "cycloid–pin contacts",
    "pin_groove": "pins in housing grooves",
    "contact_roughness": "roughness of the pin–groove contacts",
    "housing_ring": "housing ring behind the pin grooves",
    "disc_web": "cycloid disc webs",
    "disc_seats": "disc round its crank holes (beyond the web)",
    "turning_arm_bearings": "turning-arm (needle) bearings",
    "edge_loading": "needle edge loading from crank tilt",
    "crank_bending": "crankshaft bending + shear",
    "crank_support_bearings": "crank support bearings",
    "carrier": "carrier pillars and end plates",
    "carrier_seats": "carrier plates round the bearing cups",
    "carrier_joints": "end plate–pillar bolted joints",
    "carrier_housing_bearing": "carrier–housing (main) bearing",
}
#: the families doc 000's 20-DOF model always has (its contact laws)
BASE_FAMILIES = ("sun_support", "sun_planet_mesh", "cycloid_pin", "turning_arm_bearings", "crank_support_bearings",
                 "carrier_housing_bearing")
SCALE_PREFIX = "compliance_scale."


def scale_key(family: str) -> str:
    """The design key that scales a family's compliance (``compliance_scale.<family>``)."""
    return SCALE_PREFIX + family


def with_compliance_scales(design, scales: dict[str, float], source: str = "", note: str = ""):
    """The design with ``compliance_scale.<family>`` set to each value of ``scales`` (added when absent)."""
    from types import MappingProxyType

    from ..design import DesignParam

    params = dict(design.params)
    for family, v in scales.items():
        key = scale_key(family)
        if family not in FAMILIES:
            raise SpecError(f"unknown compliance family {family!r} (known: {', '.join(FAMILIES)})", key=key)
        old = params.get(key)
        params[key] = DesignParam(key, float(v), "1", source or (old.source if old else "set by the caller"),
                                  note or (old.note if old else ""))
    return replace(design, params=MappingProxyType(params))


def compliance_scale(design, family: str) -> float:
    """The family's compliance scale from the design (default 1), checked > 0."""
    if family not in FAMILIES:
        raise SpecError(f"unknown compliance family {family!r} (known: {', '.join(FAMILIES)})", key=family)
    key = scale_key(family)
    if design is None or key not in design:
        return 1.0
    v = float(design[key])
    if not (math.isfinite(v) and v > 0):
        raise SpecError(f"a compliance scale must be > 0, got {v:g}", file=design.where(key), key=key)
    return v


def _check_scales(design) -> None:
    for name in design.params:
        if name.startswith(SCALE_PREFIX) and name[len(SCALE_PREFIX):] not in FAMILIES:
            raise SpecError(f"unknown compliance family {name[len(SCALE_PREFIX):]!r} "
                            f"(known: {', '.join(FAMILIES)})", file=design.where(name), key=name)


def _num(design, key, *, nonnegative=False):
    v = design[key]
    if isinstance(v, str) or not np.isfinite(v) or not (v >= 0 if nonnegative else v > 0):
        raise SpecError(f"must be {'>= 0' if nonnegative else '> 0'}, got {design.param(key).value!r}",
                        file=design.where(key), key=key)
    return float(v)


def _located(design, key):
    """Context for element errors: a SpecError from an element names the design key it came from."""
    class _Ctx:
        def __enter__(self):
            return self

        def __exit__(self, et, ev, tb):
            if isinstance(ev, SpecError) and ev.file is None:
                ev.file, ev.key = design.where(key), key
            return False
    return _Ctx()


# ------------------------------------------------------------------------------------------------ crank
@dataclass(frozen=True)
class CrankGeometry:
    """Axial layout of one crankshaft in the crank frame (module doc) and its stepped shaft."""

    support: tuple            # (z_A, z_B) support-bearing centres
    eccentrics: tuple         # (z of disc 1's eccentric, z of disc 2's)
    gear: float               # z of the planet gear
    shaft: shafts.SteppedShaft

    @classmethod
    def from_design(cls, design, E: float, nu: float) -> "CrankGeometry":
        L = _num(design, "crank.support_span")
        p = _num(design, "crank.disc_pitch", nonnegative=True)
        c = _num(design, "crank.gear_overhang", nonnegative=True)
        dj = _num(design, "crank.journal_diameter")
        de = _num(design, "crank.eccentric_diameter")
        wkey = "cycloid.face_width" if "cycloid.face_width" in design else "cycloid.width"
        w = _num(design, wkey)
        lo, hi = -0.5 * p - 0.5 * w, 0.5 * p + 0.5 * w
        if not (-0.5 * L < lo and hi < 0.5 * L):
            raise SpecError(f"the eccentrics (z = {lo:g} … {hi:g} mm, disc pitch ± half the disc width) must lie "
                            f"between the support bearings (z = ±{0.5 * L:g} mm)",
                            file=design.where("crank.support_span"),
                            key="crank.support_span")
        with _located(design, "crank.journal_diameter"):
            sh = shafts.SteppedShaft((-0.5 * L - c, lo, hi, 0.5 * L), (dj, de, dj), (0.0, 0.0, 0.0), E, nu)
        return cls((-0.5 * L, 0.5 * L), (0.5 * p, -0.5 * p), -0.5 * L - c, sh)

    @property
    def span(self) -> float:
        return self.support[1] - self.support[0]

    def bending_flexibility(self, points) -> np.ndarray:
        """Flexibility (mm/N) of the beam on rigid supports between ``points`` (bending + shear)."""
        return self.shaft.flexibility(points, supports=self.support)

    def twist(self, z_from: float, z_to: float) -> float:
        """Torsional compliance ``∫ dz / (G J)`` between two stations (rad per N·mm)."""
        return self.shaft.torsional_compliance(z_from, z_to)


# ------------------------------------------------------------------------------------------------ groove
@dataclass(frozen=True)
class GrooveContact:
    """A pin (radius ``r_pin``) in its housing groove (radius ``r_groove``), loaded over ``length`` (mm)."""

    r_pin: float
    r_groove: float
    length: float
    E: float
    nu: float

    def approach(self, F):
        """Pin centre to the housing point one groove radius deep (mm): the conforming pin-in-hole contact
        (:func:`.pin_groove.conforming_groove_approach`)."""
        return pin_groove.conforming_groove_approach(F, self.length, self.r_pin, self.r_groove, self.E, self.nu)

    def hertz_approach(self, F):
        """doc 004's Hertz formula alone (:func:`.pin_groove.groove_approach`), outside its validity here."""
        return pin_groove.groove_approach(F, self.length, self.r_pin, self.r_groove, self.E, self.nu)

    def half_angle(self, F):
        """Half-angle of the contact arc (rad) of the conforming solution."""
        return pin_groove.contact_half_angle(F, self.length, self.r_pin, self.r_groove, self.E, self.nu)


# ------------------------------------------------------------------------------------------------ all
#: ChainElements.from_design's results by (id of the design, crank circle), the last few
_MADE: dict = {}


@dataclass(frozen=True)
class ChainElements:
    """The design's compliance elements (None where the design does not give an element's data).

    ``crank_radius`` is the crank circle (mm) of the model that asks (the 20-DOF operating centre
    distance a', doc 004's a0 or the design's ``crank_bearing.centre_radius``).
    """

    E: float | None
    nu: float | None
    crank_radius: float
    crank: CrankGeometry | None = None
    pair: BearingPair | None = None
    pair_preload: float = 0.0
    groove: GrooveContact | None = None
    input_shaft_stiffness: float | None = None      # K_in, N·mm/rad
    carrier_stiffness: float | None = None          # K_carrier between end plate and flange, N·mm/rad
    web_stiffness: float | None = None              # K_web of one disc, N·mm/rad
    web_radii: tuple | None = None                  # (r_i, r_o)
    needle: NeedleRollerBearing | None = None       # the turning-arm needle row (Palmgren), zero clearance
    disc_seat_compliance: float | None = None       # per crank hole, beyond the web (mm/N), FE
    carrier_seat_compliance: tuple | None = None    # per cup (end plate A, flange B) (mm/N), FE
    housing_ring_compliance: float | None = None    # per pin (mm/N), FE
    carrier_joint_compliance: float | None = None   # 1/K_carrier with the joints less without (rad/(N·mm))
    roughness_compliance: float | None = None       # per pin (mm/N), the groove contact's rough layer
    scales: dict = field(default_factory=dict)
    sources: dict = field(default_factory=dict)     # family -> how it was built (for reports)

    @property
    def present(self) -> tuple[str, ...]:
        """Families beyond doc 000's contact laws that this design provides."""
        out = []
        if self.crank is not None:
            out += ["crank_bending", "crank_torsion"]
        if self.pair is not None:
            out.append("crank_support_bearings")
        for name, v in (("carrier", self.carrier_stiffness), ("carrier_seats", self.carrier_seat_compliance),
                        ("carrier_joints", self.carrier_joint_compliance),
                        ("contact_roughness", self.roughness_compliance),
                        ("pin_groove", self.groove), ("housing_ring", self.housing_ring_compliance),
                        ("disc_web", self.web_stiffness), ("disc_seats", self.disc_seat_compliance),
                        ("input_shaft", self.input_shaft_stiffness)):
            if v is not None:
                out.append(name)
        return tuple(out)

    def scale(self, family: str) -> float:
        return float(self.scales.get(family, 1.0))

    def pair_at(self, preload: float) -> BearingPair:
        """The crank support pair set to the axial ``preload`` (N; 0: mounted line-to-line) instead of the
        design's (a unit's own, as its shims and run-in set it)."""
        if self.pair is None:
            raise SpecError("the design has no crank support pair", key="crank_support_bearing.preload")
        free = BearingPair(self.pair.bearing_a, self.pair.bearing_b, self.pair.positions, self.pair.arrangement)
        return free.with_preload_force(preload) if preload > 0 else free

    @classmethod
    def from_design(cls, design, crank_radius: float) -> "ChainElements":
        """Every element whose data the design gives (module doc); bad numbers name their key.

        Made once per design (an immutable :class:`rvtol.design.Design`) and crank circle: a study's models —
        the 20-DOF geometry, the torsion angle, the torsion curve — share one set of elements."""
        key = (id(design), float(crank_radius))
        kept = _MADE.get(key)
        if kept is not None and kept[0] is design:
            return kept[1]
        made = cls._from_design(design, crank_radius)
        _MADE[key] = (design, made)            # the design is kept with it, so its id is not reused meanwhile
        while len(_MADE) > 8:
            _MADE.pop(next(iter(_MADE)))
        return made

    @classmethod
    def _from_design(cls, design, crank_radius: float) -> "ChainElements":
        _check_scales(design)
        scales = {f: compliance_scale(design, f) for f in FAMILIES}
        if not _has(design, "material.youngs_modulus", "material.poisson_ratio"):
            return cls(None, None, float(crank_radius), scales=scales)
        E = _num(design, "material.youngs_modulus")
        nu = float(design["material.poisson_ratio"])
        if not 0.0 < nu < 0.5:
            raise SpecError(f"must be > 0 and < 0.5, got {nu:g}",
                            file=design.where("material.poisson_ratio"), key="material.poisson_ratio")
        G = E / (2.0 * (1.0 + nu))
        kw: dict = {}
        src: dict = {}
        crank = None
        if _has(design, "crank.support_span", "crank.disc_pitch", "crank.gear_overhang", "crank.journal_diameter",
               "crank.eccentric_diameter"):
            crank = CrankGeometry.from_design(design, E, nu)
            kw["crank"] = crank
            src["crank_bending"] = src["crank_torsion"] = S.CRANK.format(
                journal=design.value("crank.journal_diameter", "mm"),
                eccentric=design.value("crank.eccentric_diameter", "mm"), span=crank.span)
        _crank_support(design, crank, kw, src)
        _pin_groove(design, E, nu, kw, src)
        if _has(design, "input_shaft.diameter", "input_shaft.length"):
            d, Ls = _num(design, "input_shaft.diameter"), _num(design, "input_shaft.length")
            kw["input_shaft_stiffness"] = float(G * shafts.circle_section(d)[2] / Ls)
            src["input_shaft"] = S.INPUT_SHAFT.format(d=d, length=Ls)
        _carrier(design, E, nu, G, crank, kw, src)
        _disc_web(design, float(crank_radius), G, kw, src)
        _needles(design, kw, src)
        _fe_elements(design, float(crank_radius), E, nu, G, kw, src)
        return cls(E, nu, float(crank_radius), scales=scales, sources=src, **kw)


def _crank_support(design, crank, kw: dict, src: dict) -> None:
    """The crank support pair of tapered roller bearings and its preload, given the crank layout."""
    keys = [f"crank_support_bearing.{k}" for k in ("rollers", "roller_length", "pitch_diameter", "cup_angle",
                                                    "cone_angle", "preload")]
    if _has(design, *keys):
        if crank is None:
            raise SpecError("the crank support pair needs the crank layout (crank.support_span, disc_pitch, "
                            "gear_overhang, journal_diameter, eccentric_diameter)",
                            file=design.where("crank_support_bearing.preload"),
                            key="crank_support_bearing.preload")
        arrangement = design.get("crank_support_bearing.arrangement", "X")
        if arrangement not in ("X", "O"):
            raise SpecError(f"must be 'X' (face-to-face) or 'O' (back-to-back), got {arrangement!r}",

                            file=design.where("crank_support_bearing.arrangement"),
                            key="crank_support_bearing.arrangement")
        with _located(design, "crank_support_bearing.cup_angle"):
            brg = TaperedRollerBearing(
                rollers=_num(design, keys[0]), alpha=_num(design, keys[3]),
                length=_num(design, keys[1]), pitch_diameter=_num(design, keys[2]),
                alpha_inner=_num(design, keys[4]))
        pre = _num(design, keys[5], nonnegative=True)
        pair = BearingPair(brg, brg, crank.support, arrangement)
        with _located(design, keys[5]):
            pair = pair.with_preload_force(pre) if pre > 0 else pair
        kw.update(pair=pair, pair_preload=pre)
        src["crank_support_bearings"] = S.CRANK_SUPPORT.format(
            arrangement=arrangement, rollers=brg.rollers, length=brg.length, alpha_deg=math.degrees(brg.alpha),
            preload=pre, interference_um=pair.interference * 1e3)


def _pin_groove(design, E: float, nu: float, kw: dict, src: dict) -> None:
    """The pins in their housing grooves: a conforming line contact."""
    if _has(design, "pin.groove_radius", "pin.groove_contact_length", "pin.radius"):
        rp, rg = _num(design, "pin.radius"), _num(design, "pin.groove_radius")
        if not rg > rp:
            raise SpecError(f"must exceed the pin radius {rp:g} mm (zero clearance is a conforming contact "
                            "outside Hertz theory)",
                            file=design.where("pin.groove_radius"), key="pin.groove_radius")
        kw["groove"] = GrooveContact(rp, rg, _num(design, "pin.groove_contact_length"), E, nu)
        src["pin_groove"] = S.PIN_GROOVE.format(rp=rp, rg=rg, clearance_um=(rg - rp) * 1e3)


def _carrier(design, E: float, nu: float, G: float, crank, kw: dict, src: dict) -> None:
    """The carrier's pillars and plates, and its bolted end-plate joint."""
    ckeys = [f"carrier.{k}" for k in ("pillars", "pillar_radius", "pillar_width", "pillar_thickness",
                                      "pillar_length", "flange_thickness", "end_plate_thickness",
                                      "plate_clamp_radius")]
    if _has(design, *ckeys):
        n, R, w, t, h, tf, te, a = (_num(design, k) for k in ckeys)
        with _located(design, "carrier.pillar_width"):
            sec = carrier_structure.rectangle(w, t, nu)
            b0 = carrier_structure.equivalent_boss_radius(sec)
        with _located(design, "carrier.plate_clamp_radius"):
            kphi = (carrier_structure.boss_rotational_stiffness(b0, a, te, E, nu),
                    carrier_structure.boss_rotational_stiffness(b0, a, tf, E, nu))
        k = carrier_structure.pillar_stiffness(sec, h, E, nu, kphi)
        kw["carrier_stiffness"] = float(carrier_structure.carrier_torsional_stiffness(
            n, R, k, section=sec, length=h, G=G))
        jkeys = ("carrier.joint_bolts", "carrier.joint_bolt_diameter", "carrier.joint_roughness_ra",
                 "roughness.summit_radius", "reducer.rated_torque", "crank.support_span")
        if _has(design, *jkeys) and crank is not None:
            nb, db, ra, beta, T, _ = (_num(design, k) for k in jkeys)
            with _located(design, "carrier.joint_bolt_diameter"):
                joint = BoltedJoint(db, te, w, t, E, bolts=int(round(nb)))
            with _located(design, "carrier.joint_roughness_ra"):
                gw = GreenwoodWilliamson.from_ra(ra, ra, beta, E / (2.0 * (1.0 - nu * nu)))
                c_tilt, c_shear = joint.tilt_compliance(gw), joint.shear_compliance(gw, nu)
            zA, zB = crank.support
            FQ = zB / (zB - zA) * T / (n * R)                    # pillar shear at rated (end-plate share)
            chk = joint.opening_and_slip(0.5 * FQ * h, FQ)
            if chk["opens"] or chk["slips"]:
                raise SpecError(f"the end plate's bolted joint {'opens' if chk['opens'] else 'slips'} at rated "
                                f"torque (VDI 2230: preload {joint.preload():.4g} N, pillar shear {FQ:.4g} N)",
                                file=design.where("carrier.joint_bolts"), key="carrier.joint_bolts")
            k_j = 1.0 / (1.0 / carrier_structure.pillar_stiffness(
                sec, h, E, nu, (1.0 / (1.0 / kphi[0] + c_tilt), kphi[1])) + c_shear)
            K_j = float(carrier_structure.carrier_torsional_stiffness(n, R, k_j, section=sec, length=h, G=G))
            kw["carrier_joint_compliance"] = 1.0 / K_j - 1.0 / kw["carrier_stiffness"]
            src["carrier_joints"] = S.CARRIER_JOINTS.format(
                bolts=int(round(nb)), d=db, preload=joint.preload(), open=chk["margin_open"],
                slip=chk["margin_slip"], ra_um=ra * 1e3, tilt=c_tilt, shear=c_shear * 1e6)
        src["carrier"] = S.CARRIER.format(pillars=int(round(n)), w=w, t=t, h=h, R=R, te=te, tf=tf, a=a)


def _disc_web(design, crank_radius: float, G: float, kw: dict, src: dict) -> None:
    """The disc's annular web between its crank holes and its lobes."""
    if _has(design, "cycloid.crank_hole_diameter", "pin.circle_radius", "pin.radius", "cycloid.eccentricity") and (
            "cycloid.face_width" in design or "cycloid.width" in design):
        wkey = "cycloid.face_width" if "cycloid.face_width" in design else "cycloid.width"
        ri = float(crank_radius) + 0.5 * _num(design, "cycloid.crank_hole_diameter")
        ro = _num(design, "pin.circle_radius") - _num(design, "pin.radius") - _num(design, "cycloid.eccentricity")
        with _located(design, "cycloid.crank_hole_diameter"):
            kw["web_stiffness"] = float(disc_web.annular_web_stiffness(ri, ro, _num(design, wkey), G))
        kw["web_radii"] = (ri, ro)
        src["disc_web"] = S.DISC_WEB.format(ri=ri, ro=ro)


def _needles(design, kw: dict, src: dict) -> None:
    """The needle rollers of the crank's eccentric (turning-arm) bearings."""
    if _has(design, "crank_bearing.rollers", "crank_bearing.roller_length"):
        with _located(design, "crank_bearing.rollers"):
            rollers = _checks.whole("rollers", design["crank_bearing.rollers"])
        kw["needle"] = NeedleRollerBearing(rollers, _num(design, "crank_bearing.roller_length"))
        src["turning_arm_bearings"] = S.NEEDLE.format(rollers=kw["needle"].rollers, length=kw["needle"].length)


def _has(design, *keys: str) -> bool:
    """Whether the design gives every one of ``keys`` (an element is built only from all its numbers)."""
    return all(k in design for k in keys)


def _statics(design):
    """``(T, i, z_c, z_p, R_p, r_p, e, w)``: rated torque (N·mm), ratio and the pin-gear data the finite-element
    seats are loaded with, or None when the design lacks one."""
    keys = ("reducer.rated_torque", "reducer.ratio", "cycloid.teeth", "pin.count", "pin.circle_radius", "pin.radius",
            "cycloid.eccentricity")
    wkey = "cycloid.face_width" if "cycloid.face_width" in design else "cycloid.width"
    if not all(k in design for k in keys) or wkey not in design:
        return None
    T, i, zc, zp, Rp, rp, e = (_num(design, k) for k in keys)
    return T, i, int(round(zc)), int(round(zp)), Rp, rp, e, _num(design, wkey)


def _fe_elements(design, a: float, E: float, nu: float, G: float, kw: dict, src: dict) -> None:
    """The finite-element seats and ring (:mod:`.fe_seats`) where the design gives their dimensions."""
    st = _statics(design)
    if st is None:
        return
    T, i, zc, zp, Rp, rp, e, w = st
    Tc = T * (1.0 - 1.0 / i) * zc / zp / 2.0               # one disc's torque, T i_b / 2
    if kw.get("web_stiffness") is not None and _has(design, "cycloid.centre_bore_diameter",
                                                    "cycloid.pillar_hole_diameter", "carrier.pillar_radius"):
        with _located(design, "cycloid.crank_hole_diameter"):
            res = fe_seats.disc_work(Tc, r_root=Rp - rp - e, bore=_num(design, "cycloid.centre_bore_diameter"),
                                     crank_radius=a, crank_hole=_num(design, "cycloid.crank_hole_diameter"),
                                     pillar_radius=_num(design, "carrier.pillar_radius"),
                                     pillar_hole=_num(design, "cycloid.pillar_hole_diameter"), thickness=w, z_p=zp,
                                     z_c=zc, R_p=Rp, ecc=e, E=E, nu=nu)
            kw["disc_seat_compliance"] = fe_seats.disc_seat_compliance(res, Tc, kw["web_stiffness"])
        src["disc_seats"] = S.DISC_SEATS.format(work=np.mean(res.work), web=Tc ** 2 / kw["web_stiffness"],
                                                compliance=kw["disc_seat_compliance"] * 1e6)
    ckeys = ("carrier.outer_radius", "carrier.bore_diameter", "crank_support_bearing.outside_diameter",
             "carrier.pillar_radius", "carrier.pillar_width", "carrier.pillar_thickness", "carrier.end_plate_thickness",
             "carrier.flange_thickness", "crank.support_span")
    if kw.get("crank") is not None and _has(design, *ckeys):
        ro, bore, D, Rpil, pw, pt, te, tf, _ = (_num(design, k) for k in ckeys)
        zA, zB = kw["crank"].support
        rhoA = zB / (zB - zA)
        b0 = carrier_structure.equivalent_boss_radius(carrier_structure.rectangle(pw, pt, nu))
        cups = []
        with _located(design, "carrier.outer_radius"):
            for t, share in ((te, rhoA), (tf, 1.0 - rhoA)):
                r = fe_seats.carrier_plate_work(T, r_outer=ro, bore=bore, crank_radius=a, cup_diameter=D,
                                                pillar_radius=Rpil, pillar_root_radius=b0, thickness=t, share=share,
                                                E=E, nu=nu)
                cups.append(r.compliance)
        kw["carrier_seat_compliance"] = tuple(cups)
        src["carrier_seats"] = S.CARRIER_SEATS.format(te=te, tf=tf, D=D, a=a, end_plate=cups[0] * 1e6,
                                                      flange=cups[1] * 1e6)
    if kw.get("groove") is not None and _has(design, "housing.clamp_radius", "pin.length"):
        gr = kw["groove"]
        with _located(design, "housing.clamp_radius"):
            r = fe_seats.housing_ring_work(Tc, r_inner=Rp + gr.r_pin + gr.r_groove,
                                           r_outer=_num(design, "housing.clamp_radius"),
                                           thickness=_num(design, "pin.length"), z_p=zp, z_c=zc, R_p=Rp, ecc=e, E=E,
                                           nu=nu)
        kw["housing_ring_compliance"] = r.compliance
    if kw.get("groove") is not None and _has(design, "pin.roughness_ra", "pin.groove_roughness_ra",
                                             "roughness.summit_radius"):
        gr = kw["groove"]
        with _located(design, "pin.roughness_ra"):
            gw = GreenwoodWilliamson.from_ra(_num(design, "pin.roughness_ra"), _num(design, "pin.groove_roughness_ra"),
                                             _num(design, "roughness.summit_radius"), E / (2.0 * (1.0 - nu * nu)))
        _, F = fe_seats.pin_forces(Tc, zp, zc, Rp, e)
        F = np.hypot(*F.T)
        F = F[F > 0]
        ang = pin_groove.contact_half_angle(F, gr.length, gr.r_pin, gr.r_groove, E, nu)
        area = 2.0 * ang * gr.r_pin * gr.length
        c = np.array([gw.layer_compliance(f / a, a) for f, a in zip(F, area)])
        kw["roughness_compliance"] = float(np.sum(F ** 2 * c) / np.sum(F ** 2))
        src["contact_roughness"] = S.CONTACT_ROUGHNESS.format(sigma_um=gw.sigma * 1e3, beta_um=gw.beta * 1e3,
                                                              compliance=kw["roughness_compliance"] * 1e6)
        src["housing_ring"] = S.HOUSING_RING.format(ri=Rp + gr.r_pin + gr.r_groove,
                                                    ro=_num(design, "housing.clamp_radius"),
                                                    compliance=r.compliance * 1e6)
