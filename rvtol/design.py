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
number was estimated when the source does not give it directly.  The keys of the head and of a number are
declared (:class:`DesignHead`, :class:`DesignEntry`) and listed by ``rvtol kinds design`` and
``rvtol kinds design_parameter``.

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

**What is known of a number** (issue 39: the estimated design carries its own uncertainty).  Optional keys:

* ``status`` — one of :data:`STATUSES`: ``"document"`` (taken from a document or catalogue, the
  ``source``), ``"computed"`` (from other numbers of the design: a ``formula``, whose status it is by
  default), ``"choice"`` (a design choice made by a rule the ``note`` states: no uncertainty of its own) or
  ``"estimate"`` (an engineering estimate);
* ``range = [lo, hi]`` — the plausible range of the number, **in its own unit**, with ``basis`` (required
  with a range) saying why: what a maker of this size would draw, the catalogue sizes, the physics that
  bounds it.  An ``"estimate"`` needs both.  The loader checks lo < hi and lo ≤ value ≤ hi;
* ``step`` — the number takes the values lo + k·step only (counts, standard sizes: ISO 3096 needle
  diameters in 0.5 mm); a written value must be one of them, a formula's value is rounded to the nearest
  (lo = 0 without a range: a count of rollers from their pitch circle).

A formula's number follows the numbers it names wherever they change: in a variant and in
:meth:`Design.with_values`, so a design drawn from the ranges stays consistent (the disc's crank hole = the
eccentric + two needle diameters).  The numbers with a range and no formula are the design's uncertain inputs
(:meth:`Design.uncertain`): the epistemic band of a prediction samples them (:mod:`rvtol.epistemic`).
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
from .model_kind import Where
from .options import REQUIRED, option, read_options
from .params import Params, read_toml

#: what is known of a design number (the ``status`` key; module docstring)
STATUSES = {
    "document": "taken from a document or catalogue (its source)",
    "computed": "computed from other numbers of the design (a formula)",
    "choice": "a design choice made by a rule the note states",
    "estimate": "an engineering estimate: a plausible range and its basis",
}


@dataclass(frozen=True)
class DesignParam:
    name: str
    value: Any  # as written: float, tuple of floats, or str (a formula's: its value in ``unit``)
    unit: str
    source: str
    note: str = ""
    formula: str = ""                                   # a derived number: the expression it is computed by
    file: str | None = field(default=None, compare=False)   # the file the number (or formula) is written in
    status: str = ""                                    # :data:`STATUSES` ("" = not stated)
    range: tuple[float, float] | None = None            # plausible range, in ``unit``
    basis: str = ""                                     # why that range
    step: float | None = None                           # the values lo + k·step only (in ``unit``)

    @property
    def base_range(self) -> tuple[float, float] | None:
        """The range in base units."""
        if self.range is None:
            return None
        return (float(units.to_base(self.range[0], self.unit)), float(units.to_base(self.range[1], self.unit)))

    @property
    def uncertain(self) -> bool:
        """A number with a plausible range that is not a formula of others: an input of the epistemic band."""
        return self.range is not None and not self.formula

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
        """A copy with some parameters replaced (values in base units); every formula is evaluated again, so the
        numbers that follow a replaced one follow it (a replaced formula's number keeps the value given)."""
        new = dict(self.params)
        for k, v in base_values.items():
            p = self.param(k)
            written = (tuple(float(x) for x in units.from_base(np.asarray(v, float), p.unit))
                       if np.ndim(v) else float(units.from_base(v, p.unit)))
            new[k] = replace(p, value=written, note=(p.note + " (overridden)").strip(), formula="")
        return replace(self, params=MappingProxyType(_evaluated(new)))

    def uncertain(self) -> tuple[DesignParam, ...]:
        """The numbers with a plausible range that are no formula (module docstring), in file order."""
        return tuple(p for p in self.params.values() if p.uncertain)

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
            "status": [p.status for p in self.params.values()],
            "range": [("" if p.range is None else f"{p.range[0]:g} … {p.range[1]:g}") for p in self.params.values()],
            "basis": [p.basis for p in self.params.values()],
        })

    def ranges_frame(self):
        """The uncertain numbers: key, value, range, step, unit, basis (the report's table of estimates)."""
        import pandas as pd

        rows = [{"parameter": p.name, "value": p.value, "low": p.range[0], "high": p.range[1],
                 "step": p.step if p.step is not None else np.nan, "unit": p.unit, "status": p.status,
                 "basis": p.basis} for p in self.uncertain()]
        return pd.DataFrame(rows, columns=["parameter", "value", "low", "high", "step", "unit", "status", "basis"])


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


