"""Spreadsheet files both ways: rows of cells from CSV/TSV/XLSX with their locations, and rows or
DataFrames written as CSV (UTF-8 with a byte-order mark, so Excel shows ``±`` and ``µ``) or XLSX.

Every reader of a table in rvtol (spec tables, measured values, measured parts and kit lists,
measured curves) goes through :func:`read_rows`, so a problem is always one line naming the file,
the sheet (XLSX), the row and the column (:class:`Location`): ``stack.xlsx: sheet 'spec', row 7,
column 'tolerance' (E): …``.  :func:`read_table` reads a table with a header row: rows whose first
cell starts with ``#`` are comments, blank rows are skipped, and a header cell is ``name`` or
``name [unit]`` (:func:`split_header`: the unit is a bracket group after a space, so a name may hold
brackets itself, ``E_c[1,2] [um]``).

Nothing is guessed: a workbook is read from the sheet named, else its only visible sheet, else the one it
opens on if that is its first (:func:`_pick_sheet`); hidden rows are refused; a number written as text is
read one way only (:func:`read_number`), an ambiguous ``1,250`` decided by the file's other numbers or
refused.  Nothing is written as a formula (:func:`write_rows`).
"""
from __future__ import annotations

import array
import csv
import datetime as _dt
import hashlib
import io
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

from ..params import decode_text, read_bytes
from ..errors import InputError, SpecError
from ..safetext import FORMULA_START, formula_like  # noqa: F401  (what a spreadsheet runs: one definition, for both)

#: table formats rvtol reads and writes
READ_SUFFIXES = (".csv", ".tsv", ".txt", ".xlsx", ".xlsm")
WRITE_SUFFIXES = (".csv", ".tsv", ".xlsx")


class Location:
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


def col_letter(i: int) -> str:
    """The spreadsheet letter of 0-based column ``i`` (A, …, Z, AA, …)."""
    s = ""
    i += 1
    while i:
        i, r = divmod(i - 1, 26)
        s = chr(65 + r) + s
    return s


@dataclass
class Sheet:
    """The rows of one sheet: ``[(row number, cells)]``, its title (XLSX), whether columns have letters."""

    rows: list[tuple[int, list]]
    title: str | None
    lettered: bool
    sha256: str
    merged: tuple[tuple[int, int, int, int], ...] = ()   # XLSX merged ranges (first row, col, last row, col; 1-based)
    delimiter: str | None = None                         # of a text file (None: a workbook)

    def location(self, file: str) -> Location:
        return Location(file, self.title)


