"""ISO 286-1:2010 limits and fits: standard tolerance grades and fundamental deviations.

Every number here is the standard's *tabulated* value (ISO 286-1:2010, Tables 1–3; the same
values as ISO 286-2 and DIN EN ISO 286), not the value of the formulas the tables were
derived from: the standard rounds its formulas and then adjusts some rows, and a drawing
means the table.  ``tests/inputs/test_iso286.py`` holds the tables to published limit deviations
and to the standard's formulas within their rounding.

Coverage
--------
* standard tolerance grades IT01, IT0 (≤ 500 mm), IT1 … IT18 (≤ 3150 mm);
* shafts ``a`` … ``zc`` and holes ``A`` … ``ZC`` with ``js``/``JS``:
  a, b, c (A, B, C) ≤ 500 mm (not ≤ 1 mm); cd, ef, fg ≤ 50 mm (the 2010 edition; the 1988
  edition stopped at 10 mm); d … h, k, m, n, p, r, s, t, u
  ≤ 3150 mm (t from 24 mm); v (from 14 mm), x, y (from 18 mm), z, za, zb, zc ≤ 500 mm;
  j5, j6, j7 and J6, J7, J8 ≤ 500 mm (j8 ≤ 3 mm); K, M, N above IT8 ≤ 500 mm (published
  transcriptions disagree on those columns above 500 mm, so rvtol refuses rather than guess);
  N above IT8 and a, b, A, B not at or below 1 mm (the standard's "shall not be used");
* the tabulated Δ covers IT3 … IT8: K, M, N and P … ZC in IT01 … IT2 are refused above 3 mm;
* holes K, M, N up to IT8 and P … ZC up to IT7 take the Δ of Table 3 (3 < D ≤ 500 mm),
  with the standard's special case M6 for 250 < D ≤ 315 mm (ES = −9 µm);
* ``js``/``JS``: ±IT/2 exactly (the standard *allows* odd IT values of grades 7–11 to be
  rounded down to even; rvtol does not round).

Sizes are "above … up to and including …": 18 mm is in 10–18, 18.001 mm in 18–30.

>>> limits("H7", 25).upper, limits("H7", 25).lower
(21.0, 0.0)
>>> f = fit("H7", "g6", 25); (f.min_clearance, f.max_clearance, f.kind)
(7.0, 41.0, 'clearance')
"""
from __future__ import annotations

import re
from bisect import bisect_left
from dataclasses import dataclass

from ..errors import InputError

#: largest nominal size covered (mm)
SIZE_LIMIT = 3150.0

#: upper bounds of the main size steps (mm); a size D belongs to the first bound >= D
MAIN_STEPS = (3, 6, 10, 18, 30, 50, 80, 120, 180, 250, 315, 400, 500,
              630, 800, 1000, 1250, 1600, 2000, 2500, 3150)
#: upper bounds of the intermediate steps (used by a, b, c and r … zc)
INTERMEDIATE_STEPS = (3, 6, 10, 14, 18, 24, 30, 40, 50, 65, 80, 100, 120, 140, 160, 180, 200, 225, 250,
                      280, 315, 355, 400, 450, 500, 560, 630, 710, 800, 900, 1000, 1120, 1250, 1400, 1600,
                      1800, 2000, 2240, 2500, 2800, 3150)

GRADES = ("01", "0") + tuple(str(i) for i in range(1, 19))

