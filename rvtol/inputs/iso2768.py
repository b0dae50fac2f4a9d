"""ISO 2768 general tolerances: what a dimension without an individual tolerance means on a drawing
whose title block says "ISO 2768-mK".

Every number is the standard's tabulated value (ISO 2768-1:1989 Table 1, linear dimensions except
broken edges; ISO 2768-2:1989 Tables 1–4, geometric tolerances), in mm.  Sizes are "above … up to and
including …" as in the tables; the first linear range starts at 0.5 mm (below it the standard asks for
an individual tolerance).  A dash in the standard (class v below 3 mm, class f above 2000 mm) is refused,
not guessed.

>>> linear("m", 50)
0.3
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


def linear(cls: str, nominal: float) -> float:
    """The permissible deviation ± (mm) of a linear dimension of ``nominal`` mm in class ``cls`` (f, m, c, v)."""
    c = cls.strip().lower()
    if c not in LINEAR:
        raise InputError(f"unknown ISO 2768-1 class {cls!r} (f, m, c or v)")
    d = abs(float(nominal))
    if not 0.5 <= d <= LINEAR_STEPS[-1]:
        raise InputError(f"ISO 2768-1 covers 0.5 … {LINEAR_STEPS[-1]} mm, not {nominal:g} mm (give an individual "
                         "tolerance)")
    v = LINEAR[c][bisect_left(LINEAR_STEPS, d)]
    if v is None:
        raise InputError(f"ISO 2768-1 class {c} ({CLASS_NAMES[c]}) has no value at {nominal:g} mm (a dash in the "
                         "table): give an individual tolerance")
    return v


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