def read_rows(path: str | Path, sheet: str | None = None, *, delimiters: str = ",;\t") -> Sheet:
    """The rows of a CSV/TSV/TXT file or of one XLSX sheet (the first unless ``sheet`` names one)."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix in (".xlsx", ".xlsm"):
        raw = read_bytes(path, "a table file")
        import openpyxl

        try:
            wb = openpyxl.load_workbook(io.BytesIO(raw), read_only=True, data_only=True)
        except Exception as exc:  # openpyxl raises many kinds for a bad file
            raise SpecError(f"not a readable .xlsx workbook ({type(exc).__name__}: {exc})", file=str(path),
                            key="-") from None
        try:
            ws = _pick_sheet(wb, sheet, path)
            rows = [(r, list(cells)) for r, cells in enumerate(ws.iter_rows(values_only=True), start=1)]
            title = ws.title
            xml = _sheet_xml(raw, getattr(ws, "_worksheet_path", None))
        finally:
            wb.close()
        _refuse_hidden_rows(xml, rows, Location(str(path), title))
        _check_formulas(raw, path, title, rows)
        return Sheet(rows, title, True, hashlib.sha256(raw).hexdigest(), _merged_ranges(xml))
    if suffix in TEXT_SUFFIXES:
        raw = read_bytes(path, "a table file")
        rows, delim = _text_rows(raw, path, delimiters)
        return Sheet(list(rows), None, False, hashlib.sha256(raw).hexdigest(), delimiter=delim)
    raise _unknown_format(path, TEXT_SUFFIXES)


#: text table formats (CSV with its delimiter sniffed, TSV)
TEXT_SUFFIXES = (".csv", ".txt", ".tsv")


def _unknown_format(path: Path, text_suffixes) -> SpecError:
    shown = ", ".join(s for s in text_suffixes if s)
    return SpecError(f"unknown table format {path.suffix!r} (expected {shown} or .xlsx; save other spreadsheets as "
                     ".xlsx)", file=str(path), key="-")


def _text_rows(raw: bytes, path: Path, delimiters: str):
    """``(rows, delimiter)`` of a text table: its decoded text read by :mod:`csv` one row at a time (a quoted cell
    after ``, `` is one cell)."""
    text = decode_text(raw, str(path), fallback="cp1252")   # cp1252: Excel's "CSV" on Western Windows
    delim = "\t" if path.suffix.lower() == ".tsv" else sniff(text, delimiters)
    reader = csv.reader(io.StringIO(text), delimiter=delim, skipinitialspace=True)
    return enumerate(reader, start=1), delim


@dataclass
class RowStream:
    """The rows of a table file one at a time (:func:`stream_rows`): ``rows`` yields ``(row number, cells)``;
    ``delimiter`` of a text file (None: a workbook), its ``size`` in bytes."""

    rows: Iterator[tuple[int, list]]
    title: str | None
    lettered: bool
    delimiter: str | None
    size: int

    def location(self, file: str) -> Location:
        return Location(file, self.title)


def stream_rows(path: str | Path, sheet: str | None = None, *, delimiters: str = ",;\t",
                text_suffixes: tuple[str, ...] = TEXT_SUFFIXES, what: str = "a table file") -> RowStream:
    """:func:`read_rows` one row at a time, for a file too large to hold as cells (only what the reader keeps
    of each row stays in memory); ``text_suffixes``: the suffixes read as text tables."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix in (".xlsx", ".xlsm"):
        sh = read_rows(path, sheet)
        return RowStream(iter(sh.rows), sh.title, True, None, 0)
    if suffix in text_suffixes:
        raw = read_bytes(path, what)
        rows, delim = _text_rows(raw, path, delimiters)
        return RowStream(rows, None, False, delim, len(raw))
    raise _unknown_format(path, text_suffixes)


_MERGE = re.compile(rb'<(?:\w+:)?mergeCell\s+ref="([A-Z]+)(\d+):([A-Z]+)(\d+)"')


def _col_number(letters: bytes) -> int:
    n = 0
    for ch in letters.decode():
        n = n * 26 + ord(ch) - 64
    return n


def _pick_sheet(wb, sheet: str | None, path: Path):
    """The worksheet to read: the one named, else the only visible one, else the one the workbook opens on if it
    is also its first visible sheet.  Anything else could read the wrong revision without a word — a hidden
    "rev A" first and an active "rev B", or several visible sheets opened on another than the first — and is
    refused, listing the visible sheets."""
    if sheet is not None:
        if sheet in wb.sheetnames:
            return wb[sheet]
        raise SpecError(f"no sheet {sheet!r} (sheets: {_sheet_list(wb)})", file=str(path), key="sheet")
    visible = [ws for ws in wb.worksheets if ws.sheet_state == "visible"]
    if len(visible) == 1:
        return visible[0]
    if not visible:
        raise SpecError(f"the workbook has no visible sheet (sheets: {_sheet_list(wb)}): name the one to read",
                        file=str(path), key="sheet")
    active = wb.active
    if active is visible[0]:
        return active
    raise SpecError(f"which sheet? the workbook has {len(visible)} visible sheets "
                    f"({', '.join(repr(ws.title) for ws in visible)}) and opens on {active.title!r}, not on the first "
                    f"one: name the sheet to read (a study: spec_sheet = \"…\"; a measured factor: sheet = \"…\"; "
                    "rvtol spec export: --sheet)", file=str(path), key="sheet")


def _sheet_list(wb) -> str:
    return ", ".join(ws.title + ("" if ws.sheet_state == "visible" else f" ({ws.sheet_state})") for ws in wb.worksheets)


def _sheet_xml(raw: bytes, sheet_path: str | None) -> bytes:
    """The XML of one sheet of an .xlsx file (what openpyxl's read-only mode does not read: merged ranges, hidden
    rows); empty if it cannot be found."""
    if not sheet_path:
        return b""
    import zipfile

    with zipfile.ZipFile(io.BytesIO(raw)) as z:
        try:
            return z.read(sheet_path.lstrip("/"))
        except KeyError:
            return b""


