"""Units: conversion at the edges, base units inside.

Inside rvtol every quantity is in base units: **mm, N, s, rad** and what
follows from them (N·mm for torque, N/mm for stiffness, tonne for mass so
that N = t·mm/s², t·mm² for inertia, MPa = N/mm² for stress).  Files and
reports use whatever unit is written next to the number; :func:`to_base`
and :func:`from_base` convert.

The table below holds the units rvtol names (each factor checked against pint in
tests/units/test_units_table.py).  A unit outside it (``mm^2``, ``N/mm²``, ``h``, ``ft``, ``1/K``) is read by
pint: its base is its root units in rvtol's (m → mm, g → tonne, s, rad, K), so ``cm^2`` is 100 mm²
and ``N/mm²`` 1 MPa; it belongs to a table dimension when its base is that dimension's base unit
(``N/mm²`` is a pressure, ``h`` a time), else to the dimension named by its base (``mm**2``).  Two
units convert only within one dimension (``mm²`` never to ``mm``); an angle is a dimension of its own
(rad ≠ 1, as in the table, where pint would call both dimensionless).  A unit pint does not read either
is refused with the table's did-you-mean, and so is one pint reads as none of rvtol's (not a product
of powers of mm, t, s, rad and K: an offset scale ``degC``, an ampere, ``de`` — a typo of ``deg``
that pint reads as a deci-elementary-charge).

>>> round(from_base(to_base(1.0, "um"), "mm"), 12)
0.001
>>> round(convert(1.0, "arcmin", "arcsec"), 9)
60.0
"""
from __future__ import annotations

import math
from functools import cache
from typing import NamedTuple

import numpy as np

from .errors import UnitError, did_you_mean

_ARCMIN = math.pi / 10800.0
_ARCSEC = math.pi / 648000.0

# name -> (dimension, factor to the base unit of that dimension)
_TABLE: dict[str, tuple[str, float]] = {
    # dimensionless
    "1": ("dimensionless", 1.0),
    "%": ("dimensionless", 0.01),
    # length (base mm)
    "mm": ("length", 1.0),
    "um": ("length", 1e-3),
    "nm": ("length", 1e-6),
    "cm": ("length", 10.0),
    "m": ("length", 1e3),
    "in": ("length", 25.4),          # international inch (exact)
    "thou": ("length", 0.0254),      # 0.001 in
    # angle (base rad)
    "rad": ("angle", 1.0),
    "mrad": ("angle", 1e-3),
    "urad": ("angle", 1e-6),
    "deg": ("angle", math.pi / 180.0),
    "arcmin": ("angle", _ARCMIN),
    "arcsec": ("angle", _ARCSEC),
    # force (base N)
    "N": ("force", 1.0),
    "kN": ("force", 1e3),
    # torque (base N·mm)
    "N*mm": ("torque", 1.0),
    "N*m": ("torque", 1e3),
    "kN*m": ("torque", 1e6),
    # linear stiffness (base N/mm)
    "N/mm": ("stiffness", 1.0),
    "N/um": ("stiffness", 1e3),
    "N/m": ("stiffness", 1e-3),
    # torsional stiffness (base N·mm/rad)
    "N*mm/rad": ("torsional_stiffness", 1.0),
    "N*m/rad": ("torsional_stiffness", 1e3),
    "N*m/arcmin": ("torsional_stiffness", 1e3 / _ARCMIN),
    "N*m/arcsec": ("torsional_stiffness", 1e3 / _ARCSEC),
    # stress / modulus (base MPa = N/mm²)
    "MPa": ("pressure", 1.0),
    "GPa": ("pressure", 1e3),
    "Pa": ("pressure", 1e-6),
    # time (base s)
    "s": ("time", 1.0),
    "ms": ("time", 1e-3),
    "min": ("time", 60.0),
    # angular speed (base rad/s)
    "rad/s": ("angular_speed", 1.0),
    "rpm": ("angular_speed", 2.0 * math.pi / 60.0),
    # mass (base tonne: N·s²/mm)
    "t": ("mass", 1.0),
    "kg": ("mass", 1e-3),
    "g": ("mass", 1e-6),
    # inertia (base t·mm²)
    "t*mm^2": ("inertia", 1.0),
    "kg*mm^2": ("inertia", 1e-3),
    "kg*m^2": ("inertia", 1e3),
    # density (base t/mm³)
    "kg/m^3": ("density", 1e-12),
    "t/mm^3": ("density", 1.0),
    # damping (base N·s/mm)
    "N*s/mm": ("damping", 1.0),
    "N*s/m": ("damping", 1e-3),
    # angle per length, e.g. sensitivities (base rad/mm)
    "rad/mm": ("angle_per_length", 1.0),
    "arcmin/mm": ("angle_per_length", _ARCMIN),
    "arcsec/um": ("angle_per_length", _ARCSEC / 1e-3),
    "arcmin/um": ("angle_per_length", _ARCMIN / 1e-3),
    # money (cost models): one unit, whatever the currency
    "cost": ("cost", 1.0),
}

