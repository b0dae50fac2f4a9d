"""Dimensional analysis of formulas at load time (pint), compiled into plain float arithmetic.

A formula model's factors carry their units into its formulas (``[model] units = "checked"``, the
default).  Before anything runs, every formula is walked once with :mod:`pint` quantities standing
for the units of its parts — never for its values:

* ``+ - min max hypot atan2 sum mean`` need operands of one dimension; the second and later
  operands are converted to the first one's unit (``a_um + b_mm`` adds micrometres), and a length
  added to an angle (or to a bare number) is an error naming the formula;
* ``sin cos tan`` take an angle (or a ratio) and get it **in radians**, whatever unit the factor was
  given in (a factor in degrees is multiplied by π/180 inside the call); ``asin acos atan atan2``
  give radians; ``exp log`` and a variable exponent need a ratio;
* ``* / **`` combine units (pint's algebra); ``sqrt`` halves them;
* a bare number has no unit: beside an angle it is read in radians (SI: rad = 1, ``pi/2 - alpha``),
  beside any other dimension it is an error (give the constant as a factor, or as a definition with
  a ``unit``);
* an output's declared ``unit`` must have the dimension its formula yields; the value is converted.

The result is the same tree with a multiplication by a constant wherever a conversion is needed —
so evaluation (and exact differentiation) stays plain NumPy on floats in the hot loop, and a
formula whose units already agree is evaluated exactly as written (bit for bit).

Angles follow the SI convention (rad = 1), as pint does: an angle is a ratio, so a torque (N·mm)
and a torsional stiffness (N·mm/rad) share a dimension and cannot be told apart here.
"""
from __future__ import annotations

import math
from functools import lru_cache

from ... import units as _units
from ...errors import InputError
from ...expressions import ExpressionError, _value

#: rvtol's base unit of each dimension, written in the registry's base units
_BASE = {"dimensionless": "", "length": "mm", "angle": "rad", "force": "N", "torque": "N*mm",
         "stiffness": "N/mm", "torsional_stiffness": "N*mm/rad", "pressure": "N/mm**2", "time": "s",
         "angular_speed": "rad/s", "mass": "t", "inertia": "t*mm**2", "density": "t/mm**3",
         "damping": "N*s/mm", "angle_per_length": "rad/mm", "cost": "cost"}

_ARTICLE = {"angle": "an angle", "angular_speed": "an angular speed", "inertia": "an inertia",
            "angle_per_length": "an angle per length"}


@lru_cache(maxsize=1)
def registry():
    """A pint registry of rvtol's base units only (mm, rad = 1, s, tonne, N = t·mm/s², K, cost)."""
    import pint

    reg = pint.UnitRegistry(None)
    for line in ("millimetre = [length] = mm", "radian = [] = rad", "second = [time] = s",
                 "tonne = [mass] = t", "kelvin = [temperature] = K", "cost_unit = [cost] = cost",
                 "newton = tonne * millimetre / second ** 2 = N"):
        reg.define(line)
    return reg


def quantity(unit: str):
    """One ``unit`` as a pint quantity in base units (``um`` → 0.001 mm, ``deg`` → π/180 rad, ``cm^2`` → 100 mm²: a
    dimension outside the table is named by its base unit, :mod:`rvtol.units`)."""
    reg = registry()
    u = _units.canonical(unit)
    dim = _units.dimension(u)
    base = _BASE.get(dim, dim)
    return reg.Quantity(_units.factor(u), base) if base else reg.Quantity(_units.factor(u))


def _is_angle(q) -> bool:
    return "radian" in str(q.units)


def describe(q) -> str:
    """``a length (µm)``, ``an angle (°)``, ``a number`` — a unit for an error message."""
    for u in _units.known_units():
        ref = quantity(u)
        if (ref.dimensionality == q.dimensionality and _is_angle(ref) == _is_angle(q)
                and math.isclose(_ratio(q, ref), 1.0, rel_tol=1e-12)):
            dim = _units.dimension(u)
            if dim == "dimensionless":
                return "a number" if u == "1" else f"a ratio ({_units.label(u)})"
            return f"{_ARTICLE.get(dim, 'a ' + dim.replace('_', ' '))} ({_units.label(u)})"
    return f"a quantity in {q.magnitude:g} {q.units:~}".replace(" 1 ", " ")


def _ratio(a, b) -> float:
    """``a / b`` as a pure number (a and b of one dimension)."""
    return float((a / b).to("dimensionless").magnitude)


def _same(a, b) -> bool:
    return a.dimensionality == b.dimensionality


# --------------------------------------------------------------------------- printing a sub-formula
_SYMBOL = {"add": "+", "sub": "-", "mul": "*", "div": "/", "pow": "**"}


