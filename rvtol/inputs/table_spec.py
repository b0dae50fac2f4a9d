"""A tolerance spec as a table (CSV or XLSX), one row per factor — and back.

The layout a quality engineer keeps in a spreadsheet::

    #spec          rv80e_axial_stack
    #description   Cycloid disc axial clearance
    #correlation   disc1_width   disc2_width   0.5
    name         part      feature        nominal  tolerance     distribution      unit  direction  source
    carrier_gap  carrier   flange gap     24.08    ±0.0105       normal(shift=0.003) mm   +          ISO 286 IT7
    disc1_width  disc 1    face width     12       h6            normal            mm    -          doc 000 Table 1
    bore         housing   bearing seat   62       +0.030/0      uniform           mm               drawing 4711
    bore_cmm     housing   bearing seat   62       H7            measured(data=cmm.csv, column=bore)  mm

* **Columns** (any order, case-insensitive; aliases in brackets): ``name`` (factor), ``part``
  (component), ``feature``, ``group`` (default: the part), ``description``, ``nominal``, ``tolerance`` (tol) in drawing
  notation (:mod:`rvtol.inputs.notation`: ``±0.05``, ``+0.10/-0.00``, ``h6``, ``25 H7/g6``,
  ``max 0.02``, ``Cpk 1.33 k 0.25``…) *or* the two columns ``+tol`` (upper) and ``-tol``
  (lower; its size is taken below the nominal, ``0.05`` and ``-0.05`` both mean −0.05),
  ``distribution`` (dist; default ``normal``), ``unit`` (units), ``direction`` (coefficient,
  sign, dir: ``+``, ``-``, ``+1``, ``-0.5``… for a linear stack: ``[model] kind = "linear"`` with
  ``coefficients = "spec"``), ``source`` (reference); ``notes``/``comment`` columns are ignored
  (an export writes them back, :func:`write_table_spec`'s ``keep``).
  ``name`` is required, and ``unit`` unless the tolerance has one (``25 H7`` is in mm).
  ``multiplicity`` (count, qty) makes a row with ``[k]`` in its name a family of N identical
  factors (:mod:`rvtol.spec`).  ``shorter side`` (shorter leg; mm) and ``broken edge`` (yes/no, true/false,
  blank = no) are an ISO 2768 general tolerance's ``shorter_side`` (an angle, Table 3) and ``broken_edge``
  (a chamfer height or external radius, Table 2).
* **Distribution cell**: a kind of :mod:`rvtol.distributions` read over the tolerance band
  (``normal`` at ±3σ, ``uniform``, ``triangular``, ``truncnorm``, ``rayleigh``/``weibull``
  for magnitudes), optionally with parameters that refine or override what the band gives:
  ``normal(sigma_level=4, shift=0.003)``, ``weibull(shape=2)``, ``truncnorm(sigma=0.5)``,
  ``lognormal(median=2, shape=0.3)`` (no band needed).  Parameters are numbers in the row's unit.
  ``measured(data=cmm.csv, column=bore, method=kde, measurement_sigma=0.001)`` reads measured
  values (:mod:`rvtol.inputs.measured`; the file relative to the table; ``families=normal|weibull``).
* **Nominal**: blank means the factor is itself a deviation (the band sits about 0) or the
  tolerance gives absolute limits; the factor's ``nominal`` (the base point of local
  sensitivities) is then its mean, as in a TOML spec.
* **Position zones**: two rows with tolerance ``⌀t`` and the same name in an optional ``zone``
  column are the x and y coordinates of one circular position zone (:mod:`rvtol.spec`).
* **Metadata rows** start with ``#`` in the first cell: ``#spec`` (name), ``#description``,
  ``#correlation a b rho`` (a Gaussian-copula pair, as ``[[correlation]] pair``); ``# text``
  (hash, space) is a comment.  Blank rows are skipped.

A table is read as the ``[[factor]]`` tables of a TOML spec (:func:`read_spec_table` gives that
document; :func:`rvtol.spec.load_spec` builds the spec from it with the spec's own reader), so
both forms mean the same.  Every problem is one line naming the file, the sheet (XLSX), the row
and the column: ``stack.xlsx: sheet 'spec', row 7, column 'tolerance' (E): cannot read tolerance
'0.05': …``.

:func:`write_table_spec` writes a :class:`~rvtol.spec.ToleranceSpec` in this layout (CSV in
UTF-8 with a byte-order mark, so Excel shows ``±`` and ``µ``; XLSX with openpyxl); reading it
back gives the same spec to 12 significant digits (the numbers are written that way).  A factor
written in drawing notation is written with its drawing limits; measured factors are written
with the file they were read from; a family whose copies are alike as one row with its
``multiplicity``; with ``keep`` (the table the spec was read from) its comment rows, each in its
place, and its notes columns.  Text a spreadsheet would run as a formula is written as text (XLSX)
or refused (CSV).
"""
from __future__ import annotations

