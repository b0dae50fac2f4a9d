"""Geometric tolerancing of a spec's factors: circular position zones and their material condition (bonus
from the feature of size), datum features of size at MMB (datum shifts), Rule #1 envelopes, composite frames,
and the checks that the factors of one zone, frame or envelope agree."""
from __future__ import annotations

import re
from dataclasses import dataclass

from .. import units
from ..errors import SpecError, did_you_mean
from ..inputs.notation import NotationError, Tolerance, parse_tolerance
from ..options import Given
from ..patterns import drawn_zone

#: a factor's or a pattern's name: letters, digits, _ [ ] , . - + and spaces, not starting with a digit
NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_\[\],.\-+ ]*$")


def position_zone(p: Given, tol: Tolerance | None) -> str:
    """``zone``: the circular position zone (``tolerance = "⌀t"``) this factor is one coordinate of."""
    zone = p.get("zone", "")
    is_zone = tol is not None and tol.form == "zone"
    if is_zone and not zone:
        raise p.error("tolerance", f"a position zone {tol.text!r} has two coordinates: give zone = NAME on both "
                                   "factors (x and y)")
    if zone and not is_zone:
        raise p.error("zone", "a zone coordinate needs tolerance = \"⌀t\" (the zone's diameter)")
    return zone


FEATURE_TYPES = ("internal", "external")


def material_condition(p: Given, tol: Tolerance | None, zone: str) -> dict:
    """A position zone's material condition (``⌀0.4 (M)``: MMC, ``(L)``: LMC) and the features of size it
    depends on: ``size`` (the toleranced feature's size factor; its departure from MMC/LMC is the bonus) with
    ``feature_type`` (internal: a hole, external: a pin), and ``datum_size``/``datum_type`` (a datum feature of
    size referenced at MMB: its departure from MMB shifts every zone that references it together, one pattern,
    :func:`datum_shifts`)."""
    modifier = tol.modifier if tol is not None and tol.form == "zone" else ""
    size = p.get("size", "")
    ftype = p.get("feature_type", "")
    dsize = p.get("datum_size", "")
    dtype = p.get("datum_type", "")
    separate = p.get("separate", False)
    frame = p.get("frame", "")
    if frame and not zone:
        raise p.error("frame", "a feature control frame's name groups position zones (an nX pattern): give zone = NAME")
    if separate and not dsize:
        raise p.error("separate", "SEP REQT separates a zone's datum-feature shift from its pattern's: it needs "
                                  "datum_size (a datum feature of size referenced at MMB); without one there is no shift")
    if (size or (ftype and "envelope" not in p.data) or dsize) and not zone:
        raise p.error("size" if size else "feature_type" if ftype else "datum_size",
                      "a material condition belongs to a position zone (tolerance = \"⌀t (M)\", zone = NAME)")
    if modifier and not size:
        raise p.error("size", f"a zone at {modifier} gets its bonus from the feature's actual size: give size = "
                              "the size factor's name and feature_type = \"internal\" (a hole) or \"external\" (a pin)")
    if size and not modifier:
        raise p.error("size", "size names the feature whose departure from MMC/LMC is the bonus: the zone needs a "
                              "modifier (\"⌀t (M)\" or \"⌀t (L)\"); at RFS there is no bonus")
    if size and not ftype:
        raise p.error("feature_type", "the bonus needs the feature type: \"internal\" (a hole: MMC = smallest) or "
                                      "\"external\" (a pin: MMC = largest)")
    if bool(dsize) != bool(dtype):
        raise p.error("datum_type" if dsize else "datum_size",
                      "a datum-feature shift needs both datum_size (the datum feature's size factor) and datum_type")
    return {"modifier": modifier, "size": size, "feature_type": ftype, "datum_size": dsize, "datum_type": dtype,
            "separate": separate, "frame": frame}


def envelope_of(p: Given, tol: Tolerance | None) -> str:
    """``envelope``: the size factor whose departure from MMC a form tolerance stays within (Rule #1, the envelope
    requirement: :mod:`rvtol.envelopes`); with ``feature_type`` (internal: a hole, external: a shaft)."""
    size = p.get("envelope", "")
    if not size:
        return ""
    if not getattr(tol, "is_form", False):
        raise p.error("envelope", "the envelope (Rule #1) bounds a form tolerance by its feature's size: give "
                                  "tolerance = \"⏥t\" (flatness), \"⏤t\", \"○t\" or \"⌭t\"")
    if "feature_type" not in p.data:
        raise p.error("feature_type", "the envelope needs the feature type: \"internal\" (a hole: MMC = smallest) or "
                                      "\"external\" (a shaft: MMC = largest)")
    return size