_ALIASES = {
    "": "1",
    "-": "1",
    "µm": "um",
    "μm": "um",
    "micron": "um",
    "inch": "in",
    "inches": "in",
    "mil": "thou",                   # a thou: 0.001 in, as US drawings write it (not the millimetre)
    "mils": "thou",
    '"': "in",
    "µrad": "urad",
    "μrad": "urad",
    "°": "deg",
    "degree": "deg",
    "degrees": "deg",
    "′": "arcmin",
    "″": "arcsec",
    "N·mm": "N*mm",
    "Nmm": "N*mm",
    "N·m": "N*m",
    "Nm": "N*m",
    "kN·m": "kN*m",
    "N/μm": "N/um",
    "N/µm": "N/um",
    "N·mm/rad": "N*mm/rad",
    "N·m/rad": "N*m/rad",
    "N·m/arcmin": "N*m/arcmin",
    "Nm/arcmin": "N*m/arcmin",
    "N·m/arcsec": "N*m/arcsec",
    "kg·m²": "kg*m^2",
    "kg·mm²": "kg*mm^2",
    "kg m^2": "kg*m^2",
    "N·s/mm": "N*s/mm",
    "N·s/m": "N*s/m",
    "arcsec/µm": "arcsec/um",
    "arcsec/μm": "arcsec/um",
    "arcmin/µm": "arcmin/um",
    "arcmin/μm": "arcmin/um",
    "′/mm": "arcmin/mm",
    "r/min": "rpm",
    "rev/min": "rpm",
}

#: the base unit of each dimension
BASE_UNITS = {dim: name for name, (dim, f) in _TABLE.items() if f == 1.0 and name not in ("1",)}
BASE_UNITS["dimensionless"] = "1"


def canonical(unit: str, dimension: str | tuple[str, ...] | None = None) -> str:
    """The canonical spelling of ``unit`` (the table's, else pint's: ``mm²`` → ``mm**2``); raises :class:`UnitError` if
    unknown.  ``dimension`` (one or several): what the unit is expected to measure — an unknown unit's "did you mean"
    and list of known units then hold only units of that dimension (``mils`` for a length is never answered with
    ``min``, a time)."""
    if not isinstance(unit, str):
        raise UnitError(f"unit must be a string, got {type(unit).__name__}")
    u = in_table(unit)
    if u is not None:
        return u
    u = unit.strip()
    read = _read_by_pint(u)
    if read is None:
        dims = None if dimension is None else ((dimension,) if isinstance(dimension, str) else tuple(dimension))
        known = [n for n, (d, _) in _TABLE.items() if dims is None or d in dims]
        spellings = known + [a for a, n in _ALIASES.items() if n in known]
        what = "" if dims is None else f" {' or '.join(d.replace('_', ' ') for d in dims)}"
        raise UnitError(f"unknown{what} unit {unit!r}{did_you_mean(u, spellings)} "
                        f"(known: {', '.join(sorted(known))})")
    return read.spelling


def in_table(unit: str) -> str | None:
    """The table's spelling of ``unit`` (an alias resolved), None if the table does not hold it (pint is not asked)."""
    u = _ALIASES.get(unit.strip(), unit.strip())
    return u if u in _TABLE else None


#: pint's root units -> rvtol's base units (mm, tonne, s, rad; K for temperature differences; cost)
_PINT_BASE = {"meter": "mm", "gram": "t", "second": "s", "radian": "rad", "kelvin": "K", "cost_unit": "cost"}


@cache
def _pint():
    """pint's default registry with rvtol's cost (loaded on the first unit outside the table: about a second) and the
    table's dimensions by the spelling of their base unit in rvtol's root units."""
    import pint

    reg = pint.UnitRegistry()
    reg.define("cost_unit = [cost] = cost")
    return reg, {_base(reg.Quantity(b))[0]: d for d, b in BASE_UNITS.items()}


def _base(q) -> tuple[str, object]:
    """(spelling, pint unit) of the base of the dimension of the pint quantity ``q``: its root units in rvtol's.
    Raises ValueError for a unit that is no product of their powers (an offset scale such as degC, a current)."""
    roots = q.to_root_units().unit_items()
    if not q._is_multiplicative or any(n not in _PINT_BASE for n, _ in roots):
        raise ValueError(q.units)
    base = q._REGISTRY.Unit("*".join(f"{_PINT_BASE[n]}**{e}" for n, e in roots))
    return format(base, "~C"), base


