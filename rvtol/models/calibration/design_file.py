"""Writing a design back to TOML, and reading a calibrated design's clearances.

:func:`design_toml` serialises a :class:`rvtol.design.Design` in the design format
(:mod:`rvtol.design`: every number a table ``{value, unit, source, note}``), groups as written
(``stiffness.sun_support`` → ``[stiffness] sun_support = {...}``; a derived number as its formula), so that
:func:`rvtol.design.load_design` reads back exactly the same parameters.  Comments of the original
file are not carried over; every number keeps its ``source`` and ``note``.

A calibrated design keeps the fitted clearances and error factors, which are not design numbers of
the 20-DOF model (they are factors of a tolerance spec), under ``[calibration.clearance]`` and
``[calibration.factor]``; :func:`calibrated_factors` turns them back into factor values.
"""
from __future__ import annotations

import json
import os
import re
import secrets
from pathlib import Path

from ...design import Design, load_design
from ...errors import InputError
from .parameters import CLEARANCES

CALIBRATION = "calibration"
_BARE = re.compile(r"^[A-Za-z0-9_-]+$")


def _key(k: str) -> str:
    return k if _BARE.match(k) else json.dumps(k, ensure_ascii=False)


def _value(v) -> str:
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, tuple):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    return repr(float(v))


def _split(name: str) -> tuple[str, str]:
    """``"a.b.c"`` -> ``("a.b", "c")``; names of quoted keys (``calibration.factor.E_c[1,2]``) keep their
    brackets, so split on the last dot outside brackets."""
    depth = 0
    for i in range(len(name) - 1, -1, -1):
        c = name[i]
        depth += c == "]"
        depth -= c == "["
        if c == "." and depth == 0:
            return name[:i], name[i + 1:]
    return "", name


def design_toml(design: Design, *, source: str = "", comments=()) -> str:
    """The design as TOML text (module docstring)."""
    lines = [f"# {c}" for c in comments]
    lines += ["", "[design]", f"name = {_value(design.name)}"]
    if design.description:
        lines.append(f"description = {_value(design.description)}")
    if source:
        lines.append(f"source = {_value(source)}")
    groups: dict[str, list[str]] = {}
    for name, p in design.params.items():
        group, key = _split(name)
        fields = [f"formula = {_value(p.formula)}" if p.formula else f"value = {_value(p.value)}",
                  f"unit = {_value(p.unit)}", f"source = {_value(p.source)}"]
        if p.note:
            fields.append(f"note = {_value(p.note)}")
        groups.setdefault(group, []).append(f"{_key(key)} = {{ {', '.join(fields)} }}")
    if "" in groups:
        raise InputError("a design parameter outside any group cannot follow the [design] table", key="design")
    for group, entries in groups.items():
        lines += ["", "[" + ".".join(_key(g) for g in _split_all(group)) + "]", *entries]
    return "\n".join(lines) + "\n"


def _split_all(group: str) -> list[str]:
    parts = []
    while group:
        group, last = _split(group)
        parts.append(last)
    return parts[::-1]


def write_design(design: Design, path: str | Path, *, source: str = "", comments=()) -> Design:
    """Write ``design`` to ``path`` atomically and return it as read back by ``load_design``.

    The text goes to a temporary file beside ``path``, is loaded and compared parameter by parameter,
    and only then replaces ``path`` (nothing half-written).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.parent / f".{path.name}.tmp-{secrets.token_hex(4)}"
    try:
        tmp.write_text(design_toml(design, source=source, comments=comments), encoding="utf-8")
        back = load_design(tmp)
        if dict(back.params) != dict(design.params):
            raise InputError("the written design does not read back as written", file=str(path), key="-")
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return load_design(path)


def calibrated_factors(design: Design) -> dict[str, float]:
    """``{error factor: base value}`` of the clearances and factors a calibration stored in ``design``."""
    out: dict[str, float] = {}
    for name in design.params:
        group, key = _split(name)
        if group == f"{CALIBRATION}.clearance":
            if key not in CLEARANCES:
                raise InputError(f"unknown clearance {key!r} (known: {', '.join(CLEARANCES)})",
                                 file=design.file, key=name)
            for f in CLEARANCES[key].factors:
                out[f] = float(design[name])
        elif group == f"{CALIBRATION}.factor":
            out[key] = float(design[name])
    return out
