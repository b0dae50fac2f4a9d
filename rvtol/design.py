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

**What is known of a number** (issue 39: the estimated design carries its own uncertainty).  Optional keys:

* ``status`` — one of :data:`STATUSES`: ``"document"`` (taken from a document or catalogue, the
  ``source``), ``"computed"`` (from other numbers of the design), ``"choice"`` (a design choice made by a
  rule the ``note`` states: no uncertainty of its own) or ``"estimate"`` (an engineering estimate);
* ``range = [lo, hi]`` — the plausible range of the number, **in its own unit**, with ``basis`` (required
  with a range) saying why: what a maker of this size would draw, the catalogue sizes, the physics that
  bounds it.  An ``"estimate"`` needs both.  The loader checks lo < hi and lo ≤ value ≤ hi;
* ``step`` — the number takes the values lo + k·step only (counts, standard sizes: ISO 3096 needle
  diameters in 0.5 mm); the value must be one of them (a computed number is rounded to a multiple of its
  step, e.g. a count of rollers);
* ``follows = "expression"`` — a ``"computed"`` number that follows other numbers of the design (an
  expression of their keys, :mod:`rvtol.expressions`, in base units: mm, rad, N), rounded to ``step``
  when one is given; e.g. the disc's crank hole = the eccentric + two needle diameters.  The loader
  checks that the written value is the expression's, and :meth:`Design.with_values` recomputes it when a
  number it follows changes, so a variant of the design stays consistent.

The numbers with a range and no ``follows`` are the design's uncertain inputs (:meth:`Design.uncertain`):
the epistemic band of a prediction samples them (:mod:`rvtol.epistemic`).
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

from . import units
from .errors import InputError, SpecError
from .expressions import Expression
from .params import Params, check_number, read_toml

#: what is known of a design number (the ``status`` key; module docstring)
STATUSES = {
    "document": "taken from a document or catalogue (its source)",
    "computed": "computed from other numbers of the design",
    "choice": "a design choice made by a rule the note states",
    "estimate": "an engineering estimate: a plausible range and its basis",
}
#: relative tolerance of the check that a computed number is its expression's value
FOLLOWS_RTOL = 1e-9


@dataclass(frozen=True)
class DesignParam:
    name: str
    value: Any  # as written: float, tuple of floats, or str
    unit: str
    source: str
    note: str = ""
    status: str = ""                              # :data:`STATUSES` ("" = not stated)
    range: tuple[float, float] | None = None      # plausible range, in ``unit``
    basis: str = ""                               # why that range
    step: float | None = None                     # the values lo + k·step only (in ``unit``)
    follows: Expression | None = None             # a computed number: its expression (base units)

    @property
    def base_range(self) -> tuple[float, float] | None:
        """The range in base units."""
        if self.range is None:
            return None
        return (float(units.to_base(self.range[0], self.unit)), float(units.to_base(self.range[1], self.unit)))

    @property
    def uncertain(self) -> bool:
        """A number with a plausible range that does not follow others: an input of the epistemic band."""
        return self.range is not None and self.follows is None

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
        """A copy with some parameters replaced (values in base units); the computed numbers that follow a
        replaced one (``follows``) are recomputed, unless given themselves."""
        new = dict(self.params)
        for k, v in base_values.items():
            p = self.param(k)
            written = (tuple(float(x) for x in units.from_base(np.asarray(v, float), p.unit))
                       if np.ndim(v) else float(units.from_base(v, p.unit)))
            new[k] = replace(p, value=written, note=(p.note + " (overridden)").strip())
        changed = set(base_values)
        for name in _follow_order(new):
            p = new[name]
            if name in base_values or not (set(p.follows.names) & changed):
                continue
            value = _followed_value(p, new)
            new[name] = replace(p, value=float(units.from_base(value, p.unit)))
            changed.add(name)
        return replace(self, params=MappingProxyType(new))

    def uncertain(self) -> tuple[DesignParam, ...]:
        """The numbers with a plausible range that follow no other (module docstring), in file order."""
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
    _check_follows(params, file)
    return Design(name, MappingProxyType(params), desc, file)