@dataclass
class DesignHead:
    """``[design]``: the head of a design file: its name, what it is, where its numbers come from, and the design a
    variant changes (the format: the docstring of rvtol.design)."""

    name: str = option(REQUIRED, "the design's name (the report's title of it)")
    description: str = option("", "what the design is")
    source: str = option("", "where its numbers come from, in general (each number names its own source)")
    extends: Path | None = option(None, "a variant: the design file it changes, relative to this file (that file "
                                        "extends nothing itself)")


@dataclass
class DesignEntry:
    """``[group] key = { value, unit, source, ... }``: one number of a design (``group.key``), written as a value or
    as a formula of other design numbers, with what is known of it (the docstring of rvtol.design)."""

    value: float | list[float] | str | None = option(None, "the number in unit (or a list of numbers, or a text); "
                                                           "either it or formula")
    formula: str | None = option(None, "a derived number: an expression of other design numbers (dotted keys), "
                                       "evaluated in base units")
    unit: str = option("1", "the unit the value (and range, step) is written in")
    source: str = option(REQUIRED, "where the number comes from (a document, a catalogue, the rule it follows)")
    note: str = option("", "how the number was estimated when the source does not give it directly")
    status: str | None = option(None, "what is known of the number (default: computed for a formula, else unstated)",
                                choices=tuple(STATUSES))
    basis: str = option("", "why the number may lie in its range (required with a range)")
    range: list[float] | None = option(None, "[low, high]: the plausible range, in unit (a single number only)")
    step: float | None = option(None, "the number takes the values low + k·step only (needs a range; a formula's "
                                      "value is rounded to the nearest k·step)", positive=True)

    def complete(self, study, error):
        """The checks across keys (module docstring): a value or a formula, a known unit, a source, and what is
        known of the number consistent with it."""
        formula = self.formula is not None
        if formula and self.value is not None:
            raise error("formula", "give a number either as a value or as a formula, not both")
        if not formula and self.value is None:
            raise error("value", "missing required key (or a formula)")
        try:
            self.unit = units.canonical(self.unit)
        except InputError as exc:
            raise error("unit", exc.reason) from None
        if not self.source.strip():
            raise error("source", "every design number needs its source")
        if isinstance(self.value, list):
            self.value = tuple(self.value)
        if formula and self.status not in (None, "computed"):
            raise error("status", "a number given by a formula is computed: status = \"computed\" (or leave it out)")
        if formula and self.range is not None:
            raise error("range", "a formula's number follows the numbers it names: give their ranges instead")
        if self.range is not None:
            self._check_range(error)
        elif self.step is not None and not formula:
            raise error("step", "a step needs the range it divides (range = [lo, hi])")
        if self.range is not None and not self.basis.strip():
            raise error("basis", "a range needs its basis: why the number may lie there")
        if self.status == "estimate" and self.range is None:
            raise error("range", "an estimate needs its plausible range (range = [lo, hi], in the value's unit) "
                                 "and its basis")
        if self.step is not None and self.range is not None and not all(
                _on_grid(x, self.range[0], self.step) for x in (self.value, self.range[1])):
            raise error("step", f"the value {self.value:g} and the range's high end must be lo + k·step (lo "
                                f"{self.range[0]:g}, step {self.step:g})")
        self.status = self.status or ("computed" if formula else "")

    def _check_range(self, error) -> None:
        """``range = [lo, hi]`` in the value's unit: two numbers, lo < hi, lo ≤ value ≤ hi, a single number."""
        if len(self.range) != 2:
            raise error("range", f"expected 2 numbers, got {len(self.range)}")
        lo, hi = self.range = tuple(self.range)
        if isinstance(self.value, (str, tuple)):
            raise error("range", "a range is given for a single number only")
        if not lo < hi:
            raise error("range", f"expected [low, high] with low < high, got [{lo:g}, {hi:g}]")
        if not lo <= self.value <= hi:
            raise error("range", f"the value {self.value:g} {self.unit} lies outside its range [{lo:g}, {hi:g}] "
                                 f"{self.unit}")


