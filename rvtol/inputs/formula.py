"""Model outputs as formulas of the factors — parsed safely, evaluated vectorised, differentiated exactly.

The language (Python's expression syntax, read with :mod:`ast` under a strict whitelist and
never passed to ``eval``/``compile``):

* numbers (``12``, ``0.5``, ``1e-3``), factor names and earlier definitions, ``pi``;
  a name that is not a Python identifier (``E_c[1,2]``, ``pin gap``) is written in backticks:
  ```E_c[1,2]```;
* ``+ - * / **``, unary ``-``/``+``, parentheses (``^`` is refused: in Python it is not a power);
* functions ``sqrt sin cos tan asin acos atan atan2(y, x) exp log abs hypot(a, b, …)
  min(a, b, …) max(a, b, …)`` (angles in radians, ``log`` natural).

Anything else — attribute access, indexing, calls of other names, keywords, lambdas,
comprehensions, comparisons, ``and``/``or``, conditionals, strings, ``:=`` — is refused with a
message saying what is allowed.  Length (4000 characters) and nesting (200 levels) are capped.

Evaluation is elementwise NumPy over the rows of ``X`` (row-deterministic); a row where a
formula is undefined (``sqrt`` of a negative, ``log 0``) gives NaN/inf and the engine counts it
as a failed sample (``Model.evaluate_with_status``).  Derivatives are exact: forward-mode
automatic differentiation over the expression tree (each node carries its value and its
partial derivatives), not finite differences.  At non-differentiable points the derivative
is a one-sided choice: ``abs`` → sign(x) (0 at 0), ``min``/``max`` → the derivative of the
first argument that attains the extremum.

:class:`FormulaModel` is a :class:`rvtol.model.Model` whose outputs are named formulas::

    model = FormulaModel.from_spec(spec, {"clearance": ("carrier_gap - disc1_width - disc2_width", "mm", "um")})

Inside the formulas each factor is in its own unit (``units="factor"``, the unit written in
the spec) or in rvtol's base units (``units="base"``); each output declares the unit its
formula yields.  ``evaluate`` and :meth:`FormulaModel.gradient` work in base units like every
Model.  A study names it as::

    [model]
    kind = "formula"
    units = "factor"                 # or "base"
    [model.define]                   # optional intermediate quantities, in order
    tilt = "atan2(e1 - e2, L)"
    [[model.output]]
    name = "gap"
    formula = "carrier_gap - disc1_width - disc2_width"
    unit = "mm"
    display_unit = "um"
"""
from __future__ import annotations

import ast
import math
import re
from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np

from .. import units as _units
from ..errors import InputError
from ..model import Model, Quantity

#: function name -> (min args, max args or None)
FUNCTIONS: dict[str, tuple[int, int | None]] = {
    "sqrt": (1, 1), "sin": (1, 1), "cos": (1, 1), "tan": (1, 1), "asin": (1, 1), "acos": (1, 1),
    "atan": (1, 1), "atan2": (2, 2), "exp": (1, 1), "log": (1, 1), "abs": (1, 1),
    "hypot": (2, None), "min": (2, None), "max": (2, None),
}
CONSTANTS: dict[str, float] = {"pi": math.pi}
MAX_LENGTH = 4000
MAX_DEPTH = 200

ALLOWED = ("numbers, factor names (`quoted` if not identifiers), pi, + - * / ** (unary -), parentheses and "
           "the functions " + ", ".join(FUNCTIONS))


class FormulaError(InputError):
    """A formula that cannot be read (names the formula and says what is allowed)."""


# --------------------------------------------------------------------------- the tree
@dataclass(frozen=True)
class Num:
    value: float


@dataclass(frozen=True)
class Var:
    name: str


@dataclass(frozen=True)
class Neg:
    arg: object


@dataclass(frozen=True)
class Bin:
    op: str
    a: object
    b: object


@dataclass(frozen=True)
class Call:
    fn: str
    args: tuple


