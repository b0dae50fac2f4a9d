"""A tolerance spec as a table (CSV or XLSX), one row per factor — and back.

The layout a quality engineer keeps in a spreadsheet::

    #spec          rv80e_axial_stack
    #description   Cycloid disc axial clearance
    #correlation   disc1_width   disc2_width   0.5
    name         part      feature        nominal  tolerance     distribution      unit  coefficient  source
    carrier_gap  carrier   flange gap     24.08    ±0.0105       normal(shift=0.003) mm   +1           ISO 286 IT7
    disc1_width  disc 1    face width     12       h6            normal            mm    -1           doc 000 Table 1
    bore         housing   bearing seat   62       +0.030/0      uniform           mm                 drawing 4711

* **Columns** (any order, case-insensitive; aliases in brackets): ``name`` (factor), ``part``
  (group, component), ``feature`` (description), ``nominal``, ``tolerance`` (tol) in drawing
  notation (:mod:`rvtol.inputs.notation`: ``±0.05``, ``+0.10/-0.00``, ``h6``, ``25 H7/g6``,
  ``max 0.02``, ``Cpk 1.33 k 0.25``…) *or* the two columns ``+tol`` (upper) and ``-tol``
  (lower; its size is taken below the nominal, ``0.05`` and ``-0.05`` both mean −0.05),
  ``distribution`` (dist; default ``normal``), ``unit`` (units), ``coefficient`` (direction,
  sign: ``+``, ``-``, ``+1``, ``-0.5``… for a linear stack), ``source`` (reference);
  ``notes``/``comment`` columns are ignored.  ``name`` and ``unit`` are required (the unit may
  come from the tolerance, e.g. ``25 H7`` is in mm).
* **Distribution cell**: a kind of :mod:`rvtol.distributions` read over the tolerance band
  (``normal`` at ±3σ, ``uniform``, ``triangular``, ``truncnorm``, ``rayleigh``/``weibull``
  for magnitudes), optionally with parameters that refine or override what the band gives:
  ``normal(sigma_level=4, shift=0.003)``, ``weibull(shape=2)``, ``truncnorm(sigma=0.5)``,
  ``lognormal(median=2, shape=0.3)`` (no band needed).  Parameters are numbers in the row's unit.
* **Nominal**: blank means the factor is itself a deviation (the band sits about 0) or the
  tolerance gives absolute limits; the factor's ``nominal`` (the base point of local
  sensitivities) is then its mean, as in a TOML spec.
* **Metadata rows** start with ``#`` in the first cell: ``#spec`` (name), ``#description``,
  ``#correlation a b rho`` (a Gaussian-copula pair, as ``[[correlation]] pair``); ``# text``
  (hash, space) is a comment.  Blank rows are skipped.

Every problem is one line naming the file, the sheet (XLSX), the row and the column:
``stack.xlsx: sheet 'spec', row 7, column 'tolerance' (E): cannot read tolerance '0.05': …``.

:func:`write_table_spec` writes a :class:`~rvtol.spec.ToleranceSpec` in this layout (CSV in
UTF-8 with a byte-order mark, so Excel shows ``±`` and ``µ``; XLSX with openpyxl); reading it
back gives the same spec to 12 significant digits (the numbers are written that way).
"""
from __future__ import annotations

import csv
import datetime as _dt
import io
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

from .. import units
from ..distributions import KINDS, Distribution
from ..errors import InputError, SpecError
from ..model import LinearModel, Quantity
from ..params import Params
from ..spec import ToleranceSpec, correlation_from_tables, factor_from_params, spec_from_table
from .notation import NotationError, Tolerance, fmt, format_deviations, format_limits, parse_tolerance

COLUMNS = ("name", "part", "feature", "nominal", "tolerance", "distribution", "unit", "coefficient",
           "source")