import datetime as _dt
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

from ..distributions import KINDS
from ..errors import InputError, SpecError
from .notation import fmt, format_deviations, format_limits, zone_level
from .geometric import FORMS, PROFILES
from .sheets import (EITHER, Location, NumberFormError, blank, cell_number, col_letter, comma_role, read_rows,
                     write_rows)

COLUMNS = ("name", "part", "feature", "nominal", "tolerance", "distribution", "unit", "direction", "source")
_ALIASES = {
    "name": "name", "factor": "name",
    "part": "part", "component": "part", "group": "group",
    "feature": "feature", "description": "description",
    "nominal": "nominal",
    "tolerance": "tolerance", "tol": "tolerance", "drawing tolerance": "tolerance",
    "+tol": "upper", "+ tol": "upper", "upper": "upper", "upper tol": "upper", "plus tol": "upper",
    "upper deviation": "upper",
    "-tol": "lower", "- tol": "lower", "lower": "lower", "lower tol": "lower", "minus tol": "lower",
    "lower deviation": "lower",
    "distribution": "distribution", "dist": "distribution",
    "unit": "unit", "units": "unit",
    "direction": "direction", "coefficient": "direction", "coef": "direction", "dir": "direction",
    "sign": "direction",
    "source": "source", "reference": "source", "ref": "source",
    "zone": "zone", "position zone": "zone",
    "size": "size", "feature of size": "size", "bonus from": "size",
    "feature type": "feature_type", "feature_type": "feature_type",
    "datum size": "datum_size", "datum_size": "datum_size", "datum type": "datum_type", "datum_type": "datum_type",
    "multiplicity": "multiplicity", "count": "multiplicity", "qty": "multiplicity", "quantity": "multiplicity",
    "shorter side": "shorter_side", "shorter_side": "shorter_side", "shorter leg": "shorter_side",
    "broken edge": "broken_edge", "broken_edge": "broken_edge",
    "separate": "separate", "sep reqt": "separate", "separate requirement": "separate",
    "frame": "frame", "feature control frame": "frame", "basic": "basic", "true position": "basic",
    "pattern": "pattern", "feature relating": "feature_relating", "feature_relating": "feature_relating",
    "frtzf": "feature_relating", "envelope": "envelope", "rule 1": "envelope", "rule #1": "envelope",
    "notes": None, "note": None, "comment": None, "comments": None, "remarks": None,
}
#: distribution parameters a distribution cell may set (numbers)
CELL_KEYS = ("mean", "sigma", "tolerance", "lower", "upper", "mode", "median", "shape", "scale", "shift",
             "sigma_level", "alpha", "beta", "gamma", "delta", "location", "skewness", "kurtosis")
#: parameters of a ``measured(...)`` cell (text or numbers)
MEASURED_CELL_KEYS = ("data", "column", "sheet", "method", "families", "family", "location", "interpolate",
                      "bandwidth", "measurement_sigma")
_DIRECTIVES = ("spec", "description", "correlation")
_NUMBER = re.compile(r"^[+-]?(?:\d+(?:[.,]\d*)?|[.,]\d+)$")
#: the [[factor]] keys the columns fill (the spec's own keys)
_KEY_OF = {"part": "part", "feature": "feature", "group": "group", "description": "description", "source": "source",
           "zone": "zone", "size": "size", "feature_type": "feature_type", "datum_size": "datum_size",
           "datum_type": "datum_type", "pattern": "pattern", "feature_relating": "feature_relating",
           "envelope": "envelope", "frame": "frame"}
#: columns written only when some factor needs them
_OPTIONAL = ("group", "description", "zone", "size", "feature_type", "datum_size", "datum_type", "pattern",
             "feature_relating", "envelope", "separate", "frame", "basic")


