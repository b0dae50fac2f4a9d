"""Text from a study in what rvtol reads and writes: control characters and spreadsheet formulas.

A study's text (a requirement's name, a title, a factor's source) ends up in a terminal, JUnit XML, Markdown,
HTML, XLSX and CSV.  Two kinds of text are never safe everywhere:

* **control characters** — C0 (U+0000–U+001F) but tab, line feed and carriage return, DEL and C1
  (U+007F–U+009F), surrogates and U+FFFE/U+FFFF: XML 1.0 forbids most of them (an ESC makes junit.xml
  ill-formed, openpyxl refuses it in a cell), a terminal obeys them (an ANSI escape in a name recolours or
  rewrites the screen).  The loaders refuse them (:func:`control_character`, :class:`rvtol.params.Params`);
  the writers show any that reach them as ``\\x1b`` (:func:`visible`);
* **formulas** — a spreadsheet evaluates a cell that starts with ``=`` (and, in a CSV it opens, ``+``,
  ``-``, ``@``, a tab or a carriage return: OWASP's "CSV injection"), so a requirement named
  ``=HYPERLINK(...)`` would become a live link (:func:`formula_like`).  XLSX text cells are written as
  text, quote-prefixed when they start like a formula (:func:`xlsx_as_text`; ``rvtol spec export`` too); a
  report's CSV text cells that would run get a leading ``'`` (:func:`csv_text`: a run never fails after
  computing; ``spec export`` refuses such text in a CSV instead, it must read back as written).
"""
from __future__ import annotations

import re

#: characters no text may hold: XML 1.0's forbidden ones (C0 but tab, LF, CR; surrogates; U+FFFE, U+FFFF) and the
#: ones a terminal obeys (DEL, C1)
CONTROL = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f\ud800-\udfff\ufffe\uffff]")
#: what may not break a name (one line, one cell): line breaks and tabs besides :data:`CONTROL`
LINE_BREAKS = re.compile("[\t\n\r\x85\u2028\u2029]")
#: the first characters that make a spreadsheet read a cell as a formula (OWASP: CSV injection)
FORMULA_START = ("=", "+", "-", "@", "\t", "\r")
#: signed numbers, deviations and limits as rvtol writes them (+0.1/-0.05, -0.5, -0.1..0.2, a "+"/"-" direction): no
#: function call in them, and they must read back as written
_SIGNED = re.compile(r"[+-](?:\d*\.?\d+(?:/[+-]?\d*\.?\d+|\.\.[+-]?\d*\.?\d+)?)?")


def formula_like(v) -> bool:
    """Whether a spreadsheet would run text as a formula: it starts with ``=``, ``@``, a tab or a carriage return,
    or with ``+``/``-`` and is not a signed number or deviation (:data:`_SIGNED`)."""
    return isinstance(v, str) and v.startswith(FORMULA_START) and not _SIGNED.fullmatch(v)


def _code(ch: str) -> str:
    return f"U+{ord(ch):04X}"


def control_character(text: str, name: bool = False) -> str | None:
    """Why ``text`` cannot be used (its first control character, e.g. ``holds the control character U+001B``), or
    None; with ``name``, a line break or a tab too (a name is one line)."""
    m = CONTROL.search(text) or (LINE_BREAKS.search(text) if name else None)
    if m is None:
        return None
    what = "the control character" if CONTROL.match(m.group()) else "a line break or a tab"
    return f"holds {what} {_code(m.group())} at character {m.start() + 1}"


def visible(text: str) -> str:
    """``text`` with every :data:`CONTROL` character written as its escape (``\\x1b``, ``\\ud800``): what XML and a
    spreadsheet cell can hold, and a terminal shows as it is."""
    return CONTROL.sub(lambda m: m.group().encode("unicode_escape").decode("ascii"), text)


def csv_text(value):
    """A CSV cell's value: text made :func:`visible`, and a leading ``'`` when a spreadsheet would run it
    (:func:`formula_like`: a signed number such as -0.5 stays as it is)."""
    if not isinstance(value, str):
        return value
    value = visible(value)
    return "'" + value if formula_like(value) else value


#: the most characters an XLSX cell holds (Excel's limit: a longer one makes the file one Excel must repair)
XLSX_CELL_CHARS = 32_767


def xlsx_text(value: str) -> str:
    """An XLSX cell's text: :func:`visible`, cut to :data:`XLSX_CELL_CHARS` (ending in ``…``)."""
    value = visible(value)
    return value if len(value) <= XLSX_CELL_CHARS else value[:XLSX_CELL_CHARS - 1] + "…"


def xlsx_as_text(worksheet, columns=()) -> None:
    """Cells of ``worksheet`` that openpyxl took for formulas (text starting with ``=``) made text again: the header
    row and the 1-based ``columns`` (the text columns; a large numeric sheet is not scanned)."""
    cells = [c for row in worksheet.iter_rows(max_row=1) for c in row]
    for col in columns:
        cells += [c for row in worksheet.iter_rows(min_row=2, min_col=col, max_col=col) for c in row]
    for cell in cells:
        if cell.data_type == "f":
            cell.data_type = "s"
        if isinstance(cell.value, str) and cell.value.startswith(FORMULA_START):
            cell.quotePrefix = True            # and a spreadsheet keeps it text when it is edited