def _merged_ranges(xml: bytes) -> tuple[tuple[int, int, int, int], ...]:
    """The merged ranges of one sheet, from its XML."""
    return tuple((int(r0), _col_number(c0), int(r1), _col_number(c1)) for c0, r0, c1, r1 in _MERGE.findall(xml))


_ROW_TAG = re.compile(rb"<(?:\w+:)?row\b([^>]*)>")
_HIDDEN = re.compile(rb'\bhidden="(?:1|true)"')
_ROW_NUMBER = re.compile(rb'\br="(\d+)"')


def hidden_rows(xml: bytes) -> list[int]:
    """The rows a sheet's XML marks hidden (hidden by hand, by a filter or in a collapsed outline)."""
    out = []
    for attrs in _ROW_TAG.findall(xml):
        if _HIDDEN.search(attrs):
            m = _ROW_NUMBER.search(attrs)
            if m:
                out.append(int(m.group(1)))
    return out


def _refuse_hidden_rows(xml: bytes, rows: list[tuple[int, list]], loc: Location) -> None:
    """Hidden rows that hold something are refused: read, they would be factors or values nobody sees; skipped,
    an engineer who hid a row to tidy the sheet would lose it.  Nothing tells which is meant."""
    hidden = set(hidden_rows(xml))
    if not hidden:
        return
    full = [r for r, cells in rows if r in hidden and not all(blank(c) for c in cells)]
    if full:
        shown = ", ".join(map(str, full[:10])) + (f" and {len(full) - 10} more" if len(full) > 10 else "")
        raise loc.error(f"hidden row{'s' if len(full) > 1 else ''} {shown}: a hidden row would be read like any "
                        "other, unseen — unhide and check them, or delete the rows not meant (a filter hides rows "
                        "too: clear it)", full[0])


def _check_formulas(raw: bytes, path: Path, title: str, rows: list[tuple[int, list]]) -> None:
    """A formula cell whose value was never computed reads as blank: say so instead."""
    if not any(c is None for _, cells in rows for c in cells):
        return
    import openpyxl

    wb = openpyxl.load_workbook(io.BytesIO(raw), read_only=True, data_only=False)
    try:
        for (r, values), cells in zip(rows, wb[title].iter_rows(values_only=True)):
            for i, (v, f) in enumerate(zip(values, cells)):
                if v is None and isinstance(f, str) and f.startswith("="):
                    raise SpecError(f"the formula {f} has no stored value (the file was written by a program "
                                    "that does not compute formulas): open and save it in a spreadsheet program",
                                    file=str(path), key=Location(str(path), title).key(r, None, col_letter(i)))
    finally:
        wb.close()


#: files from this size on show a progress bar while read (on a terminal)
PROGRESS_BYTES = 8 * 2**20


class _Progress:
    def __init__(self, total: int, desc: str):
        self.bar = None
        if total >= PROGRESS_BYTES:
            import sys

            from tqdm.auto import tqdm

            self.bar = tqdm(total=total, desc=desc, unit="B", unit_scale=True, delay=1.0, leave=False,
                            file=sys.stderr, disable=None, dynamic_ncols=True)

    def advance(self, n: int) -> None:
        if self.bar is not None:
            self.bar.update(min(n, self.bar.total - self.bar.n))

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        if self.bar is not None:
            self.bar.close()


def byte_progress(total: int, desc: str) -> _Progress:
    """A progress bar on stderr for reading ``total`` bytes (only for a large file, only on a terminal)."""
    return _Progress(total, desc)


def sniff(text: str, delimiters: str = ",;\t") -> str:
    """The delimiter of CSV text, from its first 50 lines that are not blank or comments; ``,`` when it cannot
    be told."""
    head = []
    for line in io.StringIO(text):                  # line by line: a large file is not split whole
        if line.strip() and not line.lstrip().startswith("#"):
            head.append(line)
            if len(head) == 50:
                break
    try:
        return csv.Sniffer().sniff("".join(head) or text[:4096], delimiters=delimiters).delimiter
    except csv.Error:
        return ","


def blank(v) -> bool:
    return v is None or (isinstance(v, str) and not v.strip())


def skipped(cells) -> bool:
    """A row every table reader skips: all cells blank, or a comment (its first cell starts with ``#``)."""
    return all(blank(c) for c in cells) or (bool(cells) and isinstance(cells[0], str)
                                            and cells[0].lstrip().startswith("#"))


