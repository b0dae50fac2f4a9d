"""Safe arithmetic expressions of named quantities: parsed once, evaluated vectorised, differentiated exactly.

The grammar is Python's expression syntax restricted to

* numbers, the constant ``pi``;
* names — a plain identifier (``e``), a dotted path (``carrier.crank_bore_1.position.x1``), an
  indexed name (``E_c[1,2]``, ``housing.pin_groove[3].radial_residual``), written as they are; any
  other name in braces (``{pin-set A}``);
* ``+ - * / **``, unary ``-``/``+``, parentheses;
* calls of :data:`FUNCTIONS` (``sqrt``, ``hypot``, ``atan2``, ``min``, ``mean``, ...).

Nothing else parses (no attribute calls, subscripts of expressions, lambdas, comprehensions,
keywords, comparisons): the text is read with :func:`ast.parse` and every node is checked against
this whitelist, never evaluated by Python.  A name stands for its value in base units (mm, rad, N,
N·mm, ...): ``hypot(cam.x, cam.y)`` of two coordinates in mm is a length in mm.

``Expression.evaluate(env)`` evaluates over arrays (NumPy broadcasting); ``Expression.gradient(env)``
gives the exact partial derivative with respect to every name (forward-mode differentiation of the
same tree), for linearised analyses and for the chain rule through composed models.
"""
from __future__ import annotations

import ast
import math
import re
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from .errors import InputError

#: name -> (number of arguments or None for any ≥ 1, description)
FUNCTIONS = {
    "sqrt": (1, "square root"), "exp": (1, "exponential"), "log": (1, "natural logarithm"),
    "sin": (1, "sine (rad)"), "cos": (1, "cosine (rad)"), "tan": (1, "tangent (rad)"),
    "asin": (1, "arc sine"), "acos": (1, "arc cosine"), "atan": (1, "arc tangent"),
    "atan2": (2, "atan2(y, x): angle of the vector (x, y)"), "hypot": (2, "hypot(x, y) = √(x² + y²)"),
    "abs": (1, "absolute value"), "min": (None, "smallest argument"), "max": (None, "largest argument"),
    "sum": (None, "sum of the arguments"), "mean": (None, "mean of the arguments"),
}
CONSTANTS = {"pi": math.pi}

_BRACED = re.compile(r"\{([^{}]+)\}")
_BINOPS = {ast.Add: "add", ast.Sub: "sub", ast.Mult: "mul", ast.Div: "div", ast.Pow: "pow"}


def _fail(text: str, reason: str) -> InputError:
    return InputError(f"expression {text!r}: {reason}")


@dataclass(frozen=True)
class Expression:
    """A parsed expression (see the module docstring)."""

    text: str
    tree: tuple
    names: tuple[str, ...]

    @classmethod
    def parse(cls, text) -> "Expression":
        if isinstance(text, (int, float)) and not isinstance(text, bool):
            return cls(str(text), ("num", float(text)), ())
        if not isinstance(text, str) or not text.strip():
            raise InputError(f"expected an expression (text or a number), got {text!r}")
        quoted: dict[str, str] = {}

        def hold(m):
            key = f"__q{len(quoted)}__"
            quoted[key] = m.group(1).strip()
            return key

        src = _BRACED.sub(hold, text.strip())
        try:
            node = ast.parse(src, mode="eval").body
        except SyntaxError as exc:
            raise _fail(text, f"not a valid expression ({exc.msg})") from None
        names: list[str] = []
        tree = _convert(node, text, quoted, names)
        return cls(text, tree, tuple(dict.fromkeys(names)))

    # -- evaluation --------------------------------------------------------------------------
    def evaluate(self, env: Mapping[str, np.ndarray]):
        """The value, with every name taken from ``env`` (arrays broadcast)."""
        return _value(self.tree, env)

    def gradient(self, env: Mapping[str, np.ndarray]) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        """``(value, {name: ∂value/∂name})``, exact (forward-mode differentiation of the tree)."""
        v, d = _dual(self.tree, env)
        return v, {n: d.get(n, 0.0 * v) for n in self.names}

    @property
    def is_name(self) -> bool:
        """True for an expression that is just one name (an identity mapping)."""
        return self.tree[0] == "var"

    def __str__(self) -> str:
        return self.text


def parse(text) -> Expression:
    return Expression.parse(text)


# --------------------------------------------------------------------------- AST -> tree
def _name_of(node, text: str) -> str:
    """Flatten a dotted/indexed name (Name, Attribute, Subscript with integer indices)."""
    if isinstance(node, ast.Name):
        return node.id
    if isinstance(node, ast.Attribute):
        return f"{_name_of(node.value, text)}.{node.attr}"
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
                raise _fail(text, "an index of a name must be an integer or a word (e.g. E_c[1,2])")
        return f"{_name_of(node.value, text)}[{','.join(idx)}]"
    raise _fail(text, f"{type(node).__name__} is not allowed in a name")