# --------------------------------------------------------------------------- Table 1
# Standard tolerance grades (µm) per main step.  IT01 and IT0 are given up to 500 mm only.
_IT: dict[str, tuple[float, ...]] = {
    "01": (0.3, 0.4, 0.4, 0.5, 0.6, 0.6, 0.8, 1, 1.2, 2, 2.5, 3, 4),
    "0": (0.5, 0.6, 0.6, 0.8, 1, 1, 1.2, 1.5, 2, 3, 4, 5, 6),
    "1": (0.8, 1, 1, 1.2, 1.5, 1.5, 2, 2.5, 3.5, 4.5, 6, 7, 8, 9, 10, 11, 13, 15, 18, 22, 26),
    "2": (1.2, 1.5, 1.5, 2, 2.5, 2.5, 3, 4, 5, 7, 8, 9, 10, 11, 13, 15, 18, 21, 25, 30, 36),
    "3": (2, 2.5, 2.5, 3, 4, 4, 5, 6, 8, 10, 12, 13, 15, 16, 18, 21, 24, 29, 35, 41, 50),
    "4": (3, 4, 4, 5, 6, 7, 8, 10, 12, 14, 16, 18, 20, 22, 25, 28, 33, 39, 46, 55, 68),
    "5": (4, 5, 6, 8, 9, 11, 13, 15, 18, 20, 23, 25, 27, 32, 36, 40, 47, 55, 65, 78, 96),
    "6": (6, 8, 9, 11, 13, 16, 19, 22, 25, 29, 32, 36, 40, 44, 50, 56, 66, 78, 92, 110, 135),
    "7": (10, 12, 15, 18, 21, 25, 30, 35, 40, 46, 52, 57, 63, 70, 80, 90, 105, 125, 150, 175, 210),
    "8": (14, 18, 22, 27, 33, 39, 46, 54, 63, 72, 81, 89, 97, 110, 125, 140, 165, 195, 230, 280, 330),
    "9": (25, 30, 36, 43, 52, 62, 74, 87, 100, 115, 130, 140, 155, 175, 200, 230, 260, 310, 370, 440, 540),
    "10": (40, 48, 58, 70, 84, 100, 120, 140, 160, 185, 210, 230, 250, 280, 320, 360, 420, 500, 600, 700,
           860),
    "11": (60, 75, 90, 110, 130, 160, 190, 220, 250, 290, 320, 360, 400, 440, 500, 560, 660, 780, 920,
           1100, 1350),
    "12": (100, 120, 150, 180, 210, 250, 300, 350, 400, 460, 520, 570, 630, 700, 800, 900, 1050, 1250,
           1500, 1750, 2100),
    "13": (140, 180, 220, 270, 330, 390, 460, 540, 630, 720, 810, 890, 970, 1100, 1250, 1400, 1650, 1950,
           2300, 2800, 3300),
    "14": (250, 300, 360, 430, 520, 620, 740, 870, 1000, 1150, 1300, 1400, 1550, 1750, 2000, 2300, 2600,
           3100, 3700, 4400, 5400),
    "15": (400, 480, 580, 700, 840, 1000, 1200, 1400, 1600, 1850, 2100, 2300, 2500, 2800, 3200, 3600, 4200,
           5000, 6000, 7000, 8600),
    "16": (600, 750, 900, 1100, 1300, 1600, 1900, 2200, 2500, 2900, 3200, 3600, 4000, 4400, 5000, 5600,
           6600, 7800, 9200, 11000, 13500),
    "17": (1000, 1200, 1500, 1800, 2100, 2500, 3000, 3500, 4000, 4600, 5200, 5700, 6300, 7000, 8000, 9000,
           10500, 12500, 15000, 17500, 21000),
    "18": (1400, 1800, 2200, 2700, 3300, 3900, 4600, 5400, 6300, 7200, 8100, 8900, 9700, 11000, 12500,
           14000, 16500, 19500, 23000, 28000, 33000),
}

# --------------------------------------------------------------------------- Table 2 (shafts)
_M, _I = "main", "intermediate"
_ = None  # not defined for that size step

