"""ISO 2768 general tolerances: what a dimension without an individual tolerance means on a drawing
whose title block says "ISO 2768-mK".

Every number is the standard's tabulated value (ISO 2768-1:1989 Table 1, linear dimensions except
broken edges; Table 2, broken edges — external radii and chamfer heights; Table 3, angular dimensions;
ISO 2768-2:1989 Tables 1–4, geometric tolerances), in mm (angles in minutes of arc).  Sizes are
"above … up to and including …" as in the tables; the first linear and broken-edge range starts at 0.5 mm
(below it the standard asks for an individual tolerance), the first angular range at any length.  A dash
in the standard (class v below 3 mm, class f above 2000 mm) is refused, not guessed.

An angle's general tolerance goes by the length of its **shorter side** (Table 3), not by the angle:
±1° up to 10 mm in class m, ±0°5' above 400 mm.  Tables 2 and 3 were checked cell by cell against two
public copies of ISO 2768-1: handfest.engineer's "Allgemeintoleranzen" (ISO 2768-1 Längen-, Rundungs-/Fasen-
und Winkelmaße; https://handfest.engineer/Toleranz/Allgemeintol.html) and, for Table 2, CAMCUT's "General
Tolerances for Broken edges (external radii and chamfer)" (ISO 2768-1:1989;
https://www.camcut-group.com/en-us/support/instructions/measuring/general-tolerances/general-tolerances-for-broken-edges-external-radii-and-chamfer);
Table 3 again against Schmidbauer's copy of DIN ISO 2768-1 (http://www.schmidbauer.net/de/toleranzen-din-iso-2768-1/,
whose range "über 50 bis 100" is a misprint of 120, the next range starting "über 120").

>>> linear("m", 50)
0.3
>>> broken_edge("m", 2)
0.2
>>> angular("m", 35)      # arcmin: ±0°30'
30
>>> geometric("straightness", "K", 120)
0.4
"""
from __future__ import annotations

from bisect import bisect_left

from ..errors import InputError

#: upper bounds of the linear size ranges (mm), from 0.5 mm
LINEAR_STEPS = (3, 6, 30, 120, 400, 1000, 2000, 4000)
#: ISO 2768-1 Table 1: permissible deviations ± (mm); None where the standard has a dash
LINEAR = {
    "f": (0.05, 0.05, 0.1, 0.15, 0.2, 0.3, 0.5, None),
    "m": (0.1, 0.1, 0.2, 0.3, 0.5, 0.8, 1.2, 2.0),
    "c": (0.2, 0.3, 0.5, 0.8, 1.2, 2.0, 3.0, 4.0),
    "v": (None, 0.5, 1.0, 1.5, 2.5, 4.0, 6.0, 8.0),
}
CLASS_NAMES = {"f": "fine", "m": "medium", "c": "coarse", "v": "very coarse"}

#: upper bounds of the broken-edge size ranges (mm), from 0.5 mm; the last range is open ("over 6")
EDGE_STEPS = (3, 6)
#: ISO 2768-1 Table 2: broken edges (external radius, chamfer height), permissible deviations ± (mm)
BROKEN_EDGE = {"f": (0.2, 0.5, 1.0), "m": (0.2, 0.5, 1.0), "c": (0.4, 1.0, 2.0), "v": (0.4, 1.0, 2.0)}

#: upper bounds of the ranges of the angle's shorter side (mm); the last range is open ("over 400")
ANGULAR_STEPS = (10, 50, 120, 400)
#: ISO 2768-1 Table 3: angular dimensions, permissible deviations ± in minutes of arc (60 = 1°)
ANGULAR = {"f": (60, 30, 20, 10, 5), "m": (60, 30, 20, 10, 5), "c": (90, 60, 30, 15, 10),
           "v": (180, 120, 60, 30, 20)}