_BINOPS = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/", ast.Pow: "**"}
_REFUSED = {
    ast.Attribute: "attribute access (a.b)", ast.Subscript: "indexing (a[i]); write a name with brackets in "
    "backticks, e.g. `E_c[1,2]`", ast.Lambda: "lambda", ast.ListComp: "comprehensions",
    ast.SetComp: "comprehensions", ast.DictComp: "comprehensions", ast.GeneratorExp: "comprehensions",
    ast.Compare: "comparisons", ast.BoolOp: "and/or", ast.IfExp: "conditional expressions (a if c else b)",
    ast.NamedExpr: "assignment (:=)", ast.JoinedStr: "strings", ast.FormattedValue: "strings",
    ast.List: "lists", ast.Tuple: "tuples", ast.Dict: "dicts", ast.Set: "sets", ast.Starred: "unpacking (*)",
    ast.Await: "await", ast.Yield: "yield", ast.YieldFrom: "yield", ast.Slice: "slices",
}


class Formula:
    """A parsed formula: ``text``, the tree, and the names it uses (in order of appearance)."""

    def __init__(self, text: str, tree, names: tuple[str, ...]):
        self.text, self.tree, self.names = text, tree, names

    def __repr__(self) -> str:
        return f"Formula({self.text!r})"

    def evaluate(self, env: Mapping[str, np.ndarray]):
        with np.errstate(all="ignore"):
            return _value(self.tree, env)

    def evaluate_with_gradient(self, env: Mapping[str, np.ndarray], seeds: Mapping[str, dict] | None = None):
        """``(value, {name: ∂value/∂name})``; ``seeds`` give the derivatives of the names themselves
        (default: each name is an independent variable, ∂x/∂x = 1)."""
        with np.errstate(all="ignore"):
            return _dual(self.tree, env, seeds)


def parse(text: str, names, *, what: str = "formula") -> Formula:
    """Read ``text`` with the whitelist above; ``names`` are the variables it may use."""
    if not isinstance(text, str):
        raise FormulaError(f"{what} must be text, got {type(text).__name__}")
    if not text.strip():
        raise FormulaError(f"{what} is empty")
    if len(text) > MAX_LENGTH:
        raise FormulaError(f"{what} is longer than {MAX_LENGTH} characters")
    known = set(names)
    # `quoted names` → placeholders that no user identifier can collide with
    prefix = "_q"
    while prefix in text:
        prefix += "_"
    quoted: dict[str, str] = {}

    def sub(m):
        name = m.group(1)
        if name not in known:
            raise FormulaError(f"{what}: unknown name `{name}` (known: {', '.join(sorted(known)) or 'none'})")
        key = f"{prefix}{len(quoted)}"
        quoted[key] = name
        return f" {key} "

    src = re.sub(r"`([^`]*)`", sub, text)
    if "`" in src:
        raise FormulaError(f"{what}: unmatched backtick in {text!r}")
    try:
        tree = ast.parse(src.strip(), mode="eval")
    except SyntaxError as exc:
        col = f" at column {exc.offset}" if exc.offset else ""
        raise FormulaError(f"{what}: cannot read {text!r}: {exc.msg}{col} (allowed: {ALLOWED})") from None
    except (RecursionError, MemoryError, ValueError):
        raise FormulaError(f"{what}: {text[:40]!r}… is nested too deeply or too long") from None
    used: list[str] = []
    node = _convert(tree.body, known, quoted, used, what, text, 0)
    return Formula(text, node, tuple(used))


def _refuse(node, what: str, text: str) -> FormulaError:
    kind = _REFUSED.get(type(node))
    if kind is None:
        kind = type(node).__name__
    return FormulaError(f"{what}: {kind} is not allowed in {text!r} (allowed: {ALLOWED})")


