"""The assembly graph (doc 003): parts, features, deviation terms, fits, sequences, KCs.

An assembly description file (``data/assemblies/*.toml``) lists the parts
and their features, the deviations each feature carries, the fits that join
features of different parts, one or more assembly sequences and the key
characteristics (KCs) to report.  Each table is read by its declared schema (:mod:`.assembly_tables`;
``rvtol kinds part`` lists a table's keys).  Format::

    [assembly]
    name = "..."
    ground = "housing"                 # the part everything is placed on

    [dimensions]                       # named numbers, each with its source
    crank_radius = { value = 41.94, unit = "mm", source = "...", note = "..." }
    eccentricity = { design = "cycloid.eccentricity", source = "..." }  # from the study's design

    [[part]]
    name = "carrier"
    [[part.feature]]
    name = "crank_hole_1"
    datum = false                      # a datum feature *is* the part frame (identity, no pose deviation)
    radius = "crank_radius"            # nominal frame: origin (r cos θ, r sin θ, z) or x / y / z ...
    angle = 0                          # ... θ in deg; optional rotation (deg) about z
    z = 0
    size = "carrier.crank_hole_1.size" # optional: diameter deviation factor (used by clearance fits)
    form = "carrier.crank_hole_1.form" # optional (flow f2): mating-envelope loss, mm, reduces clearance
    [[part.feature.deviation]]         # pose deviation terms, composed in order (several: flow f5)
    name = "position"
    kind = "axis"                      # axis: end points x1, y1 (z = +L/2) and x2, y2 (z = -L/2), mm
    length = 50                        # distance between the two end points, mm
    zone = 0.012                       # optional: cylindrical zone diameter (factor bands must fit)
    # kind = "dof": dofs = ["u", "gamma"] (mm / rad); kind = "plane": w, alpha, beta with
    # zone = t, length = L (along x), width = W (along y)

    [[fit]]
    name = "needle_1"
    base = "crank_1.eccentric"         # part.feature
    mate = "cycloid.crank_hole_1"
    clearance = 0.010                  # nominal diametral clearance, mm (absent: a fixed, continuous fit)
    length = 12                        # engagement length, mm (clearance fits)
    hole = "mate"                      # which side is the hole (its size adds to the clearance)
    float = "uniform"                  # uniform | worst_tilt | worst_offset | centred
    type = "Mgg"                       # optional: checked against the datum flags

    [[sequence]]
    name = "carrier_first"
    steps = [{ part = "carrier", by = "main_bearing" }, ...]

    [[kc]]
    name = "cycloid_axis"
    feature = "cycloid.center"
    relative_to = "housing.pin_axis"
    components = ["radial", "tilt"]    # u v w alpha beta gamma radial tilt e_norm eps_norm
    length_unit = "um"
    angle_unit = "arcmin"
    radii = [12.5, 12.5, 12.5]         # effective radii (mm) for e_norm / eps_norm

Flow types (doc 003): f1 — within a part, datum to feature (its pose
deviation terms); f2 — form deviation (acts through the clearance of a fit);
f3 — fit between parts; f4 — clearance float in a fit; f5 — several
deviation terms on one feature.  Fit types: MDD (both features datums), MgD
(one), Mgg (none).  An assembly sequence places each part through one fit
onto a part already placed (the fits it uses *locate*, the others *close*
the loop and are reported as misfits).
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ... import units
from ...design import Design
from ...errors import InputError, SpecError
from ...options import read_options
from ...params import Params, read_toml
from .assembly_tables import (COMPONENTS, DEVIATION_KEYS, AssemblyFitTable, AssemblyHead, DeviationTable,
                              DimensionTable, FeatureTable, KCTable, PartTable, SequenceTable)
from .transforms import DOF, homogeneous, inverse, rotation_exact

FLOW_TYPES = {
    "f1": "same-part geometric position deviation (datum → feature)",
    "f2": "geometric shape (form) deviation, through a fit's clearance",
    "f3": "between-part geometric position (fit)",
    "f4": "assembly position correction (float in a clearance fit)",
    "f5": "several deviations on one geometry",
}
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
CLOSE_TOL = (1e-9, 1e-12)  # nominal loop closure: mm, rad
_REQUIRED = object()


@dataclass(frozen=True)
class Term:
    """A pose deviation of a feature: ``E = A · x[factors]`` (6-vector in the feature frame)."""

    name: str
    kind: str
    factors: tuple[str, ...]
    units: tuple[str, ...]  # base unit per factor
    A: np.ndarray  # 6 × len(factors)
    zone: dict = field(default_factory=dict)  # kind-specific zone data for checks and reports
    key: str = ""

    def band_limits(self) -> dict[str, float]:
        """Largest |value| each factor may take inside the zone's box (mm or rad)."""
        z = self.zone
        if not z:
            return {}
        if self.kind == "axis":
            return {f: 0.5 * z["t"] for f in self.factors}
        if self.kind == "plane":
            t, L, W = z["t"], z["L"], z["W"]
            lim = {"w": 0.5 * t, "alpha": t / W, "beta": t / L}
            return {f: lim[f.rsplit(".", 1)[1]] for f in self.factors}
        return {}