def load_design(path: str | Path) -> Design:
    """A design file, or a variant of one (``[design] extends``: module docstring)."""
    data, sha = read_toml(path)
    head = data.get("design")
    if isinstance(head, dict) and "extends" in head:
        return _variant(data, Path(path), sha)
    d = design_from_table(data, file=str(path))
    return replace(d, sha256=sha)


def design_from_table(data: dict, *, file: str | None = None) -> Design:
    """The design of a table as a design file holds it (a variant is read from its file: :func:`load_design`)."""
    root = Params(data, file=file)
    head, params = _head(root, Path(file).parent if file else Path("."))
    if head.extends is not None:
        raise params.error("extends", "a variant is read from its file (rvtol.design.load_design), its base "
                                      "relative to it")
    return _design(root, head)


def _head(root: Params, folder: Path) -> tuple[DesignHead, Params]:
    """The ``[design]`` head (:class:`DesignHead`) and its table; ``extends`` relative to ``folder``."""
    params = root.sub("design")
    head = read_options(DesignHead, params, Where(folder))
    params.finish()
    if head.extends is not None:
        head.extends = Path(os.path.normpath(head.extends))
    return head, params


def _design(root: Params, head: DesignHead) -> Design:
    params: dict[str, DesignParam] = {}
    _collect(root, "", params, skip={"design"})
    if not params:
        raise root.error(None, "a design needs at least one parameter table with a 'value'")
    return Design(head.name, MappingProxyType(_evaluated(params)), head.description, root.file)


def _variant(data: dict, path: Path, sha: str) -> Design:
    """A variant: its base design with the variant's numbers over the base's (module docstring)."""
    file = str(path)
    root = Params(data, file=file)
    head, hp = _head(root, path.parent)
    bpath = head.extends
    if bpath.resolve() == path.resolve():
        raise hp.error("extends", "a design cannot extend itself")
    if not bpath.is_file():
        raise hp.error("extends", f"base design {str(bpath)!r} not found")
    bdata, bsha = read_toml(bpath)
    if isinstance(bdata.get("design"), dict) and "extends" in bdata["design"]:
        raise hp.error("extends", f"{bpath.name} extends another design itself (one level only: give the "
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
    return Design(head.name, MappingProxyType(_evaluated(params)), head.description, file, sha, (str(bpath), bsha))


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
    """One number (:class:`DesignEntry`); a formula is parsed here, evaluated by :func:`_evaluated`."""
    from .expressions import Expression

    e = read_options(DesignEntry, p)
    p.finish()
    rng = tuple(e.range) if e.range is not None else None
    if e.formula is None:
        return DesignParam(name, e.value, e.unit, e.source, e.note, file=p.file, status=e.status, range=rng,
                           basis=e.basis, step=e.step)
    try:
        Expression.parse(e.formula, what=f"formula of {name}")
    except InputError as exc:
        raise p.error("formula", exc.reason) from None
    return DesignParam(name, float("nan"), e.unit, e.source, e.note, formula=e.formula.strip(), file=p.file,
                       status=e.status, basis=e.basis, step=e.step)


def _on_grid(x: float, lo: float, step: float) -> bool:
    k = (x - lo) / step
    return abs(k - round(k)) <= 1e-9 * max(1.0, abs(k))


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
        if p.step is not None:                    # a count or a standard size: the nearest lo + k·step (lo = 0)
            st = float(units.to_base(p.step, p.unit))
            v = st * round(v / st)
        env[k] = v
        out[k] = replace(p, value=float(units.from_base(v, p.unit)))
        state[k] = 2

    for k in formulas:
        evaluate(k, ())
    return out