#: a number written plainly: digits with a decimal point, an optional exponent
_PLAIN = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?")
#: a number with separators: sign, digits with ``.``, ``,`` or spaces (a space, U+00A0, U+202F) between them
_SEPARATED = re.compile(r"([+-]?)(\d[\d.,\u0020\u00a0\u202f]*\d|[.,]\d+|\d+[.,])([eE][+-]?\d+)?")
_SPACES = " \u00a0\u202f"
#: a number whose one point could group thousands where commas are decimal: 1.250 (1.25 or 1250?)
_POINT_GROUPED = re.compile(r"[+-]?[1-9]\d{0,2}\.\d{3}")


class NumberFormError(ValueError):
    """Text that is not one number to rvtol: ``str(exc)`` says why; ``advice`` is True when it also says how to
    write the number (an ambiguous or misplaced separator, a date), False for text that is simply no number."""

    def __init__(self, reason: str, advice: bool = True):
        super().__init__(reason)
        self.advice = advice


#: how a file's numbers use the comma (:func:`read_number`): only to group thousands (a comma-separated file),
#: as the decimal comma (the file's other numbers say so), or either (nothing says: ``1,250`` is refused)
THOUSANDS, DECIMAL, EITHER = "thousands", "decimal", "either"


@dataclass(frozen=True)
class _Reading:
    value: float                 # the number, a comma read as the decimal comma where it could be either
    comma: str | None            # how it uses the comma: "decimal", "thousands", "either" (1,250), None (no comma)
    grouped: float | None = None   # the number with the comma read as a thousands separator (comma == "either")


def _reading(s: str) -> _Reading:
    """How text with separators reads (:func:`read_number`'s rules), or :class:`NumberFormError`."""
    m = _SEPARATED.fullmatch(s)
    if not m:
        raise NumberFormError(f"not a number: {s!r}", False)
    sign, body, exp = m.group(1), m.group(2), m.group(3) or ""
    dots, commas = body.count("."), body.count(",")

    def number(whole: str, frac: str, group: str) -> float:
        if frac and not frac.isdigit():
            raise NumberFormError(f"not a number: {s!r}", False)
        return float(f"{sign}{_ungrouped(whole, group, s) or '0'}.{frac or '0'}{exp}")

    last = max(body.rfind("."), body.rfind(","))
    whole, frac = body[:last], body[last + 1:]
    if dots and commas:                            # 1.250,5 or 1,250.5: the last one is the decimal separator
        dec = body[last]
        if body.count(dec) > 1:
            raise NumberFormError(f"not a number: {s!r} (two decimal separators)", False)
        return _Reading(number(whole, frac, "," if dec == "." else "."), "decimal" if dec == "," else "thousands")
    if commas > 1 or dots > 1:                     # 1,250,000 or 1.250.000: thousands, no decimals
        return _Reading(number(body, "", "," if commas else "."), "thousands" if commas else "decimal")
    if commas:
        if _grouped(body, ","):                    # 1,250: 1.25 or 1250
            return _Reading(number(whole, frac, " "), "either", number(body, "", ","))
        return _Reading(number(whole, frac, " "), "decimal")
    if dots:
        return _Reading(number(whole, frac, " "), None)
    return _Reading(number(body, "", " "), None)   # 1 250: grouped by spaces


def _ungrouped(whole: str, sep: str, s: str) -> str:
    """The digits of an integer part grouped by ``sep`` (spaces: any of :data:`_SPACES`), checked by
    :func:`_grouped`."""
    if whole.isdigit() or not whole:
        return whole
    seps = {" " if c in _SPACES else c for c in whole if not c.isdigit()}
    if seps != {sep} or not _grouped(whole, sep):
        raise NumberFormError(f"not a number: {s!r} (its thousands are not grouped by threes)", False)
    return "".join(c for c in whole if c.isdigit())


def _grouped(whole: str, sep: str) -> bool:
    """Whether ``whole`` is digits grouped by ``sep`` (spaces: any of :data:`_SPACES`): 1–3 digits (not a leading
    0), then groups of three."""
    if sep == " ":
        for sp in _SPACES[1:]:
            whole = whole.replace(sp, " ")
    return re.fullmatch(rf"[1-9]\d{{0,2}}(?:{re.escape(sep)}\d{{3}})+", whole) is not None


