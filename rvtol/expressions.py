"""Safe arithmetic expressions of named quantities: parsed once, evaluated vectorised, differentiated exactly.

The one expression language of rvtol: the mappings of composed studies
(:mod:`rvtol.models.composite`) and the outputs of formula models (:mod:`rvtol.models.formula`)
are written in it.  The grammar is Python's expression syntax restricted to

* numbers (``12``, ``0.5``, ``1e-3``; finite), the constant ``pi``;
* names — a plain identifier (``e``), a dotted path (``carrier.crank_bore_1.position.x1``), an
  indexed name (``E_c[1,2]``, ``housing.pin_groove[3].radial_residual``), written as they are; any
  other name in braces (``{pin-set A}``, ``{pi}`` for a factor named like the constant);
* ``+ - * / **``, unary ``-``/``+``, parentheses (``^`` is refused: in Python it is not a power);
* calls of :data:`FUNCTIONS` (``sqrt``, ``hypot``, ``atan2``, ``min``, ``mean``, ...; angles in
  radians, ``log`` natural).

Nothing else parses — calls of other names or of expressions, attribute access of an expression,
subscripts other than a name's integer/word index, lambdas, comprehensions, keywords, comparisons,
``and``/``or``, conditionals, strings, ``:=``, names or name parts starting with ``__`` — and each
refusal says what is allowed.  The text is read with :func:`ast.parse` and every node is checked
against this whitelist, never evaluated by Python; length (:data:`MAX_LENGTH` characters) and
nesting (:data:`MAX_DEPTH` levels) are capped.  Given the names an expression may use
(``Expression.parse(text, names)``), an unknown name is an error at parse time.

A name stands for the array ``env[name]``: ``Expression.evaluate(env)`` evaluates elementwise with
NumPy broadcasting (row-deterministic; a row where the expression is undefined, ``sqrt`` of a
negative or ``log 0``, gives NaN/inf, never an exception).  ``Expression.gradient(env)`` gives the
exact partial derivative with respect to every name: forward-mode differentiation of the same tree
(each node carries its value and its partial derivatives), not finite differences.  At
non-differentiable points the derivative is an element of the subdifferential, never NaN from 0/0:
``abs`` → sign(x) (0 at 0); ``min``/``max`` → the derivative of the first argument that attains the
extremum; a norm at the origin — ``hypot(x, y)``, ``sqrt(x**2 + y**2)``, ``(x**2 + y**2)**0.5`` at
x = y = 0, where every direction increases it (a cone) — → 0, the subgradient of least norm (the
centre of the unit disc of subgradients): ``sqrt``/``**`` of an argument that is 0 *and stationary*
contributes 0, not ∞·0.  A root of an argument that is 0 and *moving* (``sqrt(x)`` at x = 0) keeps its
infinite one-sided slope, and ``atan2`` at the origin (no direction) stays NaN: undefined.  A
derivative at a kink says nothing about the other side; analyses that linearise (the stack-up
conventions) therefore detect kinks by one-sided differences of the model itself
(:mod:`rvtol.stacking.slopes`) instead of trusting any single derivative there.
"""
from __future__ import annotations

import ast
import math
import re
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from .errors import InputError

#: name -> (fewest arguments, most arguments or None for any number, description)
FUNCTIONS = {
    "sqrt": (1, 1, "square root"), "exp": (1, 1, "exponential"), "log": (1, 1, "natural logarithm"),
    "sin": (1, 1, "sine (rad)"), "cos": (1, 1, "cosine (rad)"), "tan": (1, 1, "tangent (rad)"),
    "asin": (1, 1, "arc sine"), "acos": (1, 1, "arc cosine"), "atan": (1, 1, "arc tangent"),
    "atan2": (2, 2, "atan2(y, x): angle of the vector (x, y)"),
    "hypot": (2, None, "hypot(x, y, …) = √(x² + y² + …)"),
    "abs": (1, 1, "absolute value"), "min": (2, None, "smallest argument"), "max": (2, None, "largest argument"),
    "sum": (1, None, "sum of the arguments"), "mean": (1, None, "mean of the arguments"),
}
CONSTANTS = {"pi": math.pi}
MAX_LENGTH = 4000
MAX_DEPTH = 200