def _convert(node, known, quoted, used, what, text, depth):
    if depth > MAX_DEPTH:
        raise FormulaError(f"{what}: nested deeper than {MAX_DEPTH} levels")
    rec = lambda n: _convert(n, known, quoted, used, what, text, depth + 1)  # noqa: E731
    if isinstance(node, ast.Constant):
        v = node.value
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise FormulaError(f"{what}: {type(v).__name__} constants are not allowed in {text!r} "
                               f"(allowed: {ALLOWED})")
        try:
            x = float(v)
        except OverflowError:
            x = math.inf
        if not math.isfinite(x):
            raise FormulaError(f"{what}: the number {v!r} is not finite")
        return Num(x)
    if isinstance(node, ast.Name):
        n = node.id
        if n in quoted:
            n = quoted[n]
        elif n in CONSTANTS:
            if n in known:
                raise FormulaError(f"{what}: {n!r} is both a factor and a constant: write `{n}` for the factor")
            return Num(CONSTANTS[n])
        elif n not in known:
            hint = " (it is a function: call it, e.g. sqrt(x))" if n in FUNCTIONS else ""
            raise FormulaError(f"{what}: unknown name {n!r}{hint} (known: {', '.join(sorted(known)) or 'none'})")
        if n not in used:
            used.append(n)
        return Var(n)
    if isinstance(node, ast.UnaryOp):
        if isinstance(node.op, ast.USub):
            a = rec(node.operand)
            return Num(-a.value) if isinstance(a, Num) else Neg(a)
        if isinstance(node.op, ast.UAdd):
            return rec(node.operand)
        raise FormulaError(f"{what}: the operator {type(node.op).__name__} is not allowed in {text!r} "
                           f"(allowed: {ALLOWED})")
    if isinstance(node, ast.BinOp):
        op = _BINOPS.get(type(node.op))
        if op is None:
            if isinstance(node.op, ast.BitXor):
                raise FormulaError(f"{what}: '^' is not a power here; write a**b in {text!r}")
            raise FormulaError(f"{what}: the operator {type(node.op).__name__} is not allowed in {text!r} "
                               f"(allowed: {ALLOWED})")
        return Bin(op, rec(node.left), rec(node.right))
    if isinstance(node, ast.Call):
        if not isinstance(node.func, ast.Name) or node.func.id not in FUNCTIONS or node.func.id in quoted:
            fn = node.func.id if isinstance(node.func, ast.Name) else "an expression"
            raise FormulaError(f"{what}: calling {fn} is not allowed in {text!r}; the functions are "
                               f"{', '.join(FUNCTIONS)}")
        fn = node.func.id
        if node.keywords:
            raise FormulaError(f"{what}: keyword arguments are not allowed ({fn}(...))")
        if any(isinstance(a, ast.Starred) for a in node.args):
            raise FormulaError(f"{what}: unpacking (*) is not allowed ({fn}(...))")
        lo, hi = FUNCTIONS[fn]
        n = len(node.args)
        if n < lo or (hi is not None and n > hi):
            want = f"{lo}" if lo == hi else f"at least {lo}"
            raise FormulaError(f"{what}: {fn} takes {want} argument{'s' if (hi or 2) > 1 else ''}, got {n}")
        return Call(fn, tuple(rec(a) for a in node.args))
    raise _refuse(node, what, text)


# --------------------------------------------------------------------------- values
_F1 = {"sqrt": np.sqrt, "sin": np.sin, "cos": np.cos, "tan": np.tan, "asin": np.arcsin, "acos": np.arccos,
       "atan": np.arctan, "exp": np.exp, "log": np.log, "abs": np.abs}


def _value(node, env):
    if isinstance(node, Num):
        return node.value
    if isinstance(node, Var):
        return env[node.name]
    if isinstance(node, Neg):
        return -_value(node.arg, env)
    if isinstance(node, Bin):
        a, b = _value(node.a, env), _value(node.b, env)
        if node.op == "+":
            return a + b
        if node.op == "-":
            return a - b
        if node.op == "*":
            return a * b
        if node.op == "/":
            return np.true_divide(a, b)
        return np.power(np.asarray(a, dtype=float), b)
    args = [_value(a, env) for a in node.args]
    if node.fn in _F1:
        return _F1[node.fn](args[0])
    if node.fn == "atan2":
        return np.arctan2(args[0], args[1])
    if node.fn == "hypot":
        out = args[0]
        for a in args[1:]:
            out = np.hypot(out, a)
        return out
    red = np.minimum if node.fn == "min" else np.maximum
    out = args[0]
    for a in args[1:]:
        out = red(out, a)
    return out


