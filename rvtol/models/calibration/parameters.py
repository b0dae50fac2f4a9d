"""Calibration parameters: a small named set, each with its unit, start, bounds and what it acts on.

Four kinds, named by a prefix:

``compliance.<family>``
    a **compliance scale** ``c`` (dimensionless, > 0) of one element family of the reducer's torque
    path — the families of the compliance chain (:data:`rvtol.elements.reducer_chain.FAMILIES`: doc
    000's contact laws and, where the design gives them, the crank support pair, crank bending and
    torsion, carrier, pin grooves, disc webs, input shaft): every deflection of that family at a given
    force is multiplied by ``c``.  It acts on the family's one design key ``compliance_scale.<family>``
    (default 1 = as derived; both reducer models read it, doc 000's laws as ``k0 / c``).
    ``compliance.all`` scales every family the design's model has (the one compliance scale a single
    torsion curve can identify).  Scales, not
    stiffnesses, are fitted because the output angle is nearly linear in compliances (springs in
    series add their compliances), which keeps the linearised confidence intervals honest.
``clearance.<name>``
    an **effective clearance** (length, ≥ 0) set on a group of the 20-DOF model's clearance
    factors at once (:data:`CLEARANCES`; e.g. ``clearance.crank_bearing`` = δ_b on all six
    cycloid–crank bearings, not doc 000's Table 3 pattern).
``factor.<name>``
    any single error factor of the 20-DOF model as it is named in a spec
    (:mod:`rvtol.models.reducer_20dof.factors`, e.g. ``factor.E_c`` or ``factor.delta_b[1,2]``).
``friction.<group>``
    a **friction scale** ``c`` (dimensionless, ≥ 0) of one friction group of the torsion curve
    (:data:`rvtol.models.reducer_20dof.friction.KEYS`: ``pin``, ``needle``, ``crank_support``): it multiplies
    the design's coefficient (``friction.pin_sliding`` …; the design must give it).  ``friction.all`` scales
    every coefficient the design gives.  Friction widens the hysteresis loop in proportion to the torque (the
    mid-line stays), a clearance opens it at zero torque only, a compliance changes the mid-line's slope: a
    curve measured on both branches over a wide torque range tells them apart, so a calibration with a
    friction parameter does not read the friction loop as clearance.
``offset.<measurement>``
    a constant added to one measured curve: the zero of a rig's angle encoder is arbitrary.  It
    enters the model linearly (its Jacobian column is exact) and costs no 20-DOF evaluation.

**An element family** added to the compliance chain is a calibration parameter at once; its line in
:data:`SEPARATED_BY` says which measurement tells it apart from the others.  A family the design's
model does not have is refused with the design file.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ... import units
from ...design import Design
from ...errors import InputError
from ...elements.reducer_chain import BASE_FAMILIES, scale_key
from ...elements.reducer_chain import FAMILIES as CHAIN_FAMILIES
from ..reducer_20dof.factors import ErrorFactors
from ..reducer_20dof.friction import KEYS as FRICTION_KEYS
from ..reducer_20dof.friction import LABELS as FRICTION_LABELS
from . import advice

STIFFNESS = "stiffness"     # the design key is a stiffness or k0: key / c
COMPLIANCE = "compliance"   # the design key is a compliance or a compliance multiplier: key · c


@dataclass(frozen=True)
class Family:
    key: str
    acts: str
    label: str
    separated_by: str


#: what measurement tells each family apart from the others (:mod:`.advice`)
SEPARATED_BY = advice.FAMILY_SEPARATED_BY

#: element families of the reducer's torque path (:data:`rvtol.elements.reducer_chain.FAMILIES`): each is
#: scaled through its one design key ``compliance_scale.<family>`` (a compliance multiplier; default 1)
FAMILIES: dict[str, Family] = {name: Family(scale_key(name), COMPLIANCE, label,
                                            SEPARATED_BY.get(name, advice.FAMILY_DEFAULT))
                               for name, label in CHAIN_FAMILIES.items()}


def families_in(design: Design) -> tuple[str, ...]:
    """The families the design's 20-DOF model has: doc 000's contact laws and the chain's elements it gives."""
    from ..reducer_20dof.geometry import geometry_from_design

    chain = geometry_from_design(design).chain
    present = set(BASE_FAMILIES) | set(chain.families if chain is not None else ())
    return tuple(f for f in FAMILIES if f in present)


_CRANK_BEARINGS = tuple(f"delta_b[{j},{i}]" for j in (1, 2) for i in (1, 2, 3))


@dataclass(frozen=True)
class Clearance:
    factors: tuple[str, ...]
    label: str
    separated_by: str


#: effective clearances: one value set on every factor of the group (base unit mm)
CLEARANCES: dict[str, Clearance] = {
    "crank_bearing": Clearance(_CRANK_BEARINGS, "cycloid–crank bearing clearance δ_b, all six bearings",
                               advice.CLEARANCE_SEPARATED_BY["crank_bearing"]),
    "crank_support": Clearance(("delta_oc",), "crank–carrier bearing clearance δ_oc, all three",
                               advice.CLEARANCE_SEPARATED_BY["crank_support"]),
    "carrier_housing": Clearance(("delta_ca",), "carrier–housing bearing clearance δ_ca",
                                 advice.CLEARANCE_SEPARATED_BY["carrier_housing"]),
    "pin": Clearance(("delta_pin",), "normal clearance δ at every pin (undersize pins)",
                     advice.CLEARANCE_SEPARATED_BY["pin"]),
}