_ALIASES = {
    "name": "name", "factor": "name",
    "part": "part", "group": "part", "component": "part",
    "feature": "feature", "description": "feature",
    "nominal": "nominal",
    "tolerance": "tolerance", "tol": "tolerance", "drawing tolerance": "tolerance",
    "+tol": "upper", "+ tol": "upper", "upper": "upper", "upper tol": "upper", "plus tol": "upper",
    "upper deviation": "upper",
    "-tol": "lower", "- tol": "lower", "lower": "lower", "lower tol": "lower", "minus tol": "lower",
    "lower deviation": "lower",
    "distribution": "distribution", "dist": "distribution",
    "unit": "unit", "units": "unit",
    "coefficient": "coefficient", "coef": "coefficient", "direction": "coefficient", "dir": "coefficient",
    "sign": "coefficient",
    "source": "source", "reference": "source", "ref": "source",
    "notes": None, "note": None, "comment": None, "comments": None, "remarks": None,
}
#: distribution parameters a distribution cell may set
CELL_KEYS = ("mean", "sigma", "tolerance", "lower", "upper", "mode", "median", "shape", "scale", "shift",
             "sigma_level")
_DIRECTIVES = ("spec", "description", "correlation")
_NUMBER = re.compile(r"^[+-]?(?:\d+(?:[.,]\d*)?|[.,]\d+)$")


@dataclass(frozen=True)
class TableSpec:
    """What a table holds: the spec, each row's drawing tolerance and stack coefficient."""

    spec: ToleranceSpec
    coefficients: dict[str, float] = field(default_factory=dict)   # factor -> coefficient (rows that have one)
    tolerances: dict[str, Tolerance | None] = field(default_factory=dict)  # the drawing band of each row
    rows: dict[str, int] = field(default_factory=dict)            # factor -> row number in the file

    def linear_model(self, output: str = "stack", unit: str | None = None,
                     display_unit: str | None = None) -> LinearModel:
        """The linear stack ``Σ coefficient·factor`` (base units) as a :class:`LinearModel`.

        Factors without a coefficient take 0.  ``unit``: the output's unit (default: the first
        factor's), ``display_unit`` the unit to report in.
        """
        if not self.coefficients:
            raise SpecError("no row has a coefficient (direction) for a linear stack", file=self.spec.file,
                            key="coefficient")
        u = unit or self.spec.factors[0].unit
        q = Quantity(output, units.base_unit(u), display_unit or u)
        row = [self.coefficients.get(n, 0.0) for n in self.spec.names]
        return LinearModel(self.spec.names, [f.base_unit for f in self.spec.factors], [q], [row])


# ------------------------------------------------------------------------------ reading
class _Loc:
    """Where a cell is: file, sheet, row, column → the key of an error."""

    def __init__(self, file: str, sheet: str | None):
        self.file, self.sheet = file, sheet

    def key(self, row: int, col: str | None = None, letter: str | None = None) -> str:
        k = f"sheet {self.sheet!r}, row {row}" if self.sheet is not None else f"row {row}"
        if col:
            k += f", column {col!r}" + (f" ({letter})" if letter else "")
        elif letter:
            k += f", column {letter}"
        return k

    def error(self, reason: str, row: int, col: str | None = None, letter: str | None = None) -> SpecError:
        return SpecError(reason, file=self.file, key=self.key(row, col, letter))


def _col_letter(i: int) -> str:
    s = ""
    i += 1
    while i:
        i, r = divmod(i - 1, 26)
        s = chr(65 + r) + s
    return s