def show(t) -> str:
    """A tree back as text (for messages)."""
    op = t[0]
    if op == "num":
        return f"{t[1]:g}"
    if op == "var":
        name = t[1]
        return name if name.replace(".", "").replace("_", "").isalnum() or "[" in name else f"{{{name}}}"
    if op == "neg":
        return f"-{_wrap(t[1])}"
    if op in _SYMBOL:
        return f"{_wrap(t[1])} {_SYMBOL[op]} {_wrap(t[2])}"
    return f"{t[1]}({', '.join(show(a) for a in t[2])})"


def _wrap(t) -> str:
    return f"({show(t)})" if t[0] in _SYMBOL or t[0] == "neg" else show(t)


# --------------------------------------------------------------------------- the walk
def _scaled(t, f: float):
    """``t`` times the conversion factor ``f`` (nothing added when f is 1: bit-identical evaluation)."""
    if f == 1.0:
        return t
    if t[0] == "num":
        return ("num", t[1] * f)
    return ("mul", t, ("num", f))


class _Walk:
    def __init__(self, names: dict, what: str, text: str):
        self.names, self.what, self.text = names, what, text
        self.one = registry().Quantity(1.0)
        self.rad = registry().Quantity(1.0, "rad")

    def fail(self, reason: str) -> ExpressionError:
        return ExpressionError(f"{self.what}: {reason} (in {self.text!r}; factors carry their units into the "
                               "formula: rvtol docs writing-a-study, \"Units in formulas\")")

    def to_unit(self, node, want, where: str):
        """``node`` = (tree, q, is_number) converted to the unit ``want`` (of the same dimension)."""
        t, q, _ = node
        if not _same(q, want):
            raise self.fail(f"{where} {describe(want)} and {describe(q)} ({show(t)})")
        return _scaled(t, _ratio(q, want))

    def ratio(self, node, what: str):
        """A node that must be a pure number (a ratio; an angle in radians): the tree in plain numbers."""
        t, q, _ = node
        if q.dimensionality != self.one.dimensionality:
            raise self.fail(f"{what} needs an angle or a ratio, got {describe(q)} ({show(t)})")
        return _scaled(t, _ratio(q, self.one))

    def same_unit(self, nodes, where: str):
        """Operands of one dimension, converted to the unit of the first that is not a bare number; that unit.

        A bare number beside an angle is in radians; beside any other dimension it is an error."""
        ref = next((n for n in nodes if not n[2]), None)
        if ref is None:
            return [n[0] for n in nodes], self.one
        want = ref[1]
        out = []
        for n in nodes:
            if not n[2]:
                out.append(self.to_unit(n, want, where))
            elif _is_angle(want):
                out.append(_scaled(n[0], _ratio(self.rad, want)))
            elif want.dimensionality == self.one.dimensionality:
                out.append(_scaled(n[0], _ratio(self.one, want)))
            else:
                raise self.fail(f"{where} {describe(want)} and a bare number ({show(n[0])}): a number in a "
                                "formula has no unit — give the constant as a factor, or as a [model.define] "
                                "entry with a unit")
        return out, want

    def walk(self, t):
        """``(tree, unit quantity, is a bare number)``."""
        op = t[0]
        reg = registry()
        if op == "num":
            return t, self.one, True
        if op == "var":
            return t, self.names[t[1]], False
        if op == "neg":
            a, q, number = self.walk(t[1])
            return ("neg", a), q, number
        if op in ("add", "sub"):
            nodes = [self.walk(t[1]), self.walk(t[2])]
            (a, b), q = self.same_unit(nodes, "cannot add or subtract")
            return (op, a, b), q, nodes[0][2] and nodes[1][2]
        if op in ("mul", "div"):
            (a, qa, na), (b, qb, nb) = self.walk(t[1]), self.walk(t[2])
            return (op, a, b), (qa * qb if op == "mul" else qa / qb), na and nb
        if op == "pow":
            (a, qa, na), (b, qb, nb) = self.walk(t[1]), self.walk(t[2])
            if nb:   # a constant exponent: the unit to that power
                e = float(_value(b, {}))
                if not math.isfinite(e):
                    raise self.fail(f"the exponent {show(t[2])} is not a finite number")
                return ("pow", a, b), qa ** e, na
            return ("pow", self.ratio((a, qa, na), "a variable exponent's base"),
                    self.ratio((b, qb, nb), "an exponent")), reg.Quantity(1.0), na and nb
        fn, args = t[1], [self.walk(x) for x in t[2]]
        number = all(n[2] for n in args)
        if fn in ("sin", "cos", "tan"):
            return ("call", fn, (self.ratio(args[0], f"{fn}()"),)), self.one, number
        if fn in ("asin", "acos", "atan"):
            return ("call", fn, (self.ratio(args[0], f"{fn}()"),)), self.rad, number
        if fn in ("exp", "log"):
            return ("call", fn, (self.ratio(args[0], f"{fn}()"),)), self.one, number
        if fn == "sqrt":
            return ("call", fn, (args[0][0],)), args[0][1] ** 0.5, number
        if fn == "abs":
            return ("call", fn, (args[0][0],)), args[0][1], number
        conv, q = self.same_unit(args, f"{fn}() cannot combine")
        return ("call", fn, tuple(conv)), (self.rad if fn == "atan2" else q), number