@dataclass
class SpecTable:
    """A spec table read as a TOML spec document, with where every value came from."""

    document: dict                                   # {"spec": …, "factor": […], "correlation": […]}
    file: str
    sha256: str
    location: Location
    factor_rows: list[int] = field(default_factory=list)
    factor_columns: list[dict] = field(default_factory=list)   # per factor: key -> (column label, letter)
    correlation_rows: list[int] = field(default_factory=list)
    # what the spec does not hold and an export keeps (:func:`write_table_spec`'s ``keep``):
    comments: list[tuple[int, list]] = field(default_factory=list)   # (factor rows above it, -1: above the header;
    #                                                                    its cells)
    extra: dict[str, dict[str, object]] = field(default_factory=dict)   # notes column label -> factor name -> cell

    _KEY = re.compile(r"^(factor|correlation)\[(\d+)\](?:\.([A-Za-z_]+))?")

    def locate(self, exc: InputError) -> SpecError:
        """An error of the spec reader (``factor[i].key``, ``correlation[j]…``) at its sheet, row and column."""
        m = self._KEY.match(exc.key or "")
        if m and m.group(1) == "factor" and int(m.group(2)) < len(self.factor_rows):
            i = int(m.group(2))
            cols = self.factor_columns[i]
            col = cols.get(m.group(3) or "", cols.get("dist") if m.group(3) in CELL_KEYS else cols["name"])
            return self.location.error(exc.reason, self.factor_rows[i], *(col or (None, None)))
        if m and m.group(1) == "correlation" and int(m.group(2)) < len(self.correlation_rows):
            return self.location.error(f"#correlation: {exc.reason}", self.correlation_rows[int(m.group(2))])
        if (exc.key or "").startswith("correlation") and self.correlation_rows:
            return self.location.error(f"#correlation: {exc.reason}", self.correlation_rows[0])
        return SpecError(exc.reason, file=self.file, key=exc.key)


def _trimmed(cells: list) -> list:
    """A row's cells without its trailing blank ones."""
    cells = list(cells)
    while cells and blank(cells[-1]):
        cells.pop()
    return cells


def _text(v) -> str:
    if isinstance(v, float) and v.is_integer():
        return str(int(v))
    return str(v).strip()


def _number(v, where, comma: str = EITHER) -> float | None:
    """A number cell (blank → None; text as :func:`~rvtol.inputs.sheets.read_number` reads it, ``comma``: how the
    file uses the comma, :func:`~rvtol.inputs.sheets.comma_role`); ``where(reason)`` builds the error."""
    if isinstance(v, str):
        v = v.strip().lstrip("Ø⌀")
    try:
        x = cell_number(v, comma)
    except NumberFormError as exc:
        raise where(str(exc) if exc.advice else f"expected a number, got {str(v)!r}") from None
    if x is None:
        return None
    if not math.isfinite(x):
        raise where(f"must be a finite number, got {v}")
    return x


def _direction(v, where, comma: str = EITHER) -> float | None:
    if blank(v):
        return None
    if isinstance(v, str) and v.strip().replace("\u2212", "-") in ("+", "-"):
        return 1.0 if v.strip() == "+" else -1.0
    try:
        return _number(v, where, comma)
    except SpecError:
        raise where(f"expected a direction (+, -) or a number, got {str(v).strip()!r}") from None


_CELL = re.compile(r"^\s*([A-Za-z]+)\s*(?:\((.*)\))?\s*$", re.S)


def _cell_value(k: str, val: str, where, s: str):
    """One ``key=value`` of a distribution cell: a number, or text where a measured key takes text."""
    val = val.strip().replace("\u2212", "-")
    if k in MEASURED_CELL_KEYS and not _NUMBER.match(val):
        if k == "families":
            return [x.strip() for x in val.split("|") if x.strip()]
        if k == "interpolate":
            if val.lower() not in ("true", "false"):
                raise where(f"parameter interpolate needs true or false, got {val!r}")
            return val.lower() == "true"
        if not val:
            raise where(f"parameter {k} needs a value in {s!r}")
        return val
    if not _NUMBER.match(val) or "," in val:
        raise where(f"parameter {k} needs a number, got {val!r}")
    x = float(val)
    return int(x) if k == "column" and x.is_integer() else x


def _distribution_cell(v, where) -> tuple[str, dict]:
    """``normal`` / ``weibull(shape=2, shift=0.1)`` / ``measured(data=f.csv, column=x)`` → (kind, params)."""
    if blank(v):
        return "normal", {}
    s = _text(v)
    m = _CELL.match(s)
    if not m:
        raise where(f"cannot read distribution {s!r} (expected a kind such as normal, or e.g. "
                    "weibull(shape=2))")
    kind = m.group(1).lower()
    if kind not in KINDS and kind != "measured":
        raise where(f"unknown distribution {m.group(1)!r} (expected one of: {', '.join(KINDS)}, measured)")
    keys = MEASURED_CELL_KEYS if kind == "measured" else CELL_KEYS
    params: dict = {}
    body = (m.group(2) or "").strip()
    for part in filter(None, (x.strip() for x in body.split(","))) if body else ():
        k, eq, val = part.partition("=")
        k = k.strip()
        if not eq and _NUMBER.match(k) and params:
            raise where(f"cannot read {s!r}: commas separate the parameters, write decimals with a point")
        if not eq or k not in keys:
            raise where(f"cannot read {part!r} in {s!r}: parameters are key=value with key one of "
                        f"{', '.join(keys)}")
        if k in params:
            raise where(f"parameter {k} is given twice")
        params[k] = _cell_value(k, val, where, s)
    if kind == "measured" and "data" not in params:
        raise where(f"measured(...) needs data=FILE (and column=NAME for a file of several columns), got {s!r}")
    return kind, params