def _read_rows(path: Path, sheet: str | None) -> tuple[list[tuple[int, list]], str | None, bool]:
    """``[(row number, cells)]``, the sheet name (XLSX) and whether cells carry column letters."""
    suffix = path.suffix.lower()
    if suffix in (".xlsx", ".xlsm"):
        try:
            import openpyxl
        except ImportError:  # pragma: no cover - a declared dependency
            raise SpecError("reading .xlsx needs openpyxl (pip install openpyxl)", file=str(path), key="-") from None
        try:
            wb = openpyxl.load_workbook(path, read_only=True, data_only=True)
        except FileNotFoundError:
            raise SpecError("file not found", file=str(path), key="-") from None
        except Exception as exc:  # openpyxl raises many kinds for a bad file
            raise SpecError(f"not a readable .xlsx workbook ({type(exc).__name__}: {exc})", file=str(path),
                            key="-") from None
        try:
            if sheet is None:
                ws = wb.worksheets[0]
            elif sheet in wb.sheetnames:
                ws = wb[sheet]
            else:
                raise SpecError(f"no sheet {sheet!r} (sheets: {', '.join(wb.sheetnames)})", file=str(path),
                                key="sheet")
            rows = [(r, list(cells)) for r, cells in enumerate(ws.iter_rows(values_only=True), start=1)]
            title = ws.title
        finally:
            wb.close()
        _check_formulas(path, title, rows)
        return rows, title, True
    if suffix in (".csv", ".txt", ".tsv"):
        try:
            raw = path.read_bytes()
        except FileNotFoundError:
            raise SpecError("file not found", file=str(path), key="-") from None
        except OSError as exc:
            raise SpecError(f"cannot read file ({exc.strerror})", file=str(path), key="-") from None
        try:
            text = raw.decode("utf-8-sig")
        except UnicodeDecodeError:
            try:
                text = raw.decode("cp1252")   # Excel's "CSV" on Western Windows
            except UnicodeDecodeError:
                raise SpecError("not UTF-8 (or Windows-1252) text", file=str(path), key="-") from None
        delim = "\t" if suffix == ".tsv" else _sniff(text)
        rows = [(r, cells) for r, cells in enumerate(csv.reader(io.StringIO(text), delimiter=delim), start=1)]
        return rows, None, False
    raise SpecError(f"unknown table format {path.suffix!r} (expected .csv, .tsv or .xlsx)", file=str(path),
                    key="-")


def _check_formulas(path: Path, title: str, rows: list[tuple[int, list]]) -> None:
    """A formula cell whose value was never computed reads as blank: say so instead."""
    if not any(c is None for _, cells in rows for c in cells):
        return
    import openpyxl

    wb = openpyxl.load_workbook(path, read_only=True, data_only=False)
    try:
        for (r, values), cells in zip(rows, wb[title].iter_rows(values_only=True)):
            for i, (v, f) in enumerate(zip(values, cells)):
                if v is None and isinstance(f, str) and f.startswith("="):
                    raise SpecError(f"the formula {f} has no stored value (the file was written by a program "
                                    "that does not compute formulas): open and save it in a spreadsheet program",
                                    file=str(path), key=_Loc(str(path), title).key(r, None, _col_letter(i)))
    finally:
        wb.close()


def _sniff(text: str) -> str:
    head = "\n".join(line for line in text.splitlines()[:50] if not line.lstrip().startswith("#"))
    try:
        return csv.Sniffer().sniff(head or text[:4096], delimiters=",;\t").delimiter
    except csv.Error:
        return ","


def _blank(v) -> bool:
    return v is None or (isinstance(v, str) and not v.strip())


def _text(v) -> str:
    if isinstance(v, float) and v.is_integer():
        return str(int(v))
    return str(v).strip()


def _number(v, where) -> float | None:
    """A number cell (blank → None); ``where(reason)`` builds the error."""
    if _blank(v):
        return None
    if isinstance(v, bool):
        raise where(f"expected a number, got {v}")
    if isinstance(v, (int, float)):
        x = float(v)
    elif isinstance(v, (_dt.date, _dt.time)):
        raise where("the spreadsheet turned this cell into a date; format the column as number or text")
    else:
        s = str(v).strip().lstrip("Ø⌀").strip().replace("\u2212", "-")
        if not _NUMBER.match(s):
            raise where(f"expected a number, got {str(v)!r}")
        x = float(s.replace(",", "."))
    if not math.isfinite(x):
        raise where(f"must be a finite number, got {v}")
    return x


def _coefficient(v, where) -> float | None:
    if _blank(v):
        return None
    if isinstance(v, str) and v.strip().replace("\u2212", "-") in ("+", "-"):
        return 1.0 if v.strip() == "+" else -1.0
    try:
        return _number(v, where)
    except SpecError:
        raise where(f"expected a direction (+, -) or a number, got {str(v).strip()!r}") from None


_CELL = re.compile(r"^\s*([A-Za-z]+)\s*(?:\((.*)\))?\s*$", re.S)


