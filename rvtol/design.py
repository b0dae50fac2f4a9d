"""Design: the nominal geometry and stiffness of one reducer, every number with its source.

File format (``data/designs/*.toml``): a ``[design]`` head and parameter
tables, grouped as the author likes; any table with a ``value`` key is a
parameter::

    [design]
    name = "RV-80E (transmission-error document)"
    description = "..."

    [sun]
    teeth = { value = 16, unit = "1", source = "doc 000, Table 1" }
    module = { value = 1.75, unit = "mm", source = "doc 000, Table 1" }

The parameter is addressed as ``"sun.teeth"``; ``design["sun.module"]``
returns it in base units (mm).  ``source`` is required; ``note`` says how a
number was estimated when the source does not give it directly.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

from . import units
from .errors import InputError, SpecError
from .params import Params, check_number, read_toml


@dataclass(frozen=True)
class DesignParam:
    name: str
    value: Any  # as written: float, tuple of floats, or str
    unit: str
    source: str
    note: str = ""

    @property
    def base(self):
        if isinstance(self.value, str):
            return self.value
        if isinstance(self.value, tuple):
            return units.to_base(np.array(self.value, dtype=float), self.unit)
        return float(units.to_base(self.value, self.unit))


@dataclass(frozen=True)
class Design:
    name: str
    params: Mapping[str, DesignParam]
    description: str = ""
    file: str | None = None
    sha256: str | None = field(default=None, compare=False)

    def __contains__(self, name: str) -> bool:
        return name in self.params

    def __getitem__(self, name: str):
        """Value in base units (mm, N, rad, ...)."""
        return self.param(name).base

    def param(self, name: str) -> DesignParam:
        try:
            return self.params[name]
        except KeyError:
            raise SpecError(f"design has no parameter {name!r}", file=self.file, key=name) from None

    def get(self, name: str, default=None):
        return self[name] if name in self.params else default

    def value(self, name: str, unit: str):
        """Value converted to ``unit``."""
        return units.from_base(self[name], unit)

    def with_values(self, **base_values) -> "Design":
        """A copy with some parameters replaced (values in base units)."""
        new = dict(self.params)
        for k, v in base_values.items():
            p = self.param(k)
            written = (tuple(float(x) for x in units.from_base(np.asarray(v, float), p.unit))
                       if np.ndim(v) else float(units.from_base(v, p.unit)))
            new[k] = replace(p, value=written, note=(p.note + " (overridden)").strip())
        return replace(self, params=MappingProxyType(new))

    def to_frame(self):
        import pandas as pd

        return pd.DataFrame({
            "parameter": list(self.params),
            "value": [p.value if not isinstance(p.value, tuple) else ", ".join(f"{x:g}" for x in p.value)
                      for p in self.params.values()],
            "unit": [p.unit for p in self.params.values()],
            "source": [p.source for p in self.params.values()],
            "note": [p.note for p in self.params.values()],
        })


#: the prefix that names a design number in an expression (``design.pin.count``)
DESIGN_PREFIX = "design."


def design_numbers(names, design: "Design | None") -> dict[str, float]:
    """The ``design.<key>`` names among ``names`` that ``design`` holds, with their values (base units), in
    the order first named; a parameter that is not a single number is an error naming it."""
    out = {}
    for n in dict.fromkeys(names):
        key = n[len(DESIGN_PREFIX):]
        if not n.startswith(DESIGN_PREFIX) or design is None or key not in design:
            continue
        value = design[key]
        if not isinstance(value, float):
            raise InputError(f"design parameter {key!r} is not a single number", key=n)
        out[n] = value
    return out


def load_design(path: str | Path) -> Design:
    data, sha = read_toml(path)
    d = design_from_table(data, file=str(path))
    return replace(d, sha256=sha)


def design_from_table(data: dict, *, file: str | None = None) -> Design:
    root = Params(data, file=file)
    head = root.sub("design")
    name = head.str("name")
    desc = head.str("description", "")
    head.raw("source", None)
    head.finish()
    params: dict[str, DesignParam] = {}
    _collect(root, "", params, skip={"design"})
    if not params:
        raise root.error(None, "a design needs at least one parameter table with a 'value'")
    return Design(name, MappingProxyType(params), desc, file)


def _collect(p: Params, prefix: str, out: dict, skip=()) -> None:
    for key in list(p.keys()):
        if key in skip:
            continue
        v = p.raw(key)
        name = f"{prefix}{key}"
        if not isinstance(v, dict):
            raise p.error(key, "expected a parameter table {value, unit, source} or a group of them")
        sub = Params(v, file=p.file, key=p.path(key))
        if "value" in v:
            out[name] = _param(sub, name)
        else:
            _collect(sub, f"{name}.", out)


def _param(p: Params, name: str) -> DesignParam:
    raw = p.raw("value")
    unit = p.unit("unit", "1")
    source = p.str("source")
    if not source.strip():
        raise p.error("source", "every design number needs its source")
    note = p.str("note", "")
    if isinstance(raw, str):
        value: Any = raw
    elif isinstance(raw, list):
        value = tuple(check_number(x, p.error, f"value[{i}]") for i, x in enumerate(raw))
    else:
        value = check_number(raw, p.error, "value")
    p.finish()
    return DesignParam(name, value, unit, source, note)