KINDS = ("compliance", "friction", "clearance", "factor", "offset")
FRICTION_SEPARATED_BY = advice.FRICTION_SEPARATED_BY
DEFAULTS = {  # (start, lower, upper) as written in the display unit, display unit
    "compliance": ((1.0, 0.1, 10.0), "1"),
    "friction": ((1.0, 0.0, 10.0), "1"),
    "clearance": ((1.0, 0.0, 50.0), "um"),
    "factor_length": ((0.0, -50.0, 50.0), "um"),
    "factor_angle": ((0.0, -180.0, 180.0), "deg"),
    "offset": ((0.0, -3600.0, 3600.0), "arcsec"),
}


@dataclass(frozen=True)
class Parameter:
    """One fitted parameter. ``start``, ``lower``, ``upper``, ``typical`` in base units; ``unit`` is the
    display unit; ``targets`` the design keys (compliance), factor names (clearance, factor) or the
    measurement name (offset)."""

    name: str
    kind: str
    unit: str
    start: float
    lower: float
    upper: float
    targets: tuple[str, ...]
    label: str
    separated_by: str = ""
    acts: tuple[str, ...] = ()     # compliance: STIFFNESS or COMPLIANCE per target key

    @property
    def typical(self) -> float:
        """Size used to scale steps and finite differences: 1 display unit, or |start| if larger."""
        return max(abs(self.start), float(units.to_base(1.0, self.unit)))

    def display(self, v):
        return units.from_base(v, self.unit)

    def acts_on(self) -> str:
        if self.kind in ("compliance", "friction"):
            return ", ".join(f"{k} {'÷' if a == STIFFNESS else '×'} c" for k, a in zip(self.targets, self.acts))
        if self.kind == "offset":
            return f"added to every point of {self.targets[0]}"
        return ", ".join(self.targets)


def make_parameter(name: str, design: Design, *, start=None, bounds=None, unit: str | None = None,
                   measurements=()) -> Parameter:
    """A :class:`Parameter` from its name (module docstring); ``start``/``bounds`` as written in ``unit``
    (default: the kind's display unit, :data:`DEFAULTS`).  Raises :class:`InputError` (key ``name`` etc.)."""
    if not isinstance(name, str) or "." not in name:
        raise InputError(f"unknown parameter {name!r}: expected compliance.<family>, friction.<group>, "
                         f"clearance.<name>, factor.<factor> or offset.<measurement>", key="name")
    kind, _, what = name.partition(".")
    separated_by = ""
    acts: tuple[str, ...] = ()
    if kind == "compliance":
        here = families_in(design)
        if what == "all":
            fams = [FAMILIES[f] for f in here]
            targets, acts = tuple(f.key for f in fams), tuple(f.acts for f in fams)
            label, separated_by = "every element family's compliance", advice.ALL_FAMILIES_SEPARATED_BY
        elif what in FAMILIES:
            f = FAMILIES[what]
            if what not in here:
                raise InputError(f"the design has no {what} element (families here: {', '.join(here)})",
                                 file=design.file, key="name")
            targets, acts, label, separated_by = (f.key,), (f.acts,), f.label, f.separated_by
        else:
            raise InputError(f"unknown element family {what!r} (known: all, {', '.join(FAMILIES)})", key="name")
        if not targets:
            raise InputError("the design has none of the element families' keys", file=design.file, key="name")
        (s0, lo0, hi0), u0 = DEFAULTS["compliance"]
    elif kind == "friction":
        given = [g for g, key in FRICTION_KEYS.items() if key in design and float(design[key]) > 0.0]
        if what == "all":
            groups, label = given, "every friction coefficient of the design"
        elif what in FRICTION_KEYS:
            if what not in given:
                raise InputError(f"the design gives no friction coefficient {FRICTION_KEYS[what]} (> 0) to scale",
                                 file=design.file, key="name")
            groups, label = [what], f"friction of the {FRICTION_LABELS[what]}"
        else:
            raise InputError(f"unknown friction group {what!r} (known: all, {', '.join(FRICTION_KEYS)})", key="name")
        if not groups:
            raise InputError("the design gives no friction coefficient ([friction] keys)", file=design.file,
                             key="name")
        targets = tuple(FRICTION_KEYS[g] for g in groups)
        acts, separated_by = (COMPLIANCE,) * len(targets), FRICTION_SEPARATED_BY
        (s0, lo0, hi0), u0 = DEFAULTS["friction"]
    elif kind == "clearance":
        if what not in CLEARANCES:
            raise InputError(f"unknown clearance {what!r} (known: {', '.join(CLEARANCES)})", key="name")
        c = CLEARANCES[what]
        targets, label, separated_by = c.factors, c.label, c.separated_by
        (s0, lo0, hi0), u0 = DEFAULTS["clearance"]
    elif kind == "factor":
        try:
            ef = ErrorFactors([what], int(design.get("pin.count", 40)))
        except InputError as exc:
            raise InputError(exc.reason, key="name") from None
        angle = ef.units[0] == "rad"
        targets, label = (what,), f"error factor {what}"
        separated_by = advice.FACTOR_SEPARATED_BY
        (s0, lo0, hi0), u0 = DEFAULTS["factor_angle" if angle else "factor_length"]
    elif kind == "offset":
        names = [m.name for m in measurements]
        if what not in names:
            raise InputError(f"no measurement named {what!r} (measurements: {', '.join(names) or 'none'})",
                             key="name")
        m = measurements[names.index(what)]
        targets, label = (what,), f"angle offset of {what}"
        separated_by = advice.OFFSET_SEPARATED_BY[m.kind == "torsion"]
        (s0, lo0, hi0), u0 = DEFAULTS["offset"]
    else:
        raise InputError(f"unknown parameter kind {kind!r} in {name!r} (known: {', '.join(KINDS)})", key="name")
    u = units.canonical(unit) if unit else u0
    try:
        units.require_dimension(u, units.dimension(u0))
    except InputError as exc:
        raise InputError(exc.reason, key="unit") from None
    if start is None:
        start = float(units.convert(s0, u0, u))
    if bounds is None:
        bounds = (float(units.convert(lo0, u0, u)), float(units.convert(hi0, u0, u)))
    lo, hi = (float(b) for b in bounds)
    start = float(start)
    if not all(math.isfinite(v) for v in (lo, hi, start)):
        raise InputError("start and bounds must be finite numbers", key="bounds")
    if not lo < hi:
        raise InputError(f"bounds must be [lower, upper] with lower < upper, got [{lo:g}, {hi:g}]", key="bounds")
    if not lo <= start <= hi:
        raise InputError(f"start {start:g} lies outside the bounds [{lo:g}, {hi:g}]", key="start")
    if kind == "compliance" and not lo > 0:
        raise InputError(f"a compliance scale must stay > 0: lower bound {lo:g}", key="bounds")
    if kind == "clearance" and lo < 0:
        raise InputError(f"a clearance must stay >= 0: lower bound {lo:g} {u}", key="bounds")
    b = lambda v: float(units.to_base(v, u))  # noqa: E731
    return Parameter(name, kind, u, b(start), b(lo), b(hi), targets, label, separated_by, acts)