def _distribution_cell(v, where) -> tuple[str, dict]:
    """``normal`` / ``weibull(shape=2, shift=0.1)`` → (kind, params)."""
    if _blank(v):
        return "normal", {}
    s = _text(v)
    m = _CELL.match(s)
    if not m:
        raise where(f"cannot read distribution {s!r} (expected a kind such as normal, or e.g. "
                    "weibull(shape=2))")
    kind = m.group(1).lower()
    if kind not in KINDS:
        raise where(f"unknown distribution {m.group(1)!r} (expected one of: {', '.join(KINDS)})")
    params: dict[str, float] = {}
    body = (m.group(2) or "").strip()
    for part in filter(None, (x.strip() for x in body.split(","))) if body else ():
        k, eq, val = part.partition("=")
        k = k.strip()
        if not eq and _NUMBER.match(k) and params:
            raise where(f"cannot read {s!r}: commas separate the parameters, write decimals with a point")
        if not eq or k not in CELL_KEYS:
            raise where(f"cannot read {part!r} in {s!r}: parameters are key=number with key one of "
                        f"{', '.join(CELL_KEYS)}")
        val = val.strip().replace("\u2212", "-")
        if not _NUMBER.match(val) or "," in val:
            raise where(f"parameter {k} needs a number, got {val!r}")
        if k in params:
            raise where(f"parameter {k} is given twice")
        params[k] = float(val)
    return kind, params


def read_table_spec(path: str | Path, *, sheet: str | None = None, name: str | None = None) -> TableSpec:
    """Read a spec table (CSV/TSV/XLSX, see the module docstring)."""
    path = Path(path)
    rows, sheet_name, lettered = _read_rows(path, sheet)
    loc = _Loc(str(path), sheet_name)
    meta: dict[str, object] = {}
    corr_rows: list[tuple[int, list]] = []
    header: list[str | None] | None = None
    header_row = 0
    factors: list[tuple[int, dict, dict]] = []   # (row, table, key -> column)
    coefficients: dict[str, float] = {}
    tolerances: dict[str, Tolerance | None] = {}
    row_of: dict[str, int] = {}
    names_seen: dict[str, int] = {}

    for r, cells in rows:
        if all(_blank(c) for c in cells):
            continue
        first = _text(cells[0]) if cells and not _blank(cells[0]) else ""
        if first.startswith("#"):
            word = first[1:].strip().lower()
            if first[1:2].isspace() or not word:
                continue  # a comment
            word = word.rstrip(":")
            if word not in _DIRECTIVES:
                raise loc.error(f"unknown directive {first!r} (known: {', '.join('#' + d for d in _DIRECTIVES)};"
                                " '# text' is a comment)", r, "A" if lettered else None)
            rest = [c for c in cells[1:] if not _blank(c)]
            if word == "correlation":
                corr_rows.append((r, rest))
            else:
                if len(rest) != 1:
                    raise loc.error(f"#{word} takes one value", r)
                if word in meta:
                    raise loc.error(f"#{word} is given twice", r)
                meta[word] = _text(rest[0])
            continue
        if header is None:
            header, header_row = _header(cells, loc, r, lettered), r
            continue
        f = _row(cells, header, loc, r, lettered)
        if f is None:
            continue
        table, cols, coef, tol = f
        n = table["name"]
        if n in names_seen:
            raise loc.error(f"duplicate factor name {n!r} (first in row {names_seen[n]})", r, *cols["name"])
        names_seen[n] = r
        factors.append((r, table, cols))
        if coef is not None:
            coefficients[n] = coef
        tolerances[n] = tol
        row_of[n] = r
    if header is None:
        raise SpecError("no header row (expected columns such as name, nominal, tolerance, distribution, unit)",
                        file=str(path), key=loc.key(1) if rows else "-")
    if not factors:
        raise loc.error("no factor rows below the header", header_row)

    # every factor through the spec's own reader, errors pointed at the row and column
    for r, table, cols in factors:
        try:
            factor_from_params(Params(dict(table), file=str(path), key=""))
        except InputError as exc:
            k = (exc.key or "").split(".")[0]
            raise loc.error(exc.reason, r, *cols.get(k, (None, None))) from None
    names = [t["name"] for _, t, _ in factors]
    corr = []
    for r, rest in corr_rows:
        if len(rest) != 3:
            raise loc.error("#correlation takes two factor names and a correlation: #correlation a b 0.5", r)
        rho = _number(rest[2], lambda why, r=r: loc.error(f"correlation: {why}", r))
        t = {"pair": [_text(rest[0]), _text(rest[1])], "rho": rho}
        try:
            correlation_from_tables([Params(t, file=str(path), key="")], names)
        except InputError as exc:
            raise loc.error(f"#correlation: {exc.reason}", r) from None
        corr.append(t)
    doc = {"spec": {k: v for k, v in (("name", meta.get("spec") or name), ("description", meta.get("description")))
                    if v is not None},
           "factor": [t for _, t, _ in factors]}
    if corr:
        doc["correlation"] = corr
    try:
        spec = spec_from_table(doc, file=str(path))
    except InputError as exc:   # should not happen after the checks above; keep it one line
        raise SpecError(exc.reason, file=str(path), key=exc.key) from None
    return TableSpec(spec, coefficients, tolerances, row_of)