class _PintUnit(NamedTuple):
    spelling: str       # the canonical spelling (pint's: mm**2)
    dimension: str      # the table's dimension of the same base unit, else the base unit's spelling (mm**2)
    factor: float       # to that base unit
    label: str          # as printed (mm²)


@cache
def _read_by_pint(unit: str) -> _PintUnit | None:
    """A unit outside the table as pint reads it, or None if pint does not know it or reads it as none of rvtol's
    (``de``, a typo of ``deg``, is a deci-elementary-charge to pint)."""
    reg, dims = _pint()
    try:
        q = reg.Unit(unit) * 1.0
        name, base = _base(q)
    except Exception:        # pint's parser raises many kinds: UndefinedUnitError, ValueError, TokenError, ...
        return None
    return _PintUnit(format(q.units, "~C"), dims.get(name, name), float(q.to(base).magnitude), format(q.units, "~P"))


def _entry(unit: str) -> tuple[str, float]:
    """(dimension, factor to its base unit) of ``unit``."""
    u = canonical(unit)
    if u in _TABLE:
        return _TABLE[u]
    read = _read_by_pint(u)
    return read.dimension, read.factor


def dimension(unit: str) -> str:
    """The physical dimension of ``unit`` (``'length'``, ``'angle'``, ... ; ``'mm**2'`` for one outside the table)."""
    return _entry(unit)[0]


def base_unit(unit: str) -> str:
    """The base unit of the dimension of ``unit`` (``'um'`` → ``'mm'``, ``'cm^2'`` → ``'mm**2'``)."""
    d = dimension(unit)
    return BASE_UNITS.get(d, d)


def factor(unit: str) -> float:
    """Multiply a value in ``unit`` by this to get base units."""
    return _entry(unit)[1]


def to_base(value, unit: str):
    """Convert ``value`` (scalar or array) from ``unit`` to base units."""
    f = factor(unit)
    return value * f if f != 1.0 else value


def from_base(value, unit: str):
    """Convert ``value`` from base units to ``unit``."""
    f = factor(unit)
    return value / f if f != 1.0 else value


def convert(value, src: str, dst: str):
    """Convert ``value`` from unit ``src`` to unit ``dst`` (same dimension)."""
    if dimension(src) != dimension(dst):
        raise UnitError(f"cannot convert {src!r} ({dimension(src)}) to {dst!r} ({dimension(dst)})")
    return from_base(to_base(value, src), dst)


def require_dimension(unit: str, expected: str | tuple[str, ...]) -> str:
    """Check that ``unit`` has the ``expected`` dimension; return its canonical name."""
    exp = (expected,) if isinstance(expected, str) else tuple(expected)
    u = canonical(unit, exp)
    if dimension(u) not in exp:
        raise UnitError(f"unit {unit!r} is a {dimension(u)}, expected {' or '.join(exp)}")
    return u


_LABELS = {"um": "µm", "urad": "µrad", "deg": "°", "N*mm": "N·mm", "N*m": "N·m", "kN*m": "kN·m",
           "N/um": "N/µm", "N*mm/rad": "N·mm/rad", "N*m/rad": "N·m/rad", "N*m/arcmin": "N·m/arcmin",
           "N*m/arcsec": "N·m/arcsec", "t*mm^2": "t·mm²", "kg*mm^2": "kg·mm²", "kg*m^2": "kg·m²",
           "kg/m^3": "kg/m³", "t/mm^3": "t/mm³", "N*s/mm": "N·s/mm", "N*s/m": "N·s/m",
           "arcsec/um": "arcsec/µm", "arcmin/um": "arcmin/µm", "1": "–"}


def number_label(v: float) -> str:
    """A number as written in a table or title: ``%g``, and ``∞`` for infinity."""
    return "∞" if math.isinf(v) else f"{v:g}"


def label(unit: str) -> str:
    """How a unit is printed in reports and on axes (``'um'`` → ``'µm'``)."""
    try:
        u = canonical(unit)
    except UnitError:
        return str(unit)
    return _LABELS.get(u, u) if u in _TABLE else _read_by_pint(u).label


def known_units() -> list[str]:
    """The table's units (pint reads others)."""
    return sorted(_TABLE)


def arcsec_per_um_at_radius(radius_mm: float) -> float:
    """Angle in arcsec subtended by 1 µm of arc at ``radius_mm`` (206.2648 / R)."""
    return float(np.degrees(1e-3 / radius_mm) * 3600.0)
