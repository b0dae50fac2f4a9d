"""Profile and form tolerances as a drawing's feature control frame writes them (ASME Y14.5-2018 §5, §11; ISO 1101).

==========================  ============================================  ================================================
written                     characteristic                                the factor: its band
==========================  ============================================  ================================================
``⌓0.1 A B C``              profile of a surface, related to datums        the surface's deviation along its normal,
``⌒0.05 A``                 profile of a line                              −t/2 … +t/2 about the true profile (equally
``profile 0.1 A|B``         (words: profile of a surface / of a line,      disposed); ``+`` is the side that adds material
                            surface profile, line profile, profile)
``⌓0.1 U 0.03 A``           unequally disposed (Ⓤ, §11.3.1.2)              −(t − u) … +u: u toward added material
``⌓0.1``                    profile without datums                         the same band about the best-fit profile: form
                                                                           (and size, orientation) only — its location
                                                                           comes from another tolerance
``⏥0.02``, ``flatness 0.02`` flatness; ``⏤`` straightness, ``○``          a form deviation: a magnitude 0 … t
                            circularity (roundness), ``⌭`` cylindricity    (Rayleigh by default: 99.73 % below t)
==========================  ============================================  ================================================

A number may carry its unit (``⌓0.1 mm A``, ``⏥0.0004"``; converted to the factor's) and a decimal comma.  Datum
letters are recorded (profile with datums locates the surface; without, it does not); datum modifiers are not read.

Rule #1, the envelope (ASME Y14.5-2018 §5.8; ISO 8015's Ⓔ): a form tolerance on a feature of size may name that
size, ``envelope = "shaft.d"`` with ``feature_type`` — the feature's form then stays within its size's departure from
MMC (:mod:`rvtol.envelopes`).
"""
from __future__ import annotations

import re
from dataclasses import dataclass

from .notation import NotationError, Tolerance, _decimal_points, fmt, parse_tolerance

PROFILES = {"⌓": "profile of a surface", "⌒": "profile of a line"}
FORMS = {"⏥": "flatness", "⏤": "straightness", "○": "circularity", "◯": "circularity", "⌭": "cylindricity"}
_WORDS = {"profile of a surface": "profile of a surface", "surface profile": "profile of a surface",
          "profile of a line": "profile of a line", "line profile": "profile of a line",
          "profile": "profile of a surface", "flatness": "flatness", "straightness": "straightness",
          "circularity": "circularity", "roundness": "circularity", "cylindricity": "cylindricity"}
_HEAD = re.compile(r"^\s*(" + "|".join(sorted(map(re.escape, _WORDS), key=len, reverse=True))
                   + "|" + "|".join(map(re.escape, {**PROFILES, **FORMS})) + r")(?![A-Za-z])\s*(.*)$", re.IGNORECASE)
_NUMBER = re.compile(r"^[+-]?(?:\d+(?:[.,]\d+)?|[.,]\d+)")
_DATUM = re.compile(r"^[A-Z]$")
_UNEQUAL = ("U", "Ⓤ", "(U)")
_ZERO = re.compile(r"^[+-]?(?:0+(?:[.,]0*)?|[.,]0+)(?:\s.*)?$")


@dataclass(frozen=True)
class GeometricTolerance(Tolerance):
    """A profile or form tolerance: the band a :class:`~rvtol.inputs.notation.Tolerance` gives, and what the frame
    says — its characteristic and datums."""

    characteristic: str = ""
    datums: tuple[str, ...] = ()

    @property
    def is_form(self) -> bool:
        return self.characteristic in FORMS.values()

    def describe(self) -> str:
        return self.text


def is_geometric(text: str) -> bool:
    """True when ``text`` starts with a profile or form symbol or word."""
    return _HEAD.match(text) is not None


