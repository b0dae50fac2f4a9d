"""The 6-DOF stack-up's assembly file (``data/assemblies/*.toml``, :mod:`.graph`), declared (:mod:`rvtol.options`):
``[assembly]``, each ``[dimensions]`` entry, ``[[part]]``, ``[[part.feature]]``, ``[[part.feature.deviation]]``,
``[[fit]]``, ``[[sequence]]`` and ``[[kc]]`` — so ``rvtol kinds part`` (``assembly``, ``dimension``, ``feature``,
``deviation``, ``assembly_fit``, ``sequence``, ``kc``) lists their keys and the common invalid-value test covers
them — and a stack-up study's ``[[analysis.domain]]`` tables (``rvtol kinds domain``).  What the keys mean
together (names that exist, a datum at the part's origin, the keys a deviation's kind takes, a sequence that
places every part, the nominal loop closing) is checked where the assembly is made
(:func:`rvtol.models.stackup.graph.assembly_from_table`).

A length or an angle of the assembly file is a number (in mm, or deg for an angle), ``{ value, unit }``, or the
name of one of its ``[dimensions]`` (``"-name"`` for its negative): typed ``float | str`` with a ``unit``, the
string is resolved by the loader.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from ...options import REQUIRED, option
from ...params import Params

COMPONENTS = ("u", "v", "w", "alpha", "beta", "gamma", "radial", "tilt", "e_norm", "eps_norm", "margin")
FLOAT_MODES = ("uniform", "worst_tilt", "worst_offset", "centred")
FIT_TYPES = ("MDD", "MgD", "Mgg")

_LENGTH = "mm, { value, unit } or a dimension's name"
_ANGLE = "deg, { value, unit } or a dimension's name"
_NAME = "letters, digits and _"


@dataclass
class AssemblyHead:
    """``[assembly]`` of a stack-up's assembly file: its name and the part everything is placed on."""

    name: str = option(REQUIRED, "the assembly's name")
    description: str = option("", "what the assembly is, for the report")
    ground: str = option(REQUIRED, "the [[part]] everything is placed on (its frame is the world's)")
    source: object = option(None, "where the data come from (a citation: any form)")


@dataclass
class DimensionTable:
    """``[dimensions] <name> = { ... }`` of a stack-up's assembly file: a named length or angle and its source —
    written (value, unit) or the study's design number (design)."""

    value: float | None = option(None, "the number, in unit (not with design)")
    unit: str | None = option(None, "its unit: a length or an angle (not with design)")
    design: str | None = option(None, "instead of value and unit: the study design's parameter that holds it")
    source: str = option(REQUIRED, "where the number comes from (not empty)")
    note: str = option("", "how it was obtained, when no source gives it as it is")


@dataclass
class PartTable:
    """``[[part]]`` of a stack-up's assembly file: a part and its features."""

    name: str = option(REQUIRED, f"the part's name ({_NAME})")
    description: str = option("", "what the part is, for the report")
    feature: list[Params] = option([], "its [[part.feature]] tables (rvtol kinds feature)")


@dataclass
class FeatureTable:
    """``[[part.feature]]`` of a stack-up's assembly file: a feature's nominal frame in its part, and the deviations
    it carries (origin as radius/angle or x/y, not both)."""

    name: str = option(REQUIRED, f"the feature's name in its part ({_NAME})")
    datum: bool = option(False, "the part's datum: it is the part frame (origin and rotation zero, no deviation)")
    radius: float | str | None = option(None, f"the origin's distance from the part's z axis: {_LENGTH} "
                                              "(default 0)", unit="mm")
    angle: float | str | None = option(None, f"the origin's angle about z: {_ANGLE} (default 0)", unit="deg")
    x: float | str | None = option(None, f"the origin's x: {_LENGTH} (default 0)", unit="mm")
    y: float | str | None = option(None, f"the origin's y: {_LENGTH} (default 0)", unit="mm")
    z: float | str = option(0.0, f"the origin's z: {_LENGTH}", unit="mm")
    rotation: float | str = option(0.0, f"the frame's rotation about z: {_ANGLE}", unit="deg")
    size: str | None = option(None, "the factor of its diameter deviation (acts through a clearance fit)")
    form: str | None = option(None, "the factor of its form deviation: mating-envelope loss, reduces a clearance")
    description: str = option("", "what the feature is, for the report")
    deviation: list[Params] = option([], "its [[part.feature.deviation]] pose deviation terms, composed in order "
                                         "(rvtol kinds deviation)")


@dataclass
class DeviationTable:
    """``[[part.feature.deviation]]`` of a stack-up's assembly file: a pose deviation term of a feature —
    kind "axis" (length, zone), "plane" (zone with length and width) or "dof" (dofs)."""

    name: str = option(REQUIRED, f"the term's name in its feature ({_NAME})")
    kind: Literal["axis", "dof", "plane"] = option(REQUIRED, "axis: end points x1, y1, x2, y2; plane: w, alpha, "
                                                             "beta; dof: the named degrees of freedom")
    prefix: str | None = option(None, "its factors' names before .<coordinate> (default: part.feature.name)")
    length: float | str | None = option(None, f"axis: the distance of its end points; plane: the zone's length "
                                              f"(along x): {_LENGTH}", unit="mm", positive=True)
    zone: float | str | None = option(None, f"axis, plane: the tolerance zone (an axis': its diameter): {_LENGTH}",
                                      unit="mm", positive=True)
    width: float | str | None = option(None, f"plane: the zone's width (along y): {_LENGTH}", unit="mm",
                                       positive=True)
    dofs: list[str] | None = option(None, "dof: the degrees of freedom it moves (u v w alpha beta gamma)",
                                    min_length=1)