def read_spec_table(path: str | Path, *, sheet: str | None = None, name: str | None = None) -> SpecTable:
    """Read a spec table (CSV/TSV/XLSX, see the module docstring) as a TOML spec document."""
    path = Path(path)
    sh = read_rows(path, sheet)
    lettered = sh.lettered
    comma = comma_role(sh.delimiter, (c for _, cells in sh.rows for c in cells))
    loc = sh.location(str(path))
    meta: dict[str, object] = {}
    corr: list[dict] = []
    table = SpecTable({}, str(path), sh.sha256, loc)
    header: list[str | None] | None = None
    header_row = 0
    names_seen: dict[str, int] = {}
    factors: list[dict] = []

    for r, cells in sh.rows:
        if all(blank(c) for c in cells):
            continue
        first = _text(cells[0]) if cells and not blank(cells[0]) else ""
        if first.startswith("#"):
            word = first[1:].strip().lower()
            if first[1:2].isspace() or not word:   # a comment: kept by an export
                table.comments.append((-1 if header is None else len(factors), _trimmed(cells)))
                continue
            word = word.rstrip(":")
            if word not in _DIRECTIVES:
                raise loc.error(f"unknown directive {first!r} (known: {', '.join('#' + d for d in _DIRECTIVES)};"
                                " '# text' is a comment)", r, "A" if lettered else None)
            rest = [c for c in cells[1:] if not blank(c)]
            if word == "correlation":
                if len(rest) != 3:
                    raise loc.error("#correlation takes two factor names and a correlation: #correlation a b 0.5",
                                    r)
                rho = _number(rest[2], lambda why, r=r: loc.error(f"#correlation: {why}", r), comma)
                corr.append({"pair": [_text(rest[0]), _text(rest[1])], "rho": rho})
                table.correlation_rows.append(r)
            else:
                if len(rest) != 1:
                    raise loc.error(f"#{word} takes one value", r)
                if word in meta:
                    raise loc.error(f"#{word} is given twice", r)
                meta[word] = _text(rest[0])
            continue
        if header is None:
            header, header_row = _header(cells, loc, r, lettered), r
            _refuse_merged(sh, header, header_row, loc)
            ignored = [(i, _text(c)) for i, (c, h) in enumerate(zip(cells, header)) if h is None]
            table.extra = {label: {} for _, label in ignored}
            continue
        f, cols = _row(cells, header, loc, r, lettered, comma)
        n = f["name"]
        if n in names_seen:
            raise loc.error(f"duplicate factor name {n!r} (first in row {names_seen[n]})", r, *cols["name"])
        names_seen[n] = r
        for i, label in ignored:
            if i < len(cells) and not blank(cells[i]):
                table.extra[label][n] = cells[i]
        factors.append(f)
        table.factor_rows.append(r)
        table.factor_columns.append(cols)
    if header is None:
        raise SpecError("no header row (expected columns such as name, nominal, tolerance, distribution, unit)",
                        file=str(path), key=loc.key(1) if sh.rows else "-")
    if not factors:
        raise loc.error("no factor rows below the header", header_row)
    head = {k: v for k, v in (("name", meta.get("spec") or name or path.stem),
                              ("description", meta.get("description"))) if v is not None}
    table.document = {"spec": head, "factor": factors}
    if corr:
        table.document["correlation"] = corr
    return table


def _header(cells: list, loc: Location, r: int, lettered: bool) -> list[str | None]:
    """Standard column names; ``None`` for an ignored column (notes), ``""`` for a blank header."""
    out: list[str | None] = []
    seen: dict[str, int] = {}
    filled = [c for c in cells if not blank(c)]
    if not any(" ".join(_text(c).lower().replace("\u2212", "-").split()) in _ALIASES for c in filled):
        # not a spec table at all (a data file named by mistake): say so without echoing what it holds
        raise loc.error(f"not the header of a spec table: none of its {len(filled)} cells is a known column "
                        f"({', '.join(COLUMNS)}, +tol, -tol)", r)
    for i, c in enumerate(cells):
        letter = col_letter(i) if lettered else None
        if blank(c):
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


_LABEL = {"upper": "+tol", "lower": "-tol", "shorter_side": "shorter side", "broken_edge": "broken edge"}