def load_table_spec(path: str | Path, *, sheet: str | None = None) -> ToleranceSpec:
    """The :class:`ToleranceSpec` of a spec table."""
    return read_table_spec(path, sheet=sheet).spec


def _header(cells: list, loc: _Loc, r: int, lettered: bool) -> list[str | None]:
    """Standard column names; ``None`` for an ignored column (notes), ``""`` for a blank header."""
    out: list[str | None] = []
    seen: dict[str, int] = {}
    for i, c in enumerate(cells):
        letter = _col_letter(i) if lettered else None
        if _blank(c):
            out.append("")
            continue
        h = " ".join(_text(c).lower().replace("\u2212", "-").split())
        if h not in _ALIASES:
            raise loc.error(f"unknown column {_text(c)!r} (known: {', '.join(COLUMNS)}, +tol, -tol; "
                            "notes/comment are ignored)", r, _text(c), letter)
        std = _ALIASES[h]
        if std is not None and std in seen:
            raise loc.error(f"column {std!r} appears twice (columns {seen[std] + 1} and {i + 1})", r)
        if std is not None:
            seen[std] = i
        out.append(std)
    if "name" not in seen:
        raise loc.error("the header has no 'name' column", r)
    if "tolerance" in seen and ("upper" in seen or "lower" in seen):
        raise loc.error("give the tolerance either in drawing notation ('tolerance') or as '+tol'/'-tol', "
                        "not both", r)
    if ("upper" in seen) != ("lower" in seen):
        raise loc.error("'+tol' and '-tol' go together", r)
    return out


_LABEL = {"upper": "+tol", "lower": "-tol"}