@dataclass(frozen=True)
class Feature:
    part: str
    name: str
    datum: bool
    frame: np.ndarray  # nominal 4×4 in the part frame
    terms: tuple[Term, ...] = ()
    size: str | None = None
    form: str | None = None
    description: str = ""
    key: str = ""

    @property
    def id(self) -> str:
        return f"{self.part}.{self.name}"

    @property
    def letter(self) -> str:
        """'D' for a datum geometry, 'g' for a deviation-prone one (doc 003 fit types)."""
        return "D" if self.datum else "g"


@dataclass(frozen=True)
class Fit:
    name: str
    base: str
    mate: str
    clearance: float | None  # nominal diametral clearance (mm); None: fixed fit
    length: float | None
    hole: str  # "base" | "mate"
    float_mode: str
    type: str
    description: str = ""
    key: str = ""

    @property
    def is_clearance(self) -> bool:
        return self.clearance is not None

    @property
    def float_factors(self) -> tuple[str, ...]:
        return tuple(f"{self.name}.{c}" for c in ("a1", "b1", "a2", "b2"))

    def part_of(self, side: str) -> str:
        return (self.base if side == "base" else self.mate).split(".", 1)[0]


@dataclass(frozen=True)
class Sequence:
    name: str
    steps: tuple[tuple[str, str], ...]  # (part, fit)
    description: str = ""

    @property
    def locating(self) -> set[str]:
        return {f for _, f in self.steps}


@dataclass(frozen=True)
class KC:
    name: str
    feature: str
    relative_to: str
    components: tuple[str, ...]
    length_unit: str = "um"
    angle_unit: str = "arcmin"
    radii: tuple[float, float, float] | None = None
    description: str = ""
    fit: str | None = None  # set for the automatic misfit KC of a closing fit


@dataclass(frozen=True)
class Dimension:
    name: str
    value: float  # base units
    unit: str
    source: str
    note: str = ""