def _row(cells: list, header: list, loc: Location, r: int, lettered: bool, comma: str) -> tuple[dict, dict]:
    """One factor row → (its ``[[factor]]`` table, key → (column label, letter)); ``comma``: how the file's numbers
    use the comma (:func:`~rvtol.inputs.sheets.comma_role`)."""
    cell: dict[str, object] = {}
    col: dict[str, tuple[str, str | None]] = {}
    for i, h in enumerate(cells):
        letter = col_letter(i) if lettered else None
        if i >= len(header) or header[i] == "":
            if not blank(h):
                raise loc.error(f"a value ({_text(h)!r}) in a column without a header", r, None, letter)
            continue
        if header[i] is None:
            continue
        cell[header[i]] = h
        col[header[i]] = (_LABEL.get(header[i], header[i]), letter)
    for i, h in enumerate(header):   # columns the row is too short to reach
        if h and h not in col:
            cell[h] = None
            col[h] = (_LABEL.get(h, h), col_letter(i) if lettered else None)

    def where(h):
        c, letter = col[h]
        return lambda why: loc.error(why, r, c, letter)

    if blank(cell.get("name")):
        raise where("name")("missing factor name")
    table: dict[str, object] = {"name": _text(cell["name"])}
    keycol: dict[str, tuple[str, str | None]] = {"name": col["name"]}
    if not blank(cell.get("unit")):
        table["unit"] = _text(cell["unit"]).replace('"', "in")
    keycol["unit"] = col.get("unit", col["name"])
    if "nominal" in cell:
        nominal = _number(cell["nominal"], where("nominal"), comma)
        if nominal is not None:
            table["nominal"] = nominal
        keycol["nominal"] = col["nominal"]
    if not blank(cell.get("tolerance")):
        v = cell["tolerance"]
        if isinstance(v, (int, float)) and not isinstance(v, bool):
            raise where("tolerance")(f"a bare number ({_text(v)}) is ambiguous: write ±{_text(v)} for a "
                                     f"symmetric tolerance, +a/-b for deviations or a..b for limits")
        if isinstance(v, (_dt.date, _dt.time)):
            raise where("tolerance")("the spreadsheet turned this cell into a date; format the column as text")
        table["tolerance"] = _text(v)
        keycol["tolerance"] = col["tolerance"]
    elif "upper" in cell and not (blank(cell["upper"]) and blank(cell["lower"])):
        up = _number(cell["upper"], where("upper"), comma)
        lo = _number(cell["lower"], where("lower"), comma)
        if up is None or lo is None:
            raise where("upper" if up is None else "lower")("+tol and -tol go together (write 0 for none)")
        if up < -abs(lo):
            raise where("upper")(f"the upper deviation (+tol {fmt(up)}) is below the lower one (-tol, taken below the "
                                 f"nominal: {fmt(-abs(lo))}): the columns are swapped or a sign is wrong")
        table["tolerance"] = format_deviations(-abs(lo), up)
        keycol["tolerance"] = col["upper"]
    dcol = col.get("distribution", col["name"])
    kind, params = (_distribution_cell(cell.get("distribution"), where("distribution"))
                    if "distribution" in cell else ("normal", {}))
    if kind == "measured" and "data" in params:
        data = Path(str(params["data"]))
        params["data"] = str(data if data.is_absolute() else data)   # relative to the table, as in a TOML spec
    table["dist"] = kind
    keycol["dist"] = dcol
    for k, v in params.items():   # the distribution cell refines / overrides the band
        if k == "tolerance" and "tolerance" in table:
            raise where("distribution")("the tolerance is given twice (tolerance column and distribution cell)")
        table[k] = v
        keycol[k] = dcol
    for h, key in _KEY_OF.items():
        if not blank(cell.get(h)):
            table[key] = _text(cell[h])
            keycol[key] = col[h]
    for key in ("basic", "shorter_side"):      # number columns
        if key in cell:
            v = _number(cell[key], where(key), comma)
            if v is not None:
                table[key] = v
            keycol[key] = col[key]
    for key in ("broken_edge", "separate"):     # yes/no columns
        if key in cell:
            if _yes(cell[key], where(key)):
                table[key] = True
            keycol[key] = col[key]
    if not blank(cell.get("multiplicity")):
        m = _number(cell["multiplicity"], where("multiplicity"), comma)
        if not float(m).is_integer():
            raise where("multiplicity")(f"expected a whole number of copies, got {_text(cell['multiplicity'])}")
        table["multiplicity"] = int(m)
        keycol["multiplicity"] = col["multiplicity"]
    if "direction" in cell:
        d = _direction(cell["direction"], where("direction"), comma)
        if d is not None:
            table["direction"] = d
        keycol["direction"] = col["direction"]
    if "nominal" not in table and _relative(table.get("tolerance"), table.get("unit")):
        tol = table["tolerance"]
        fix = "write 0 for a factor that is itself a deviation from its nominal, e.g. a position or form error"
        if "nominal" in col:
            raise where("nominal")(f"missing nominal: the tolerance {tol!r} is a deviation from it ({fix})")
        raise loc.error(f"no 'nominal' column: the tolerance {tol!r} is a deviation from a nominal (add the column; "
                        f"{fix})", r, "nominal")
    return table, keycol