def composite_position(p: Given, drawing: Tolerance | None, zone: str, unit: str | None,
                       measured) -> tuple[dict, Tolerance | None]:
    """A composite frame's keys of a zone coordinate (:func:`composite_frame`; ``basic``, its true position for the
    framework's rotation) as :class:`Factor` fields, and the feature-relating zone its own deviation is read in (None
    for a plain factor)."""
    pattern, relating, datums = composite_frame(p, drawing, zone, unit)
    basic = p.get("basic")
    if basic is not None and not pattern:
        raise p.error("basic", "basic places a composite frame's feature in its pattern (for the framework's rotation): "
                               "give pattern and feature_relating")
    keys = {"pattern": pattern, "basic": basic}
    if relating is not None:
        if measured is not None:
            raise p.error("feature_relating", "a measured position is the feature's location from the datums, not "
                                              "its deviation within the pattern: fit it as a plain zone")
        keys.update(locating=drawing.width, datums=datums)    # the lower line's datums: may the framework rotate
    return keys, relating


def composite_frame(p: Given, tol: Tolerance | None, zone: str,
                    unit: str | None) -> tuple[str, Tolerance | None, tuple[str, ...]]:
    """A composite position frame's second line (:mod:`rvtol.patterns`): ``pattern = NAME`` (the features one
    frame locates) and ``feature_relating = "⌀T₂ A B"`` (the FRTZF, smaller than the zone's ⌀T₁, the PLTZF, and the
    datums it references: orientation only).  Returns the pattern's name, the FRTZF read in the factor's unit (None
    without one) and its datum letters."""
    pattern = p.get("pattern", "")
    text = p.get("feature_relating")
    if not pattern and text is None:
        return "", None, ()
    key = "pattern" if pattern else "feature_relating"
    if not zone:
        raise p.error(key, "a composite frame locates position zones: give tolerance = \"⌀T1\" (the pattern-locating "
                           "zone), zone = NAME, pattern = NAME and feature_relating = \"⌀T2\"")
    if not pattern or text is None:
        raise p.error("feature_relating" if pattern else "pattern",
                      "a composite frame needs both pattern (the pattern's name) and feature_relating (\"⌀T2\", "
                      "the frame's second line)")
    if not NAME.match(pattern):
        raise p.error("pattern", f"invalid pattern name {pattern!r} (letters, digits, _ [ ] , . - + and spaces)")
    zone_text, datums = frame_datums(p, "feature_relating", text)
    try:
        relating = parse_tolerance(zone_text, unit=unit)
    except NotationError as exc:
        raise p.error("feature_relating", exc.reason) from None
    if relating.form != "zone":
        raise p.error("feature_relating", f"{text!r} is not a position zone: write the frame's second line as \"⌀T2\"")
    relating = relating.in_unit(unit or relating.unit)
    if relating.modifier != tol.modifier:
        raise p.error("feature_relating", f"the frame's two lines have different material conditions "
                                          f"({tol.describe()} and {relating.describe()}): give both the same")
    if not relating.width < tol.width:
        raise p.error("feature_relating", f"the feature-relating zone {relating.describe()} must be smaller than the "
                                          f"pattern-locating zone {tol.describe()} (equal zones are one position "
                                          "tolerance: leave out pattern and feature_relating)")
    return pattern, relating, datums


#: a frame line's datum letters after its tolerance: "⌀0.1 A B", "⌀0.1 (M) | A"
_FRAME_DATUMS = re.compile(r"((?:[\s|]+[A-Z](?![A-Za-z]))+)\s*$")
#: a datum letter with a modifier of its own: "A (M)", "B(L)"
_DATUM_MODIFIER = re.compile(r"[\s|][A-Z]\s*(?:\(\s*[MLS]\s*\)|[ⓂⓁⓈ])")


def frame_datums(p: Given, key: str, text: str) -> tuple[str, tuple[str, ...]]:
    """A position frame line's tolerance and its datum letters (``"⌀0.5 (M) A B C"`` → ``"⌀0.5 (M)"``, A B C).  A
    datum letter may not repeat, a datum's own modifier is not read (a datum feature of size at MMB is
    ``datum_size``), and a lone M, L or S is refused: a material condition written without its brackets would read as a
    datum letter."""
    if _DATUM_MODIFIER.search(text):
        raise p.error(key, f"{text!r}: a datum's material condition is not read from the frame — a datum feature of "
                           "size referenced at MMB is datum_size (and datum_type) beside the zone")
    m = _FRAME_DATUMS.search(text)
    datums = tuple(m.group(1).replace("|", " ").split()) if m else ()
    if len(set(datums)) < len(datums):
        raise p.error(key, f"{text!r} names a datum twice")
    odd = [d for d in datums if d in "MLS"]
    if odd:
        raise p.error(key, f"{text!r}: {odd[0]!r} after the zone reads as a datum letter or as a material condition — "
                           "write the condition as (M), (L) or Ⓜ, Ⓛ")
    return (text[:m.start()] if m else text), datums