def read_number(text: str, comma: str = EITHER) -> float:
    """The number a spreadsheet cell or a drawing writes as text, its separators read one way only.

    * ``.`` is the decimal point; spaces (also U+00A0, U+202F, as French locales write them) group thousands.
    * Both ``.`` and ``,``: the last one is the decimal separator, the other groups thousands (``1.250,5`` and
      ``1,250.5`` are 1250.5).  Two or more of one kind group thousands (``1,250,000``, ``1.250.000``).
    * One ``,``: a decimal comma where it cannot group thousands (``0,250``, ``1,25``, ``1,2500``); ``1,250``
      could be either, and ``comma`` decides: :data:`THOUSANDS` (a comma-separated file, where Excel quotes
      ``"1,250"`` for a ``#,##0`` cell: a comma only groups thousands, and ``"1,25"`` is refused),
      :data:`DECIMAL` (the file's other numbers write decimal commas: 1.25), :data:`EITHER` (nothing tells:
      refused, saying how to write it).

    Groups are checked: 1–3 digits (not a leading 0), then groups of exactly 3.  Raises
    :class:`NumberFormError` (a ValueError).
    """
    s = str(text).strip().replace("\u2212", "-")
    if _PLAIN.fullmatch(s):
        if comma == DECIMAL and _POINT_GROUPED.fullmatch(s):
            grouped = fmt_plain(float(s.replace(".", "")))
            raise NumberFormError(f"{s!r} is ambiguous: the other numbers here write decimal commas, so its point "
                                  f"may group thousands ({grouped}) or be a decimal point ({fmt_plain(float(s))}) — "
                                  f"write {grouped} or {fmt_plain(float(s)).replace('.', ',')}")
        return float(s)
    if s.startswith("'"):
        raise NumberFormError(f"{s!r} starts with an apostrophe (a spreadsheet's mark for text): write the number "
                              "without it")
    r = _reading(s)
    if r.comma == "either":
        if comma == THOUSANDS:
            return r.grouped
        if comma == DECIMAL:
            return r.value
        raise NumberFormError(f"{s!r} is ambiguous: {fmt_plain(r.value)} with a decimal comma or "
                              f"{fmt_plain(r.grouped)} with a thousands separator, and no other number here says "
                              f"which — write {fmt_plain(r.value)} or {fmt_plain(r.grouped)}")
    if r.comma == "decimal" and comma == THOUSANDS and "," in s:
        raise NumberFormError(f"{s!r}: a comma-separated file has no decimal commas (a comma in its numbers groups "
                              f"thousands) — write {fmt_plain(r.value)}")
    return r.value


def fmt_plain(x: float) -> str:
    """A number as plain digits with a decimal point (no exponent, no separators)."""
    import numpy as np

    return np.format_float_positional(x, trim="-")


def comma_use(text) -> str | None:
    """How a number written as ``text`` uses the comma when it can be read one way only: ``"decimal"`` (``1,25``,
    ``1.250,5``, ``1.250.000``), ``"thousands"`` (``1,250,000``, ``1,250.5``), else None (no separators, an
    ambiguous ``1,250``, not a number)."""
    if not isinstance(text, str) or not any(c in text for c in ".,"):
        return None
    s = text.strip().replace("\u2212", "-")
    if _PLAIN.fullmatch(s):
        return None
    try:
        use = _reading(s).comma
    except NumberFormError:
        return None
    return use if use in ("decimal", "thousands") else None


def comma_role(delimiter: str | None, texts=()) -> str:
    """How the numbers of a table use the comma (:func:`read_number`'s ``comma``): :data:`THOUSANDS` in a
    comma-separated file; elsewhere (``;``, tab or space separated text, a workbook's text cells) what its
    numbers that can be read one way only say (``texts``: its cells, or one column's): :data:`DECIMAL` or
    :data:`THOUSANDS` if they agree, :data:`EITHER` if none says or they disagree."""
    if delimiter == ",":
        return THOUSANDS
    seen = {u for u in map(comma_use, texts) if u is not None}
    return seen.pop() if len(seen) == 1 else EITHER