@dataclass(frozen=True)
class Assembly:
    name: str
    description: str
    ground: str
    parts: dict[str, str]  # name -> description (insertion order)
    features: dict[str, Feature]
    fits: dict[str, Fit]
    sequences: dict[str, Sequence]
    kcs: tuple[KC, ...]
    dimensions: dict[str, Dimension]
    file: str | None = None
    sha256: str | None = None

    # -- queries --------------------------------------------------------------------
    def feature(self, fid: str) -> Feature:
        try:
            return self.features[fid]
        except KeyError:
            raise InputError(f"unknown feature {fid!r}", file=self.file, key="feature") from None

    def sequence(self, name: str | None) -> Sequence:
        if name is None:
            return next(iter(self.sequences.values()))
        if name not in self.sequences:
            raise InputError(f"unknown sequence {name!r} (assembly has: {', '.join(self.sequences)})",
                             key="sequence")
        return self.sequences[name]

    def closing_fits(self, seq: Sequence) -> list[Fit]:
        return [f for f in self.fits.values() if f.name not in seq.locating]

    def kcs_for(self, seq: Sequence) -> tuple[KC, ...]:
        """The declared KCs plus one misfit KC per fit that closes the loop in ``seq``."""
        auto = []
        for f in self.closing_fits(seq):
            comps = ("radial", "tilt") + (("margin",) if f.is_clearance else ())
            auto.append(KC(f"{f.name}_misfit", f.mate, f.base, comps, "um", "arcmin", None,
                           f"misfit of {f.mate} against {f.base} where the loop closes ({f.name} does not locate)",
                           fit=f.name))
        return self.kcs + tuple(auto)

    def factor_units(self) -> dict[str, str]:
        """Every factor name the graph knows -> base unit it expects."""
        out: dict[str, str] = {}
        for feat in self.features.values():
            for t in feat.terms:
                out.update(zip(t.factors, t.units))
            for f in (feat.size, feat.form):
                if f:
                    out[f] = "mm"
        for fit in self.fits.values():
            if fit.is_clearance:
                out.update({f: "1" for f in fit.float_factors})
        return out

    def nominal_poses(self, seq: Sequence) -> dict[str, np.ndarray]:
        """World pose (4×4) of every part with all deviations zero."""
        poses = {self.ground: np.eye(4)}
        for part, fname in seq.steps:
            fit = self.fits[fname]
            here, there = (fit.base, fit.mate) if fit.part_of("mate") == part else (fit.mate, fit.base)
            a, b = self.features[here], self.features[there]
            poses[part] = poses[a.part] @ a.frame @ inverse(b.frame)
        return poses

    def world_frame(self, fid: str, poses: dict[str, np.ndarray]) -> np.ndarray:
        f = self.features[fid]
        return poses[f.part] @ f.frame

    def flows(self, seq: Sequence | None = None):
        """The deviation flows of the graph as a table (edges with flow types)."""
        import pandas as pd

        rows = []
        for f in self.features.values():
            if f.terms:
                datum = next((g.id for g in self.features.values() if g.part == f.part and g.datum),
                             f"{f.part} (frame)")
                rows.append(("f1", datum, f.id, ", ".join(t.name for t in f.terms), ""))
            if len(f.terms) > 1:
                rows.append(("f5", f.id, f.id, " ∘ ".join(t.name for t in f.terms), ""))
        for fit in self.fits.values():
            role = "" if seq is None else ("locates" if fit.name in seq.locating else "closes")
            rows.append(("f3", fit.base, fit.mate, f"{fit.name} ({fit.type})", role))
            if fit.is_clearance:
                rows.append(("f4", fit.base, fit.mate, f"{fit.name}: float {fit.float_mode}", role))
                for fid in (fit.base, fit.mate):
                    if self.features[fid].form:
                        rows.append(("f2", fid, fit.name, self.features[fid].form, role))
        return pd.DataFrame(rows, columns=["flow", "from", "to", "what", "role"])


# =========================================================================== loading
def load_assembly(path: str | Path, design: Design | None = None) -> Assembly:
    data, sha = read_toml(path)
    a = assembly_from_table(data, file=str(path), design=design)
    return Assembly(**{**a.__dict__, "sha256": sha})


def _read(cls, p: Params):
    """The table ``p`` read by its declared schema ``cls`` (:mod:`.assembly_tables`); no key left unread."""
    o = read_options(cls, p)
    p.finish()
    return o


