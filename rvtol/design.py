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

**Derived numbers** are written as a formula of other design numbers instead of a value, so that they follow
the numbers they derive from (in a variant too)::

    [reducer]
    ratio = { formula = "1 + pin.count * planet.teeth / sun.teeth", unit = "1", source = "i = 1 + z_b z_p / z_s" }

The formula is an :mod:`rvtol.expressions` expression of other design numbers (dotted keys), evaluated in
base units (mm, rad, N, t, s; a density in kg/m^3 is t/mm^3) and written in ``unit``; a formula may use
another formula's number, not its own (a cycle is refused, naming it).

**A variant of a design** is a small file that names its base and gives only the numbers it changes::

    [design]
    name = "RV-80E-153"
    extends = "../rv80e/design.toml"     # relative to this file; the base extends nothing itself
    [sun]
    teeth = { value = 10, unit = "1", source = "..." }

Every table of the variant overrides the base's number of the same key (a value, or a formula); a key the
base does not have is refused (a variant changes a design, it does not add to it), with the closest key.  The
base's formulas are evaluated with the variant's numbers, so every derived number is recomputed, never
copied.  Each number remembers the file it was written in (``DesignParam.file``, the ``file`` column of
:meth:`Design.to_frame`, :meth:`Design.where`), and an error about a number names that file
(:meth:`Design.relocate`).
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

from . import units
from .errors import InputError, SpecError, did_you_mean
from .params import Params, check_number, read_toml


@dataclass(frozen=True)
class DesignParam:
    name: str
    value: Any  # as written: float, tuple of floats, or str (a formula's: its value in ``unit``)
    unit: str
    source: str
    note: str = ""
    formula: str = ""                                   # a derived number: the expression it is computed by
    file: str | None = field(default=None, compare=False)   # the file the number (or formula) is written in

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
    #: a variant's base design file and its SHA-256 (None: the design extends nothing)
    base: tuple[str, str] | None = field(default=None, compare=False)

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

    def where(self, name: str) -> str | None:
        """The file the number ``name`` is written in (a variant's number: the variant; else its base)."""
        p = self.params.get(name)
        return (p.file or self.file) if p is not None else self.file

    def relocate(self, exc: InputError) -> InputError:
        """An error a model located in this design (file = the design's, key = one of its numbers) names the
        file that number is written in: the base of a variant for a number the variant does not change."""
        if exc.file == self.file and exc.key in self.params:
            exc.file = self.where(exc.key)
        return exc

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
            new[k] = replace(p, value=written, note=(p.note + " (overridden)").strip(), formula="")
        return replace(self, params=MappingProxyType(_evaluated(new)))

    def to_frame(self):
        import pandas as pd

        return pd.DataFrame({
            "parameter": list(self.params),
            "value": [p.value if not isinstance(p.value, tuple) else ", ".join(f"{x:g}" for x in p.value)
                      for p in self.params.values()],
            "unit": [p.unit for p in self.params.values()],
            "source": [p.source for p in self.params.values()],
            "note": [p.note for p in self.params.values()],
            "formula": [p.formula for p in self.params.values()],
            "file": [_short(p.file) for p in self.params.values()],
        })


def _short(file: str | None) -> str:
    """``rv80e_153/design.toml``: a design file by its folder and name (a variant and its base are often both
    called design.toml)."""
    if not file:
        return ""
    p = Path(file)
    return f"{p.parent.name}/{p.name}" if p.parent.name else p.name


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
    """A design file, or a variant of one (``[design] extends``: module docstring)."""
    data, sha = read_toml(path)
    head = data.get("design")
    if isinstance(head, dict) and "extends" in head:
        return _variant(data, Path(path), sha)
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
    return Design(name, MappingProxyType(_evaluated(params)), desc, file)