#: ISO 2768-2 Table 1: straightness and flatness by nominal length (mm)
FORM_STEPS = (10, 30, 100, 300, 1000, 3000)
#: ISO 2768-2 Table 2: perpendicularity by the shorter side (mm); Table 3: symmetry (the same ranges)
ORIENTATION_STEPS = (100, 300, 1000, 3000)
GEOMETRIC = {
    "straightness": {"H": (0.02, 0.05, 0.1, 0.2, 0.3, 0.4), "K": (0.05, 0.1, 0.2, 0.4, 0.6, 0.8),
                     "L": (0.1, 0.2, 0.4, 0.8, 1.2, 1.6)},
    "perpendicularity": {"H": (0.2, 0.3, 0.4, 0.5), "K": (0.4, 0.6, 0.8, 1.0), "L": (0.6, 1.0, 1.5, 2.0)},
    "symmetry": {"H": (0.5, 0.5, 0.5, 0.5), "K": (0.6, 0.6, 0.8, 1.0), "L": (0.6, 1.0, 1.5, 2.0)},
}
GEOMETRIC["flatness"] = GEOMETRIC["straightness"]
#: ISO 2768-2 Table 4: circular run-out, independent of size
RUNOUT = {"H": 0.1, "K": 0.2, "L": 0.5}


def _class(cls: str) -> str:
    """An ISO 2768-1 class letter (f, m, c, v), in lower case."""
    c = cls.strip().lower()
    if c not in LINEAR:
        raise InputError(f"unknown ISO 2768-1 class {cls!r} (f, m, c or v)")
    return c


def linear(cls: str, nominal: float) -> float:
    """The permissible deviation ± (mm) of a linear dimension of ``nominal`` mm in class ``cls`` (f, m, c, v)."""
    c = _class(cls)
    d = abs(float(nominal))
    if not 0.5 <= d <= LINEAR_STEPS[-1]:
        raise InputError(f"ISO 2768-1 covers 0.5 … {LINEAR_STEPS[-1]} mm, not {nominal:g} mm (give an individual "
                         "tolerance)")
    v = LINEAR[c][bisect_left(LINEAR_STEPS, d)]
    if v is None:
        raise InputError(f"ISO 2768-1 class {c} ({CLASS_NAMES[c]}) has no value at {nominal:g} mm (a dash in the "
                         "table): give an individual tolerance")
    return v


def broken_edge(cls: str, nominal: float) -> float:
    """The permissible deviation ± (mm) of a broken edge — an external radius or a chamfer height — of ``nominal`` mm
    in class ``cls`` (Table 2)."""
    c = _class(cls)
    d = abs(float(nominal))
    if not d >= 0.5:
        raise InputError(f"ISO 2768-1 Table 2 covers broken edges from 0.5 mm, not {nominal:g} mm (give an individual "
                         "tolerance)")
    return BROKEN_EDGE[c][bisect_left(EDGE_STEPS, d)]


def angular(cls: str, shorter_side: float) -> int:
    """The permissible deviation ± (minutes of arc) of an angle whose shorter side is ``shorter_side`` mm long, in class
    ``cls`` (Table 3)."""
    c = _class(cls)
    if not shorter_side > 0:
        raise InputError(f"the shorter side of an angle is a length > 0, not {shorter_side:g} mm")
    return ANGULAR[c][bisect_left(ANGULAR_STEPS, float(shorter_side))]


def geometric(kind: str, cls: str, length: float | None = None) -> float:
    """The general geometric tolerance (mm) of ISO 2768-2 class ``cls`` (H, K, L): ``kind`` straightness / flatness
    (``length``: the feature's nominal length), perpendicularity / symmetry (the shorter side), or runout."""
    c = cls.strip().upper()
    if c not in RUNOUT:
        raise InputError(f"unknown ISO 2768-2 class {cls!r} (H, K or L)")
    if kind == "runout":
        return RUNOUT[c]
    if kind not in GEOMETRIC:
        raise InputError(f"unknown ISO 2768-2 tolerance {kind!r} (one of: {', '.join(sorted(GEOMETRIC))}, runout)")
    if length is None or not length > 0:
        raise InputError(f"ISO 2768-2 {kind} needs the nominal length (mm)")
    steps = FORM_STEPS if kind in ("straightness", "flatness") else ORIENTATION_STEPS
    if length > steps[-1]:
        raise InputError(f"ISO 2768-2 covers lengths up to {steps[-1]} mm, not {length:g} mm")
    return GEOMETRIC[kind][c][bisect_left(steps, float(length))]
