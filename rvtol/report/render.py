"""One view model → HTML (Jinja2 template) → PDF (WeasyPrint)."""
from __future__ import annotations

import base64
import logging
import re
from pathlib import Path

import numpy as np
from jinja2 import Environment, PackageLoader, select_autoescape
from markupsafe import Markup

from .. import __version__
from ..blocks import Figure, Links, RunTable, Section, Table, Text
from .standard import run_table
from .summary import now_iso

_ENV = Environment(loader=PackageLoader("rvtol.report", "templates"), autoescape=select_autoescape(["html", "j2"]))

#: rows of a table the PDF shows (the HTML and summary.json hold every row): page layout of tables is what
#: costs a PDF its time — the sign-off's 276-factor and mapping tables made 104 pages and 2½ minutes
PDF_MAX_ROWS = 40


#: how many characters of table text an A4 portrait page holds across (the PDF's 7.5 pt DejaVu Sans, 182 mm between
#: the margins: about 1.45 mm a character), a column's padding counted as 2
PDF_WIDTH_CHARS = 118
#: the width (characters) a column of long text is given in the PDF before it wraps at its spaces
PDF_WRAP_CHARS = 28


def _breakable(name: str) -> str:
    """A column name that may wrap after its dots and underscores (zero-width spaces): output names such as
    ``stackup.disc_1_axis.tilt`` would otherwise set a column's width."""
    return re.sub(r"([._])", "\\1\u200b", name)


def _pdf_width(name: str, values) -> int:
    """A column's width in the PDF (characters): its longest unbreakable word, its text up to
    :data:`PDF_WRAP_CHARS`, and the padding."""
    words = [w for v in (_breakable(name), *values) for w in re.split(r"[\s\u200b]+", v)]
    return 2 + max(max(len(w) for w in words), min(max((len(v) for v in values), default=0), PDF_WRAP_CHARS))


def _pdf_column_parts(df, index: bool) -> list[list[int]]:
    """The columns (by position) in parts that each fit the PDF's page width, each part led by the column that
    names the rows (the first, or the index)."""
    n = df.shape[1]
    lead = [] if index else [0]
    width = [_pdf_width(str(df.columns[k]), list(df.iloc[:, k])) for k in range(n)]
    budget = PDF_WIDTH_CHARS - (_pdf_width("", list(df.index)) if index else sum(width[k] for k in lead))
    parts, used = [[]], 0
    for k in range(len(lead), n):
        if parts[-1] and used + width[k] > budget:
            parts.append([])
            used = 0
        parts[-1].append(k)
        used += width[k]
    return [lead + p for p in parts]


def _table_html(t: Table, max_rows: int | None = None, omit: list[str] = (), pdf: bool = False) -> tuple[Markup, int, str]:
    """The table as HTML, in how many parts of columns and the column that leads each part (the PDF's view,
    ``pdf``: in parts that fit the page)."""
    df = t.frame if max_rows is None else t.frame.iloc[:max_rows]
    df = df.drop(columns=list(omit))

    def fmt(v):
        if v is None:
            return "—"
        if isinstance(v, (float, np.floating)):
            return "—" if not np.isfinite(v) else t.float_format.format(v)
        return str(v)

    df = df.apply(lambda col: col.map(fmt).astype(object)) if df.shape[1] else df
    if t.index:
        df.index = [fmt(i) for i in df.index]
    parts = _pdf_column_parts(df, t.index) if pdf and df.shape[1] else [list(range(df.shape[1]))]
    html = ""
    for cols in parts:
        part = df.iloc[:, cols]
        if pdf:
            part = part.set_axis([_breakable(str(c)) for c in part.columns], axis=1)
        html += part.to_html(index=t.index, escape=True, border=0, classes="data" + (" text" if t.text else ""),
                             na_rep="—")
    lead = "the row names" if t.index or not df.shape[1] else f"column {df.columns[0]}"
    return Markup(_LIGHT.sub(r'<td class="light light-\1">● \1', html)), len(parts), lead


#: a requirement's traffic light in a table cell (rvtol.signoff.signoff_section): coloured by the template's CSS
_LIGHT = re.compile(r"<td>● (PASS|UNDECIDED|FAIL)")


def _block_view(b, max_rows: int | None = None, result=None, keys=()) -> dict:
    if isinstance(b, RunTable):
        b = run_table(result)
    if isinstance(b, Links):
        return {"type": "links", "lead": b.lead, "items": [(k, t) for k, t in b.items if k in keys]}
    if isinstance(b, Text):
        return {"type": "text", "paragraphs": [p.strip() for p in b.text.split("\n\n") if p.strip()]}
    if isinstance(b, Table):          # max_rows given: the PDF's view
        cut = max_rows is not None and len(b.frame) > max_rows
        omit = [c for c in b.pdf_omit if c in b.frame.columns] if max_rows is not None else []
        left = [f"the first {max_rows} of {len(b.frame)} rows"] if cut else []
        left += [f"without the column{'s' if len(omit) > 1 else ''} {', '.join(omit)}"] if omit else []
        html, parts, lead = _table_html(b, max_rows if cut else None, omit, pdf=max_rows is not None)
        if parts > 1:
            left += [f"its columns in {parts} parts across the page, each led by {lead}"]
        caption = b.caption + (f" ({'; '.join(left)}: every row and column is in report.html and summary.json)"
                               if left else "")
        return {"type": "table", "html": html, "caption": caption}
    if isinstance(b, Figure):
        return {"type": "figure", "src": "data:image/png;base64," + base64.b64encode(b.png).decode("ascii"),
                "caption": b.caption, "width": b.width}
    raise TypeError(f"unknown report block {type(b).__name__}")


def view_model(result, max_rows: int | None = None) -> dict:
    """Everything the template shows, as plain data (the one view model for HTML and PDF; ``max_rows``: the
    rows a table keeps, for the PDF).  It only formats: the sections were built during the run."""
    st = result.study
    sections: list[Section] = list(result.standard_sections) + list(result.sections)
    keys = {s.key for s in sections}
    return {
        "title": st.title,
        "name": st.name,
        "description": [p.strip() for p in st.description.split("\n\n") if p.strip()],
        "verdict": result.verdict,
        "generated": now_iso(),
        "version": __version__,
        "study_file": st.file,
        "toc": [(s.key, s.title) for s in sections],
        "sections": [{"key": s.key, "title": s.title, "blocks": [_block_view(b, max_rows, result, keys) for b in s.blocks]}
                     for s in sections],
    }


def render_html(result, max_rows: int | None = None) -> str:
    return _ENV.get_template("report.html.j2").render(**view_model(result, max_rows), link_base="")


def render_summary_html(result) -> str:
    """The one-page summary: the verdict and the sign-off section (the first page of the full report)."""
    view = view_model(result)
    view["sections"] = [s for s in view["sections"] if s["key"] == "signoff"]
    return _ENV.get_template("summary.html.j2").render(**view, link_base="report.html")


def render_pdf(html: str, path: str | Path) -> None:
    for name in ("weasyprint", "fontTools"):
        logging.getLogger(name).setLevel(logging.ERROR)
    from weasyprint import HTML

    HTML(string=html).write_pdf(str(path))