def _follow_order(params: Mapping[str, DesignParam]) -> list[str]:
    """The computed numbers (``follows``) in an order where each comes after those it follows."""
    order: list[str] = []
    state: dict[str, int] = {}

    def visit(name: str, chain: tuple) -> None:
        if state.get(name) == 2:
            return
        if state.get(name) == 1:
            raise SpecError(f"'follows' is circular: {' -> '.join(chain + (name,))}", key=f"{name}.follows")
        state[name] = 1
        for m in params[name].follows.names:
            if params[m].follows is not None:
                visit(m, chain + (name,))
        state[name] = 2
        order.append(name)

    for name, p in params.items():
        if p.follows is not None:
            visit(name, ())
    return order


def _followed_value(p: DesignParam, params: Mapping[str, DesignParam]) -> float:
    """The base-unit value of the computed number ``p`` from the numbers it follows (rounded to its step)."""
    env = {m: np.asarray(params[m].base, dtype=float) for m in p.follows.names}
    v = float(np.asarray(p.follows.evaluate(env), dtype=float))
    if p.step is not None:
        st = float(units.to_base(p.step, p.unit))
        lo = float(units.to_base(p.range[0], p.unit)) if p.range is not None else 0.0
        v = lo + st * round((v - lo) / st)
    return v


def _check_follows(params: dict[str, DesignParam], file: str | None) -> None:
    """Every ``follows`` names numbers of the design, is not circular, and gives the value written."""
    for name, p in params.items():
        if p.follows is None:
            continue
        for m in p.follows.names:
            if m not in params:
                raise SpecError(f"'follows' names {m!r}, which is not a number of this design", file=file,
                                key=f"{name}.follows")
            if not isinstance(params[m].base, float):
                raise SpecError(f"'follows' names {m!r}, which is not a single number", file=file,
                                key=f"{name}.follows")
    try:
        order = _follow_order(params)
    except SpecError as exc:
        raise exc.located(file=file) from None
    for name in order:
        p = params[name]
        want = _followed_value(p, params)
        if not np.isclose(p.base, want, rtol=FOLLOWS_RTOL, atol=1e-12):
            raise SpecError(f"the value {p.value:g} {p.unit} is not what it follows: {p.follows.text} = "
                            f"{float(units.from_base(want, p.unit)):.6g} {p.unit}", file=file, key=f"{name}.value")


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
    status = p.str("status", "")
    if status:
        status = p.str("status", choices=STATUSES)
    basis = p.str("basis", "")
    rng = _range(p, value, unit)
    step = None
    if "step" in p:
        step = p.float("step", positive=True)
        if rng is None and "follows" not in p:
            raise p.error("step", "a step needs the range it divides (range = [lo, hi])")
    follows = None
    if "follows" in p:
        try:
            follows = Expression.parse(p.raw("follows"), what="follows")
        except InputError as exc:
            raise p.error("follows", exc.reason) from None
        if status != "computed":
            raise p.error("status", "a number that follows others is computed: status = \"computed\"")
    if rng is not None and not basis.strip():
        raise p.error("basis", "a range needs its basis: why the number may lie there")
    if status == "estimate" and rng is None:
        raise p.error("range", "an estimate needs its plausible range (range = [lo, hi], in the value's unit) "
                               "and its basis")
    if step is not None and rng is not None:
        points = [rng[1]] if follows is not None else [value, rng[1]]
        if not all(_on_grid(x, rng[0], step) for x in points):
            raise p.error("step", f"the value {value:g} and the range's high end must be lo + k·step (lo {rng[0]:g}, "
                                  f"step {step:g})")
    p.finish()
    return DesignParam(name, value, unit, source, note, status, rng, basis, step, follows)


def _on_grid(x: float, lo: float, step: float) -> bool:
    k = (x - lo) / step
    return abs(k - round(k)) <= 1e-9 * max(1.0, abs(k))


def _range(p: Params, value, unit: str) -> tuple[float, float] | None:
    """``range = [lo, hi]`` in the value's unit, checked: lo < hi, lo ≤ value ≤ hi, a single number."""
    if "range" not in p:
        return None
    lo, hi = p.floats("range", length=2)
    if isinstance(value, (str, tuple)):
        raise p.error("range", "a range is given for a single number only")
    if not lo < hi:
        raise p.error("range", f"expected [low, high] with low < high, got [{lo:g}, {hi:g}]")
    if not lo <= value <= hi:
        raise p.error("range", f"the value {value:g} {unit} lies outside its range [{lo:g}, {hi:g}] {unit}")
    return (lo, hi)