def _yes(v, where) -> bool:
    """A yes/no cell: yes, true (or the spreadsheet's TRUE) is True; no, false, FALSE or blank is False."""
    if isinstance(v, bool):
        return v
    word = "" if blank(v) else _text(v).lower()
    if word not in ("", "yes", "true", "no", "false"):
        raise where(f"expected yes or no, got {_text(v)!r}")
    return word in ("yes", "true")


def _relative(tolerance, unit) -> bool:
    """True for a tolerance written as deviations from a nominal it does not give itself (``±0.05``,
    ``+0.1/-0``, ``+tol``/``-tol``): read without a nominal it would sit about 0 — an invented nominal."""
    if not isinstance(tolerance, str):
        return False
    from .notation import NotationError, parse_tolerance

    try:
        t = parse_tolerance(tolerance, unit=unit)
    except (NotationError, InputError):
        return False          # the spec reader reports it, at this row and column
    return t.nominal is None and t.form in ("symmetric", "deviations")


def _refuse_merged(sh, header: list, header_row: int, loc: Location) -> None:
    """Merged cells below the header: a merged range keeps its value in its first cell only and every other
    cell reads blank — a missing nominal would silently become 0.  Refused, naming the range."""
    for (r0, c0, r1, c1) in sh.merged:
        if r1 <= header_row:
            continue
        r = max(r0, header_row + 1)
        label = header[c0 - 1] if c0 - 1 < len(header) and header[c0 - 1] else None
        rng = f"{col_letter(c0 - 1)}{r0}:{col_letter(c1 - 1)}{r1}"
        raise loc.error(f"merged cells {rng}: only the first cell of a merged range holds the value, the others "
                        "read as blank — unmerge them and write the value in every row", r,
                        _LABEL.get(label, label), col_letter(c0 - 1))