# --------------------------------------------------------------------------- forward-mode derivatives
def _add(da: dict, db: dict, sb: float = 1.0) -> dict:
    out = dict(da)
    for k, v in db.items():
        out[k] = out[k] + sb * v if k in out else sb * v
    return out


def _scale(d: dict, f) -> dict:
    return {k: v * f for k, v in d.items()}


def _dual(node, env, seeds):
    if isinstance(node, Num):
        return node.value, {}
    if isinstance(node, Var):
        v = env[node.name]
        if seeds is not None and node.name in seeds:
            return v, seeds[node.name]
        return v, {node.name: 1.0}
    if isinstance(node, Neg):
        v, d = _dual(node.arg, env, seeds)
        return -v, _scale(d, -1.0)
    if isinstance(node, Bin):
        a, da = _dual(node.a, env, seeds)
        b, db = _dual(node.b, env, seeds)
        if node.op == "+":
            return a + b, _add(da, db)
        if node.op == "-":
            return a - b, _add(da, db, -1.0)
        if node.op == "*":
            return a * b, _add(_scale(da, b), _scale(db, a))
        if node.op == "/":
            q = np.true_divide(a, b)
            return q, _add(_scale(da, np.true_divide(1.0, b)), _scale(db, -q / b))
        a = np.asarray(a, dtype=float)
        v = np.power(a, b)
        out = {}
        if da:
            out = _scale(da, (b * np.power(a, b - 1.0)) if not (np.isscalar(b) and b == 0) else 0.0)
        if db:
            out = _add(out, _scale(db, v * np.log(a)))
        return v, out
    vals = [_dual(a, env, seeds) for a in node.args]
    fn = node.fn
    if fn in _F1:
        x, d = vals[0]
        v = _F1[fn](x)
        if fn == "sqrt":
            g = 0.5 / v
        elif fn == "sin":
            g = np.cos(x)
        elif fn == "cos":
            g = -np.sin(x)
        elif fn == "tan":
            g = 1.0 + v * v
        elif fn == "asin":
            g = 1.0 / np.sqrt(1.0 - x * x)
        elif fn == "acos":
            g = -1.0 / np.sqrt(1.0 - x * x)
        elif fn == "atan":
            g = 1.0 / (1.0 + x * x)
        elif fn == "exp":
            g = v
        elif fn == "log":
            g = 1.0 / x
        else:  # abs
            g = np.sign(x)
        return v, _scale(d, g)
    if fn == "atan2":
        (y, dy), (x, dx) = vals
        r2 = x * x + y * y
        return np.arctan2(y, x), _add(_scale(dy, x / r2), _scale(dx, -y / r2))
    if fn == "hypot":
        v, d = vals[0]
        for w, dw in vals[1:]:
            h = np.hypot(v, w)
            d = _add(_scale(d, v / h), _scale(dw, w / h))
            v = h
        return v, d
    # min / max: the derivative of the first argument attaining the extremum
    xs = np.broadcast_arrays(*[np.asarray(x, dtype=float) for x, _ in vals])
    stack = np.stack(xs)
    pick = np.argmin(stack, axis=0) if fn == "min" else np.argmax(stack, axis=0)
    v = np.take_along_axis(stack, pick[None], axis=0)[0]
    keys = {k for _, d in vals for k in d}
    out = {}
    for k in keys:
        ds = np.stack(np.broadcast_arrays(*[np.asarray(d.get(k, 0.0), dtype=float) for _, d in vals], stack[0]))[:-1]
        out[k] = np.take_along_axis(ds, pick[None], axis=0)[0]
    return (v if v.ndim else float(v)), out


