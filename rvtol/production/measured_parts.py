"""Measured parts: one table file per part family, one row per serial number, and a kit list.

**Part family file** (CSV, TSV or an XLSX sheet, read by :func:`rvtol.inputs.sheets.read_table`; rows
starting with ``#`` are comments — say there where the numbers come from; the first other row is the
header)::

    # crankshafts of the RV-80E, CMM report 2026-03 (cam positions to A-B), u: CMM MPE/√3
    serial, cam_1.position.x1 [um], cam_1.position.y1 [um], cam_1.form [um], cam_1.form.u [um]
    uncertainty, 0.3, 0.3, ,
    C-0001, 0.42, -1.10, 0.6, 0.2
    C-0002, -0.85, 0.31, 0.9, 0.2

* ``serial``: the part's serial number (unique in the file);
* a **feature column** holds a measured value of a drawing-spec factor, in the spec's own terms
  (the deviation from the drawing nominal the factor stands for).  Its name is the factor's name
  without the part's place in the reducer (its *slot*): the family is declared with the slots its
  parts can take (``crank_1``, ``crank_2``, ``crank_3``), and a crankshaft in slot ``crank_2``
  gives the factor ``crank_2.cam_1.position.x1``.  A family index joins without a dot: column
  ``[7].diameter_in_lot`` in slot ``pins`` is ``pins[7].diameter_in_lot``.  The unit in brackets
  after a space (``cam_1.form [um]``); without one, the factor's unit in the spec.  A name with a
  comma (``"E_c[1,2]"``) is quoted, as CSV quotes any cell;
* **measurement uncertainty** of every feature column: the standard uncertainty u (k = 1, GUM) of
  one reading, in the column's unit — either in the row whose serial is ``uncertainty`` (one value
  for every part) or in a column ``<feature>.u`` (one per part; its own unit in brackets or the
  feature's) — or from a **gauge study** the study names for the feature (``[[analysis.parts.gauge]]``,
  :mod:`rvtol.production.msa`: u = √(σ²_GRR + u_cal²) of its crossed gauge R&R).  Exactly one of the three
  for each feature; 0 means exact;
* every cell of a part row holds a finite number (a feature measured on some parts only belongs
  in another file: one file per inspection plan).

**Kit list** (same conventions)::

    # which serial parts form which reducer (assembly records)
    reducer, housing, pins, disc_1, disc_2, crank_1, crank_2, crank_3
    RV80E-0001, H-0001, P-0003, D-0007, D-0008, C-0001, C-0002, C-0003

``reducer`` is the reducer's serial number; one column per slot of the declared families (all of
them), holding the serial of the part in that slot or ``-`` when that slot's part was not measured
(its factors are then sampled from the spec).  A part belongs to one reducer, in one slot.

**QIF and DFQ.**  A part family may come as the inspection room writes it — a QIF 3.0 file (``.qif``, ``.xml``:
MeasurementResults, one per serial) or a Q-DAS DFQ file (``.dfq``: one value set per serial, K0014 the serial)
— with a mapping file (characteristic → feature column, reading, unit, uncertainty): :mod:`rvtol.inputs.inspection`
turns the two into the table above, read from then on as a CSV is.

Every problem is one :class:`~rvtol.errors.InputError` naming the file and the row and column
(``FILE: row 5, column 'cam_1.form [um]': not a number: 'x'``; in a workbook also the sheet).  Values
are returned in base units (mm, rad).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np
import pandas as pd

from .. import units
from ..errors import InputError, did_you_mean
from ..inputs.sheets import Table, read_table
from .msa import Gauge

SERIAL = "serial"
REDUCER = "reducer"
UNCERTAINTY_ROW = "uncertainty"
U_SUFFIX = ".u"
NOT_MEASURED = "-"


def factor_name(slot: str, column: str) -> str:
    """The spec factor a feature column stands for in ``slot`` (``crank_2`` + ``cam_1.form``)."""
    return f"{slot}{column}" if column.startswith("[") else f"{slot}.{column}"


def _text(v) -> str:
    """A cell as text (an XLSX serial number may be a number)."""
    return v if isinstance(v, str) else (f"{v:g}" if isinstance(v, float) else str(v))


def _nonnegative(t: Table, row: int, cells: list, col: int) -> float:
    v = t.number(row, cells, col)
    if v < 0:
        raise t.error(f"an uncertainty must be >= 0, got {cells[col]!r}", row, col)
    return v


def uncertainty_row(t: Table) -> tuple[tuple[int, list] | None, list[tuple[int, list]]]:
    """``(uncertainty row, other rows)`` of a table whose first column names each row (a serial, a reducer): the
    row named ``uncertainty`` (at most one; None without) and the others, each ``(row number, cells)``, every row
    with as many fields as the header."""
    u_row: tuple[int, list] | None = None
    rows: list[tuple[int, list]] = []
    for row, cells in t.rows:
        if len(cells) != len(t.names):
            raise t.error(f"{len(cells)} fields, the header has {len(t.names)}", row)
        if _text(cells[0]).lower() == UNCERTAINTY_ROW:
            if u_row is not None:
                raise t.error(f"a second {UNCERTAINTY_ROW!r} row (the first on row {u_row[0]})", row, 0)
            u_row = (row, cells)
        else:
            rows.append((row, cells))
    return u_row, rows


# --------------------------------------------------------------------------- part families
@dataclass(frozen=True)
class PartFamily:
    """The measured parts of one family (base units)."""

    name: str
    file: str
    sha256: str
    slots: tuple[str, ...]
    columns: tuple[str, ...]          # feature names, relative to the slot
    units: tuple[str, ...]            # unit each column was written in
    serials: tuple[str, ...]
    lines: tuple[int, ...]            # row of each part in the file
    values: np.ndarray                # [parts, columns], base units
    uncertainty: np.ndarray           # [parts, columns], standard uncertainty, base units
    gauges: tuple[Gauge, ...] = ()    # the gauge studies some columns' uncertainty comes from
    mapping: tuple[str, str] | None = None   # (path, sha256) of a QIF/DFQ file's mapping

    def row(self, serial: str) -> int:
        return self.serials.index(serial)

    def factors(self, slot: str) -> tuple[str, ...]:
        return tuple(factor_name(slot, c) for c in self.columns)


def family_table(path, mapping=None) -> Table:
    """The table of a part family file: rvtol's CSV/TSV/XLSX, or a QIF/DFQ file read through its ``mapping``
    (:func:`rvtol.inputs.inspection.mapped_table`: the same table, so both take one code path after reading)."""
    from ..inputs import inspection

    if inspection.is_inspection_file(path):
        if mapping is None:
            raise InputError(f"a {Path(path).suffix} file needs a mapping file (characteristic -> feature)",
                             file=str(path), key="mapping")
        return inspection.mapped_table(path, mapping)
    if mapping is not None:
        raise InputError("a mapping is for a QIF (.qif, .xml) or DFQ (.dfq) file, not a table", file=str(path),
                         key="mapping")
    return read_table(path, what="serial, <feature> [unit], ...")


def read_part_family(path, slots: Sequence[str], spec, name: str | None = None, gauges: Sequence[Gauge] = (),
                     mapping=None) -> PartFamily:
    """Read and check one part family file (module docstring) against ``spec``'s factors; ``gauges``: gauge
    studies giving the uncertainty of the features they name (:class:`~rvtol.production.msa.Gauge`); a QIF or
    DFQ file through its ``mapping`` file (:func:`family_table`)."""
    t = family_table(path, mapping)
    slots = tuple(slots)
    if not slots:
        raise InputError("a part family needs at least one slot", file=t.file, key="slots")
    names = t.names
    if names.count(SERIAL) != 1 or names[0] != SERIAL:
        raise t.error(f"the first column must be {SERIAL!r} (once)", col=0)
    dup = next((i for i, n in enumerate(names) if n in names[:i]), None)
    if dup is not None:
        raise t.error("column appears twice", col=dup)
    features = [i for i, n in enumerate(names) if i > 0 and not n.endswith(U_SUFFIX)]
    if not features:
        raise t.error("no feature columns")
    col_units = _feature_units(t, names, features, slots, spec)
    u_cols = _uncertainty_columns(t, names, features, col_units)
    by_gauge = _gauged_features(t, names, features, col_units, gauges)
    u_row, parts = uncertainty_row(t)
    if not parts:
        raise t.error("no parts (rows) in the file")
    row_u = _row_uncertainties(t, names, features, col_units, u_cols, by_gauge, u_row)
    serials, lines, values, unc = _parts(t, parts, features, col_units, u_cols, row_u)
    m = getattr(t, "mapping", None)
    return PartFamily(name or Path(t.file).stem, t.file, t.sha256, slots, tuple(names[i] for i in features),
                      tuple(col_units), tuple(serials), tuple(lines), values, unc, tuple(gauges),
                      (m.file, m.sha256) if m is not None else None)


def _feature_units(t, names: list[str], features: list[int], slots: tuple[str, ...], spec) -> list[str]:
    """Each feature column's unit (its header's, else its factors'): the factor of every slot in the spec, of one
    dimension."""
    col_units: list[str] = []
    for i in features:
        fnames = [factor_name(s, names[i]) for s in slots]
        missing = [f for f in fnames if f not in spec.names]
        if missing:
            raise t.error(f"no factor {missing[0]!r} in the spec {spec.name!r} (column name = factor name without "
                          f"the slot {slots[0]!r})", col=i)
        fu = spec.factor(fnames[0]).unit
        for f in fnames[1:]:
            if units.dimension(spec.factor(f).unit) != units.dimension(fu):
                raise t.error(f"factors {fnames[0]!r} and {f!r} have different dimensions", col=i)
        unit = t.unit(i) or fu
        if units.dimension(unit) != units.dimension(fu):
            raise t.error(f"unit {unit!r} does not fit the factor's unit {fu!r}", col=i)
        col_units.append(unit)
    return col_units


def _uncertainty_columns(t, names: list[str], features: list[int], col_units: list[str]) -> dict[int, tuple[int, str]]:
    """feature index -> (column, unit) of its per-part uncertainty column ``<feature> u``."""
    u_cols: dict[int, tuple[int, str]] = {}
    for i, n in enumerate(names):
        if i == 0 or not n.endswith(U_SUFFIX):
            continue
        base = n[: -len(U_SUFFIX)]
        if base not in names or base.endswith(U_SUFFIX):
            raise t.error(f"an uncertainty column without its feature column {base!r}", col=i)
        j = features.index(names.index(base))
        unit = t.unit(i) or col_units[j]
        if units.dimension(unit) != units.dimension(col_units[j]):
            raise t.error(f"unit {unit!r} does not fit the feature's unit {col_units[j]!r}", col=i)
        u_cols[j] = (i, unit)
    return u_cols


def _gauged_features(t, names: list[str], features: list[int], col_units: list[str], gauges) -> dict[int, Gauge]:
    """feature index -> the gauge study measuring it (one at most, reading in the feature's dimension)."""
    by_gauge: dict[int, Gauge] = {}
    for g in gauges:
        for f in g.features:
            if f not in names or names.index(f) not in features:
                raise t.error(f"no feature column {f!r} for the gauge study {Path(g.result.file).name!r}"
                              f"{did_you_mean(f, [names[i] for i in features])}")
            j = features.index(names.index(f))
            if j in by_gauge:
                raise t.error(f"feature {f!r} has two gauge studies ({Path(by_gauge[j].result.file).name!r} and "
                              f"{Path(g.result.file).name!r})", col=features[j])
            if g.unit is not None and units.dimension(g.unit) != units.dimension(col_units[j]):
                raise t.error(f"the gauge study {Path(g.result.file).name!r} reads in {g.unit!r}, which does not fit "
                              f"the feature's unit {col_units[j]!r}", col=features[j])
            by_gauge[j] = g
    return by_gauge


def _row_uncertainties(t, names, features, col_units, u_cols, by_gauge, u_row) -> np.ndarray:
    """Each feature's uncertainty for every part (base units): its gauge study's or the uncertainty row's — NaN
    where a per-part column gives it; exactly one of the three per feature."""
    row_u = np.full(len(features), np.nan)
    for j, i in enumerate(features):
        cell = u_row[1][i] if u_row else ""
        if j in by_gauge:
            typed = (u_row[0], i) if cell != "" else ((None, u_cols[j][0]) if j in u_cols else None)
            if typed is not None:
                raise t.error(f"an uncertainty here and the gauge study {Path(by_gauge[j].result.file).name!r} for "
                              "this feature: give one", *typed)
            row_u[j] = units.to_base(by_gauge[j].u, by_gauge[j].unit or col_units[j])
            continue
        if j in u_cols:
            if cell != "":
                raise t.error(f"an uncertainty here and a column {t.cells[u_cols[j][0]]!r}: give one", u_row[0], i)
            continue
        if cell == "":
            raise t.error(f"no measurement uncertainty: give it in the {UNCERTAINTY_ROW!r} row, a column "
                          f"'{names[i]}{U_SUFFIX}' or a gauge study ([[analysis.parts.gauge]])",
                          u_row[0] if u_row else None, i)
        row_u[j] = units.to_base(_nonnegative(t, u_row[0], u_row[1], i), col_units[j])
    if u_row:
        for i, cell in enumerate(u_row[1]):
            if i > 0 and i not in features and cell != "":
                raise t.error(f"the {UNCERTAINTY_ROW!r} row has no entry for an uncertainty column", u_row[0], i)
    return row_u


def _parts(t, parts, features, col_units, u_cols, row_u):
    """``(serials, file lines, values, uncertainties)`` of the measured parts (base units), each serial once."""
    serials, lines = [], []
    values = np.empty((len(parts), len(features)))
    unc = np.empty_like(values)
    seen: dict[str, int] = {}
    for r, (row, cells) in enumerate(parts):
        s = _text(cells[0])
        if not s:
            raise t.error("empty serial number", row, 0)
        if s == NOT_MEASURED:
            raise t.error(f"{NOT_MEASURED!r} is not a serial number (it marks an unmeasured slot in a kit list)",
                          row, 0)
        if s in seen:
            raise t.error(f"serial {s!r} appears twice (also on row {seen[s]})", row, 0)
        seen[s] = row
        serials.append(s)
        lines.append(row)
        for j, i in enumerate(features):
            values[r, j] = units.to_base(t.number(row, cells, i), col_units[j])
            if j in u_cols:
                ui, uunit = u_cols[j]
                unc[r, j] = units.to_base(_nonnegative(t, row, cells, ui), uunit)
            else:
                unc[r, j] = row_u[j]
    return serials, lines, values, unc


# --------------------------------------------------------------------------- kit list
@dataclass(frozen=True)
class Kit:
    """One reducer: its serial and, per slot, the serial of its measured part (None: not measured)."""

    reducer: str
    line: int                          # its row in the kit list
    parts: dict[str, str | None]


def read_kit_list(path, slots: Sequence[str]) -> tuple[Table, list[Kit]]:
    """``(table, kits)`` of a kit list whose columns are ``reducer`` and exactly ``slots``."""
    t = read_table(path, what="reducer, <slot>, ...")
    head = t.cells
    if not head or head[0] != REDUCER:
        raise t.error(f"the first column must be {REDUCER!r}", col=0 if head else None)
    for i, c in enumerate(head):
        if c in head[:i]:
            raise t.error("column appears twice", col=i)
    unknown = [i for i, c in enumerate(head) if i > 0 and c not in slots]
    if unknown:
        raise t.error(f"not a slot of the declared part families (slots: {', '.join(slots)})", col=unknown[0])
    missing = [s for s in slots if s not in head]
    if missing:
        raise t.error(f"no column for slot {missing[0]!r} (write {NOT_MEASURED!r} where a reducer's part in that slot "
                      "was not measured)")
    kits, seen = [], {}
    for row, cells in t.rows:
        if len(cells) != len(head):
            raise t.error(f"{len(cells)} fields, the header has {len(head)}", row)
        red = _text(cells[0])
        if not red:
            raise t.error("empty reducer serial number", row, 0)
        if red in seen:
            raise t.error(f"reducer {red!r} appears twice (also on row {seen[red]})", row, 0)
        seen[red] = row
        parts = {}
        for i, (c, v) in enumerate(zip(head[1:], cells[1:]), start=1):
            v = _text(v)
            if not v:
                raise t.error(f"empty cell: a serial number, or {NOT_MEASURED!r} when not measured", row, i)
            parts[c] = None if v == NOT_MEASURED else v
        kits.append(Kit(red, row, parts))
    if not kits:
        raise t.error("no reducers in the kit list")
    return t, kits


# --------------------------------------------------------------------------- the measured units
@dataclass(frozen=True)
class FamilySource:
    """Where a part family is read from and which slots its parts take."""

    file: Path
    slots: tuple[str, ...]
    name: str | None = None
    gauges: tuple[Gauge, ...] = ()                    # gauge studies giving features' uncertainty
    mapping: Path | None = None       # a QIF or DFQ file's mapping (rvtol.inputs.inspection)


@dataclass(frozen=True)
class MeasuredUnits:
    """What is known of each kitted reducer: measured factor values and their uncertainty.

    ``value`` and ``uncertainty`` are ``[units, factors]`` in base units in the spec's factor order;
    ``value`` is NaN where the factor was not measured on that unit (it is then sampled from the spec).
    """

    names: tuple[str, ...]            # the spec's factors
    units: tuple[str, ...]            # the reducers' serial numbers
    value: np.ndarray
    uncertainty: np.ndarray
    kits: tuple[Kit, ...]
    families: tuple[PartFamily, ...]
    kit_file: str = ""
    kit_sha256: str = ""

    @property
    def measured(self) -> np.ndarray:
        return np.isfinite(self.value)

    def __len__(self) -> int:
        return len(self.units)

    def files(self) -> dict[str, dict]:
        """Role -> ``{path, sha256}`` of every file read (for the study's input record)."""
        out = {"kit_list": {"path": self.kit_file, "sha256": self.kit_sha256}}
        for f in self.families:
            out[f"parts:{f.name}"] = {"path": f.file, "sha256": f.sha256}
            if f.mapping is not None:
                out[f"mapping:{f.name}"] = {"path": f.mapping[0], "sha256": f.mapping[1]}
            for g in f.gauges:
                out[f"gauge:{f.name}:{Path(g.result.file).name}"] = {"path": g.result.file, "sha256": g.result.sha256}
        return out

    def gauge_frame(self) -> pd.DataFrame | None:
        """One row per gauge study (family, features, the gauge R&R figures, u), None without gauge studies."""
        rows = [{"family": f.name, **g.row()} for f in self.families for g in f.gauges]
        return pd.DataFrame(rows) if rows else None

    def to_frame(self) -> pd.DataFrame:
        """One row per reducer: serial, number of measured factors, the part serial in every slot."""
        rows = []
        for i, k in enumerate(self.kits):
            rows.append({"reducer": k.reducer, "measured factors": int(self.measured[i].sum()),
                         **{s: (v if v is not None else NOT_MEASURED) for s, v in k.parts.items()}})
        return pd.DataFrame(rows)


def load_measured_units(spec, kit_list, families: Sequence[FamilySource]) -> MeasuredUnits:
    """Read the part families and the kit list; every reducer's measured factors (module docstring)."""
    fams = [read_part_family(f.file, f.slots, spec, f.name, f.gauges, f.mapping) for f in families]
    names = [f.name for f in fams]
    dup = next((n for i, n in enumerate(names) if n in names[:i]), None)
    if dup is not None:
        raise InputError(f"two part families are named {dup!r}: give each a name", file=fams[0].file, key="name")
    slot_family: dict[str, PartFamily] = {}
    claimed: dict[str, tuple[str, str]] = {}          # factor -> (family, slot)
    for fam in fams:
        for s in fam.slots:
            if s in slot_family:
                raise InputError(f"slot {s!r} is declared by families {slot_family[s].name!r} and {fam.name!r}",
                                 file=fam.file, key="slots")
            slot_family[s] = fam
            for f in fam.factors(s):
                if f in claimed:
                    raise InputError(f"factor {f!r} is measured by family {claimed[f][0]!r} (slot {claimed[f][1]!r}) "
                                     f"and {fam.name!r} (slot {s!r})", file=fam.file, key="slots")
                claimed[f] = (fam.name, s)
    kt, kits = read_kit_list(kit_list, list(slot_family))
    k = len(spec.names)
    value = np.full((len(kits), k), np.nan)
    unc = np.zeros((len(kits), k))
    used: dict[tuple[str, str], tuple[str, int]] = {}
    index = {n: j for j, n in enumerate(spec.names)}
    for u, kit in enumerate(kits):
        for slot, serial in kit.parts.items():
            if serial is None:
                continue
            fam = slot_family[slot]
            if serial not in fam.serials:
                raise kt.error(f"no part {serial!r} in {fam.file} (family {fam.name!r})", kit.line,
                               kt.cells.index(slot))
            if (fam.name, serial) in used:
                red, line = used[(fam.name, serial)]
                raise kt.error(f"part {serial!r} of family {fam.name!r} is already in reducer {red!r} (row {line})",
                               kit.line, kt.cells.index(slot))
            used[(fam.name, serial)] = (kit.reducer, kit.line)
            r = fam.row(serial)
            cols = [index[f] for f in fam.factors(slot)]
            value[u, cols] = fam.values[r]
            unc[u, cols] = fam.uncertainty[r]
    return MeasuredUnits(tuple(spec.names), tuple(k.reducer for k in kits), value, unc, tuple(kits), tuple(fams),
                         kt.file, kt.sha256)