ALLOWED = ("numbers, names (dotted a.b, indexed a[1,2], any other name in braces {…}), pi, + - * / ** "
           "(unary -), parentheses and the functions " + ", ".join(FUNCTIONS))

_BINOPS = {ast.Add: "add", ast.Sub: "sub", ast.Mult: "mul", ast.Div: "div", ast.Pow: "pow"}
_REFUSED = {
    ast.Lambda: "lambda", ast.ListComp: "comprehensions", ast.SetComp: "comprehensions",
    ast.DictComp: "comprehensions", ast.GeneratorExp: "comprehensions", ast.Compare: "comparisons",
    ast.BoolOp: "and/or", ast.IfExp: "conditional expressions (a if c else b)", ast.NamedExpr: "assignment (:=)",
    ast.JoinedStr: "strings", ast.FormattedValue: "strings", ast.List: "lists", ast.Tuple: "tuples",
    ast.Dict: "dicts", ast.Set: "sets", ast.Starred: "unpacking (*)", ast.Await: "await", ast.Yield: "yield",
    ast.YieldFrom: "yield", ast.Slice: "slices",
}


class ExpressionError(InputError):
    """An expression that cannot be read: names the expression and says what is allowed."""


@dataclass(frozen=True)
class Expression:
    """A parsed expression (see the module docstring): its text, tree and names (in order of appearance)."""

    text: str
    tree: tuple
    names: tuple[str, ...]

    @classmethod
    def parse(cls, text, names=None, *, what: str = "expression") -> "Expression":
        """Read ``text`` (or a number) with the whitelist; ``names``: the names it may use (None: any)."""
        if isinstance(text, (int, float)) and not isinstance(text, bool):
            if not math.isfinite(float(text)):
                raise ExpressionError(f"{what}: the number {text!r} is not finite")
            return cls(str(text), ("num", float(text)), ())
        if not isinstance(text, str):
            raise ExpressionError(f"{what}: expected an expression (text or a number), got {text!r}")
        if not text.strip():
            raise ExpressionError(f"{what} is empty: expected an expression (text or a number)")
        if len(text) > MAX_LENGTH:
            raise ExpressionError(f"{what} is longer than {MAX_LENGTH} characters")
        known = None if names is None else set(names)
        # {braced names} -> placeholders no name in the text can collide with
        prefix = "_q"
        while prefix in text:
            prefix += "_"
        quoted: dict[str, str] = {}

        def hold(m):
            key = f"{prefix}{len(quoted)}"
            quoted[key] = m.group(1).strip()
            return f" {key} "

        src = _BRACED.sub(hold, text.strip())
        if "`" in src:
            raise ExpressionError(f"{what}: write a name that is not an identifier in braces, e.g. {{pin gap}}, "
                                  f"not in backticks ({text!r})")
        try:
            node = ast.parse(src.strip(), mode="eval").body
        except SyntaxError as exc:
            col = f" at column {exc.offset}" if exc.offset else ""
            raise ExpressionError(f"{what}: cannot read {text!r}: {exc.msg}{col} (allowed: {ALLOWED})") from None
        except (RecursionError, MemoryError, ValueError):
            raise ExpressionError(f"{what}: {text[:40]!r}… is nested too deeply or too long") from None
        found: list[str] = []
        tree = _Reader(text, what, quoted, known, found).convert(node, 0)
        return cls(text, tree, tuple(dict.fromkeys(found)))

    # -- evaluation --------------------------------------------------------------------------
    def evaluate(self, env: Mapping[str, np.ndarray]):
        """The value, with every name taken from ``env`` (arrays broadcast)."""
        with np.errstate(all="ignore"):
            return _value(self.tree, env)

    def gradient(self, env: Mapping[str, np.ndarray], seeds: Mapping[str, dict] | None = None):
        """``(value, {name: ∂value/∂name})``, exact (forward-mode differentiation of the tree).

        ``seeds`` chain the rule through intermediate names: ``seeds[m]`` is ``{x: ∂m/∂x}`` of a
        name ``m`` that is itself a function of other variables; the result is then by those
        variables (names without a seed are independent variables, ∂x/∂x = 1).
        """
        with np.errstate(all="ignore"):
            v, d = _dual(self.tree, env, seeds or {})
        if seeds:
            return v, d
        return v, {n: d.get(n, 0.0 * np.asarray(v, dtype=float)) for n in self.names}

    @property
    def is_name(self) -> bool:
        """True for an expression that is just one name (an identity mapping)."""
        return self.tree[0] == "var"

    def __str__(self) -> str:
        return self.text