def _convert(node, text: str, quoted: dict, names: list) -> tuple:
    if isinstance(node, ast.Constant):
        if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
            raise _fail(text, f"only numbers are allowed as constants, not {node.value!r}")
        return ("num", float(node.value))
    if isinstance(node, (ast.Name, ast.Attribute, ast.Subscript)):
        name = _name_of(node, text)
        if name in quoted:
            name = quoted[name]
        elif name in CONSTANTS:
            return ("num", CONSTANTS[name])
        elif any(part.startswith("__") for part in re.split(r"[.\[\],]", name)):
            raise _fail(text, "names (or parts of names) starting with '__' are not allowed")
        names.append(name)
        return ("var", name)
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        inner = _convert(node.operand, text, quoted, names)
        return ("neg", inner) if isinstance(node.op, ast.USub) else inner
    if isinstance(node, ast.BinOp) and type(node.op) in _BINOPS:
        return (_BINOPS[type(node.op)], _convert(node.left, text, quoted, names),
                _convert(node.right, text, quoted, names))
    if isinstance(node, ast.Call):
        if not isinstance(node.func, ast.Name):
            raise _fail(text, "only the functions " + ", ".join(FUNCTIONS) + " may be called")
        fn = node.func.id
        if fn not in FUNCTIONS:
            raise _fail(text, f"unknown function {fn!r} (known: {', '.join(FUNCTIONS)})")
        if node.keywords:
            raise _fail(text, f"{fn}() takes no keyword arguments")
        want = FUNCTIONS[fn][0]
        if (want is None and not node.args) or (want is not None and len(node.args) != want):
            raise _fail(text, f"{fn}() takes {want if want is not None else 'one or more'} argument(s), "
                              f"got {len(node.args)}")
        if any(isinstance(a, ast.Starred) for a in node.args):
            raise _fail(text, "starred arguments are not allowed")
        return ("call", fn, tuple(_convert(a, text, quoted, names) for a in node.args))
    raise _fail(text, f"{type(node).__name__} is not allowed (numbers, names, + - * / **, parentheses and "
                      f"the functions {', '.join(FUNCTIONS)})")


# --------------------------------------------------------------------------- values
_UNARY = {"sqrt": np.sqrt, "exp": np.exp, "log": np.log, "sin": np.sin, "cos": np.cos, "tan": np.tan,
          "asin": np.arcsin, "acos": np.arccos, "atan": np.arctan, "abs": np.abs}


def _value(t, env):
    op = t[0]
    if op == "num":
        return t[1]
    if op == "var":
        try:
            return env[t[1]]
        except KeyError:
            raise InputError(f"unknown name {t[1]!r} in an expression") from None
    if op == "neg":
        return -_value(t[1], env)
    if op in ("add", "sub", "mul", "div", "pow"):
        a, b = _value(t[1], env), _value(t[2], env)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            return {"add": np.add, "sub": np.subtract, "mul": np.multiply, "div": np.true_divide,
                    "pow": np.power}[op](a, b)
    fn, args = t[1], [_value(a, env) for a in t[2]]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        if fn in _UNARY:
            return _UNARY[fn](args[0])
        if fn == "atan2":
            return np.arctan2(args[0], args[1])
        if fn == "hypot":
            return np.hypot(args[0], args[1])
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


def _dual(t, env):
    """``(value, {name: derivative})`` of a tree node."""
    op = t[0]
    if op == "num":
        return t[1], {}
    if op == "var":
        v = _value(t, env)
        return v, {t[1]: np.ones_like(np.asarray(v, dtype=float))}
    if op == "neg":
        v, d = _dual(t[1], env)
        return -v, _combine((-1.0, d))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        if op in ("add", "sub", "mul", "div", "pow"):
            (a, da), (b, db) = _dual(t[1], env), _dual(t[2], env)
            if op == "add":
                return a + b, _combine((1.0, da), (1.0, db))
            if op == "sub":
                return a - b, _combine((1.0, da), (-1.0, db))
            if op == "mul":
                return a * b, _combine((b, da), (a, db))
            if op == "div":
                return a / b, _combine((1.0 / b, da), (-a / (b * b), db))
            v = np.power(a, b)
            terms = [(b * np.power(a, b - 1.0), da)] if da else []
            if db:
                terms.append((v * np.log(a), db))
            return v, _combine(*terms)
        fn = t[1]
        duals = [_dual(a, env) for a in t[2]]
        (a, da) = duals[0]
        if fn == "sqrt":
            v = np.sqrt(a)
            return v, _combine((0.5 / v, da))
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
            return np.tan(a), _combine((1.0 / np.cos(a) ** 2, da))
        if fn == "asin":
            return np.arcsin(a), _combine((1.0 / np.sqrt(1.0 - a * a), da))
        if fn == "acos":
            return np.arccos(a), _combine((-1.0 / np.sqrt(1.0 - a * a), da))
        if fn == "atan":
            return np.arctan(a), _combine((1.0 / (1.0 + a * a), da))
        if fn == "abs":
            return np.abs(a), _combine((np.sign(a), da))
        if fn in ("atan2", "hypot"):
            (b, db) = duals[1]
            r2 = a * a + b * b
            if fn == "atan2":      # atan2(y = a, x = b)
                return np.arctan2(a, b), _combine((b / r2, da), (-a / r2, db))
            r = np.sqrt(r2)
            return np.hypot(a, b), _combine((a / r, da), (b / r, db))
        if fn in ("sum", "mean"):
            w = 1.0 if fn == "sum" else 1.0 / len(duals)
            return w * _reduce(np.add, [v for v, _ in duals]), _combine(*[(w, d) for _, d in duals])
        # min / max: the derivative of the argument that is selected, element by element
        pick = np.argmin if fn == "min" else np.argmax
        vals = np.broadcast_arrays(*[np.asarray(v, dtype=float) for v, _ in duals])
        k = pick(np.stack(vals), axis=0)
        value = np.choose(k, vals) if np.ndim(k) else vals[int(k)]
        return value, _combine(*[(np.where(k == i, 1.0, 0.0), d) for i, (_, d) in enumerate(duals)])