def _row(cells: list, header: list, loc: _Loc, r: int, lettered: bool):
    """One factor row → (factor table, key → (column, letter), coefficient, drawing tolerance)."""
    cell: dict[str, object] = {}
    col: dict[str, tuple[str, str | None]] = {}
    for i, h in enumerate(cells):
        letter = _col_letter(i) if lettered else None
        if i >= len(header) or header[i] == "":
            if not _blank(h):
                raise loc.error(f"a value ({_text(h)!r}) in a column without a header", r, None, letter)
            continue
        if header[i] is None:
            continue
        cell[header[i]] = h
        col[header[i]] = (_LABEL.get(header[i], header[i]), letter)
    for i, h in enumerate(header):   # columns the row is too short to reach
        if h and h not in col:
            cell[h] = None
            col[h] = (_LABEL.get(h, h), _col_letter(i) if lettered else None)

    def where(h):
        c, letter = col[h]
        return lambda why: loc.error(why, r, c, letter)

    if _blank(cell.get("name")):
        raise where("name")("missing factor name")
    table: dict[str, object] = {"name": _text(cell["name"])}
    keycol: dict[str, tuple[str, str | None]] = {"name": col["name"]}
    unit = None
    if not _blank(cell.get("unit")):
        try:
            unit = units.canonical(_text(cell["unit"]).replace('"', "in"))
        except InputError as exc:
            raise where("unit")(exc.reason) from None
    nominal = _number(cell.get("nominal"), where("nominal")) if "nominal" in cell else None
    dcol = col.get("distribution", col["name"])
    kind, params = (_distribution_cell(cell.get("distribution"), where("distribution"))
                    if "distribution" in cell else ("normal", {}))

    tol: Tolerance | None = None
    tcol = col["name"]
    if not _blank(cell.get("tolerance")):
        v, tcol = cell["tolerance"], col["tolerance"]
        if isinstance(v, (int, float)) and not isinstance(v, bool):
            raise where("tolerance")(f"a bare number ({_text(v)}) is ambiguous: write ±{_text(v)} for a "
                                     f"symmetric tolerance, +a/-b for deviations or a..b for limits")
        if isinstance(v, (_dt.date, _dt.time)):
            raise where("tolerance")("the spreadsheet turned this cell into a date; format the column as text")
        try:
            tol = parse_tolerance(_text(v), nominal=nominal, unit=unit)
        except NotationError as exc:
            raise where("tolerance")(exc.reason) from None
    elif "upper" in cell and not (_blank(cell["upper"]) and _blank(cell["lower"])):
        up = _number(cell["upper"], where("upper"))
        lo = _number(cell["lower"], where("lower"))
        if up is None or lo is None:
            raise where("upper" if up is None else "lower")("+tol and -tol go together (write 0 for none)")
        tcol = col["upper"]
        try:
            tol = parse_tolerance(format_deviations(-abs(lo), up), nominal=nominal, unit=unit)
        except NotationError as exc:
            raise where("upper")(exc.reason.split(" (accepted:")[0]) from None
    if unit is None:
        if tol is None or tol.unit is None:
            raise where("unit")("missing unit (the unit of the nominal and the tolerance, e.g. mm, um, in)")
        unit = tol.unit
    table["unit"] = unit
    keycol["unit"] = col.get("unit", col["name"])

    if tol is not None:
        try:
            band = tol.factor_table(kind, sigma_level=params.pop("sigma_level", None))
        except NotationError as exc:
            raise where("distribution")(exc.reason) from None
        if kind == "normal" and "sigma" in params:   # an explicit σ replaces the band's reading
            band.pop("tolerance", None)
        keycol.update(dict.fromkeys(band, tcol))
        table.update(band)
    else:
        table["dist"] = kind
        if nominal is not None:
            table["nominal"] = nominal
    if "nominal" in table:
        keycol["nominal"] = col["nominal"]
    keycol["dist"] = dcol
    for k, v in params.items():   # the distribution cell refines / overrides the band
        table[k] = v
        keycol[k] = dcol
    for h, key in (("part", "group"), ("feature", "description"), ("source", "source")):
        if not _blank(cell.get(h)):
            table[key] = _text(cell[h])
            keycol[key] = col[h]
    coef = _coefficient(cell["coefficient"], where("coefficient")) if "coefficient" in cell else None
    return table, keycol, coef, tol


