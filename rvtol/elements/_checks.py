"""Input checks shared by the compliance elements.

Every element function validates its inputs here and raises
:class:`rvtol.errors.SpecError` (a ``ValueError``) whose ``key`` is the name of
the offending argument, so a caller that knows the design file can locate it
with :meth:`~rvtol.errors.InputError.located`.
"""
from __future__ import annotations

import numpy as np

from ..errors import SpecError


def _describe(v) -> str:
    a = np.asarray(v)
    if a.ndim == 0:
        return f"{float(a):g}" if np.issubdtype(a.dtype, np.number) else repr(v)
    bad = a.ravel()
    return f"an array containing {bad[0]:g}" if bad.size == 1 else f"an array of shape {a.shape}"


def array(name: str, value) -> np.ndarray:
    """``value`` as a float array; non-numeric input raises :class:`SpecError`."""
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise SpecError(f"must be a number or an array of numbers, got {value!r}", key=name) from None
    return a


def positive(name: str, value, *, allow_inf: bool = False) -> np.ndarray:
    """``value > 0`` everywhere (and finite unless ``allow_inf``)."""
    a = array(name, value)
    ok = (a > 0) & (np.isfinite(a) | (allow_inf & np.isposinf(a)))
    if not np.all(ok):
        bad = a[~ok] if a.ndim else a
        raise SpecError(f"must be > 0{'' if allow_inf else ' and finite'}, got {_describe(bad)}", key=name)
    return a


def nonnegative(name: str, value, *, allow_inf: bool = False) -> np.ndarray:
    """``value >= 0`` everywhere (and finite unless ``allow_inf``)."""
    a = array(name, value)
    ok = (a >= 0) & (np.isfinite(a) | (allow_inf & np.isposinf(a)))
    if not np.all(ok):
        bad = a[~ok] if a.ndim else a
        raise SpecError(f"must be >= 0{'' if allow_inf else ' and finite'}, got {_describe(bad)}", key=name)
    return a


def finite(name: str, value) -> np.ndarray:
    a = array(name, value)
    if not np.all(np.isfinite(a)):
        raise SpecError(f"must be finite, got {_describe(a[~np.isfinite(a)] if a.ndim else a)}", key=name)
    return a


def poisson(name: str, value) -> np.ndarray:
    """A Poisson ratio of an isotropic solid: -1 < ν < 0.5."""
    a = finite(name, value)
    if not np.all((a > -1.0) & (a < 0.5)):
        raise SpecError(f"must be a Poisson ratio in (-1, 0.5), got {_describe(a)}", key=name)
    return a


def whole(name: str, value, *, minimum: int = 1) -> int:
    """A whole number >= ``minimum``."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise SpecError(f"must be a whole number, got {value!r}", key=name) from None
    if not np.isfinite(v) or abs(v - round(v)) > 1e-9 or round(v) < minimum:
        raise SpecError(f"must be a whole number >= {minimum}, got {value!r}", key=name)
    return int(round(v))


def angle(name: str, value, *, lower: float = 0.0, upper: float = 0.5 * np.pi) -> np.ndarray:
    """An angle in rad with ``lower < value < upper``."""
    a = finite(name, value)
    if not np.all((a > lower) & (a < upper)):
        raise SpecError(f"must be an angle in rad between {lower:g} and {upper:g} (exclusive), got {_describe(a)}",
                        key=name)
    return a


def shear_modulus(E, nu):
    """``G = E / (2 (1 + ν))`` (isotropic)."""
    return E / (2.0 * (1.0 + nu))