def parse(text, names=None, *, what: str = "expression") -> Expression:
    return Expression.parse(text, names, what=what)


# --------------------------------------------------------------------------- AST -> tree
_BRACED = re.compile(r"\{([^{}]+)\}")


class _Reader:
    def __init__(self, text: str, what: str, quoted: dict, known: set | None, found: list):
        self.text, self.what, self.quoted, self.known, self.found = text, what, quoted, known, found

    def fail(self, reason: str) -> ExpressionError:
        return ExpressionError(f"{self.what}: {reason}")

    def refuse(self, kind: str) -> ExpressionError:
        return self.fail(f"{kind} is not allowed in {self.text!r} (allowed: {ALLOWED})")

    def name_of(self, node) -> str:
        """Flatten a dotted/indexed name (Name, Attribute, Subscript with integer or word indices)."""
        if isinstance(node, ast.Name):
            return node.id
        if isinstance(node, ast.Attribute):
            return f"{self.name_of(node.value)}.{node.attr}"
        if isinstance(node, ast.Subscript):
            sl = node.slice
            items = sl.elts if isinstance(sl, ast.Tuple) else [sl]
            idx = []
            for it in items:
                if isinstance(it, ast.Constant) and isinstance(it.value, int) and not isinstance(it.value, bool):
                    idx.append(str(it.value))
                elif isinstance(it, ast.Name):
                    idx.append(it.id)
                else:
                    raise self.fail(f"an index of a name must be an integer or a word (e.g. E_c[1,2]) in "
                                    f"{self.text!r}")
            return f"{self.name_of(node.value)}[{','.join(idx)}]"
        if isinstance(node, ast.Call):
            raise self.refuse("attribute access or indexing of a call")
        raise self.refuse("attribute access or indexing of an expression")

    def var(self, name: str) -> tuple:
        if self.known is not None and name not in self.known:
            hint = " (it is a function: call it, e.g. sqrt(x))" if name in FUNCTIONS else ""
            raise self.fail(f"unknown name {name!r}{hint} (known: {', '.join(sorted(self.known)) or 'none'})")
        self.found.append(name)
        return ("var", name)

    def convert(self, node, depth: int) -> tuple:
        if depth > MAX_DEPTH:
            raise self.fail(f"nested deeper than {MAX_DEPTH} levels")
        rec = lambda n: self.convert(n, depth + 1)  # noqa: E731
        if isinstance(node, ast.Constant):
            v = node.value
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise self.fail(f"only numbers are allowed as constants, not the {type(v).__name__} {v!r} "
                                f"(allowed: {ALLOWED})")
            try:
                x = float(v)
            except OverflowError:
                x = math.inf
            if not math.isfinite(x):
                raise self.fail(f"the number {str(v)[:20]}… is not finite" if len(str(v)) > 20
                                else f"the number {v!r} is not finite")
            return ("num", x)
        if isinstance(node, ast.Name) and node.id in self.quoted:
            return self.var(self.quoted[node.id])
        if isinstance(node, (ast.Name, ast.Attribute, ast.Subscript)):
            name = self.name_of(node)
            if name in CONSTANTS:
                if self.known is not None and name in self.known:
                    raise self.fail(f"{name!r} is both a name and a constant: write {{{name}}} for the name")
                return ("num", CONSTANTS[name])
            if any(part.startswith("__") for part in re.split(r"[.\[\],]", name)):
                raise self.fail("names (or parts of names) starting with '__' are not allowed")
            return self.var(name)
        if isinstance(node, ast.UnaryOp):
            if isinstance(node.op, (ast.USub, ast.UAdd)):
                inner = rec(node.operand)
                if isinstance(node.op, ast.UAdd):
                    return inner
                return ("num", -inner[1]) if inner[0] == "num" else ("neg", inner)
            raise self.refuse(f"the operator {type(node.op).__name__}")
        if isinstance(node, ast.BinOp):
            op = _BINOPS.get(type(node.op))
            if op is None:
                if isinstance(node.op, ast.BitXor):
                    raise self.fail(f"'^' is not a power here; write a**b in {self.text!r}")
                raise self.refuse(f"the operator {type(node.op).__name__}")
            return (op, rec(node.left), rec(node.right))
        if isinstance(node, ast.Call):
            if not isinstance(node.func, ast.Name) or node.func.id in self.quoted:
                raise self.fail(f"calling an expression is not allowed in {self.text!r}; the functions are "
                                f"{', '.join(FUNCTIONS)}")
            fn = node.func.id
            if fn not in FUNCTIONS:
                raise self.fail(f"calling {fn} is not allowed in {self.text!r}; the functions are "
                                f"{', '.join(FUNCTIONS)}")
            if node.keywords:
                raise self.fail(f"{fn}() takes no keyword arguments")
            if any(isinstance(a, ast.Starred) for a in node.args):
                raise self.fail(f"unpacking (*) is not allowed ({fn}(...))")
            lo, hi, _ = FUNCTIONS[fn]
            n = len(node.args)
            if n < lo or (hi is not None and n > hi):
                want = f"{lo}" if lo == hi else f"at least {lo}"
                raise self.fail(f"{fn}() takes {want} argument{'s' if (hi or 2) > 1 else ''}, got {n}")
            return ("call", fn, tuple(rec(a) for a in node.args))
        raise self.refuse(_REFUSED.get(type(node), type(node).__name__))