# Upper deviations es (µm) of shafts a … g (h: 0); negative.
_ES: dict[str, tuple[str, tuple]] = {
    "a": (_I, (-270, -270, -280, -290, -290, -300, -300, -310, -320, -340, -360, -380, -410, -460, -520,
               -580, -660, -740, -820, -920, -1050, -1200, -1350, -1500, -1650)),
    "b": (_I, (-140, -140, -150, -150, -150, -160, -160, -170, -180, -190, -200, -220, -240, -260, -280,
               -310, -340, -380, -420, -480, -540, -600, -680, -760, -840)),
    "c": (_I, (-60, -70, -80, -95, -95, -110, -110, -120, -130, -140, -150, -170, -180, -200, -210, -230,
               -240, -260, -280, -300, -330, -360, -400, -440, -480)),
    "cd": (_M, (-34, -46, -56, -70, -85, -100)),
    "d": (_M, (-20, -30, -40, -50, -65, -80, -100, -120, -145, -170, -190, -210, -230, -260, -290, -320,
               -350, -390, -430, -480, -520)),
    "e": (_M, (-14, -20, -25, -32, -40, -50, -60, -72, -85, -100, -110, -125, -135, -145, -160, -170, -195,
               -220, -240, -260, -290)),
    "ef": (_M, (-10, -14, -18, -23, -28, -35)),
    "f": (_M, (-6, -10, -13, -16, -20, -25, -30, -36, -43, -50, -56, -62, -68, -76, -80, -86, -98, -110,
               -120, -130, -145)),
    "fg": (_M, (-4, -6, -8, -10, -12, -15)),
    "g": (_M, (-2, -4, -5, -6, -7, -9, -10, -12, -14, -15, -17, -18, -20, -22, -24, -26, -28, -30, -32, -34,
               -38)),
}

# Lower deviations ei (µm) of shafts j … zc.  k: the IT4–IT7 column (0 for other grades and > 500 mm).
_EI: dict[str, tuple[str, tuple]] = {
    "j5": (_M, (-2, -2, -2, -3, -4, -5, -7, -9, -11, -13, -16, -18, -20)),  # j5 and j6
    "j7": (_M, (-4, -4, -5, -6, -8, -10, -12, -15, -18, -21, -26, -28, -32)),
    "j8": (_M, (-6,)),
    "k": (_M, (0, 1, 1, 1, 2, 2, 2, 3, 3, 4, 4, 4, 5, 0, 0, 0, 0, 0, 0, 0, 0)),
    "m": (_M, (2, 4, 6, 7, 8, 9, 11, 13, 15, 17, 20, 21, 23, 26, 30, 34, 40, 48, 58, 68, 76)),
    "n": (_M, (4, 8, 10, 12, 15, 17, 20, 23, 27, 31, 34, 37, 40, 44, 50, 56, 66, 78, 92, 110, 135)),
    "p": (_M, (6, 12, 15, 18, 22, 26, 32, 37, 43, 50, 56, 62, 68, 78, 88, 100, 120, 140, 170, 195, 240)),
    "r": (_I, (10, 15, 19, 23, 23, 28, 28, 34, 34, 41, 43, 51, 54, 63, 65, 68, 77, 80, 84, 94, 98, 108, 114,
               126, 132, 150, 155, 175, 185, 210, 220, 250, 260, 300, 330, 370, 400, 440, 460, 550, 580)),
    "s": (_I, (14, 19, 23, 28, 28, 35, 35, 43, 43, 53, 59, 71, 79, 92, 100, 108, 122, 130, 140, 158, 170,
               190, 208, 232, 252, 280, 310, 340, 380, 430, 470, 520, 580, 640, 720, 820, 920, 1000, 1100,
               1250, 1400)),
    "t": (_I, (_, _, _, _, _, _, 41, 48, 54, 66, 75, 91, 104, 122, 134, 146, 166, 180, 196, 218, 240, 268,
               294, 330, 360, 400, 450, 500, 560, 620, 680, 780, 840, 960, 1050, 1200, 1350, 1500, 1650,
               1900, 2100)),
    "u": (_I, (18, 23, 28, 33, 33, 41, 48, 60, 70, 87, 102, 124, 144, 170, 190, 210, 236, 258, 284, 315,
               350, 390, 435, 490, 540, 600, 660, 740, 840, 940, 1050, 1150, 1300, 1450, 1600, 1850, 2000,
               2300, 2500, 2900, 3200)),
    "v": (_I, (_, _, _, _, 39, 47, 55, 68, 81, 102, 120, 146, 172, 202, 228, 252, 284, 310, 340, 385, 425,
               475, 530, 595, 660)),
    "x": (_I, (20, 28, 34, 40, 45, 54, 64, 80, 97, 122, 146, 178, 210, 248, 280, 310, 350, 385, 425, 475,
               525, 590, 660, 740, 820)),
    "y": (_I, (_, _, _, _, _, 63, 75, 94, 114, 144, 174, 214, 254, 300, 340, 380, 425, 470, 520, 580, 650,
               730, 820, 920, 1000)),
    "z": (_I, (26, 35, 42, 50, 60, 73, 88, 112, 136, 172, 210, 258, 310, 365, 415, 465, 520, 575, 640, 710,
               790, 900, 1000, 1100, 1250)),
    "za": (_I, (32, 42, 52, 64, 77, 98, 118, 148, 180, 226, 274, 335, 400, 470, 535, 600, 670, 740, 820,
                920, 1000, 1150, 1300, 1450, 1600)),
    "zb": (_I, (40, 50, 67, 90, 108, 136, 160, 200, 242, 300, 360, 445, 525, 620, 700, 780, 880, 960, 1050,
                1200, 1300, 1500, 1650, 1850, 2100)),
    "zc": (_I, (60, 80, 97, 130, 150, 188, 218, 274, 325, 405, 480, 585, 690, 800, 900, 1000, 1150, 1250,
                1350, 1550, 1700, 1900, 2100, 2400, 2600)),
}

