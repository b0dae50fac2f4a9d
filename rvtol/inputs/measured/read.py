"""Reading measured values: one column of a CSV/TSV/TXT or XLSX file of measured parts."""
from __future__ import annotations

import array
import itertools
import math
from pathlib import Path

import numpy as np

from ...errors import did_you_mean, InputError, SpecError
from ..sheets import (CommaColumn, blank, byte_progress, col_letter, is_number, skipped, split_number_hint,
                      split_header, stream_rows)


def _label(header: list[str] | None, i: int) -> str:
    """Column ``i`` as its header names it, else by its 1-based number."""
    return header[i] if header and i < len(header) and header[i] else f"{i + 1}"


def _column_index(column: str | int | None, header, names, file: str, at: str) -> int | None:
    """The 0-based index of ``column`` (a 1-based number, or a header cell: as written, its name, then its name in
    any case); None when no column is named.  ``at``: the header row's place, for the error."""
    if isinstance(column, int) and not isinstance(column, bool):
        return column - 1
    if column is None:
        return None
    if header is None:
        raise SpecError(f"the file has no header row to find column {column!r} in; give its number",
                        file=file, key="column")
    want = str(column).strip()
    hits = ([i for i, h in enumerate(header) if h == want] or [i for i, n in enumerate(names) if n == want]
            or [i for i, n in enumerate(names) if n.lower() == want.lower()])
    if not hits:
        # the header's cells are not echoed (a file's first line may hold anything): a close name only
        raise SpecError(f"no column {column!r} in the header row"
                        f"{did_you_mean(str(column), [n for n in names if n and len(n) <= 64])}", file=file, key=at)
    if len(hits) > 1:
        raise SpecError(f"column {column!r} appears {len(hits)} times", file=file, key=at)
    return hits[0]


def read_measurements(path: str | Path, column: str | int | None = None, *, sheet: str | None = None,
                      unit: str | None = None) -> np.ndarray:
    """Measured values from a CSV/TSV/TXT or XLSX file: one column by header name or 1-based number.

    The rows come through the one table reader (:mod:`rvtol.inputs.sheets`) with its rules: comment
    rows (``# …``) and blank rows skipped, a header cell ``name`` or ``name [unit]``
    (:func:`~rvtol.inputs.sheets.split_header`: ``column = "d"`` finds ``d [mm]``; the name as
    written, and then any case, are tried), numbers read one way only
    (:func:`~rvtol.inputs.sheets.read_number`: a decimal comma outside comma-separated files, thousands
    separators; an ambiguous ``1,250`` decided by the column's other numbers,
    :class:`~rvtol.inputs.sheets.CommaColumn`, or refused).  Unlike a spec table the header is optional: a
    first row that is all numbers is data; a value beyond the header's (or the first row's) columns is refused
    (a decimal comma read as the delimiter splits a number in two).  With a unit in the column's header and ``unit`` (the
    factor's) given, the values are converted to ``unit`` (another dimension is an error at the
    header cell).  Blank cells are skipped (columns of different lengths); anything else that is not
    a number is an error naming row and column.  The rows are read one at a time (only the column's
    numbers are kept: a file of millions of rows takes the memory of its numbers), with a progress
    bar on a terminal for a large file.
    """
    path = Path(path)
    file = str(path)
    rs = stream_rows(path, sheet, delimiters=",;\t ", text_suffixes=(".csv", ".tsv", ".txt", ".dat", ""),
                     what="a file of measured values")
    loc = rs.location(file)
    where_sheet = f"sheet {rs.title!r}, " if rs.title is not None else ""
    rows = ((r, c) for r, c in rs.rows if not skipped(c))
    first_row = next(rows, None)
    if first_row is None:
        raise SpecError("no values", file=file, key="-")
    r0, first = first_row

    has_header = not all(is_number(v) for v in first if not blank(v))
    header, names, col_units = None, None, None
    if has_header:
        header = [("" if v is None else str(v).strip()) for v in first]
        parsed = [split_header(h) if h else ("", None) for h in header]
        names, col_units = [n for n, _ in parsed], [u for _, u in parsed]
    body = rows if has_header else itertools.chain([first_row], rows)
    width = len(first)
    ncols = len(first) - next((k for k, v in enumerate(reversed(first)) if not blank(v)), len(first))
    j = _column_index(column, header, names, file, f"{where_sheet}row {r0}")
    # the values of column j — or, without a column, of every column (exactly one may be used)
    vals: dict[int, array.array] = {}
    commas: dict[int, CommaColumn] = {}     # per column: a 1,250 decided by the column's other numbers

    with byte_progress(rs.size, f"reading {path.name}") as bar:
        step = 0
        for r, cells in body:
            if len(cells) > ncols and any(not blank(c) for c in cells[ncols:]):
                # a value where the first row has none: a decimal comma taken for the delimiter splits "0,1" in two
                raise SpecError(f"{len(cells)} fields, the {'header' if has_header else 'first row'} has {ncols}"
                                + split_number_hint(rs.delimiter), file=file, key=f"{where_sheet}row {r}")
            width = max(width, len(cells))
            cols = (j,) if j is not None else range(len(cells))
            for i in cols:
                v = cells[i] if i < len(cells) else None
                if blank(v):
                    continue
                try:
                    col = vals.setdefault(i, array.array("d"))
                    x = commas.setdefault(i, CommaColumn(rs.delimiter)).read(v, len(col), r)
                except ValueError as exc:
                    label = _label(header, i)
                    why = str(exc) if getattr(exc, "advice", False) and len(str(v)) <= 24 else (
                        "expected a number" + (f", got {str(v).strip()!r}" if len(str(v)) <= 24 else ""))
                    raise SpecError(why, file=file, key=f"{where_sheet}row {r}, column {label!r}") from None
                if not math.isfinite(x):
                    label = _label(header, i)
                    raise SpecError(f"not a finite number: {v!r}", file=file,
                                    key=f"{where_sheet}row {r}, column {label!r}")
                col.append(x)
            step += 1
            if step == 4096:
                bar.advance(4096 * (sum(len(str(c)) + 1 for c in cells)))
                step = 0
    if j is not None and not 0 <= j < width:
        raise SpecError(f"column {column} is out of range (the file has {width})", file=file, key="column")
    if j is None:
        if len(vals) != 1:
            shown = ", ".join(h for h in (header or []) if h) if header and len(header) <= 12 else ""
            raise SpecError(f"the file has several columns{f' ({shown})' if shown else ''}: say which one "
                            "(column = ...)", file=file, key=f"{where_sheet}row {r0}")
        j = next(iter(vals))
    label = _label(header, j)
    got = vals.get(j, array.array("d"))
    undecided = commas[j].settle(got) if j in commas else None
    if undecided is not None:
        raise SpecError(str(undecided), file=file, key=f"{where_sheet}row {undecided.where}, column {label!r}")
    if len(got) < 2:
        raise SpecError(f"column {label!r} holds {len(got)} value(s); need at least 2", file=file,
                        key=f"{where_sheet}column {label!r}")
    out = np.frombuffer(got, dtype=float).copy()
    written = col_units[j] if col_units and j < len(col_units) else None
    if written is not None and unit is not None:       # the header's unit -> the factor's
        from ... import units

        try:
            out = units.convert(out, units.canonical(written, units.dimension(unit)), units.canonical(unit))
        except InputError as exc:
            raise loc.error(exc.reason, r0, header[j], col_letter(j) if rs.lettered else None) from None
    return out