# ------------------------------------------------------------------------------ writing
def _band_cells(f) -> tuple[float | None, str, str]:
    """(nominal cell, tolerance cell, distribution cell) of one factor.

    The tolerance cell holds the factor's band (:attr:`rvtol.spec.Factor.band`: its drawing limits
    or, without them, the band its distribution stands for, shift included); the distribution cell
    adds the parameters that reading that band back would not give (σ through ``sigma_level``, a
    mean off the middle, the shift, shapes), so reading the row back gives the same factor, band
    included.
    """
    d = f.dist
    nominal = f.nominal
    base = 0.0 if nominal is None else nominal

    def text(lo: float, hi: float) -> str:
        if nominal is None:      # no nominal: absolute limits (deviations would need one, _relative)
            return format_limits(lo, hi)
        return format_deviations(lo - base, hi - base)

    measured = getattr(f, "measured", None)
    if measured is not None:
        return nominal, text(*f.limits) if f.limits is not None else "", _measured_cell(measured)
    if not hasattr(d, "params") or getattr(d, "kind", None) not in KINDS:
        raise SpecError(f"factor {f.name!r}: a {type(d).__name__} cannot be written as a table row", key=f.name)
    p, extra, level = d.p, {}, d.sigma_level
    differs = lambda a, b: not math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-300)  # noqa: E731
    if d.kind == "lognormal":   # no band
        return nominal, "", "lognormal(" + ", ".join(
            f"{k}={fmt(v)}" for k, v in (("median", p["median"]), ("shape", p["shape"]), ("shift", d.shift)) if v) + ")"
    if getattr(f, "zone", "") and d.kind == "normal":   # a coordinate of a position zone: ⌀t reads it back
        lo, hi = f.limits
        if differs(p["mean"], 0.5 * (lo + hi)):
            extra["mean"] = p["mean"]
        if differs(p["sigma"], 0.5 * (hi - lo) / zone_level()):
            extra["sigma"] = p["sigma"]
        if d.shift:
            extra["shift"] = d.shift
        mod = {"MMC": " (M)", "LMC": " (L)"}.get(getattr(f, "modifier", ""), "")
        width = hi - lo if getattr(f, "locating", None) is None else f.locating   # a composite frame's first line
        return nominal, f"⌀{fmt(width)}{mod}", "normal" + (
            "(" + ", ".join(f"{k}={fmt(v)}" for k, v in extra.items()) + ")" if extra else "")
    if d.kind in ("beta", "gamma", "gumbel", "johnsonsu", "johnsonsb", "pearson3", "pearson"):   # by parameters
        cell = d.kind + "(" + ", ".join(f"{k}={fmt(v)}" for k, v in list(p.items()) + [("shift", d.shift)] if v or
                                        k != "shift") + ")"
        return nominal, text(*f.limits) if f.limits is not None else "", cell
    if d.kind in ("rayleigh", "weibull"):
        lo, hi = f.limits if f.limits is not None else (d.shift, d.shift + d.tolerance)
        # a magnitude's band says where its values start: from 0, from the nominal (+x/0) or from a (a..b)
        tol = (f"max {fmt(hi)}" if lo == 0.0 and nominal is None else text(lo, hi) if lo == base
               else format_limits(lo, hi))
        if differs(hi - lo, d.tolerance) or differs(lo, d.shift):   # the limits do not give the distribution
            extra["sigma" if d.kind == "rayleigh" else "scale"] = p["sigma" if d.kind == "rayleigh" else "scale"]
            extra["shift"] = d.shift
        if d.kind == "weibull":
            extra["shape"] = p["shape"]
    else:
        sh = d.shift
        if d.kind == "normal":
            own = (p["mean"] - level * p["sigma"], p["mean"] + level * p["sigma"])
        else:
            own = (p["lower"], p["upper"])
        # the factor's band: its drawing limits, or the band the (shifted) distribution stands for
        lo, hi = f.limits if f.limits is not None else (own[0] + sh, own[1] + sh)
        tol, mid = text(lo, hi), 0.5 * (lo + hi)
        if d.kind == "normal":
            level = (hi - lo) / (2.0 * p["sigma"])   # the band read at this level gives σ
            if differs(p["mean"], mid):
                extra["mean"] = p["mean"]
        else:
            if differs(lo, own[0]) or differs(hi, own[1]):
                extra.update(lower=own[0], upper=own[1])
            if d.kind == "triangular" and differs(p["mode"], 0.5 * sum(own)):
                extra["mode"] = p["mode"]
            if d.kind == "truncnorm":
                if differs(p["mean"], mid):
                    extra["mean"] = p["mean"]
                if differs(p["sigma"], (hi - lo) / (2 * level)):
                    extra["sigma"] = p["sigma"]
    if differs(level, 3.0):
        extra["sigma_level"] = level
    if d.shift and "shift" not in extra and d.kind not in ("rayleigh", "weibull"):   # magnitudes: from the limits
        extra["shift"] = d.shift
    cell = d.kind
    if extra:
        cell += "(" + ", ".join(f"{k}={fmt(v)}" for k, v in extra.items()) + ")"
    return nominal, tol, cell


def _measured_cell(m) -> str:
    keys = {"data": m.data, "column": m.column, "sheet": m.sheet, "method": m.method,
            "family": m.family if m.method == "fit" else None, "measurement_sigma": m.measurement_sigma}
    return "measured(" + ", ".join(f"{k}={fmt(v) if isinstance(v, float) else v}" for k, v in keys.items()
                                   if v is not None) + ")"


def spec_rows(spec, coefficients: dict[str, float] | None = None, keep: SpecTable | None = None) -> list[list]:
    """The rows of a spec table: metadata, header, one row per factor (numbers as floats) — a family's copies one
    row with its ``multiplicity`` when they are written alike.

    ``coefficients`` (factor → number) override the factors' own ``direction``.  ``keep``: the table the spec was
    read from, whose comment rows (in their place among the factor rows) and notes columns are written back.
    """
    coefficients = coefficients or {}
    unknown = sorted(set(coefficients) - set(spec.names))
    if unknown:
        raise SpecError(f"coefficient for unknown factor {unknown[0]!r}", file=spec.file, key="direction")
    comments = list(keep.comments) if keep is not None else []
    notes = keep.extra if keep is not None else {}
    rows: list[list] = [c for at, c in comments if at < 0] + [["#spec", spec.name]]
    if spec.description:
        rows.append(["#description", spec.description])
    if spec.correlation is not None:
        c = spec.correlation
        for i in range(len(spec)):
            for j in range(i + 1, len(spec)):
                if c[i, j] != 0.0:
                    rows.append(["#correlation", spec.names[i], spec.names[j], float(c[i, j])])
    body = _factor_rows(spec, coefficients)
    value = {"group": lambda f: f.group, "description": lambda f: f.description}
    value.update({c: (lambda f, c=c: getattr(f, c, "")) for c in _OPTIONAL[2:]})
    value["basic"] = lambda f: "" if getattr(f, "basic", None) is None else fmt(f.basic)   # 0 is a value
    value["frame"] = lambda f: "" if f.frame == getattr(f, "pattern", "") else f.frame   # a pattern's: its own
    value["feature_relating"] = _feature_relating
    value["separate"] = lambda f: "yes" if getattr(f, "separate", False) else ""
    written = [f for f in spec.factors if not _generated(f)]
    needed = {"group": any(f.group != getattr(f, "part", "") for f in written),
              "description": any(f.description for f in written)}
    needed.update({c: any(value[c](f) for f in written) for c in _OPTIONAL[2:]})
    extra = [c for c in _OPTIONAL if needed[c]] + (["multiplicity"] if any(n > 1 for _, _, n in body) else [])
    rows.append(list(COLUMNS) + extra + list(notes))
    value["multiplicity"] = lambda f: None
    for k, (name, cells, n) in enumerate(body):
        rows += [c for at, c in comments if at == k]
        f = spec.factor(name) if n == 1 else spec.families()[name][0]
        rows.append([name] + cells + [n if c == "multiplicity" and n > 1 else value[c](f) or None for c in extra]
                    + [notes[label].get(name) for label in notes])
    rows += [c for at, c in comments if at >= len(body)]
    return rows