# --------------------------------------------------------------------------- Table 3 (holes)
# Upper deviations ES (µm) of holes J6, J7, J8 (main steps up to 500 mm).
_J_HOLE: dict[str, tuple[float, ...]] = {
    "6": (2, 5, 5, 6, 8, 10, 13, 16, 18, 22, 25, 29, 33),
    "7": (4, 6, 8, 10, 12, 14, 18, 22, 26, 30, 36, 39, 43),
    "8": (6, 10, 12, 15, 20, 24, 28, 34, 41, 47, 55, 60, 66),
}
# Δ (µm) for K, M, N up to IT8 and P … ZC up to IT7, grades IT3 … IT8, main steps up to 500 mm.
_DELTA: dict[str, tuple[float, ...]] = {
    "3": (0, 1, 1, 1, 1.5, 1.5, 2, 2, 3, 3, 4, 4, 5),
    "4": (0, 1.5, 1.5, 2, 2, 3, 3, 4, 4, 4, 4, 5, 5),
    "5": (0, 1, 2, 3, 3, 4, 5, 5, 6, 6, 7, 7, 7),
    "6": (0, 3, 3, 3, 4, 5, 6, 7, 7, 9, 9, 11, 13),
    "7": (0, 4, 6, 7, 8, 9, 11, 13, 15, 17, 20, 21, 23),
    "8": (0, 6, 7, 9, 12, 14, 16, 19, 23, 26, 29, 32, 34),
}

SHAFT_LETTERS = ("a", "b", "c", "cd", "d", "e", "ef", "f", "fg", "g", "h", "js", "j", "k", "m", "n", "p",
                 "r", "s", "t", "u", "v", "x", "y", "z", "za", "zb", "zc")
HOLE_LETTERS = tuple(x.upper() for x in SHAFT_LETTERS)

_CLASS = re.compile(r"^\s*([A-Za-z]{1,2})\s*(01|0|1[0-8]|[1-9])\s*$")


# --------------------------------------------------------------------------- data classes
@dataclass(frozen=True)
class ToleranceClass:
    """A tolerance class such as ``H7`` (hole) or ``g6`` (shaft)."""

    letter: str
    grade: str

    @property
    def is_hole(self) -> bool:
        return self.letter[0].isupper()

    def __str__(self) -> str:
        return f"{self.letter}{self.grade}"