def assembly_from_table(data: dict, *, file: str | None = None, design: Design | None = None) -> Assembly:
    root = Params(data, file=file)
    head = root.sub("assembly")
    h = _read(AssemblyHead, head)

    dims = _dimensions(root.sub("dimensions", {}), design)
    num = _Numbers(dims)

    parts: dict[str, str] = {}
    features: dict[str, Feature] = {}
    for pt in root.tables("part"):
        o = _read(PartTable, pt)
        pname = _name(pt, "name", o.name)
        if pname in parts:
            raise pt.error("name", f"duplicate part name {pname!r}")
        parts[pname] = o.description
        n_datum = 0
        for ft in o.feature:
            f = _feature(ft, pname, num)
            if f.id in features:
                raise ft.error("name", f"duplicate feature name {f.name!r} in part {pname!r}")
            n_datum += f.datum
            if n_datum > 1:
                raise ft.error("datum", f"part {pname!r} has more than one datum feature")
            features[f.id] = f
    if not parts:
        raise root.error("part", "an assembly needs at least one [[part]]")
    if h.ground not in parts:
        raise head.error("ground", f"unknown part {h.ground!r} (parts: {', '.join(parts)})")

    fits: dict[str, Fit] = {}
    for t in root.tables("fit"):
        fit = _fit(t, features, num)
        if fit.name in fits or fit.name in parts:
            raise t.error("name", f"duplicate name {fit.name!r} (fit names must differ from other fits and parts)")
        fits[fit.name] = fit

    seqs: dict[str, Sequence] = {}
    for t in root.tables("sequence"):
        s = _sequence(t, parts, h.ground, fits)
        if s.name in seqs:
            raise t.error("name", f"duplicate sequence name {s.name!r}")
        seqs[s.name] = s
    if not seqs:
        raise root.error("sequence", "an assembly needs at least one [[sequence]]")

    kcs = tuple(_kc(t, features) for t in root.tables("kc"))
    if len({k.name for k in kcs}) != len(kcs):
        raise root.error("kc", "duplicate KC name")
    root.finish()

    _check_factor_names(features, fits, file)
    asm = Assembly(h.name, h.description, h.ground, parts, features, fits, seqs, kcs, dims, file)
    for s in seqs.values():
        _check_closure(asm, s)
        names = {k.name for k in asm.kcs_for(s)}
        if len(names) != len(asm.kcs_for(s)):
            raise SpecError("a KC name collides with an automatic misfit KC '<fit>_misfit'", file=file, key="kc")
    return asm


def _name(p: Params, key: str, v: str) -> str:
    """The name ``v`` of the key ``key``: letters, digits and _ only, or the located error."""
    if not _NAME.match(v):
        raise p.error(key, f"invalid name {v!r} (letters, digits and _ only)")
    return v


def _dimensions(p: Params, design: Design | None) -> dict[str, Dimension]:
    out = {}
    for key in list(p.keys()):
        t = p.sub(key)
        if not _NAME.match(key):
            raise p.error(key, f"invalid dimension name {key!r}")
        o = _read(DimensionTable, t)
        if not o.source.strip():
            raise t.error("source", "every dimension needs its source")
        if o.design is not None:
            for k in ("value", "unit"):
                if getattr(o, k) is not None:
                    raise t.error(k, "a dimension is either the design's (design) or written (value, unit), "
                                     "not both")
            unit, value = _design_number(t, o.design, design)
        else:
            for k in ("unit", "value"):
                if getattr(o, k) is None:
                    raise t.error(k, "missing required key (or give design)")
            unit = t.canonical_unit("unit", o.unit)
            value = float(units.to_base(o.value, unit))
        if units.dimension(unit) not in ("length", "angle", "dimensionless"):
            raise t.error("unit", f"a dimension must be a length or an angle, got {unit!r}")
        out[key] = Dimension(key, value, unit, o.source, o.note)
    return out


def _design_number(t: Params, ref: str, design: Design | None) -> tuple[str, float]:
    """``(unit, value in base units)`` of the design parameter ``ref`` a dimension names."""
    if design is None:
        raise t.error("design", f"refers to design parameter {ref!r} but the study names no design")
    if ref not in design:
        raise t.error("design", f"design {design.name!r} has no parameter {ref!r}")
    dp = design.param(ref)
    if isinstance(dp.value, (str, tuple)):
        raise t.error("design", f"design parameter {ref!r} is not a single number")
    return units.canonical(dp.unit), float(dp.base)


