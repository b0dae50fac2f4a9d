"""Measured curves from table files: a hysteresis (torsion) curve or a transmission-error curve.

File format (CSV, TSV or an XLSX sheet, read by :func:`rvtol.inputs.sheets.read_table`; rows starting
with ``#`` are comments; the first other row is the header)::

    # SYNTHETIC hysteresis curve of the RV-80E ...
    torque [N*m], angle [arcsec], sigma [arcsec]
    0.0, 0.41, 0.5
    19.6, 6.02, 0.5
    ...

Columns are recognised by name (case-insensitive; the unit in brackets after a space, or from
``units`` when the header has none):

=====================  ========================================================================
torsion curve          ``torque`` (output torque, positive turns the output forward) and ``angle``
                       (output torsion angle, input locked, same sense)
transmission error     ``output_angle`` or ``input_angle`` (the input angle is divided by the
                       ratio: the nominal output angle θ_c) and ``te`` (output-side transmission
                       error θ_out − θ_in / i, rvtol's Δθ_ca)
either                 ``sigma``: standard uncertainty of each measured angle / TE (the unit of
                       the measured column unless its own is given); or one ``sigma`` for all
=====================  ========================================================================

Other columns (time, temperature...) are read past and listed in :attr:`Measurement.ignored`.
Which curve a file holds follows from its columns.  Every problem is one :class:`InputError`
naming the file and the row/column (``FILE: row 12, column 'angle [arcsec]': not a number``).
Values are returned in base units (N·mm, rad).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ... import units
from ...errors import InputError
from ...inputs.sheets import Table, read_table

TORSION = "torsion"
TE = "transmission_error"
KINDS = (TORSION, TE)

#: recognised column names -> dimension
COLUMNS = {"torque": "torque", "angle": "angle", "output_angle": "angle", "input_angle": "angle",
           "te": "angle", "sigma": "angle"}


@dataclass(frozen=True)
class Measurement:
    """One measured curve (base units). ``x``: output torque (N·mm) or nominal output angle θ_c (rad);
    ``y``: torsion angle or TE (rad); ``sigma``: per-point standard uncertainty (rad) or None."""

    kind: str
    name: str
    file: str
    sha256: str
    x: np.ndarray
    y: np.ndarray
    sigma: np.ndarray | None
    x_label: str                       # e.g. "torque [N*m]" as in the header
    y_label: str
    x_unit: str                        # display units (the file's)
    y_unit: str
    lines: np.ndarray                  # row number of each point in the file (1-based)
    ignored: tuple[str, ...] = ()
    include: np.ndarray | None = None  # points the fit uses (default all)
    load_torque: float | None = None   # TE only: resisting output torque (N·mm)
    ratio_divided: bool = False        # TE: x came from an input angle divided by the ratio
    notes: tuple[str, ...] = field(default=())

    @property
    def n(self) -> int:
        return int(self.x.size)

    @property
    def used(self) -> np.ndarray:
        return np.ones(self.n, bool) if self.include is None else self.include

    @property
    def x_display(self) -> np.ndarray:
        return units.from_base(self.x, self.x_unit)

    @property
    def y_display(self) -> np.ndarray:
        return units.from_base(self.y, self.y_unit)


def _header(t: Table, given_units: dict[str, str]) -> dict[str, tuple[int, str, str]]:
    """``{name: (index, unit, header cell)}`` of the recognised columns."""
    out: dict[str, tuple[int, str, str]] = {}
    for i, cell in enumerate(t.cells):
        name = t.names[i].strip().lower().replace(" ", "_")
        if name not in COLUMNS:
            continue
        if name in out:
            raise t.error(f"column {name!r} appears twice", col=i)
        unit = t.unit(i)
        key = given_units.get(name)
        if unit and key and unit != units.canonical(key):
            raise t.error(f"the header says [{t.units[i]}], the 'units' key says {key!r}", col=i)
        unit = unit or key
        if unit:
            try:
                unit = units.canonical(unit)
                units.require_dimension(unit, COLUMNS[name])
            except InputError as exc:
                raise t.error(exc.reason, col=i) from None
        out[name] = (i, unit or "", cell)
    return out


def load_measurement(path: str | Path, *, column_units: dict[str, str] | None = None, sigma: float | None = None,
                     exclude_below: float = 1.0, load_torque: float | None = None, ratio: float | None = None,
                     name: str | None = None, min_points: int = 3) -> Measurement:
    """Read a measured curve (module docstring).

    ``column_units``: units of columns whose header has none (``{"angle": "arcsec"}``); ``sigma``: one
    standard uncertainty (base units) for every point when the file has no ``sigma`` column;
    ``exclude_below`` (torsion curve): points with ``|torque|`` below this percentage of the largest
    measured torque are kept out of the fit (the frictionless 20-DOF curve jumps across the
    clearances at zero torque, where its equilibrium is not unique); ``load_torque`` (TE, N·mm):
    the resisting output torque of the measurement; ``ratio``: the reducer ratio, needed for an
    ``input_angle`` column.
    """
    t = read_table(path, what="e.g. 'torque [N*m], angle [arcsec]'")
    file = t.file
    given = {k.lower(): v for k, v in (column_units or {}).items()}
    for k in given:
        if k not in COLUMNS:
            raise InputError(f"unknown column {k!r} in 'units' (known: {', '.join(COLUMNS)})", file=file, key="units")
    cols = _header(t, given)
    if "torque" in cols and "te" in cols:
        raise t.error("both 'torque' and 'te' columns: give a torsion curve or a TE curve")
    if "torque" in cols or "angle" in cols:
        kind, need = TORSION, ("torque", "angle")
    elif "te" in cols or "output_angle" in cols or "input_angle" in cols:
        kind = TE
        if "output_angle" in cols and "input_angle" in cols:
            raise t.error("give 'output_angle' or 'input_angle', not both")
        need = ("input_angle" if "input_angle" in cols else "output_angle", "te")
    else:
        raise t.error("no recognised columns: a torsion curve needs 'torque' and 'angle', a TE curve 'output_angle' "
                      "(or 'input_angle') and 'te'")
    for c in need:
        if c not in cols:
            raise t.error(f"missing column {c!r}")
    for c in need:
        if not cols[c][1]:
            raise t.error(f"no unit: write '{c} [unit]' or give units = {{{c} = ...}}", col=cols[c][0])
    if "sigma" in cols and sigma is not None:
        raise t.error("a sigma column and a sigma key: give one", col=cols["sigma"][0])
    xname, yname = need
    sig_unit = cols["sigma"][1] or cols[yname][1] if "sigma" in cols else None
    ncols = len(t.cells)
    rows = t.rows
    data = np.empty((len(rows), 3))
    lines = np.empty(len(rows), int)
    for r, (row, cells) in enumerate(rows):
        if len(cells) != ncols:
            raise t.error(f"{len(cells)} fields, the header has {ncols}", row)
        for j, c in enumerate((xname, yname, "sigma")):
            if c not in cols:
                data[r, j] = np.nan
                continue
            i, unit, _ = cols[c]
            v = t.number(row, cells, i)
            if c == "sigma" and not v > 0:
                raise t.error(f"an uncertainty must be > 0, got {cells[i]!r}", row, i)
            data[r, j] = units.to_base(v, unit if c != "sigma" else sig_unit)
        lines[r] = row
    hline = t.header_row
    if len(rows) < min_points:
        raise InputError(f"{len(rows)} data rows; need at least {min_points}", file=file, key=t.location.key(hline))
    x, y = data[:, 0], data[:, 1]
    if sigma is not None:
        if not (np.isfinite(sigma) and sigma > 0):
            raise InputError(f"sigma must be > 0, got {sigma}", file=file, key="sigma")
        s = np.full(x.size, float(sigma))
    else:
        s = data[:, 2] if "sigma" in cols else None
    notes = []
    ratio_divided = False
    if xname == "input_angle":
        if ratio is None or not ratio > 0:
            raise t.error("an input angle needs the reducer ratio", col=cols[xname][0])
        x = x / ratio
        ratio_divided = True
        notes.append(f"input angle divided by the ratio {ratio:g} (nominal output angle)")
    if kind == TORSION:
        if not 0.0 <= exclude_below < 100.0:
            raise InputError(f"exclude_below must lie in [0, 100) %, got {exclude_below}", file=file,
                             key="exclude_below")
        top = float(np.max(np.abs(x)))
        if not top > 0:
            raise t.error("every torque is zero", col=cols["torque"][0])
        include = (np.abs(x) >= exclude_below / 100.0 * top) & (x != 0.0)
        if (~include).any():
            notes.append(f"{int((~include).sum())} point(s) with |torque| < {exclude_below:g} % of the largest "
                         f"({units.from_base(top, cols['torque'][1]):g} {cols['torque'][1]}) or exactly zero left "
                         "out of the fit")
        if not (x[include] > 0).any() or not (x[include] < 0).any():
            notes.append("torques of one sign only: an angle offset and a clearance cannot be told apart")
        if include.sum() < min_points:
            raise InputError(f"{int(include.sum())} points left after exclude_below = {exclude_below:g} %",
                             file=file, key="exclude_below")
    else:
        include = np.ones(x.size, bool)
        if load_torque is not None and not load_torque > 0:
            raise InputError(f"load torque must be > 0, got {load_torque}", file=file, key="load_torque")
    ignored = tuple(c for i, c in enumerate(t.cells) if i not in {v[0] for v in cols.values()})
    return Measurement(kind, name or Path(file).stem, file, t.sha256, x, y, s, cols[xname][2], cols[yname][2],
                       cols[xname][1], cols[yname][1], lines, ignored, include,
                       load_torque if kind == TE else None, ratio_divided, tuple(notes))