@dataclass(frozen=True)
class Limits:
    """Limit deviations of one tolerance class at one nominal size (deviations in µm)."""

    nominal: float          # mm
    cls: ToleranceClass
    upper: float            # es (shaft) or ES (hole), µm
    lower: float            # ei or EI, µm
    it: float               # the standard tolerance IT of the grade, µm
    size_range: tuple[float, float]

    @property
    def width(self) -> float:
        return self.upper - self.lower

    @property
    def limits_mm(self) -> tuple[float, float]:
        """Lower and upper limit of size (mm)."""
        return self.nominal + self.lower / 1000.0, self.nominal + self.upper / 1000.0

    def __str__(self) -> str:
        return f"{self.nominal:g} {self.cls} ({self.upper:+g}/{self.lower:+g} µm)"


@dataclass(frozen=True)
class Fit:
    """A hole–shaft fit at one nominal size; clearances in µm (negative: interference)."""

    hole: Limits
    shaft: Limits

    @property
    def max_clearance(self) -> float:
        """Largest clearance: largest hole with smallest shaft (ES − ei)."""
        return self.hole.upper - self.shaft.lower

    @property
    def min_clearance(self) -> float:
        """Smallest clearance: smallest hole with largest shaft (EI − es); negative = interference."""
        return self.hole.lower - self.shaft.upper

    @property
    def kind(self) -> str:
        if self.min_clearance >= 0:
            return "clearance"
        if self.max_clearance <= 0:
            return "interference"
        return "transition"

    def __str__(self) -> str:
        return (f"{self.hole.nominal:g} {self.hole.cls}/{self.shaft.cls}: clearance "
                f"{self.min_clearance:+g} … {self.max_clearance:+g} µm ({self.kind})")


# --------------------------------------------------------------------------- look-ups
def _check_size(nominal: float) -> float:
    try:
        d = float(nominal)
    except (TypeError, ValueError):
        raise InputError(f"nominal size must be a number, got {nominal!r}") from None
    if not 0.0 < d <= SIZE_LIMIT:
        raise InputError(f"ISO 286 covers nominal sizes above 0 up to {SIZE_LIMIT:g} mm, got {d:g} mm")
    return d


def _index(steps: tuple, d: float) -> int:
    return bisect_left(steps, d)


def size_range(nominal: float, intermediate: bool = False) -> tuple[float, float]:
    """The ISO 286 size step ``(above, up to and including)`` that holds ``nominal`` (mm)."""
    d = _check_size(nominal)
    steps = INTERMEDIATE_STEPS if intermediate else MAIN_STEPS
    i = _index(steps, d)
    return (0.0 if i == 0 else float(steps[i - 1]), float(steps[i]))


def parse_grade(grade) -> str:
    """``'IT7'``, ``'7'``, ``7``, ``'01'`` → the grade key (``'7'``, ``'01'``)."""
    g = str(grade).strip().upper()
    if g.startswith("IT"):
        g = g[2:]
    if g not in GRADES:
        raise InputError(f"unknown standard tolerance grade {grade!r} (IT01, IT0, IT1 … IT18)")
    return g


def tolerance_grade(grade, nominal: float) -> float:
    """The standard tolerance ITn (µm) for ``nominal`` (mm), from ISO 286-1 Table 1."""
    g = parse_grade(grade)
    d = _check_size(nominal)
    row = _IT[g]
    i = _index(MAIN_STEPS, d)
    if i >= len(row):
        raise InputError(f"IT{g} is given by ISO 286-1 up to {MAIN_STEPS[len(row) - 1]} mm only, got {d:g} mm")
    if g in ("14", "15", "16", "17", "18") and d <= 1.0:
        raise InputError(f"IT{g} is not used for nominal sizes up to 1 mm (ISO 286-1 Table 1)")
    return float(row[i])


def delta(grade, nominal: float) -> float:
    """Δ (µm) of ISO 286-1 Table 3 for grades IT3 … IT8 (0 up to 3 mm; not given above 500 mm)."""
    g = parse_grade(grade)
    d = _check_size(nominal)
    if g not in _DELTA:
        raise InputError(f"Δ is tabulated for IT3 … IT8 only, not IT{g}")
    i = _index(MAIN_STEPS, d)
    if i >= len(_DELTA[g]):
        raise InputError(f"Δ is tabulated up to 500 mm only, got {d:g} mm")
    return float(_DELTA[g][i])