class CommaColumn:
    """One column of numbers read as they come, its ambiguous ones decided at the end by what the column's other
    numbers say (:func:`comma_role`): :meth:`read` gives the reading with a decimal comma / point at once,
    :meth:`settle` replaces a ``1,250`` by 1250 in a column that groups thousands with commas, or refuses what
    nothing decides (a ``1,250`` in a column that writes no other comma, a ``1.250`` in one that writes decimal
    commas)."""

    def __init__(self, delimiter: str | None):
        self.fixed = THOUSANDS if delimiter == "," else None
        self.seen: set[str] = set()
        self.index, self.grouped = array.array("q"), array.array("d")   # each 1,250: its place, 1250
        self.first_comma = self.first_point = None    # (text, where) of the first 1,250 and the first 1.250

    def read(self, v, index: int, where=None) -> float | None:
        """The number in a cell (:func:`cell_number`); ``index``: its place among the column's numbers, ``where``:
        where it is (its row), for :meth:`settle`'s error."""
        if self.fixed is not None or not isinstance(v, str):
            return cell_number(v, self.fixed or EITHER)
        s = v.strip().replace("\u2212", "-")
        if _PLAIN.fullmatch(s):
            if self.first_point is None and _POINT_GROUPED.fullmatch(s):
                self.first_point = (s, where)
            return float(s)
        if s.startswith("'"):
            return read_number(s)
        r = _reading(s)
        if r.comma == "either":
            self.index.append(index)
            self.grouped.append(r.grouped)
            if self.first_comma is None:
                self.first_comma = (s, where)
        elif r.comma is not None:
            self.seen.add(r.comma)
        return r.value

    def settle(self, values) -> NumberFormError | None:
        """Decide the ambiguous numbers read into ``values`` (indexable, in place): None when done, else the error
        of the first that nothing decides, with its ``where``."""
        role = next(iter(self.seen)) if len(self.seen) == 1 else EITHER
        if role == THOUSANDS:
            for i, g in zip(self.index, self.grouped):
                values[i] = g
        for first in (self.first_comma, self.first_point):
            if first is None:
                continue
            try:
                read_number(first[0], role)
            except NumberFormError as exc:
                exc.where = first[1]
                return exc
        return None


def is_number(v) -> bool:
    """Whether a cell holds a number in some reading (an ambiguous ``1,250`` and a date count: reading them says
    why they are refused) — to tell a row of numbers from a header."""
    try:
        return cell_number(v, EITHER) is not None
    except NumberFormError as exc:
        return exc.advice


def cell_number(v, comma: str = EITHER) -> float | None:
    """The number in a cell (None for a blank one): a workbook's number, or text read by :func:`read_number`
    (``−`` read as ``-``; ``comma``: how the file uses the comma); a date, a boolean or other text is a ValueError
    (:class:`NumberFormError` with the reason)."""
    if blank(v):
        return None
    if isinstance(v, bool):
        raise NumberFormError(f"not a number: {v}", False)
    if isinstance(v, (int, float)):
        return float(v)
    if isinstance(v, (_dt.date, _dt.time, _dt.timedelta)):
        raise NumberFormError("the spreadsheet turned this cell into a date or time: format the column as number "
                              "or text and write the number again")
    return read_number(v, comma)


# ------------------------------------------------------------------------------ tables with a header row
#: "name" or "name [unit]": the unit is a bracket group after a space (a name may hold brackets: "E_c[1,2]")
_HEADER = re.compile(r"^\s*(\S.*?)(?:\s+\[\s*([^\[\]]+?)\s*\])?\s*$")


def split_header(cell: str) -> tuple[str, str | None] | None:
    """``(name, unit or None)`` of a header cell ``name`` or ``name [unit]`` (the unit as written); None for a
    blank cell."""
    m = _HEADER.match(str(cell))
    if not m or not m.group(1):
        return None
    return m.group(1), m.group(2)