def _factor_rows(spec, coefficients: dict[str, float]) -> list[tuple[str, list, int]]:
    """``(name, the row's cells after the name, multiplicity)`` per row: a factor, or a family whose copies are
    written alike as its template with their number."""
    out: list[tuple[str, list, int]] = []
    families = spec.families()
    done: set[str] = set()
    for f in spec.factors:
        if f.family in done or _generated(f):
            continue
        copies = families.get(f.family, (f,)) if f.family else (f,)
        cells = [_row_cells(g, coefficients) for g in copies]
        if len(copies) > 1 and all(c == cells[0] for c in cells):
            out.append((f.family, cells[0], len(copies)))
            done.add(f.family)
        else:
            out.append((f.name, cells[0], 1))
    return out


def _generated(f) -> bool:
    """A composite frame's pattern translation (:func:`rvtol.patterns.expand`): its features' frame writes it."""
    return bool(f.zone) and f.zone == getattr(f, "pattern", "")


def _feature_relating(f) -> str:
    """A composite frame's second line, ``⌀T₂`` (:mod:`rvtol.patterns`), on the pattern's features' rows."""
    if getattr(f, "locating", None) is None:
        return ""
    lo, hi = f.limits
    return " ".join([f"⌀{fmt(hi - lo)}" + {"MMC": " (M)", "LMC": " (L)"}.get(f.modifier, ""), *f.datums])


def _frame_text(f) -> str:
    """A profile or form tolerance written back as its frame (:mod:`rvtol.inputs.geometric`), in the factor's unit."""
    lo, hi = f.limits
    if f.characteristic in FORMS.values():
        return f"{next(k for k, v in FORMS.items() if v == f.characteristic)}{fmt(hi)}"
    symbol = next(k for k, v in PROFILES.items() if v == f.characteristic)
    unequal = "" if math.isclose(hi, -lo, rel_tol=1e-12) else f" U {fmt(hi)}"
    return " ".join([f"{symbol}{fmt(hi - lo)}{unequal}", *f.datums]).strip()


def _row_cells(f, coefficients: dict[str, float]) -> list:
    nominal, tol, cell = _band_cells(f)
    if getattr(f, "characteristic", ""):
        tol = _frame_text(f)
    direction = coefficients.get(f.name, getattr(f, "direction", None))
    direction = {1.0: "+", -1.0: "-"}.get(direction, direction)
    return [getattr(f, "part", ""), getattr(f, "feature", ""), nominal, tol, cell, f.unit, direction, f.source]


def write_table_spec(spec, path: str | Path, *, coefficients: dict[str, float] | None = None,
                     sheet: str = "spec", keep: SpecTable | None = None, shown: str | None = None) -> Path:
    """Write ``spec`` as a table: ``.csv`` / ``.tsv`` (UTF-8 with BOM) or ``.xlsx``; ``keep``: the table it was
    read from (:func:`read_spec_table`), whose comment rows and notes columns are written too.

    Measured factors name their data file as the spec did (relative to the spec): export next to the
    spec, or copy the data files along.  Text a spreadsheet would run as a formula (``=…``, ``@…``) is written
    as text in XLSX and refused in CSV (:func:`rvtol.inputs.sheets.write_rows`).
    """
    rows = spec_rows(spec, coefficients, keep)
    header = next(i for i, r in enumerate(rows, start=1) if r and r[0] == COLUMNS[0])
    return write_rows(path, rows, sheet=sheet, header_row=header, text_columns=(COLUMNS.index("tolerance"),),
                      widths=(22, 16, 30, 12, 22, 26, 8, 10, 40, 16, 30, 12), number=fmt, shown=shown)
