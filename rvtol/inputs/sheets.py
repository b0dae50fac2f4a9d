"""Spreadsheet files both ways: rows of cells from CSV/TSV/XLSX with their locations, and rows or
DataFrames written as CSV (UTF-8 with a byte-order mark, so Excel shows ``±`` and ``µ``) or XLSX.

Every reader of a table in rvtol (spec tables, measured values, measured parts and kit lists,
measured curves) goes through :func:`read_rows`, so a problem is always one line naming the file,
the sheet (XLSX), the row and the column (:class:`Location`): ``stack.xlsx: sheet 'spec', row 7,
column 'tolerance' (E): …``.  :func:`read_table` reads a table with a header row: rows whose first
cell starts with ``#`` are comments, blank rows are skipped, and a header cell is ``name`` or
``name [unit]`` (:func:`split_header`: the unit is a bracket group after a space, so a name may hold
brackets itself, ``E_c[1,2] [um]``).
"""
from __future__ import annotations

import csv
import hashlib
import io
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

from ..params import decode_text, read_bytes
from ..errors import InputError, SpecError

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
            if sheet is None:
                ws = wb.worksheets[0]
            elif sheet in wb.sheetnames:
                ws = wb[sheet]
            else:
                raise SpecError(f"no sheet {sheet!r} (sheets: {', '.join(wb.sheetnames)})", file=str(path),
                                key="sheet")
            rows = [(r, list(cells)) for r, cells in enumerate(ws.iter_rows(values_only=True), start=1)]
            title = ws.title
            merged = _merged_ranges(raw, getattr(ws, "_worksheet_path", None))
        finally:
            wb.close()
        _check_formulas(raw, path, title, rows)
        return Sheet(rows, title, True, hashlib.sha256(raw).hexdigest(), merged)
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


def _merged_ranges(raw: bytes, sheet_path: str | None) -> tuple[tuple[int, int, int, int], ...]:
    """The merged ranges of one sheet, from its XML (openpyxl's read-only mode does not read them)."""
    if not sheet_path:
        return ()
    import zipfile

    with zipfile.ZipFile(io.BytesIO(raw)) as z:
        try:
            xml = z.read(sheet_path.lstrip("/"))
        except KeyError:
            return ()
    return tuple((int(r0), _col_number(c0), int(r1), _col_number(c1)) for c0, r0, c1, r1 in _MERGE.findall(xml))


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


#: a number as a table cell may write it: decimal point, or decimal comma where the text delimiter is not a comma
_NUM = re.compile(r"^[+-]?(?:\d+(?:[.,]\d*)?|[.,]\d+)(?:[eE][+-]?\d+)?$")


def decimal_comma(delimiter: str | None) -> bool:
    """Whether a text table with this delimiter may write decimal commas (``;``, tab or space separated; never a
    comma-separated file, where ``25,011`` is two cells; None: a workbook, whose numbers are numbers)."""
    return delimiter is not None and delimiter in ";\t "


def cell_number(v, comma: bool = False) -> float | None:
    """The number in a cell (None for a blank one): a workbook's number, or text as :data:`_NUM` (``−`` read as
    ``-``; a decimal comma only if ``comma``); ValueError for anything else."""
    if blank(v):
        return None
    if isinstance(v, bool):
        raise ValueError(str(v))
    if isinstance(v, (int, float)):
        return float(v)
    s = str(v).strip().replace("\u2212", "-")
    if not _NUM.match(s) or ("," in s and not comma):
        raise ValueError(s)
    return float(s.replace(",", "."))


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
    comma: bool = False               # decimal commas allowed (:func:`decimal_comma` of a text file's delimiter)

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
            x = cell_number(v, True) if self.comma and isinstance(v, str) and "," in v else float(v)
        except (TypeError, ValueError):
            raise self.error(f"not a number: {v!r}", row, col) from None
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
    return Table(file, sh.sha256, loc, hrow, head, names, col_units, rows[1:], sh.lettered,
                 decimal_comma(sh.delimiter))


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
               text_columns: tuple[int, ...] = (), widths: tuple[float, ...] = (), number=str) -> Path:
    """Write rows of cells as CSV/TSV (UTF-8 with BOM) or XLSX.

    ``header_row`` (1-based) is set bold and frozen in XLSX; ``text_columns`` (0-based) are
    formatted as text in XLSX (a tolerance like ``1/2`` must not become a date); ``number``
    writes a float into CSV (default ``str``: the shortest repr that reads back exactly).
    """
    path = check_suffix(path)
    suffix = path.suffix.lower()
    if suffix in (".csv", ".tsv"):
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