@dataclass
class Table:
    """A table with a header row (:func:`read_table`): the header's names and units, the body rows with their
    row numbers, and located errors."""

    file: str
    sha256: str
    location: Location
    header_row: int
    cells: list[str]                  # the header cells as written
    names: list[str]                  # their names
    units: list[str | None]           # their units as written, None where the header gives none
    rows: list[tuple[int, list]]      # (row number, cells: strings stripped, XLSX numbers as numbers, blank "")
    lettered: bool = False
    comma: str = EITHER               # how its numbers use the comma (:func:`comma_role` of the file)

    def error(self, reason: str, row: int | None = None, col: int | None = None) -> SpecError:
        """A located error: at ``row`` (default the header's) and column index ``col`` (None: the whole row)."""
        row = self.header_row if row is None else row
        if col is None:
            return self.location.error(reason, row)
        name = self.cells[col] if col < len(self.cells) and self.cells[col] else None
        return self.location.error(reason, row, name, col_letter(col) if self.lettered or name is None else None)

    def unit(self, col: int) -> str | None:
        """The canonical unit of column ``col`` from its header (None if it gives none; an unknown unit is an
        error at the header cell)."""
        from .. import units

        u = self.units[col]
        if u is None:
            return None
        try:
            return units.canonical(u)
        except InputError as exc:
            raise self.error(exc.reason, col=col) from None

    def number(self, row: int, cells: list, col: int) -> float:
        """The finite number in column ``col`` of a body row (an error naming row and column otherwise)."""
        v = cells[col] if col < len(cells) else ""
        if isinstance(v, bool):
            raise self.error(f"not a number: {v!r}", row, col)
        try:
            x = cell_number(v, self.comma)
        except NumberFormError as exc:
            if isinstance(v, str) and v.strip().lower().lstrip("+-") in ("inf", "infinity", "nan"):
                raise self.error(f"must be a finite number, got {v!r}", row, col) from None
            raise self.error(str(exc) if exc.advice else f"not a number: {v!r}", row, col) from None
        if x is None:
            raise self.error("not a number: ''", row, col)
        if not math.isfinite(x):
            raise self.error(f"must be a finite number, got {v!r}", row, col)
        return x


def read_table(path: str | Path, sheet: str | None = None, *, what: str = "a header row") -> Table:
    """The table in a CSV/TSV/TXT file or XLSX sheet: comment rows (first cell ``# …``) and blank rows skipped,
    the first other row the header (:func:`split_header`; :meth:`Table.unit` checks a column's unit), the rest
    the body.  ``what`` says what the header should look like (in the error of a file without one)."""
    sh = read_rows(path, sheet)
    file = str(path)
    loc = sh.location(file)
    rows = []
    for r, cells in sh.rows:
        if skipped(cells):
            continue
        cells = [c.strip() if isinstance(c, str) else ("" if c is None else c) for c in cells]
        while cells and cells[-1] == "" and sh.lettered:     # XLSX: trailing empty cells of a wider sheet
            cells.pop()
        rows.append((r, cells))
    if not rows:
        raise SpecError(f"no header row ({what})", file=file, key=loc.key(1))
    hrow, head = rows[0]
    head = [str(c) for c in head]
    names, col_units = header_cells(head, loc, hrow)
    for r, cells in rows[1:]:
        if any(not blank(c) for c in cells[len(head):]):
            raise loc.error(f"{len(cells)} fields, the header has {len(head)}{split_number_hint(sh.delimiter)}", r)
    return Table(file, sh.sha256, loc, hrow, head, names, col_units, rows[1:], sh.lettered,
                 comma_role(sh.delimiter, (c for _, cells in rows[1:] for c in cells)))


def split_number_hint(delimiter: str | None) -> str:
    return (" (the file is read as comma-separated: a decimal comma there splits a number in two — write decimal "
            "points, or separate the columns with ';')" if delimiter == "," else "")


def header_cells(head: list[str], loc: Location, row: int) -> tuple[list[str], list[str | None]]:
    """The names and units (as written; None where none is given) of a header row's cells (:func:`split_header`);
    a cell that is neither ``name`` nor ``name [unit]`` is an error at that cell."""
    names, col_units = [], []
    for i, c in enumerate(head):
        parsed = split_header(c)
        if parsed is None:
            raise loc.error("cannot read this header cell (expected 'name' or 'name [unit]')", row, c or None,
                            col_letter(i))
        names.append(parsed[0])
        col_units.append(parsed[1])
    return names, col_units


# ------------------------------------------------------------------------------ writing
def check_suffix(path: str | Path, what: str = "table") -> Path:
    path = Path(path)
    if path.suffix.lower() not in WRITE_SUFFIXES:
        raise SpecError(f"unknown {what} format {path.suffix!r} (expected .csv, .tsv or .xlsx)", file=str(path),
                        key="-")
    return path