def check_formula(expr, names: dict, what: str):
    """``(compiled tree, unit quantity, is a bare number)`` of a parsed :class:`~rvtol.expressions.Expression`
    whose names have the unit quantities ``names``."""
    return _Walk(names, what, expr.text).walk(expr.tree)


def output_conversion(expr, tree, q, number: bool, unit: str, what: str):
    """The compiled tree of an output declared in ``unit``: its value converted to ``unit``."""
    want = quantity(unit)
    if number:
        return tree     # a constant output: the number is in the declared unit
    w = _Walk({}, what, expr.text)
    if not _same(q, want):
        raise w.fail(f"the formula gives {describe(q)}, the output's unit {unit!r} is {describe(want)}")
    f = _ratio(q, want)
    if f != 1.0 and tree[0] in ("mul", "div") and tree[2][0] == "num":   # x * 1000 declared in µm
        c = tree[2][1] if tree[0] == "mul" else 1.0 / tree[2][1]
        if math.isclose(c, f, rel_tol=1e-9):
            raise w.fail(f"the formula multiplies by {tree[2][1]:g}, the conversion from {describe(q)} to {unit!r} "
                         "that rvtol makes itself: remove it (or write units = \"factor\" to keep the numbers "
                         "as written, unchecked)")
    return _scaled(tree, f)


def definition_conversion(expr, tree, q, number: bool, unit: str | None, what: str):
    """A definition, optionally declared in ``unit``: ``(tree in that unit, its unit quantity)``."""
    if unit is None:
        return tree, q
    want = quantity(unit)
    if number:
        return tree, want   # a constant given its unit: L = {formula = "25", unit = "mm"}
    w = _Walk({}, what, expr.text)
    if not _same(q, want):
        raise w.fail(f"the formula gives {describe(q)}, the definition's unit {unit!r} is {describe(want)}")
    return _scaled(tree, _ratio(q, want)), want


def unchecked_trig(expr, angle_names: dict, what: str) -> None:
    """``units = "factor"``: no unit check, but a trigonometric function of an angle written in another unit
    than radians would compute the sine of degrees — refused."""
    def walk(t):
        if t[0] == "var":
            return angle_names.get(t[1], set())
        if t[0] == "num":
            return set()
        if t[0] == "call":
            found = set().union(*(walk(a) for a in t[2]))
            if t[1] in ("sin", "cos", "tan") and found:
                name, unit = sorted(found)[0]
                raise ExpressionError(
                    f"{what}: {t[1]}() takes radians, and with units = \"factor\" the angle {name!r} enters in "
                    f"{unit} — use units = \"checked\" (the default: angles are converted) or give {name!r} in rad "
                    f"(in {expr.text!r})")
            return found
        return set().union(*(walk(a) for a in t[1:]))
    return walk(expr.tree)


def mixed_units(expr, unit_of: dict, what: str) -> list[str]:
    """``units = "factor"``: the sums and differences of factors written in different units of one dimension (a 1-D
    stack ``gap - w_mm - w_um`` adds 1 µm as if it were 1 mm) — one sentence each, for the run's notes.  Only plain
    sums of factors are looked at (a factor times a number may be converted by hand: ``0.001 * w_um``)."""
    found: list[tuple[str, str, str, str]] = []

    def unit(t):
        """The unit of a plain sum of factors (None: anything else)."""
        if t[0] == "var":
            return unit_of.get(t[1]), t[1]
        if t[0] == "neg":
            return unit(t[1])
        if t[0] in ("add", "sub"):
            (ua, na), (ub, nb) = unit(t[1]), unit(t[2])
            if ua is not None and ub is not None and ua != ub and _units.dimension(ua) == _units.dimension(ub):
                found.append((na, ua, nb, ub))
            return (ua, na) if ua is not None else (ub, nb)
        for a in (t[2] if t[0] == "call" else t[1:]):
            if isinstance(a, tuple):
                unit(a)
        return None, None

    unit(expr.tree)
    return [f"{what}: with units = \"factor\" the formula sums {a!r} ({_units.label(ua)}) and {b!r} "
            f"({_units.label(ub)}) as the numbers written — 1 {_units.label(ub)} counts as 1 {_units.label(ua)}; "
            f"units = \"checked\" (the default) converts them" for a, ua, b, ub in dict.fromkeys(found)]


def check_unit(unit: str) -> str:
    try:
        return _units.canonical(unit)
    except InputError as exc:
        raise ExpressionError(exc.reason) from None