def check_parameters(params: list[Parameter], z_b: int = 40) -> None:
    """Refuse two parameters that act on the same design key or error factor (key ``parameter``)."""
    seen: dict[str, str] = {}
    for p in params:
        if p.name in [q.name for q in params[:params.index(p)]]:
            raise InputError(f"parameter {p.name!r} given twice", key="parameter")
        if p.kind == "offset":
            continue
        for t in p.targets:
            if t in seen:
                raise InputError(f"{p.name} and {seen[t]} both act on {t}", key="parameter")
            seen[t] = p.name
    factor_names = [t for p in params if p.kind in ("clearance", "factor") for t in p.targets]
    try:
        ErrorFactors(factor_names, z_b)
    except InputError as exc:
        raise InputError(exc.reason, key="parameter") from None


def scaled_design_values(design: Design, params: list[Parameter], x) -> dict[str, float]:
    """``{design key: base value}`` of the compliance and friction parameters at ``x`` (base values, params'
    order)."""
    out = {}
    for p, v in zip(params, x):
        if p.kind not in ("compliance", "friction"):
            continue
        for k, a in zip(p.targets, p.acts):
            old = design[k] if k in design else 1.0          # a compliance scale the design leaves at 1
            out[k] = old / v if a == STIFFNESS else old * v
    return out


def factor_values(params: list[Parameter], x) -> dict[str, float]:
    """``{error factor: base value}`` of the clearance and factor parameters at ``x``."""
    return {t: float(v) for p, v in zip(params, x) if p.kind in ("clearance", "factor") for t in p.targets}


def separation_advice(group: list[Parameter], curves=()) -> str:
    """Why the parameters of ``group`` look alike to the measured ``curves`` (kinds: "torsion",
    "transmission_error"), and which measurements tell them apart."""
    kinds = {p.kind for p in group}
    torsion_only = set(curves) == {"torsion"}
    if kinds == {"compliance"}:
        reason = "same_path"
    elif kinds <= {"clearance", "factor"} and torsion_only:
        reason = "play"
    elif "offset" in kinds and kinds & {"clearance", "factor"} and torsion_only:
        reason = "offset"
    elif "compliance" in kinds and kinds & {"clearance", "factor"} and torsion_only:
        reason = "shift_and_scale"
    else:
        reason = "proportional"
    seps = "; ".join(advice.SEPARATED_BY_ONE.format(name=p.name, measurement=p.separated_by)
                     for p in group if p.separated_by)
    return advice.SEPARATION.format(why=advice.LOOK_ALIKE[reason], measurements=seps)