def _variant(data: dict, path: Path, sha: str) -> Design:
    """A variant: its base design with the variant's numbers over the base's (module docstring)."""
    file = str(path)
    root = Params(data, file=file)
    head = root.sub("design")
    name = head.str("name")
    desc = head.str("description", "")
    head.raw("source", None)
    bpath = Path(os.path.normpath(head.path_value("extends", path.parent)))
    head.finish()
    if bpath.resolve() == path.resolve():
        raise head.error("extends", "a design cannot extend itself")
    if not bpath.is_file():
        raise head.error("extends", f"base design {str(bpath)!r} not found")
    bdata, bsha = read_toml(bpath)
    if isinstance(bdata.get("design"), dict) and "extends" in bdata["design"]:
        raise head.error("extends", f"{bpath.name} extends another design itself (one level only: give the "
                                    "variant's numbers over the design it changes)")
    base = design_from_table(bdata, file=str(bpath))
    own: dict[str, DesignParam] = {}
    _collect(root, "", own, skip={"design"})
    if not own:
        raise root.error(None, "a variant gives at least one number it changes (a parameter table with a "
                               "'value' or a 'formula')")
    params = dict(base.params)
    for key, p in own.items():
        if key not in params:
            raise SpecError(f"the base design {bpath.name} has no number {key!r}{did_you_mean(key, params)}: a "
                            "variant changes its base's numbers, it does not add to them", file=file, key=key)
        params[key] = p
    return Design(name, MappingProxyType(_evaluated(params)), desc, file, sha, (str(bpath), bsha))


def _collect(p: Params, prefix: str, out: dict, skip=()) -> None:
    for key in list(p.keys()):
        if key in skip:
            continue
        v = p.raw(key)
        name = f"{prefix}{key}"
        if not isinstance(v, dict):
            raise p.error(key, "expected a parameter table {value, unit, source} or a group of them")
        sub = Params(v, file=p.file, key=p.path(key))
        if "value" in v or "formula" in v:
            out[name] = _param(sub, name)
        else:
            _collect(sub, f"{name}.", out)


def _param(p: Params, name: str) -> DesignParam:
    if "formula" in p.data:
        if "value" in p.data:
            raise p.error("formula", "give a number either as a value or as a formula, not both")
        return _formula_param(p, name)
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
    return DesignParam(name, value, unit, source, note, file=p.file)


def _formula_param(p: Params, name: str) -> DesignParam:
    """A derived number ``{ formula, unit, source, note }``: parsed here, evaluated by :func:`_evaluated`."""
    from .expressions import Expression

    text = p.str("formula")
    try:
        Expression.parse(text, what=f"formula of {name}")
    except InputError as exc:
        raise p.error("formula", exc.reason) from None
    unit = p.unit("unit", "1")
    source = p.str("source")
    if not source.strip():
        raise p.error("source", "every design number needs its source")
    note = p.str("note", "")
    p.finish()
    return DesignParam(name, float("nan"), unit, source, note, formula=text.strip(), file=p.file)


def _evaluated(params: dict[str, DesignParam]) -> dict[str, DesignParam]:
    """``params`` with every formula's value computed from the numbers it names (module docstring): in
    dependency order, base units; an unknown name, a text value, a cycle or a non-finite result is an error
    naming the formula's file and key."""
    from .expressions import Expression

    formulas = {k: p for k, p in params.items() if p.formula}
    if not formulas:
        return params
    out = dict(params)
    env: dict[str, float] = {}
    for k, p in params.items():
        if not p.formula and isinstance(p.value, float):
            env[k] = p.base
    state: dict[str, int] = {}         # 1: being evaluated, 2: done

    def error(k: str, reason: str) -> SpecError:
        return SpecError(reason, file=formulas[k].file, key=f"{k}.formula")

    def evaluate(k: str, chain: tuple[str, ...]) -> None:
        if state.get(k) == 2:
            return
        if state.get(k) == 1:
            raise error(k, "the formulas refer to each other in a cycle: " + " -> ".join(chain + (k,)))
        state[k] = 1
        p = formulas[k]
        expr = Expression.parse(p.formula, what=f"formula of {k}")
        for n in expr.names:
            if n in formulas:
                evaluate(n, chain + (k,))
            elif n not in env:
                why = (f"design number {n!r} is not a single number" if n in params else
                       f"unknown design number {n!r}{did_you_mean(n, list(params))}")
                raise error(k, why)
        with np.errstate(all="ignore"):
            v = float(expr.evaluate({n: env[n] for n in expr.names}))
        if not np.isfinite(v):
            raise error(k, f"evaluates to {v} with the design's numbers")
        env[k] = v
        out[k] = replace(p, value=float(units.from_base(v, p.unit)))
        state[k] = 2

    for k in formulas:
        evaluate(k, ())
    return out
