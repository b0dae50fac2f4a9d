"""The decimals a number is shown with: enough to resolve the tolerance it is judged against.

Four significant digits hide what a tolerance engineer reads a report for: a mean of 19.994 mm on a 12-µm band
reads 19.99 (half the band gone), a 5-µm mean shift of a 42-mm part reads ``μ=42.01 → μ=42``.  Every number in a
unit — a mean, σ, a percentile, a limit, a change — is shown in fixed point with the decimals that resolve
1/:data:`RESOLUTION` of its **scale** (:func:`decimals`): the requirement's limit interval (upper − lower) for an
output, a factor's drawing band, else the output's σ (:func:`output_scale`) — and with four significant digits
where that needs more (what the writers showed before, to 1/100 000 of the scale at most); a number with no scale
keeps four significant digits.
"""
from __future__ import annotations

import math
import re

#: a scale is resolved to 1/RESOLUTION of itself (a 12-µm band to 0.12 µm: four decimals in mm)
RESOLUTION = 100
#: and a number shows at least this many significant digits (what the writers' ``.4g`` gave) ...
SIGNIFICANT = 4
#: ... with at most this many decimals more than the scale needs (to 1/100 000 of it)
FINER = 3


def decimals(scale: float | None) -> int | None:
    """The decimals of fixed point that resolve ``scale``/:data:`RESOLUTION` (ceil(−log10(scale/100)), at least 0);
    None when ``scale`` is no usable scale (missing, not finite, not positive)."""
    if scale is None or not math.isfinite(scale) or scale <= 0:
        return None
    return max(0, math.ceil(round(-math.log10(scale / RESOLUTION), 9)))


def shown(value, scale: float | None = None, sig: int = SIGNIFICANT) -> str:
    """``value`` in fixed point with the :func:`decimals` of ``scale`` — and at least ``sig`` significant digits (a σ
    of 0.01667 on a 0.1 band stays 0.01667, not 0.017), but at most :data:`FINER` decimals more (round-off such
    as 1e-17 reads 0.00000) —; ``sig`` significant digits without a scale; ``—`` for no number."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        return "—"
    if not math.isfinite(v):
        return "—"
    d = decimals(scale)
    if d is None:
        return f"{v:.{sig}g}"
    if v != 0:
        d = max(d, min(sig - 1 - math.floor(math.log10(abs(v))), d + FINER))
    s = f"{v:.{d}f}"
    return s[1:] if s.startswith("-") and float(s) == 0 else s        # no "-0.000"


def output_scale(limits, sigma: float | None = None) -> float | None:
    """The scale of an output's numbers: the narrowest of its requirements' limit intervals (``limits``: pairs
    ``(lower, upper)``, either None for a one-sided requirement), else its σ."""
    widths = [hi - lo for lo, hi in limits if lo is not None and hi is not None and hi > lo]
    if widths:
        return min(widths)
    return sigma if sigma is not None and math.isfinite(sigma) and sigma > 0 else None


def requirements_scale(requirements, output: str, sigma: float | None = None) -> float | None:
    """:func:`output_scale` of ``output`` from requirement objects (their ``output``, ``lower``, ``upper`` in the
    output's shown unit: :class:`rvtol.spec.Requirement` as the Monte Carlo holds them)."""
    return output_scale([(r.lower, r.upper) for r in requirements if r.output == output], sigma)


def summary_scale(entry: dict) -> float | None:
    """:func:`output_scale` of an output as summary.json records it (its ``requirements`` and ``std``)."""
    return output_scale([(r.get("lower"), r.get("upper")) for r in entry.get("requirements", [])], entry.get("std"))


class Scaled(float):
    """A number in a unit that formats itself resolving its scale: ``format(x, ".4g")`` is :func:`shown` with at
    least 4 significant digits, ``"+.3g"`` signs it, ``"g"`` means 6 — so a sentence written ``{mean:.4g}``
    (:mod:`rvtol.signoff`) shows the mean to the band's resolution.  Any other format is a float's."""

    def __new__(cls, value: float, scale: float | None):
        x = super().__new__(cls, value)
        x.scale = scale
        return x

    def __format__(self, spec: str) -> str:
        m = re.fullmatch(r"(\+?)(?:\.(\d+))?g", spec)
        if m is None:
            return super().__format__(spec)
        s = shown(float(self), self.scale, int(m[2] or 6))
        return "+" + s if m[1] and not s.startswith("-") else s