# --------------------------------------------------------------------------- values
_UNARY = {"sqrt": np.sqrt, "exp": np.exp, "log": np.log, "sin": np.sin, "cos": np.cos, "tan": np.tan,
          "asin": np.arcsin, "acos": np.arccos, "atan": np.arctan, "abs": np.abs}
_BINARY = {"add": np.add, "sub": np.subtract, "mul": np.multiply, "div": np.true_divide}


def _value(t, env):
    op = t[0]
    if op == "num":
        return t[1]
    if op == "var":
        try:
            return env[t[1]]
        except KeyError:
            raise ExpressionError(f"unknown name {t[1]!r} in an expression") from None
    if op == "neg":
        return -_value(t[1], env)
    if op in _BINARY:
        return _BINARY[op](_value(t[1], env), _value(t[2], env))
    if op == "pow":
        return np.power(np.asarray(_value(t[1], env), dtype=float), _value(t[2], env))
    fn, args = t[1], [_value(a, env) for a in t[2]]
    if fn in _UNARY:
        return _UNARY[fn](args[0])
    if fn == "atan2":
        return np.arctan2(args[0], args[1])
    if fn == "hypot":
        return _reduce(np.hypot, args)
    if fn == "min":
        return _reduce(np.minimum, args)
    if fn == "max":
        return _reduce(np.maximum, args)
    if fn == "sum":
        return _reduce(np.add, args)
    return _reduce(np.add, args) / len(args)  # mean


def _reduce(f, args):
    out = args[0]
    for a in args[1:]:
        out = f(out, a)
    return out


# --------------------------------------------------------------------------- derivatives
def _combine(*terms):
    """Sum of (coefficient, {name: d}) pairs into one derivative dict."""
    out: dict = {}
    for c, d in terms:
        for n, v in d.items():
            out[n] = out[n] + c * v if n in out else c * v
    return out