@dataclass
class AssemblyFitTable:
    """``[[fit]]`` of a stack-up's assembly file (not a build file's [[fit]]: rvtol kinds fit): a fit joining
    features of two parts — a clearance fit (with clearance) or a fixed one."""

    name: str = option(REQUIRED, f"the fit's name ({_NAME}; not a part's)")
    base: str = option(REQUIRED, "one feature, as part.feature")
    mate: str = option(REQUIRED, "the other feature, of another part, as part.feature")
    fit_type: str | None = option(None, "MDD, MgD or Mgg (default: what the datum flags make it; checked)",
                                  choices=FIT_TYPES, key="type")
    clearance: float | str | None = option(None, f"the nominal diametral clearance: {_LENGTH} (absent: a fixed, "
                                                 "continuous fit)", unit="mm")
    length: float | str | None = option(None, f"a clearance fit's engagement length: {_LENGTH}", unit="mm",
                                        positive=True)
    hole: str | None = option(None, "a clearance fit's hole side (its size adds to the clearance)",
                              choices=("base", "mate"))
    float_mode: str | None = option(None, "a clearance fit's float (default: uniform)", choices=FLOAT_MODES,
                                    key="float")
    description: str = option("", "what the fit is, for the report")


@dataclass
class SequenceStep:
    """One step of a ``[[sequence]]``: a part placed through a fit onto a part already placed."""

    part: str = option(REQUIRED, "the part placed")
    by: str = option(REQUIRED, "the [[fit]] that places it")


@dataclass
class SequenceTable:
    """``[[sequence]]`` of a stack-up's assembly file: an assembly order, each part placed once by one fit."""

    name: str = option(REQUIRED, f"the sequence's name ({_NAME})")
    description: str = option("", "what the sequence is, for the report")
    steps: list[SequenceStep] = option(REQUIRED, "[{ part, by }, ...]: every part but the ground, in order")


@dataclass
class KCTable:
    """``[[kc]]`` of a stack-up's assembly file: a key characteristic, a feature's deviation relative to another."""

    name: str = option(REQUIRED, f"the KC's name ({_NAME}; its outputs are <name>.<component>)")
    feature: str = option(REQUIRED, "the feature, as part.feature")
    relative_to: str = option(REQUIRED, "the feature it is measured from, as part.feature")
    components: list[str] = option(REQUIRED, f"what it reports: {' '.join(COMPONENTS[:-1])}", min_length=1)
    length_unit: str = option("um", "the unit of its lengths")
    angle_unit: str = option("arcmin", "the unit of its angles")
    radii: list[float] | None = option(None, "three effective radii (mm) for e_norm and eps_norm (needed by them)",
                                       positive=True)
    description: str = option("", "what the KC is, for the report")


@dataclass
class DomainTable:
    """``[[analysis.domain]]`` of a stack-up study's stackup_domains analysis: a deviation domain whose derived
    moments are checked against sampling — kind "plane" (t1, t2, length, width), "cylinder" (t, length) or
    "clearance" (clearance, hole, shaft, length)."""

    kind: Literal["plane", "cylinder", "clearance"] = option(REQUIRED, "the domain's kind")
    name: str | None = option(None, "its name in the report (default: the kind)")
    k: float = option(3.0, "the tolerance band's half-width in σ of a truncated normal", positive=True)
    t1: float | None = option(None, "plane: the zone's lower face (mm, or { value, unit })", unit="mm")
    t2: float | None = option(None, "plane: the zone's upper face (> t1)", unit="mm")
    t: float | None = option(None, "cylinder: the zone's diameter", unit="mm", positive=True)
    clearance: float | None = option(None, "clearance: the nominal diametral clearance", unit="mm")
    length: float | None = option(None, "the face's length, the axis' length or the engagement length", unit="mm",
                                  positive=True)
    width: float | None = option(None, "plane: the face's width", unit="mm", positive=True)
    hole: Params | None = option(None, "clearance: the hole's size deviation, a distribution as a spec factor's "
                                       "(dist, ...; mm)")
    shaft: Params | None = option(None, "clearance: the shaft's size deviation, a distribution (mm)")


#: the keys each kind of deviation term and of domain takes, beyond those every one takes
DEVIATION_KEYS = {"axis": ("length", "zone"), "plane": ("zone", "length", "width"), "dof": ("dofs",)}
DOMAIN_KEYS = {"plane": ("t1", "t2", "length", "width"), "cylinder": ("t", "length"),
               "clearance": ("clearance", "hole", "shaft", "length")}