def _table(table: dict, key: str, d: float, what: str) -> float:
    kind, row = table[key]
    steps = MAIN_STEPS if kind == _M else INTERMEDIATE_STEPS
    i = _index(steps, d)
    v = row[i] if i < len(row) else None
    if v is None:
        lo = next((steps[j - 1] if j else 0 for j, x in enumerate(row) if x is not None), 0)
        hi = steps[len(row) - 1]
        raise InputError(f"{what} is defined by ISO 286-1 for nominal sizes above {lo:g} up to {hi:g} mm only, "
                         f"got {d:g} mm")
    return float(v)


def parse_class(text: str) -> ToleranceClass:
    """``'H7'``, ``'g6'``, ``'JS7'``, ``'zc11'`` → :class:`ToleranceClass` (raises :class:`InputError`)."""
    m = _CLASS.match(str(text))
    if not m:
        raise InputError(f"not an ISO 286 tolerance class: {text!r} (expected a deviation letter and a grade, "
                         "e.g. H7, g6, js5, ZC11)")
    letter, grade = m.group(1), m.group(2)
    if letter not in SHAFT_LETTERS and letter not in HOLE_LETTERS:
        raise InputError(f"unknown fundamental deviation {letter!r} in {text!r} (holes: "
                         f"{', '.join(HOLE_LETTERS)}; shafts: {', '.join(SHAFT_LETTERS)}; "
                         "upper case is a hole, lower case a shaft)")
    return ToleranceClass(letter, grade)


def _shaft(letter: str, g: str, d: float) -> tuple[float, float]:
    """(es, ei) of a shaft in µm."""
    it = tolerance_grade(g, d)
    name = f"shaft deviation {letter!r}"
    if letter in ("a", "b") and d <= 1.0:
        raise InputError(f"{name} is not used for nominal sizes up to 1 mm (ISO 286-1)")
    if letter == "h":
        return 0.0, -it
    if letter == "js":
        return it / 2.0, -it / 2.0
    if letter in _ES:
        es = _table(_ES, letter, d, name)
        return es, es - it
    if letter == "j":
        if g in ("5", "6"):
            ei = _table(_EI, "j5", d, "j5/j6")
        elif g in ("7", "8"):
            ei = _table(_EI, "j" + g, d, f"j{g}")
        else:
            raise InputError(f"j is tabulated for grades 5, 6, 7 (and 8 up to 3 mm) only, not j{g}; use js{g}")
        return ei + it, ei
    if letter == "k":
        ei = _table(_EI, "k", d, name) if g in ("4", "5", "6", "7") else 0.0
        return ei + it, ei
    ei = _table(_EI, letter, d, name)
    return ei + it, ei


def _grade_num(g: str) -> float:
    """Grade as a number for comparisons (IT01 → −1)."""
    return -1.0 if g == "01" else float(g)


