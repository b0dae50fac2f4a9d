"""Drawing callouts: which factors of a spec stand for one tolerance on a drawing.

A drawing callout can be several factors: the x1, y1, x2, y2 end-point coordinates of one position
zone, the copies of a per-pin or per-groove family.  Sign-off drivers, the sensitivity matrix and the
allocation's "one ±t per callout" group factors by :func:`callout_of`.
"""
from __future__ import annotations

import re

#: factors whose last name component is one of these are coordinates of one drawing tolerance
_COORDINATE = re.compile(r"\.(x1|y1|x2|y2|x|y|z|u|v|w)$")
_INDEX = re.compile(r"\[[^\]]*\]")


def callout_of(factor) -> str:
    """The callout a factor belongs to — the name of the one tolerance on the drawing it stands for: its ``feature``
    (with its part) when the spec says, else its name without a coordinate suffix (``.x1`` … ``.y``) and without a
    family index (``[k]``).  (A factor's tolerance as written in drawing notation is another thing:
    :func:`rvtol.spec.forms.drawing_tolerance`.)"""
    feat = getattr(factor, "feature", "") or ""
    part = getattr(factor, "part", "") or ""
    if feat:
        return f"{part}: {feat}" if part else feat
    return _INDEX.sub("[k]", _COORDINATE.sub("", factor.name)) if ("[" in factor.name or _COORDINATE.search(
        factor.name)) else factor.name


def short_label(tolerance: str, width: int = 70) -> str:
    """A drawing tolerance's name without its parenthesised details, for a table cell: ``crankshaft 1: eccentric cam 1
    (for disc 1, ...): position ⌀0.006 to the journal axis A-B (x: ...)`` → ``crankshaft 1: eccentric cam 1: position
    ⌀0.006 to the journal axis A-B``; cut at ``width`` characters with an ellipsis."""
    out, depth = [], 0
    for ch in tolerance:
        if ch == "(":
            depth += 1
        elif ch == ")" and depth:
            depth -= 1
        elif not depth:
            out.append(ch)
    text = re.sub(r"\s+", " ", "".join(out)).replace(" :", ":").replace(" ,", ",").strip(" ,:")
    return text if len(text) <= width else text[:width - 1].rstrip() + "…"