def _dual(t, env, seeds):
    """``(value, {name: derivative})`` of a tree node."""
    op = t[0]
    if op == "num":
        return t[1], {}
    if op == "var":
        v = _value(t, env)
        if t[1] in seeds:
            return v, seeds[t[1]]
        return v, {t[1]: np.ones_like(np.asarray(v, dtype=float))}
    if op == "neg":
        v, d = _dual(t[1], env, seeds)
        return -v, _combine((-1.0, d))
    if op in ("add", "sub", "mul", "div", "pow"):
        (a, da), (b, db) = _dual(t[1], env, seeds), _dual(t[2], env, seeds)
        if op == "add":
            return a + b, _combine((1.0, da), (1.0, db))
        if op == "sub":
            return a - b, _combine((1.0, da), (-1.0, db))
        if op == "mul":
            return a * b, _combine((b, da), (a, db))
        if op == "div":
            q = np.true_divide(a, b)
            return q, _combine((np.true_divide(1.0, b), da), (-q / b, db))
        a = np.asarray(a, dtype=float)
        v = np.power(a, b)
        terms = [(1.0, _root_chain(b * np.power(a, b - 1.0), da, a))] if da else []
        if db:
            terms.append((v * np.log(a), db))
        return v, _combine(*terms)
    fn = t[1]
    duals = [_dual(a, env, seeds) for a in t[2]]
    (a, da) = duals[0]
    if fn == "sqrt":
        v = np.sqrt(a)
        return v, _root_chain(0.5 / v, da, a)
    if fn == "exp":
        v = np.exp(a)
        return v, _combine((v, da))
    if fn == "log":
        return np.log(a), _combine((1.0 / a, da))
    if fn == "sin":
        return np.sin(a), _combine((np.cos(a), da))
    if fn == "cos":
        return np.cos(a), _combine((-np.sin(a), da))
    if fn == "tan":
        v = np.tan(a)
        return v, _combine((1.0 + v * v, da))
    if fn == "asin":
        return np.arcsin(a), _combine((1.0 / np.sqrt(1.0 - a * a), da))
    if fn == "acos":
        return np.arccos(a), _combine((-1.0 / np.sqrt(1.0 - a * a), da))
    if fn == "atan":
        return np.arctan(a), _combine((1.0 / (1.0 + a * a), da))
    if fn == "abs":
        return np.abs(a), _combine((np.sign(a), da))
    if fn == "atan2":      # atan2(y = a, x = b)
        (b, db) = duals[1]
        r2 = a * a + b * b
        return np.arctan2(a, b), _combine((b / r2, da), (-a / r2, db))
    if fn == "hypot":
        v, d = duals[0]
        for w, dw in duals[1:]:
            h = np.hypot(v, w)
            d = _combine((_over_norm(v, h), d), (_over_norm(w, h), dw))
            v = h
        return v, d
    if fn in ("sum", "mean"):
        w = 1.0 if fn == "sum" else 1.0 / len(duals)
        return w * _reduce(np.add, [v for v, _ in duals]), _combine(*[(w, d) for _, d in duals])
    # min / max: the derivative of the first argument attaining the extremum, element by element
    vals = np.broadcast_arrays(*[np.asarray(v, dtype=float) for v, _ in duals])
    k = (np.argmin if fn == "min" else np.argmax)(np.stack(vals), axis=0)
    value = np.choose(k, vals) if np.ndim(k) else vals[int(k)]
    return value, _combine(*[(np.where(k == i, 1.0, 0.0), d) for i, (_, d) in enumerate(duals)])


def _over_norm(v, h):
    """v / h of a norm's derivative, 0 where the norm is 0 (the least-norm subgradient at the origin)."""
    v, h = np.asarray(v, dtype=float), np.asarray(h, dtype=float)
    return np.divide(v, h, out=np.zeros(np.broadcast(v, h).shape), where=h != 0)



def _root_chain(c, d: dict, a) -> dict:
    """``c·∂a`` of a root's argument ``a`` (``c`` its outer derivative, infinite where ``a`` = 0), with 0 — not
    ∞·0 = NaN — where ``a`` is 0 *and stationary* (a sum of squares at its zero: a norm's cone, whose least-norm
    subgradient is 0).  Where ``a`` is 0 and moving (√x at x = 0) the infinite slope stays."""
    zero = np.asarray(a, dtype=float) == 0
    out = {}
    for n, v in d.items():
        cv = c * v
        out[n] = np.where(zero & (np.asarray(v) == 0), 0.0, cv) if np.any(zero) else cv
    return out