def zone_bonus(spec, zone: str) -> list[tuple[int, float, float]]:
    """How the radius of ``zone`` grows with its feature's size: ``[(factor index, κ, reference)]`` in base units (at
    most one), the radius being r = t/2 + κ (x − reference) ≥ t/2 over the band (ASME Y14.5-2018 §7.3.3 bonus;
    ISO 2692): the toleranced feature at MMC, bonus = the departure of its actual size from MMC (internal: MMC =
    the smallest size, κ = +½ per unit of diameter; external: MMC = the largest, κ = −½); at LMC from LMC
    (internal: the largest, κ = −½; external: the smallest, κ = +½).  Radii are half the diametral bonus.

    A datum-feature shift is not a bonus of one zone: it moves the whole pattern (:func:`datum_shifts`)."""
    fs = [f for f in spec.factors if f.zone == zone]
    if not fs or not fs[0].size or not fs[0].modifier:
        return []
    f = fs[0]
    return [_departure(spec, f.size, f.feature_type, f.modifier)]


@dataclass(frozen=True)
class DatumShift:
    """A datum feature of size referenced at MMB and the position zones it locates: one pattern, shifted together.

    The datum feature may depart from its MMB (taken as its MMC size: a datum feature without a geometric tolerance
    of its own) by d = |x − reference|; the part may then translate on the datum feature simulator by up to d/2 in
    any direction, r = κ (x − reference) ≥ 0 with κ = +½ (an internal datum feature, a bore: reference its smallest
    size) or −½ (external, a boss: its largest).  Every zone that references it moves by the *same* vector s,
    |s| ≤ r — the features of a pattern located from common datum features at MMB are one pattern (the simultaneous
    requirement, ASME Y14.5 — the default unless SEP REQT is written beneath the frames; P. J. Drake Jr. (ed.),
    *Dimensioning and Tolerancing Handbook*, McGraw-Hill 1999, ch. 5; Tec-Ease GD&T tip 223: "the pattern could
    shift as much as 0.6 total").  The shift therefore moves the pattern as a whole: the distance between two of its
    features does not change with it.  Each zone's own tolerance (and bonus) still varies feature by feature.

    A frame marked ``separate = true`` (SEP REQT beneath it) is its own pattern: its zones (those sharing its
    ``frame``, or the one zone without a frame name) shift together, by a disc of their own, ``separate`` naming the
    frame (:attr:`label`: "B (SEP REQT 2X holes)")."""

    datum: str                 # the datum feature's size factor
    index: int
    kappa: float
    reference: float           # base units
    zones: tuple[str, ...]
    separate: str = ""         # SEP REQT: the frame (or the one zone) this shift moves

    @property
    def label(self) -> str:
        """The shift's name in tables and notes: the datum feature, and the zone of a separate requirement."""
        return f"{self.datum} (SEP REQT {self.separate})" if self.separate else self.datum


def datum_shifts(spec) -> list[DatumShift]:
    """The datum-feature shifts of the spec's position zones, one per datum feature of size (``datum_size``) with the
    zones that reference it together, one per frame marked ``separate`` (SEP REQT), in the order the zones are written
    (:class:`DatumShift`)."""
    groups: dict[tuple[str, str], list[str]] = {}
    types: dict[str, str] = {}
    for f in spec.factors:
        if f.zone and f.datum_size:
            zs = groups.setdefault((f.datum_size, (f.frame or f.zone) if f.separate else ""), [])
            if f.zone not in zs:
                zs.append(f.zone)
            types[f.datum_size] = f.datum_type
    out = []
    for (name, separate), zones in groups.items():
        i, kappa, ref = _departure(spec, name, types[name], "MMC")
        out.append(DatumShift(name, i, kappa, ref, tuple(zones), separate))
    return out


def _departure(spec, name: str, feature_type: str, modifier: str) -> tuple[int, float, float]:
    """``(index, κ, reference)`` of a feature of size's departure from its MMC or LMC size (:func:`zone_bonus`)."""
    i = spec.index(name)
    lo, hi = (float(units.to_base(v, spec.factors[i].unit)) for v in spec.factors[i].band)
    at_small = (feature_type == "internal") == (modifier == "MMC")     # the reference is the smallest size
    return i, 0.5 if at_small else -0.5, lo if at_small else hi


