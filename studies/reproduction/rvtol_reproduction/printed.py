"""Printed figures of a reference document (``data/reproduction/*.toml``) and the one "reproduced?" rule.

A data file names its document and lists its figures::

    [document]
    id = "doc 001"
    file = "001_411b7d611462c065.txt"          # in ../shared/seeds/
    title = "..."

    [figure.phi12_mean]                         # key used by the reproduction module
    label = "Δφ12 mean [′]"
    where = "§1"                                # where the document prints it
    printed = "1.76"                            # as printed: a string keeps its digits; or a number,
                                                # a list, a range [lo, hi] (range = true), or a word
    unit = "arcmin"
    source = "doc 001 §1: 'Δφ12 = 1.76′ ± 2.05′'"
    tolerance = { rel = 0.10, why = "..." }     # optional, see RULE
    comparable = false                          # optional: rvtol's number answers another question
    why = "..."                                 # optional: the reason, shown beside the verdict

The rule (:data:`RULE`, :func:`verdict`) is the same for every document.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path

from rvtol.plugin import Params, SpecError, read_toml

RULE = ("'yes': rvtol's number lies within the figure's tolerance of the printed value — half a unit of the "
        "last printed digit, unless the data file states a wider tolerance with its reason (inputs the document "
        "does not give); for a printed range, within the range widened by that tolerance. 'partly': same sign "
        "and within a factor of two of the printed value (for an ordering or a trend: the direction agrees, not "
        "the full order). 'no': otherwise. 'n/a': rvtol cannot compute a comparable number (the document does "
        "not give what it needs). No constant is ever adjusted to meet a printed number.")


@dataclass(frozen=True)
class Printed:
    """One printed figure: its value(s) as printed, unit, place in the document and tolerance."""

    key: str
    label: str
    where: str
    raw: object                       # as written in the data file
    unit: str = ""
    source: str = ""
    rel: float | None = None          # stated relative tolerance
    abs: float | None = None          # stated absolute tolerance (in ``unit``)
    tolerance_why: str = ""
    is_range: bool = False
    comparable: bool = True
    why: str = ""

    # -- values ---------------------------------------------------------------------
    @property
    def text(self) -> str:
        """The figure as printed (a range as ``lo – hi``)."""
        if isinstance(self.raw, list):
            sep = " – " if self.is_range else ", "
            return sep.join(_text(v) for v in self.raw)
        return _text(self.raw)

    @property
    def value(self):
        """A float, or a list of floats (a string that is not a number stays a string)."""
        if isinstance(self.raw, list):
            return [_num(v) for v in self.raw]
        return _num(self.raw)

    def tolerance(self, printed: float, text: str | None = None) -> float:
        """Absolute tolerance around ``printed``: stated (rel/abs), else half a unit of the last digit."""
        if self.abs is not None:
            return self.abs
        if self.rel is not None:
            return self.rel * abs(printed)
        return 0.5 * 10.0 ** -_decimals(text if text is not None else _text(printed))

    def verdict(self, value) -> str:
        """The rule (:data:`RULE`) for a number (or, for a list figure, a list of numbers)."""
        if not self.comparable:
            return "n/a"
        if isinstance(self.raw, list) and not self.is_range:
            if value is None or len(value) != len(self.raw):
                return "n/a"
            vs = [self._one(_num(p), _text(p), v) for p, v in zip(self.raw, value)]
            return "yes" if all(v == "yes" for v in vs) else "no" if "no" in vs else "partly"
        if self.is_range:
            lo, hi = (_num(v) for v in self.raw)
            if value is None or not math.isfinite(value):
                return "n/a"
            if lo - self.tolerance(lo, _text(self.raw[0])) <= value <= hi + self.tolerance(hi, _text(self.raw[1])):
                return "yes"
            return _partly(0.5 * (lo + hi), value)
        return self._one(_num(self.raw), _text(self.raw), value)

    def verdict_at(self, i: int, value) -> str:
        """The rule for element ``i`` of a list figure."""
        if not self.comparable:
            return "n/a"
        return self._one(_num(self.raw[i]), _text(self.raw[i]), value)

    def _one(self, printed: float, text: str, value) -> str:
        if value is None or not math.isfinite(float(value)):
            return "n/a"
        value = float(value)
        if abs(value - printed) <= self.tolerance(printed, text) + 1e-12 * max(1.0, abs(printed)):
            return "yes"
        return _partly(printed, value)


def verdict(printed: float, value, rel: float | None = None, text: str | None = None) -> str:
    """The rule for a bare number (figures computed from printed ones, e.g. a sum of printed values)."""
    return Printed("", "", "", text if text is not None else printed, rel=rel).verdict(value)


def ordering_verdict(same_order: bool, same_direction: bool = False) -> str:
    """The rule for an ordering or a trend: 'yes' same order, 'partly' same direction only, else 'no'."""
    return "yes" if same_order else "partly" if same_direction else "no"


def _partly(printed: float, value: float) -> str:
    if printed != 0 and value != 0 and math.copysign(1, printed) == math.copysign(1, value) \
            and 0.5 <= value / printed <= 2.0:
        return "partly"
    return "no"


def _text(v) -> str:
    if isinstance(v, str):
        return v
    if isinstance(v, bool):
        return str(v).lower()
    if isinstance(v, int):
        return str(v)
    return f"{v:g}" if isinstance(v, float) else str(v)


def _num(v):
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        return float(v)
    try:
        return float(str(v).replace("−", "-"))
    except ValueError:
        return v


def _decimals(text: str) -> int:
    """Digits after the decimal point of a printed number (``6.84e-4`` → 6; ``1.76`` → 2; ``12`` → 0)."""
    t = text.strip().lower().replace("−", "-")
    mant, _, exp = t.partition("e")
    d = len(mant.split(".")[1]) if "." in mant else 0
    return d - (int(exp) if exp else 0)


@dataclass
class PrintedFigures:
    """The figures of one document, by key."""

    document: str
    file: str
    title: str
    path: str
    sha256: str
    figures: dict[str, Printed] = field(default_factory=dict)

    def __getitem__(self, key: str) -> Printed:
        try:
            return self.figures[key]
        except KeyError:
            raise SpecError(f"no printed figure {key!r} (has: {', '.join(self.figures)})", file=self.path,
                            key=f"figure.{key}") from None

    def require(self, keys, file: str | None = None, key: str = "printed") -> None:
        """Fail at load time (one line: file, key) if a figure the analysis needs is missing."""
        missing = [k for k in keys if k not in self.figures]
        if missing:
            raise SpecError(f"missing printed figure(s) {', '.join(missing)}", file=self.path,
                            key=f"figure.{missing[0]}")


def load_printed(path: str | Path) -> PrintedFigures:
    """Read ``data/reproduction/<doc>.toml``; every figure needs label, where, printed and source."""
    path = os.path.normpath(path)
    data, sha = read_toml(path)
    file = str(path)
    root = Params(data, file=file)
    doc = root.sub("document")
    out = PrintedFigures(doc.str("id"), doc.str("file"), doc.str("title"), file, sha)
    doc.finish()
    figs = root.sub("figure")
    for key in list(figs.keys()):
        t = figs.sub(key)
        tol = t.sub("tolerance", {})
        rel = tol.float("rel", None, positive=True)
        ab = tol.float("abs", None, positive=True)
        tw = tol.str("why", "")
        if (rel is not None or ab is not None) and not tw:
            raise tol.error("why", "a stated tolerance needs its reason")
        tol.finish()
        raw = t.raw("printed")
        if isinstance(raw, dict) or raw is None:
            raise t.error("printed", "expected a number, a string or a list")
        is_range = t.bool("range", False)
        if is_range and not (isinstance(raw, list) and len(raw) == 2):
            raise t.error("printed", "a range is a list [low, high]")
        out.figures[key] = Printed(key, t.str("label"), t.str("where"), raw, t.str("unit", ""), t.str("source"),
                                   rel, ab, tw, is_range, t.bool("comparable", True), t.str("why", ""))
        t.finish()
    figs.finish()
    root.finish()
    return out