class _Numbers:
    """Resolves a length or angle a schema read (:mod:`.assembly_tables`): a number already in base units, or a
    dimension's name (``"-name"``: its negative)."""

    def __init__(self, dims: dict[str, Dimension]):
        self.dims = dims

    def get(self, p: Params, key: str, v: float | str | None, unit: str, default=_REQUIRED,
            positive: bool = False) -> float | None:
        if v is None:
            if default is _REQUIRED:
                raise p.error(key, "missing required key")
            return default
        if not isinstance(v, str):
            return v
        sign, name = (-1.0, v[1:]) if v.startswith("-") else (1.0, v)
        if name not in self.dims:
            raise p.error(key, f"unknown dimension {name!r} (known: {', '.join(self.dims) or 'none'})")
        d = self.dims[name]
        if units.dimension(d.unit) != units.dimension(unit):
            raise p.error(key, f"dimension {name!r} is a {units.dimension(d.unit)}, expected a "
                               f"{units.dimension(unit)}")
        x = sign * d.value
        written = units.from_base(x, unit)
        if positive and not written > 0:
            raise p.error(key, f"must be > 0, got {written:g} {unit} (from {v!r})")
        return x


def _feature(p: Params, part: str, num: _Numbers) -> Feature:
    o = _read(FeatureTable, p)
    name = _name(p, "name", o.name)
    if o.radius is not None or o.angle is not None:
        if o.x is not None or o.y is not None:
            raise p.error("x", "give the origin either as radius/angle or as x/y, not both")
        r = num.get(p, "radius", o.radius, "mm", 0.0)
        th = num.get(p, "angle", o.angle, "deg", 0.0)
        x, y = r * math.cos(th), r * math.sin(th)
    else:
        x, y = num.get(p, "x", o.x, "mm", 0.0), num.get(p, "y", o.y, "mm", 0.0)
    z = num.get(p, "z", o.z, "mm")
    rot = num.get(p, "rotation", o.rotation, "deg")
    frame = homogeneous(rotation_exact(np.array([0.0, 0.0, rot])), np.array([x, y, z]))
    frame[np.abs(frame) < 1e-15] = 0.0
    if o.datum and not np.allclose(frame, np.eye(4), atol=1e-12):
        raise p.error("datum", "a datum feature defines its part's frame: its origin and rotation must be zero")
    fid = f"{part}.{name}"
    terms = []
    for t in o.deviation:
        term = _term(t, fid, num)
        if any(term.name == other.name for other in terms):
            raise t.error("name", f"duplicate deviation name {term.name!r}")
        terms.append(term)
    if o.datum and terms:
        raise p.error("deviation", "a datum feature cannot carry pose deviations (it is the part frame); "
                                   "put the deviations on the features toleranced against it")
    return Feature(part, name, o.datum, frame, tuple(terms), o.size, o.form, o.description, p.key)


