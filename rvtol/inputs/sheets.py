"""Spreadsheet files both ways: rows of cells from CSV/TSV/XLSX with their locations, and rows or
DataFrames written as CSV (UTF-8 with a byte-order mark, so Excel shows ``±`` and ``µ``) or XLSX.

Every reader of a table in rvtol (spec tables, measured values) goes through :func:`read_rows`, so
a problem is always one line naming the file, the sheet (XLSX), the row and the column
(:class:`Location`): ``stack.xlsx: sheet 'spec', row 7, column 'tolerance' (E): …``.
"""
from __future__ import annotations

import csv
import hashlib
import io
import re
from dataclasses import dataclass
from pathlib import Path

from ..params import decode_text, read_bytes
from ..errors import SpecError

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
    if suffix in (".csv", ".txt", ".tsv"):
        raw = read_bytes(path, "a table file")
        text = decode_text(raw, str(path), fallback="cp1252")   # cp1252: Excel's "CSV" on Western Windows
        delim = "\t" if suffix == ".tsv" else sniff(text, delimiters)
        reader = csv.reader(io.StringIO(text), delimiter=delim, skipinitialspace=delim == " ")
        rows = [(r, cells) for r, cells in enumerate(reader, start=1)]
        return Sheet(rows, None, False, hashlib.sha256(raw).hexdigest())
    raise SpecError(f"unknown table format {path.suffix!r} (expected .csv, .tsv, .txt or .xlsx; save other "
                    "spreadsheets as .xlsx)", file=str(path), key="-")


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
    """The delimiter of CSV text (comment lines ignored); ``,`` when it cannot be told."""
    head = "\n".join(line for line in text.splitlines()[:50] if line.strip() and not line.lstrip().startswith("#"))
    try:
        return csv.Sniffer().sniff(head or text[:4096], delimiters=delimiters).delimiter
    except csv.Error:
        return ","


def blank(v) -> bool:
    return v is None or (isinstance(v, str) and not v.strip())


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
    """pandas DataFrames as a table file: XLSX one sheet per frame; CSV/TSV the one frame (only one allowed)."""
    path = check_suffix(path)
    if path.suffix.lower() == ".xlsx":
        import pandas as pd

        with pd.ExcelWriter(path, engine="openpyxl") as xw:
            for name, df in frames.items():
                df.to_excel(xw, sheet_name=name[:31], index=index)
        return path
    if len(frames) != 1:
        raise ValueError("a CSV file holds one table")
    (df,) = frames.values()
    df.to_csv(path, index=index, encoding="utf-8-sig", sep="\t" if path.suffix.lower() == ".tsv" else ",")
    return path