def write_rows(path: str | Path, rows: list[list], *, sheet: str = "Sheet1", header_row: int | None = None,
               text_columns: tuple[int, ...] = (), widths: tuple[float, ...] = (), number=str,
               shown: str | None = None) -> Path:
    """Write rows of cells as CSV/TSV (UTF-8 with BOM) or XLSX.

    ``header_row`` (1-based) is set bold and frozen in XLSX; ``text_columns`` (0-based) are
    formatted as text in XLSX (a tolerance like ``1/2`` must not become a date); ``number``
    writes a float into CSV (default ``str``: the shortest repr that reads back exactly).
    Text is never written as a formula: XLSX cells hold it as text (a text cell, marked with a quote prefix
    when it starts like a formula); a CSV cannot mark it, so :func:`formula_like` text is refused there
    (``shown``: the file named in that error, default ``path``).
    """
    path = check_suffix(path)
    suffix = path.suffix.lower()
    if suffix in (".csv", ".tsv"):
        for r, row in enumerate(rows, start=1):
            for j, v in enumerate(row):
                if formula_like(v):
                    raise SpecError(f"{str(v)[:40]!r} would run as a formula when a spreadsheet opens the file, and "
                                    "a CSV cannot say it is text: write .xlsx (its cells are written as text) or "
                                    "change the text", file=shown or str(path), key=f"row {r}, column {col_letter(j)}")
        with open(path, "w", encoding="utf-8-sig", newline="") as fh:
            w = csv.writer(fh, delimiter="\t" if suffix == ".tsv" else ",")
            for row in rows:
                w.writerow(["" if v is None else number(v) if isinstance(v, float) else v for v in row])
        return path
    from openpyxl import Workbook
    from openpyxl.styles import Font

    wb = Workbook()
    ws = wb.active
    ws.title = sheet[:31]
    for row in rows:
        ws.append([None if v is None else v for v in row])
        for c in ws[ws.max_row]:
            if isinstance(c.value, str):
                c.data_type = "s"                       # text, never a formula (openpyxl makes "=…" one)
                if c.value.startswith(FORMULA_START):
                    c.quotePrefix = True                # and a spreadsheet keeps it text when it is edited
    if header_row is not None:
        for c in ws[header_row]:
            c.font = Font(bold=True)
        ws.freeze_panes = ws.cell(row=header_row + 1, column=1)
    for row in ws.iter_rows(min_row=(header_row or 0) + 1):
        for j in text_columns:
            if j < len(row):
                row[j].number_format = "@"
    for j, width in enumerate(widths):
        ws.column_dimensions[col_letter(j)].width = width
    wb.save(path)
    return path


def write_frames(path: str | Path, frames: dict[str, "object"], *, index: bool = False) -> Path:
    """pandas DataFrames as a table file: XLSX one sheet per frame; CSV/TSV the one frame (only one allowed).  Text
    is written as text, never as a formula, and control characters as their escapes (:mod:`rvtol.safetext`)."""
    from ..safetext import csv_text, xlsx_as_text, xlsx_text

    path = check_suffix(path)
    if path.suffix.lower() == ".xlsx":
        import pandas as pd

        with pd.ExcelWriter(path, engine="openpyxl") as xw:
            for name, df in frames.items():
                df, text = _text_cells(df.reset_index() if index else df, xlsx_text)
                df.to_excel(xw, sheet_name=name[:31], index=False)
                xlsx_as_text(xw.sheets[name[:31]], [c + 1 for c in text])
        return path
    if len(frames) != 1:
        raise ValueError("a CSV file holds one table")
    (df,) = frames.values()
    df, _ = _text_cells(df.reset_index() if index else df, csv_text)
    df.to_csv(path, index=False, encoding="utf-8-sig", sep="\t" if path.suffix.lower() == ".tsv" else ",")
    return path


def _text_cells(df, clean):
    """``df`` with ``clean`` applied to its column names and its text cells, and the positions of its text columns."""
    from pandas.api.types import is_object_dtype, is_string_dtype

    text = [i for i, t in enumerate(df.dtypes) if is_object_dtype(t) or is_string_dtype(t)]
    df = df.rename(columns=lambda c: clean(str(c)))
    if text:
        df = df.copy()
        for i in text:
            df.iloc[:, i] = df.iloc[:, i].map(lambda v: clean(v) if isinstance(v, str) else v)
    return df, text
