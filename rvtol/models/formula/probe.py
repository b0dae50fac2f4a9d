"""Where a formula model fails inside its spec's bands — found by ``rvtol check``, not by the run.

:func:`probe` evaluates every output at the nominal point and at the corners of the tolerance bands
(every factor at the low or the high end of :attr:`rvtol.spec.Factor.band`): all 2^k corners of the k
factors the model uses when k ≤ :data:`FULL_CORNERS`, else each factor's two ends one at a time and
:data:`RANDOM_CORNERS` corners drawn from a named sub-stream.  A point where an output is not a
finite number is evaluated once more with NumPy's floating-point errors raised, which names the
cause (division by zero, overflow, the square root or logarithm of a negative number, ...).
No model code runs: a formula model is the study's own text.
"""
from __future__ import annotations

import itertools
import re
from dataclasses import dataclass

import numpy as np

from ... import units as _units
from ...expressions import _value

#: all corners up to this many factors (2^12 = 4096 evaluations)
FULL_CORNERS = 12
#: corners drawn at random beyond that
RANDOM_CORNERS = 4096

_CAUSES = [
    (r"divide by zero encountered in (log|log10)", "the logarithm of 0"),
    (r"divide by zero", "a division by zero"),
    (r"overflow", "an overflow (a number beyond ±1.8e308)"),
    (r"invalid value encountered in sqrt", "the square root of a negative number"),
    (r"invalid value encountered in log", "the logarithm of a negative number"),
    (r"invalid value encountered in (arcsin|arccos)", "asin/acos of a number beyond ±1"),
    (r"invalid value encountered in power", "a negative number to a fractional power"),
    (r"invalid value encountered in (divide|true_divide)", "0/0"),
    (r"invalid value", "an undefined operation (∞ − ∞, 0·∞)"),
]


@dataclass
class Failure:
    output: int          # index into model.outputs
    name: str
    point: str           # "the nominal" / "a corner of the bands (a low, b high)"
    cause: str

    def describe(self) -> str:
        return f"output {self.name!r} fails at {self.point}: {self.cause}"


def _cause(model, x: np.ndarray, out: int) -> str:
    """Why output ``out`` is not finite at the row ``x`` (base units)."""
    env = model._env(x[None, :])
    try:
        with np.errstate(all="raise"):
            for name, f in model.definitions:
                env[name] = np.asarray(_value(f.tree, env), dtype=float)
            v = _value(model.formulas[out].tree, env)
    except FloatingPointError as exc:
        for pattern, text in _CAUSES:
            if re.search(pattern, str(exc)):
                return text
        return str(exc)
    except ZeroDivisionError:
        return "a division by zero"
    return f"the value {float(np.asarray(v).ravel()[0])!r}"


def _points(model, spec, seed: int) -> tuple[np.ndarray, list[str]]:
    x0 = spec.nominal_base()
    bands = np.array([[_units.to_base(v, f.unit) for v in f.band] for f in spec.factors], dtype=float)
    used = [j for j, n in enumerate(model.inputs) if any(n in e.names for _, e in model.definitions)
            or any(n in e.names for e in model.formulas)]
    rows, labels = [x0], ["the nominal"]

    def corner(bits) -> None:
        x = x0.copy()
        for j, b in zip(used, bits):
            x[j] = bands[j, b]
        rows.append(x)
        ends = [f"{model.inputs[j]} {('low', 'high')[b]}" for j, b in zip(used, bits)]
        shown = ", ".join(ends[:6]) + (", …" if len(ends) > 6 else "")
        labels.append(f"a corner of the bands ({shown})")

    if len(used) <= FULL_CORNERS:
        for bits in itertools.product((0, 1), repeat=len(used)):
            corner(bits)
    else:
        for i, j in enumerate(used):
            for b in (0, 1):
                x = x0.copy()
                x[j] = bands[j, b]
                rows.append(x)
                labels.append(f"the {('low', 'high')[b]} end of {model.inputs[j]}'s band")
        from ...sampling import substream

        rng = substream(seed, "check_corners")
        for bits in rng.integers(0, 2, size=(RANDOM_CORNERS, len(used))):
            corner(bits)
    return np.array(rows), labels


def probe(model, spec, seed: int = 0) -> list[Failure]:
    """The first failing point of each output (nominal first, then the corners); [] if none."""
    X, labels = _points(model, spec, seed)
    Y = model.evaluate(X)
    out = []
    for i, q in enumerate(model.outputs):
        bad = np.flatnonzero(~np.isfinite(Y[:, i]))
        if len(bad):
            k = int(bad[0])
            out.append(Failure(i, q.name, labels[k], _cause(model, X[k], i)))
    return out
