"""One view model → HTML (Jinja2 template) → PDF (WeasyPrint)."""
from __future__ import annotations

import base64
import logging
from pathlib import Path

import numpy as np
from jinja2 import Environment, PackageLoader, select_autoescape
from markupsafe import Markup

from .. import __version__
from .sections import Figure, Section, Table, Text
from .standard import standard_sections
from .summary import now_iso

_ENV = Environment(loader=PackageLoader("rvtol.report", "templates"), autoescape=select_autoescape(["html", "j2"]))


def _table_html(t: Table) -> Markup:
    df = t.frame.copy()

    def fmt(v):
        if v is None:
            return "—"
        if isinstance(v, (float, np.floating)):
            return "—" if not np.isfinite(v) else t.float_format.format(v)
        return str(v)

    for c in df.columns:
        df[c] = df[c].map(fmt).astype(object)
    if t.index:
        df.index = [fmt(i) for i in df.index]
    html = df.to_html(index=t.index, escape=True, border=0, classes="data", na_rep="—")
    return Markup(html)


def _block_view(b) -> dict:
    if isinstance(b, Text):
        return {"type": "text", "paragraphs": [p.strip() for p in b.text.split("\n\n") if p.strip()]}
    if isinstance(b, Table):
        return {"type": "table", "html": _table_html(b), "caption": b.caption}
    if isinstance(b, Figure):
        return {"type": "figure", "src": "data:image/png;base64," + base64.b64encode(b.png).decode("ascii"),
                "caption": b.caption, "width": b.width}
    raise TypeError(f"unknown report block {type(b).__name__}")


def view_model(result) -> dict:
    """Everything the template shows, as plain data (the one view model for HTML and PDF)."""
    st = result.study
    sections: list[Section] = standard_sections(result) + list(result.sections)
    return {
        "title": st.title,
        "name": st.name,
        "description": [p.strip() for p in st.description.split("\n\n") if p.strip()],
        "verdict": result.verdict,
        "generated": now_iso(),
        "version": __version__,
        "study_file": st.file,
        "toc": [(s.key, s.title) for s in sections],
        "sections": [{"key": s.key, "title": s.title, "blocks": [_block_view(b) for b in s.blocks]}
                     for s in sections],
    }


def render_html(result) -> str:
    return _ENV.get_template("report.html.j2").render(**view_model(result))


def render_pdf(html: str, path: str | Path) -> None:
    for name in ("weasyprint", "fontTools"):
        logging.getLogger(name).setLevel(logging.ERROR)
    from weasyprint import HTML

    HTML(string=html).write_pdf(str(path))