def _term(p: Params, fid: str, num: _Numbers) -> Term:
    o = _read(DeviationTable, p)
    name, kind = _name(p, "name", o.name), o.kind
    for k in ("length", "zone", "width", "dofs"):
        if getattr(o, k) is not None and k not in DEVIATION_KEYS[kind]:
            raise p.error(k, f"a deviation of kind {kind!r} takes no {k!r} (it takes: "
                             f"{', '.join(DEVIATION_KEYS[kind])})")
    prefix = f"{fid}.{name}" if o.prefix is None else o.prefix
    zone: dict = {}
    if kind == "axis":
        L = num.get(p, "length", o.length, "mm", positive=True)
        coords = ("x1", "y1", "x2", "y2")
        A = np.zeros((6, 4))
        # end 1 at z = +L/2, end 2 at z = -L/2 (see rvtol.models.stackup.domains.axis_from_ends)
        A[0, [0, 2]] = 0.5
        A[1, [1, 3]] = 0.5
        A[4, 0], A[4, 2] = 1.0 / L, -1.0 / L
        A[3, 1], A[3, 3] = -1.0 / L, 1.0 / L
        us = ("mm",) * 4
        zone = {"L": L}
        if o.zone is not None:
            zone["t"] = num.get(p, "zone", o.zone, "mm", positive=True)
    elif kind == "plane":
        coords = ("w", "alpha", "beta")
        A = np.zeros((6, 3))
        A[[2, 3, 4], [0, 1, 2]] = 1.0
        us = ("mm", "rad", "rad")
        if o.zone is not None:
            zone = {"t": num.get(p, "zone", o.zone, "mm", positive=True),
                    "L": num.get(p, "length", o.length, "mm", positive=True),
                    "W": num.get(p, "width", o.width, "mm", positive=True)}
        else:
            for k in ("length", "width"):
                if getattr(o, k) is not None:
                    raise p.error(k, "a plane's length and width size its zone: give zone too (or neither)")
    else:
        if o.dofs is None:
            raise p.error("dofs", "missing required key")
        coords = tuple(o.dofs)
        for c in coords:
            if c not in DOF:
                raise p.error("dofs", f"unknown DOF {c!r} (expected: {', '.join(DOF)})")
        if len(set(coords)) != len(coords):
            raise p.error("dofs", "a DOF is named twice")
        A = np.zeros((6, len(coords)))
        for j, c in enumerate(coords):
            A[DOF.index(c), j] = 1.0
        us = tuple("mm" if DOF.index(c) < 3 else "rad" for c in coords)
    return Term(name, kind, tuple(f"{prefix}.{c}" for c in coords), us, A, zone, p.key)


def _fit(p: Params, features: dict[str, Feature], num: _Numbers) -> Fit:
    o = _read(AssemblyFitTable, p)
    name = _name(p, "name", o.name)
    ends = []
    for side in ("base", "mate"):
        fid = getattr(o, side)
        if fid not in features:
            raise p.error(side, f"unknown feature {fid!r} (write part.feature)")
        ends.append(features[fid])
    if ends[0].part == ends[1].part:
        raise p.error("mate", "a fit joins features of two different parts")
    letters = "".join(sorted(e.letter for e in ends))  # 'DD', 'Dg' or 'gg'
    derived = {"DD": "MDD", "Dg": "MgD", "gg": "Mgg"}[letters]
    if o.fit_type is not None and o.fit_type != derived:
        raise p.error("type", f"declared {o.fit_type} but the features make it {derived} "
                              f"({ends[0].id}: {ends[0].letter}, {ends[1].id}: {ends[1].letter})")
    clearance = num.get(p, "clearance", o.clearance, "mm", None)
    if clearance is not None:
        length = num.get(p, "length", o.length, "mm", positive=True)
        if o.hole is None:
            raise p.error("hole", "missing required key")
        hole = o.hole
        mode = "uniform" if o.float_mode is None else o.float_mode
    else:
        for k, v in (("length", o.length), ("hole", o.hole), ("float", o.float_mode)):
            if v is not None:
                raise p.error(k, "only a clearance fit (with 'clearance') takes this key")
        length, hole, mode = None, "mate", "centred"
        for e in ends:
            if e.form:
                raise p.error("clearance", f"feature {e.id} has a form deviation, which acts only through "
                                           "the clearance of a clearance fit")
    return Fit(name, ends[0].id, ends[1].id, clearance, length, hole, mode, derived, o.description, p.key)


