"""The RV reducer's compliance chain from a design: element families, their design keys, each element built
from the closed-form elements of this package.  Both reducer models read it (the 20-DOF model of
:mod:`rvtol.models.transmission` reduces the elements to its contacts, the torsion-angle model of
:mod:`rvtol.models.stiffness` adds them as components), so the two see the same elements.

**Families.**  Every compliance of the torque path belongs to one family with a stable name
(:data:`FAMILIES`); a calibration scales a family's compliance through one optional design key,
``compliance_scale.<family>`` (dimensionless, default 1: as derived).  The first six are the contact
laws doc 000's 20-DOF model always has; the others are present only when the design gives their data:

* ``sun_support``, ``sun_planet_mesh``, ``cycloid_pin``, ``turning_arm_bearings``,
  ``carrier_housing_bearing``: doc 000's contact laws (Table 2, ``stiffness.*``); in doc 004's model the
  involute mesh (ISO 6336-1), the disc–pin Hertz contact and the needle bearings (Palmgren);
* ``crank_support_bearings``: doc 000's one planar k0·P^0.1 law per crank, or the preloaded tapered
  roller pair (:mod:`.rolling_bearings`; ``crank_support_bearing.{rollers, roller_length,
  pitch_diameter, cup_angle, cone_angle, preload, arrangement}``);
* ``crank_bending``: bending + shear of the crank between its supports, Timoshenko beam of ⌀ journals
  and eccentrics (:class:`.shafts.SteppedShaft`; ``crank.*``);
* ``crank_torsion``: twist of the crank between the planet gear and an eccentric (:mod:`.shafts`);
* ``carrier``: pillars with flexible end plates (:mod:`.carrier_structure`; ``carrier.*`` with
  ``flange_thickness``, ``end_plate_thickness``, ``plate_clamp_radius``);
* ``pin_groove``: pin in its housing groove, in series with the disc–pin contact
  (:func:`.contacts.groove_approach`; ``pin.groove_radius``, ``pin.groove_contact_length``);
* ``disc_web``: in-plane torsion of the disc web (:mod:`.disc_web`; ``cycloid.crank_hole_diameter``);
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
from . import carrier_structure, contacts, disc_web, shafts
from .rolling_bearings import BearingPair, TaperedRollerBearing

#: stable family names of the torque path's compliances and their labels (module doc)
FAMILIES: dict[str, str] = {
    "sun_support": "sun support",
    "sun_planet_mesh": "sun–planet meshes",
    "input_shaft": "input-shaft twist",
    "crank_torsion": "crankshaft torsion",
    "cycloid_pin": "cycloid–pin contacts",
    "pin_groove": "pins in housing grooves",
    "disc_web": "cycloid disc webs",
    "turning_arm_bearings": "turning-arm (needle) bearings",
    "crank_bending": "crankshaft bending + shear",
    "crank_support_bearings": "crank support bearings",
    "carrier": "carrier pillars and end plates",
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
        raise SpecError(f"a compliance scale must be > 0, got {v:g}", file=design.file, key=key)
    return v


def _check_scales(design) -> None:
    for name in design.params:
        if name.startswith(SCALE_PREFIX) and name[len(SCALE_PREFIX):] not in FAMILIES:
            raise SpecError(f"unknown compliance family {name[len(SCALE_PREFIX):]!r} "
                            f"(known: {', '.join(FAMILIES)})", file=design.file, key=name)


def _num(design, key, *, nonnegative=False):
    v = design[key]
    if isinstance(v, str) or not np.isfinite(v) or not (v >= 0 if nonnegative else v > 0):
        raise SpecError(f"must be {'>= 0' if nonnegative else '> 0'}, got {design.param(key).value!r}",
                        file=design.file, key=key)
    return float(v)


def _located(design, key):
    """Context for element errors: a SpecError from an element names the design key it came from."""
    class _Ctx:
        def __enter__(self):
            return self

        def __exit__(self, et, ev, tb):
            if isinstance(ev, SpecError) and ev.file is None:
                ev.file, ev.key = design.file, key
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
                            f"between the support bearings (z = ±{0.5 * L:g} mm)", file=design.file,
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
        """Pin centre to the housing point one groove radius deep (mm): :func:`.contacts.groove_approach`."""
        return contacts.groove_approach(F, self.length, self.r_pin, self.r_groove, self.E, self.nu)

    def half_angle(self, F):
        """Half-angle of the contact arc (rad); Hertz needs it well below ~0.3 (see :mod:`.contacts`)."""
        return contacts.groove_half_angle(F, self.length, self.r_pin, self.r_groove, self.E, self.nu)

    def log_law(self, forces=(10.0, 1000.0)) -> tuple[float, float]:
        """``(a, b)`` with ``approach(F) = F (a − b ln F)`` exactly: the formula's own form, since the
        contact half-width is ``√(κF)`` (``ln(4d/L) = ln 4d − ½ ln κ − ½ ln F``).  Fitted through two
        forces; the caller checks a third."""
        F1, F2 = (float(v) for v in forces)
        y1, y2 = float(self.approach(F1)) / F1, float(self.approach(F2)) / F2
        b = (y1 - y2) / (math.log(F2) - math.log(F1))
        return y1 + b * math.log(F1), b


# ------------------------------------------------------------------------------------------------ all
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
        for name, v in (("carrier", self.carrier_stiffness), ("pin_groove", self.groove),
                        ("disc_web", self.web_stiffness), ("input_shaft", self.input_shaft_stiffness)):
            if v is not None:
                out.append(name)
        return tuple(out)

    def scale(self, family: str) -> float:
        return float(self.scales.get(family, 1.0))

    @classmethod
    def from_design(cls, design, crank_radius: float) -> "ChainElements":
        """Every element whose data the design gives (module doc); bad numbers name their key."""
        _check_scales(design)
        scales = {f: compliance_scale(design, f) for f in FAMILIES}
        has = lambda *keys: all(k in design for k in keys)   # noqa: E731
        if not has("material.youngs_modulus", "material.poisson_ratio"):
            return cls(None, None, float(crank_radius), scales=scales)
        E = _num(design, "material.youngs_modulus")
        nu = float(design["material.poisson_ratio"])
        if not 0.0 < nu < 0.5:
            raise SpecError(f"must be > 0 and < 0.5, got {nu:g}", file=design.file, key="material.poisson_ratio")
        G = E / (2.0 * (1.0 + nu))
        kw: dict = {}
        src: dict = {}
        crank = None
        if has("crank.support_span", "crank.disc_pitch", "crank.gear_overhang", "crank.journal_diameter",
               "crank.eccentric_diameter"):
            crank = CrankGeometry.from_design(design, E, nu)
            kw["crank"] = crank
            src["crank_bending"] = src["crank_torsion"] = (
                f"stepped Timoshenko shaft ⌀{design.value('crank.journal_diameter', 'mm'):g}/"
                f"⌀{design.value('crank.eccentric_diameter', 'mm'):g} mm, supports {crank.span:g} mm apart")
        keys = [f"crank_support_bearing.{k}" for k in ("rollers", "roller_length", "pitch_diameter", "cup_angle",
                                                        "cone_angle", "preload")]
        if has(*keys):
            if crank is None:
                raise SpecError("the crank support pair needs the crank layout (crank.support_span, disc_pitch, "
                                "gear_overhang, journal_diameter, eccentric_diameter)", file=design.file,
                                key="crank_support_bearing.preload")
            arrangement = design.get("crank_support_bearing.arrangement", "X")
            if arrangement not in ("X", "O"):
                raise SpecError(f"must be 'X' (face-to-face) or 'O' (back-to-back), got {arrangement!r}",
                                file=design.file, key="crank_support_bearing.arrangement")
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
            src["crank_support_bearings"] = (f"tapered roller pair ({arrangement}), {brg.rollers} rollers × "
                                             f"{brg.length:g} mm, α = {math.degrees(brg.alpha):.2f}°, "
                                             f"preload {pre:g} N (Δ = {pair.interference * 1e3:.2f} µm)")
        if has("pin.groove_radius", "pin.groove_contact_length", "pin.radius"):
            rp, rg = _num(design, "pin.radius"), _num(design, "pin.groove_radius")
            if not rg > rp:
                raise SpecError(f"must exceed the pin radius {rp:g} mm (zero clearance is a conforming contact "
                                "outside Hertz theory)", file=design.file, key="pin.groove_radius")
            kw["groove"] = GrooveContact(rp, rg, _num(design, "pin.groove_contact_length"), E, nu)
            src["pin_groove"] = (f"Hertz line contact pin r {rp:g} in groove r {rg:g} mm "
                                 f"(radial clearance {(rg - rp) * 1e3:.3g} µm)")
        if has("input_shaft.diameter", "input_shaft.length"):
            d, Ls = _num(design, "input_shaft.diameter"), _num(design, "input_shaft.length")
            kw["input_shaft_stiffness"] = float(G * shafts.circle_section(d)[2] / Ls)
            src["input_shaft"] = f"⌀{d:g} × {Ls:g} mm solid shaft, K = G J / L"
        ckeys = [f"carrier.{k}" for k in ("pillars", "pillar_radius", "pillar_width", "pillar_thickness",
                                          "pillar_length", "flange_thickness", "end_plate_thickness",
                                          "plate_clamp_radius")]
        if has(*ckeys):
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
            src["carrier"] = (f"{int(round(n))} pillars {w:g} × {t:g} × {h:g} mm at R {R:g} (fixed–guided, "
                              f"Cowper κ, twist), end plate {te:g} / flange {tf:g} mm as Kirchhoff plates clamped at "
                              f"{a:g} mm around a pillar root")
        if has("cycloid.crank_hole_diameter", "pin.circle_radius", "pin.radius", "cycloid.eccentricity") and (
                "cycloid.face_width" in design or "cycloid.width" in design):
            wkey = "cycloid.face_width" if "cycloid.face_width" in design else "cycloid.width"
            ri = float(crank_radius) + 0.5 * _num(design, "cycloid.crank_hole_diameter")
            ro = _num(design, "pin.circle_radius") - _num(design, "pin.radius") - _num(design, "cycloid.eccentricity")
            with _located(design, "cycloid.crank_hole_diameter"):
                kw["web_stiffness"] = float(disc_web.annular_web_stiffness(ri, ro, _num(design, wkey), G))
            kw["web_radii"] = (ri, ro)
            src["disc_web"] = f"annulus r {ri:.2f} … {ro:.2f} mm (crank-hole edge to tooth root), t = disc width"
        return cls(E, nu, float(crank_radius), scales=scales, sources=src, **kw)