# ------------------------------------------------------------------------------ writing
def _band_cells(f) -> tuple[float | None, str, str]:
    """(nominal cell, tolerance cell, distribution cell) of one factor."""
    d: Distribution = f.dist
    if not isinstance(d, Distribution):
        raise SpecError(f"factor {f.name!r}: a {type(d).__name__} cannot be written as a table row",
                        key=f.name)
    p, extra = d.p, {}
    nominal = f.nominal
    base = 0.0 if nominal is None else nominal

    def band(lo: float, hi: float) -> str:
        if nominal is None and not math.isclose(lo, -hi, rel_tol=1e-12, abs_tol=0.0):
            return format_limits(lo, hi)
        return format_deviations(lo - base, hi - base)

    level = d.sigma_level
    if d.kind == "normal":
        h = level * p["sigma"]
        tol = band(p["mean"] - h, p["mean"] + h)
    elif d.kind in ("uniform", "triangular"):
        tol = band(p["lower"], p["upper"])
        if d.kind == "triangular" and not math.isclose(p["mode"], 0.5 * (p["lower"] + p["upper"]),
                                                       rel_tol=1e-12, abs_tol=1e-300):
            extra["mode"] = p["mode"]
    elif d.kind == "truncnorm":
        lo, hi = p["lower"], p["upper"]
        tol = band(lo, hi)
        if not math.isclose(p["mean"], 0.5 * (lo + hi), rel_tol=1e-12, abs_tol=1e-300):
            extra["mean"] = p["mean"]
        if not math.isclose(p["sigma"], (hi - lo) / (2 * level), rel_tol=1e-12):
            extra["sigma"] = p["sigma"]
    elif d.kind in ("rayleigh", "weibull"):
        tol = f"max {fmt(d.tolerance)}"
        if d.kind == "weibull":
            extra["shape"] = p["shape"]
    else:  # lognormal: no band
        tol = ""
        extra.update(median=p["median"], shape=p["shape"])
    if level != 3.0 and d.kind != "lognormal":
        extra["sigma_level"] = level
    if d.shift:
        extra["shift"] = d.shift
    cell = d.kind
    if extra:
        cell += "(" + ", ".join(f"{k}={fmt(v)}" for k, v in extra.items()) + ")"
    return nominal, tol, cell


def spec_rows(spec: ToleranceSpec, coefficients: dict[str, float] | None = None) -> list[list]:
    """The rows of a spec table: metadata, header, one row per factor (numbers as floats)."""
    coefficients = coefficients or {}
    unknown = sorted(set(coefficients) - set(spec.names))
    if unknown:
        raise SpecError(f"coefficient for unknown factor {unknown[0]!r}", file=spec.file, key="coefficient")
    rows: list[list] = [["#spec", spec.name]]
    if spec.description:
        rows.append(["#description", spec.description])
    if spec.correlation is not None:
        c = spec.correlation
        for i in range(len(spec)):
            for j in range(i + 1, len(spec)):
                if c[i, j] != 0.0:
                    rows.append(["#correlation", spec.names[i], spec.names[j], float(c[i, j])])
    header = list(COLUMNS)
    rows.append(header)
    for f in spec.factors:
        nominal, tol, cell = _band_cells(f)
        rows.append([f.name, f.group, f.description, nominal, tol, cell, f.unit,
                     coefficients.get(f.name), f.source])
    return rows


def write_table_spec(spec: ToleranceSpec, path: str | Path, *,
                     coefficients: dict[str, float] | None = None, sheet: str = "spec") -> Path:
    """Write ``spec`` as a table: ``.csv`` / ``.tsv`` (UTF-8 with BOM) or ``.xlsx``."""
    path = Path(path)
    rows = spec_rows(spec, coefficients)
    suffix = path.suffix.lower()
    if suffix in (".csv", ".tsv"):
        with open(path, "w", encoding="utf-8-sig", newline="") as fh:
            w = csv.writer(fh, delimiter="\t" if suffix == ".tsv" else ",")
            for row in rows:
                w.writerow(["" if v is None else fmt(v) if isinstance(v, float) else v for v in row])
        return path
    if suffix == ".xlsx":
        from openpyxl import Workbook
        from openpyxl.styles import Font

        wb = Workbook()
        ws = wb.active
        ws.title = sheet
        hdr = None
        for i, row in enumerate(rows, start=1):
            ws.append(row)
            if row and row[0] == COLUMNS[0] and hdr is None:
                hdr = i
                for c in ws[i]:
                    c.font = Font(bold=True)
        for row in ws.iter_rows(min_row=(hdr or 0) + 1):
            row[COLUMNS.index("tolerance")].number_format = "@"
        ws.freeze_panes = ws.cell(row=(hdr or 0) + 1, column=1)
        for letter, width in zip("ABCDEFGHI", (22, 16, 30, 12, 22, 26, 8, 12, 40)):
            ws.column_dimensions[letter].width = width
        wb.save(path)
        return path
    raise SpecError(f"unknown table format {path.suffix!r} (expected .csv, .tsv or .xlsx)", file=str(path),
                    key="-")