# --------------------------------------------------------------------------- the model
@dataclass(frozen=True)
class FormulaOutput:
    """A named output: its formula, the unit the formula yields, the unit to report in."""

    name: str
    formula: str
    unit: str = "1"
    display_unit: str | None = None
    description: str = ""


def _outputs(outputs) -> list[FormulaOutput]:
    if isinstance(outputs, Mapping):
        items = []
        for name, v in outputs.items():
            if isinstance(v, str):
                items.append(FormulaOutput(name, v))
            elif isinstance(v, (tuple, list)) and 1 <= len(v) <= 3:
                items.append(FormulaOutput(name, *v))
            else:
                raise FormulaError(f"output {name!r}: expected a formula or (formula, unit[, display unit])")
        return items
    out = []
    for v in outputs:
        if isinstance(v, FormulaOutput):
            out.append(v)
        elif isinstance(v, (tuple, list)) and 2 <= len(v) <= 4:
            out.append(FormulaOutput(*v))
        else:
            raise FormulaError(f"expected FormulaOutput or (name, formula[, unit[, display unit]]), got {v!r}")
    return out


class FormulaModel(Model):
    """A Model whose outputs are formulas of its inputs (see the module docstring).

    ``inputs``: factor names (the columns of ``X``); ``input_units``: the unit each input has
    *inside the formulas* (default ``"1"``; the model's :attr:`input_units` are their base
    units, as for every Model); ``definitions``: ordered ``{name: formula}`` intermediate
    quantities, each usable by later ones and by the outputs.
    """

    def __init__(self, outputs, inputs: Sequence[str], input_units: Sequence[str] | None = None, *,
                 definitions: Mapping[str, str] | None = None):
        self.inputs = tuple(inputs)
        if len(set(self.inputs)) != len(self.inputs):
            raise FormulaError("an input name is given twice")
        fu = tuple(input_units) if input_units is not None else ("1",) * len(self.inputs)
        if len(fu) != len(self.inputs):
            raise FormulaError(f"{len(self.inputs)} inputs but {len(fu)} input units")
        try:
            self.formula_units = tuple(_units.canonical(u) for u in fu)
            self.input_units = tuple(_units.base_unit(u) for u in self.formula_units)
        except InputError as exc:
            raise FormulaError(exc.reason) from None
        self._in_factor = np.array([_units.factor(u) for u in self.formula_units])
        known = list(self.inputs)
        self.definitions: list[tuple[str, Formula]] = []
        for name, text in (definitions or {}).items():
            if not isinstance(name, str) or not name:
                raise FormulaError(f"definition name must be text, got {name!r}")
            if name in known or name in CONSTANTS:
                raise FormulaError(f"definition {name!r} has the name of an input, another definition or a "
                                   "constant")
            self.definitions.append((name, parse(text, known, what=f"definition {name!r}")))
            known.append(name)
        specs = _outputs(outputs)
        if not specs:
            raise FormulaError("a formula model needs at least one output")
        names = [o.name for o in specs]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise FormulaError(f"duplicate output name {dup[0]!r}")
        self.formulas: list[Formula] = []
        outs, self._out_factor = [], []
        for o in specs:
            try:
                u = _units.canonical(o.unit)
                disp = _units.require_dimension(o.display_unit, _units.dimension(u)) if o.display_unit else u
            except InputError as exc:
                raise FormulaError(f"output {o.name!r}: {exc.reason}") from None
            self.formulas.append(parse(o.formula, known, what=f"output {o.name!r}"))
            outs.append(Quantity(o.name, _units.base_unit(u), disp, o.description))
            self._out_factor.append(_units.factor(u))
        self.outputs = tuple(outs)
        self._out_factor = np.array(self._out_factor)
        self.output_specs = tuple(specs)

    # -- construction from a spec or a study --------------------------------------------
    @classmethod
    def from_spec(cls, spec, outputs, *, definitions: Mapping[str, str] | None = None,
                  units: str = "factor") -> "FormulaModel":
        """Inputs are the spec's factors, in the formulas in their own unit (``units="factor"``)
        or in base units (``"base"``)."""
        if units not in ("factor", "base"):
            raise FormulaError(f"units must be 'factor' or 'base', got {units!r}")
        fu = spec.units if units == "factor" else tuple(f.base_unit for f in spec.factors)
        return cls(outputs, spec.names, fu, definitions=definitions)

    # -- evaluation -------------------------------------------------------------------
    def _env(self, X: np.ndarray) -> dict:
        Xf = X / self._in_factor   # base → the units written in the formulas
        return {n: Xf[:, j] for j, n in enumerate(self.inputs)}

    def evaluate(self, X):
        X = self.check_input(X)
        env = self._env(X)
        n = X.shape[0]
        with np.errstate(all="ignore"):
            for name, f in self.definitions:
                env[name] = np.broadcast_to(np.asarray(f.evaluate(env), dtype=float), (n,))
            Y = np.empty((n, len(self.formulas)))
            for i, f in enumerate(self.formulas):
                Y[:, i] = f.evaluate(env)
        return Y * self._out_factor

    def gradient(self, X) -> np.ndarray:
        """Exact ∂Y/∂X, shape ``(n, outputs, inputs)``, in base units (forward-mode AD)."""
        return self.evaluate_with_gradient(X)[1]

    def evaluate_with_gradient(self, X) -> tuple[np.ndarray, np.ndarray]:
        X = self.check_input(X)
        n, k = X.shape
        env = self._env(X)
        seeds: dict[str, dict] = {}
        with np.errstate(all="ignore"):
            for name, f in self.definitions:
                v, d = f.evaluate_with_gradient(env, seeds)
                env[name] = np.broadcast_to(np.asarray(v, dtype=float), (n,))
                seeds[name] = d
            Y = np.empty((n, len(self.formulas)))
            G = np.zeros((n, len(self.formulas), k))
            col = {nm: j for j, nm in enumerate(self.inputs)}
            for i, f in enumerate(self.formulas):
                v, d = f.evaluate_with_gradient(env, seeds)
                Y[:, i] = v
                for nm, g in d.items():
                    G[:, i, col[nm]] = g
        Y *= self._out_factor
        G *= self._out_factor[None, :, None] / self._in_factor[None, None, :]
        return Y, G