def check_zones(factors, file: str | None) -> None:
    """Each position zone has exactly two coordinate factors with the same unit and diameter."""
    zones: dict[str, list] = {}
    for f in factors:
        if f.zone:
            zones.setdefault(f.zone, []).append(f)
    for z, fs in zones.items():
        if len(fs) != 2:
            raise SpecError(f"position zone {z!r} has {len(fs)} coordinate factor(s) "
                            f"({', '.join(f.name for f in fs)}); it needs two (x and y)", file=file, key="factor.zone")
        a, b = fs
        if a.unit != b.unit or a.limits != b.limits:
            raise SpecError(f"the two coordinates of position zone {z!r} ({a.name}, {b.name}) need the same unit "
                            "and diameter", file=file, key="factor.zone")
        gd = lambda f: (f.modifier, f.size, f.feature_type, f.datum_size, f.datum_type, f.separate,  # noqa: E731
                        f.frame, f.pattern, f.locating)
        if gd(a) != gd(b):
            raise SpecError(f"the two coordinates of position zone {z!r} ({a.name}, {b.name}) need the same "
                            "modifier, size, feature_type, datum_size, datum_type, separate, frame, pattern and feature_relating", file=file, key="factor.zone")
        names = {f.name: f for f in factors}
        other = next((g for g in factors if g.datum_size and g.datum_size == a.datum_size
                      and g.datum_type != a.datum_type), None)
        if other is not None:
            raise SpecError(f"datum feature {a.datum_size!r} is {a.datum_type} for zone {z!r} and {other.datum_type} "
                            f"for zone {other.zone!r}: one feature has one type", file=file, key="factor.datum_type")
        for key in ("size", "datum_size"):
            ref = getattr(a, key)
            if not ref:
                continue
            g = names.get(ref)
            if g is None:
                raise SpecError(f"position zone {z!r}: {key} names no factor ({ref!r}){did_you_mean(ref, list(names))}",
                                file=file, key=f"factor.{key}")
            if g.zone:
                raise SpecError(f"position zone {z!r}: {key} {ref!r} is a zone coordinate, not a size", file=file,
                                key=f"factor.{key}")
            if units.dimension(g.unit) != units.dimension(a.unit):
                raise SpecError(f"position zone {z!r}: {key} {ref!r} is in {g.unit}, not a length like the zone",
                                file=file, key=f"factor.{key}")
    check_frames(factors, file)


def check_frames(factors, file: str | None) -> None:
    """The zones of one feature control frame (``frame``, an nX pattern) reference the same datum feature and are all
    a separate requirement or none: SEP REQT is written beneath a frame, not beside one of its features."""
    first: dict[str, object] = {}
    for f in factors:
        if not (f.zone and f.frame):
            continue
        g = first.setdefault(f.frame, f)
        if (g.separate, g.datum_size) != (f.separate, f.datum_size):
            raise SpecError(f"frame {f.frame!r}: zones {g.zone!r} and {f.zone!r} differ in separate or datum_size — the "
                            "zones of one frame share its datums and its SEP REQT", file=file, key="factor.frame")
        if drawn_zone(g) != drawn_zone(f):
            raise SpecError(f"frame {f.frame!r}: zones {g.zone!r} and {f.zone!r} differ in diameter or modifier — one "
                            "frame gives its features one zone", file=file, key="factor.frame")
    check_feature_types(factors, file)


def check_feature_types(factors, file: str | None) -> None:
    """A feature of size has one type wherever the spec names it: as a zone's ``size``, a ``datum_size`` or a form's
    ``envelope`` (internal: a hole, external: a shaft or boss)."""
    seen: dict[str, tuple[str, str]] = {}
    for f in factors:
        for ref, kind, key in ((f.size, f.feature_type, "feature_type"), (f.datum_size, f.datum_type, "datum_type"),
                               (f.envelope, f.feature_type, "feature_type")):
            if not ref or not kind:
                continue
            prev = seen.setdefault(ref, (kind, f.name))
            if prev[0] != kind:
                raise SpecError(f"feature of size {ref!r} is {prev[0]} for {prev[1]!r} and {kind} for {f.name!r}: one "
                                "feature has one type", file=file, key=f"factor.{key}")


def check_envelopes(factors, file: str | None) -> None:
    """Each envelope (Rule #1) names a size factor of the spec in a length, not a position zone's coordinate nor
    another form tolerance."""
    names = {f.name: f for f in factors}
    for f in factors:
        if not f.envelope:
            continue
        g = names.get(f.envelope)
        if g is None:
            raise SpecError(f"factor {f.name!r}: envelope names no factor ({f.envelope!r})"
                            f"{did_you_mean(f.envelope, list(names))}", file=file, key="factor.envelope")
        if g.zone or g.characteristic or g is f:
            raise SpecError(f"factor {f.name!r}: envelope {f.envelope!r} is not a size (a position zone's "
                            "coordinate, or a profile or form tolerance)", file=file, key="factor.envelope")
        if units.dimension(g.unit) != "length" or units.dimension(f.unit) != "length":
            raise SpecError(f"factor {f.name!r} ({f.unit}) and its envelope {f.envelope!r} ({g.unit}): a form and its "
                            "size must both be lengths", file=file, key="factor.envelope")