def _sequence(p: Params, parts: dict, ground: str, fits: dict[str, Fit]) -> Sequence:
    o = read_options(SequenceTable, p)      # the steps read, their tables kept to blame a step
    steps_at = p.tables("steps")
    p.finish()
    name = _name(p, "name", o.name)
    placed = {ground}
    steps = []
    for sp, s in zip(steps_at, o.steps):
        part, by = s.part, s.by
        if part not in parts:
            raise sp.error("part", f"unknown part {part!r}")
        if part in placed:
            raise sp.error("part", f"part {part!r} is placed twice (or is the ground)")
        if by not in fits:
            raise sp.error("by", f"unknown fit {by!r}")
        fit = fits[by]
        sides = {fit.part_of("base"), fit.part_of("mate")}
        if part not in sides:
            raise sp.error("by", f"fit {by!r} does not touch part {part!r}")
        other = (sides - {part}).pop()
        if other not in placed:
            raise sp.error("by", f"fit {by!r} joins {part!r} to {other!r}, which is not placed yet")
        placed.add(part)
        steps.append((part, by))
    missing = [q for q in parts if q not in placed]
    if missing:
        raise p.error("steps", f"part {missing[0]!r} is never placed")
    return Sequence(name, tuple(steps), o.description)


def _kc(p: Params, features: dict[str, Feature]) -> KC:
    o = _read(KCTable, p)
    name = _name(p, "name", o.name)
    for k in ("feature", "relative_to"):
        if getattr(o, k) not in features:
            raise p.error(k, f"unknown feature {getattr(o, k)!r} (write part.feature)")
    comps = tuple(o.components)
    for c in comps:
        if c not in COMPONENTS or c == "margin":
            raise p.error("components", f"unknown component {c!r} (expected: {', '.join(COMPONENTS[:-1])})")
    if len(set(comps)) != len(comps):
        raise p.error("components", "a component is named twice")
    lu = p.canonical_unit("length_unit", o.length_unit, dimension="length")
    au = p.canonical_unit("angle_unit", o.angle_unit, dimension="angle")
    radii = None
    if o.radii is not None or {"e_norm", "eps_norm"} & set(comps):
        if o.radii is None:
            raise p.error("radii", "missing required key (e_norm and eps_norm need three effective radii)")
        if len(o.radii) != 3:
            raise p.error("radii", f"expected 3 numbers, got {len(o.radii)}")
        radii = tuple(o.radii)
    return KC(name, o.feature, o.relative_to, comps, lu, au, radii, o.description)


def _check_factor_names(features: dict[str, Feature], fits: dict[str, Fit], file) -> None:
    seen: dict[str, str] = {}

    def claim(name: str, where: str):
        if name in seen:
            raise SpecError(f"factor name {name!r} is used twice ({seen[name]} and {where})", file=file, key=where)
        seen[name] = where

    for f in features.values():
        for t in f.terms:
            for fn in t.factors:
                claim(fn, t.key)
        for k in ("size", "form"):
            if getattr(f, k):
                claim(getattr(f, k), f"{f.key}.{k}")
    for fit in fits.values():
        if fit.is_clearance:
            for fn in fit.float_factors:
                claim(fn, fit.key)


def _check_closure(asm: Assembly, seq: Sequence) -> None:
    """Every fit's two features must coincide in the nominal geometry (else the data are inconsistent)."""
    poses = asm.nominal_poses(seq)
    for fit in asm.fits.values():
        rel = inverse(asm.world_frame(fit.base, poses)) @ asm.world_frame(fit.mate, poses)
        dt = float(np.abs(rel[:3, 3]).max())
        dr = float(np.abs(rel[:3, :3] - np.eye(3)).max())
        if dt > CLOSE_TOL[0] or dr > CLOSE_TOL[1]:
            raise SpecError(f"the nominal geometry does not close at fit {fit.name!r} in sequence {seq.name!r}: "
                            f"{fit.mate} is off {fit.base} by {rel[:3, 3].round(6).tolist()} mm "
                            f"and {math.degrees(math.acos(max(-1.0, min(1.0, (np.trace(rel[:3, :3]) - 1) / 2)))):.4g}°",
                            file=asm.file, key=fit.key)