def from_study(params, design, spec) -> FormulaModel:
    """The study factory (``[model] kind = "formula"``); errors name the file and key."""
    u = params.str("units", "factor", choices=("factor", "base"))
    defs_p = params.sub("define", {})
    definitions = {}
    for name in list(defs_p.keys()):
        definitions[name] = defs_p.str(name)
    outs = params.tables("output")
    if not outs:
        raise params.error("output", "a formula model needs at least one [[model.output]]")
    specs = []
    for t in outs:
        name = t.str("name")
        formula = t.str("formula")
        unit = t.unit("unit", "1")
        disp = t.unit("display_unit", unit, dimension=_units.dimension(unit))
        desc = t.str("description", "")
        t.finish()
        specs.append((t, FormulaOutput(name, formula, unit, disp, desc)))
    params.finish()
    fu = spec.units if u == "factor" else tuple(f.base_unit for f in spec.factors)
    for name, text in definitions.items():   # locate errors before building
        try:
            parse(text, list(spec.names) + [n for n in definitions if n != name], what=f"definition {name!r}")
        except FormulaError as exc:
            raise defs_p.error(name, exc.reason) from None
    for t, o in specs:
        try:
            parse(o.formula, list(spec.names) + list(definitions), what=f"output {o.name!r}")
        except FormulaError as exc:
            raise t.error("formula", exc.reason) from None
    try:
        return FormulaModel([o for _, o in specs], spec.names, fu, definitions=definitions)
    except FormulaError as exc:
        raise params.error(None, exc.reason) from None


__all__ = ["FUNCTIONS", "CONSTANTS", "Formula", "FormulaError", "FormulaModel", "FormulaOutput", "parse",
           "from_study"]