def _hole(letter: str, g: str, d: float) -> tuple[float, float]:
    """(ES, EI) of a hole in µm, from the shaft of the same letter and Table 3's rules."""
    it = tolerance_grade(g, d)
    name = f"hole deviation {letter!r}"
    low = letter.lower()
    n = _grade_num(g)
    if low in ("a", "b") and d <= 1.0:
        raise InputError(f"{name} is not used for nominal sizes up to 1 mm (ISO 286-1)")
    if letter == "H":
        return it, 0.0
    if letter == "JS":
        return it / 2.0, -it / 2.0
    if low in _ES:  # A … G: EI = −es
        ei = -_table(_ES, low, d, name)
        return ei + it, ei
    if letter == "J":
        if g not in _J_HOLE:
            raise InputError(f"J is tabulated for grades 6, 7, 8 only, not J{g}; use JS{g}")
        es = _table({"J": (_M, _J_HOLE[g])}, "J", d, f"J{g}")
        return es, es - it

    with_delta = 3.0 < d <= 500.0
    if letter in ("K", "M", "N"):
        if n <= 8:
            if letter == "K":
                base = -_table(_EI, "k", d, name)  # the IT4–IT7 value of k (0 above 500 mm)
            else:
                base = -_table(_EI, low, d, name)
            es = base + (delta(g, d) if with_delta else 0.0)
            if letter == "M" and g == "6" and 250.0 < d <= 315.0:
                es = -9.0  # ISO 286-1 Table 3, special case
        else:
            if d > 500.0:
                raise InputError(f"{letter}{g}: {letter} above IT8 is defined up to 500 mm only")
            if letter == "N" and d <= 1.0:
                raise InputError("N above IT8 is not used for nominal sizes up to 1 mm (ISO 286-1)")
            es = {"K": 0.0, "M": -_table(_EI, "m", d, name), "N": -4.0 if d <= 3.0 else 0.0}[letter]
        return es, es - it
    # P … ZC: ES = −ei, plus Δ up to IT7
    es = -_table(_EI, low, d, name)
    if n <= 7 and with_delta:
        es += delta(g, d)
    return es, es - it


def limits(cls: str | ToleranceClass, nominal: float) -> Limits:
    """Limit deviations (µm) of tolerance class ``cls`` (``'H7'``, ``'g6'``…) at ``nominal`` (mm)."""
    c = cls if isinstance(cls, ToleranceClass) else parse_class(cls)
    d = _check_size(nominal)
    if c.letter[0].isupper():
        up, lo = _hole(c.letter, c.grade, d)
    else:
        up, lo = _shaft(c.letter, c.grade, d)
    # table values are exact multiples of 0.1 µm: drop binary noise from the additions
    up, lo = round(up, 6) + 0.0, round(lo, 6) + 0.0
    return Limits(d, c, up, lo, tolerance_grade(c.grade, d), size_range(d))


def fit(hole: str | ToleranceClass, shaft: str | ToleranceClass, nominal: float) -> Fit:
    """The fit of ``hole`` (``'H7'``) and ``shaft`` (``'g6'``) at ``nominal`` (mm)."""
    h = hole if isinstance(hole, ToleranceClass) else parse_class(hole)
    s = shaft if isinstance(shaft, ToleranceClass) else parse_class(shaft)
    if not h.is_hole:
        raise InputError(f"a fit is written hole/shaft: {h} is a shaft class (holes are upper case, e.g. H7)")
    if s.is_hole:
        raise InputError(f"a fit is written hole/shaft: {s} is a hole class (shafts are lower case, e.g. g6)")
    return Fit(limits(h, nominal), limits(s, nominal))


def farthest_band(nominal: float) -> float:
    """How far (µm) the farthest band of any ISO 286 tolerance class at ``nominal`` (mm) lies from the nominal:
    the largest fundamental deviation over every letter and grade the tables define there (0 outside the
    standard's sizes).  300 µm at 25 mm (a, es = −300 µm), 2100 µm at 400 mm (zc)."""
    try:
        d = _check_size(nominal)
    except InputError:
        return 0.0
    return _farthest_band_in_step((_index(INTERMEDIATE_STEPS, d), d <= 1.0), d)


_FARTHEST: dict[tuple[int, bool], float] = {}


def _farthest_band_in_step(step: tuple[int, bool], d: float) -> float:
    """:func:`farthest_band` for ``step`` = (the intermediate size step, at or below 1 mm): every size there has
    the same classes and deviations (a, b, N above IT8 and IT14 … IT18 are not used at or below 1 mm); ``d`` a
    size in it."""
    if step not in _FARTHEST:
        far = 0.0
        for letter in SHAFT_LETTERS + HOLE_LETTERS:
            for g in GRADES:
                try:
                    lim = limits(ToleranceClass(letter, g), d)
                except InputError:
                    continue
                if not lim.lower <= 0.0 <= lim.upper:
                    far = max(far, min(abs(lim.lower), abs(lim.upper)))
        _FARTHEST[step] = far
    return _FARTHEST[step]