def parse_geometric(text: str, *, unit: str | None = None) -> GeometricTolerance:
    """The band of a profile or form tolerance (module docstring) in ``unit`` (the factor's)."""
    m = _HEAD.match(text)
    if m is None:
        raise NotationError(f"{text!r}: not a profile or form tolerance (⌓0.1 A B, ⌒0.05, ⏥0.02, flatness 0.02, …)")
    head = m.group(1)
    rest = _decimal_points(m.group(2), text).replace("|", " ")   # decimal commas decided by all the frame's numbers
    characteristic = PROFILES.get(head) or FORMS.get(head) or _WORDS[head.lower()]
    words = rest.split()
    width, written, word, words = _magnitude(words, text, "the tolerance (the zone's width)", unit)
    u = None
    if words and words[0] in _UNEQUAL:
        if characteristic not in PROFILES.values():
            raise NotationError(f"{text!r}: an unequally disposed zone (U) belongs to a profile tolerance")
        # the amount after U is in the width's unit unless it writes its own (⌓0.1 mm U 0.03: 0.03 mm)
        u, _, _, words = _magnitude(words[1:], text, "the amount toward added material after U", unit, word)
    bad = [w for w in words if not _DATUM.match(w)]
    twice = next((w for i, w in enumerate(words) if w in words[:i]), None)
    if twice is not None and not bad:
        raise NotationError(f"{text!r}: datum {twice} is named twice (a frame names each datum once)")
    if bad:
        raise NotationError(f"{text!r}: {bad[0]!r} is not a datum letter (the frame reads: tolerance, optional "
                            "U and its amount, datum letters; datum modifiers are not read)")
    if not width > 0:
        raise NotationError(f"{text!r}: the zone needs a positive width")
    if characteristic in FORMS.values():
        if words:
            raise NotationError(f"{text!r}: a form tolerance ({characteristic}) relates to no datum")
        return GeometricTolerance(text, "max", None, 0.0, width, written, characteristic=characteristic)
    toward = 0.5 * width if u is None else u
    if not 0 <= toward <= width:
        raise NotationError(f"{text!r}: the amount after U ({fmt(toward)}) must lie between 0 and the zone's width "
                            f"({fmt(width)})")
    return GeometricTolerance(text, "deviations", 0.0, toward - width, toward, written, characteristic=characteristic,
                              datums=tuple(words))


def _magnitude(words: list[str], text: str, what: str, unit: str | None,
               default_word: str | None = None) -> tuple[float, str | None, str | None, list[str]]:
    """A number with its optional unit (the next word, or glued: ``0.1mm``, ``0.0004"``; else ``default_word``) read by
    the drawing notation's own reader, in ``unit`` (0 is a number too: ``U 0``); its unit, the unit word it was read
    with, and the words after it."""
    m = _NUMBER.match(words[0]) if words else None
    if m is None:
        raise NotationError(f"{text!r}: expected {what}")
    number, after, word = words[0], words[1:], words[0][m.end():] or None
    if word is None and after and after[0] not in _UNEQUAL and not _DATUM.match(after[0]):   # a unit word
        word, after = after[0], after[1:]
    if word is None:
        word = default_word
    written = number if number[m.end():] else f"{number} {word}" if word else number
    if _ZERO.match(number[:m.end()]):
        return 0.0, unit, word, after
    if number.startswith("-"):
        raise NotationError(f"{text!r}: {what} is a width: {number!r} must not be negative")
    try:
        t = parse_tolerance(f"max {written}", unit=unit)
    except NotationError as exc:       # the reader's own reason (an ambiguous 1,000, an unknown unit) without its
        why = re.sub(r"^cannot read tolerance '[^']*':\s*", "", exc.reason.split(" (accepted:")[0])   # 'max …'
        raise NotationError(f"{text!r}: {what}: {written!r} is not a number with a length unit (0.1, 0.1 mm, "
                            f"100 um, 0.004\"){': ' + why if why != exc.reason else ''}") from None
    return t.upper, t.unit, word, after
