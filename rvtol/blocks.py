"""Report building blocks: a :class:`Section` holds tables, figures and text — plain data.

Every analysis returns Sections (its capability's ``texts`` layout makes the blocks); the HTML/PDF
report (:mod:`rvtol.report`) renders them generically, and ``Section.summary`` (JSON-able) goes into
``summary.json`` under ``analyses.<key>``.  A base module: the capabilities lay their results out
with it, and the report package renders it, so neither imports the other.  Figures are rendered to PNG as soon as they are
added (and the matplotlib figure closed), so Sections are cheap to keep — or, inside :func:`deferred_figures` (a
study run), pickled when added and rendered together by :func:`render_deferred` on the study's workers.
"""
from __future__ import annotations

import io
import pickle
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

import pandas as pd

from .records import frame_records  # noqa: F401  (re-exported for the analyses)


@dataclass
class Table:
    frame: pd.DataFrame
    caption: str = ""
    float_format: str = "{:.4g}"
    index: bool = False
    text: bool = False          # a table of words: every cell left-aligned
    #: columns the PDF leaves out (an A4 page holds about ten columns of a factor table): report.html and
    #: summary.json keep them
    pdf_omit: tuple[str, ...] = ()


@dataclass
class Figure:
    png: bytes
    caption: str = ""
    width: str = "100%"


@dataclass
class Text:
    text: str  # plain text; blank lines separate paragraphs; escaped when rendered


@dataclass
class Links:
    """Links to other sections of the report: ``(section key, text)``; a key the report does not hold is left out
    (the renderer knows which sections exist)."""

    items: list[tuple[str, str]]
    lead: str = "See"


@dataclass
class RunTable:
    """Where the run's timings table goes: the timings end with the run, so the renderer fills it in
    (:func:`rvtol.report.standard.run_table`)."""


@dataclass
class Section:
    key: str
    title: str
    blocks: list = field(default_factory=list)
    summary: dict[str, Any] = field(default_factory=dict)
    files: dict[str, bytes] = field(default_factory=dict)   # extra files for the report folder (name -> content)
    fixes: list = field(default_factory=list)   # rvtol.signoff.Fix: ways to pass a requirement this section shows

    def add_text(self, text: str) -> "Section":
        self.blocks.append(Text(text))
        return self

    def add_table(self, frame: pd.DataFrame, caption: str = "", float_format: str = "{:.4g}",
                  index: bool = False, text: bool = False, pdf_omit: tuple[str, ...] = ()) -> "Section":
        self.blocks.append(Table(frame, caption, float_format, index, text, tuple(pdf_omit)))
        return self

    def add_file(self, name: str, content: bytes | str) -> "Section":
        """A file the report folder holds beside report.html (e.g. a CSV for CI), named ``name``."""
        if not name or "/" in name or "\\" in name or name.startswith("."):
            raise ValueError(f"invalid report file name {name!r}")
        self.files[name] = content.encode("utf-8") if isinstance(content, str) else content
        return self

    def add_figure(self, fig, caption: str = "", width: str = "100%") -> "Section":
        """Add a matplotlib figure (rendered to PNG now, then closed) or PNG bytes."""
        self.blocks.append(Figure(fig if isinstance(fig, bytes) else figure_png(fig), caption, width))
        return self


class PendingFigure(bytes):
    """Stands for a figure's PNG inside :func:`deferred_figures` (empty bytes; ``data``: the pickled figure)."""

    data: bytes
    dpi: int
    rc: dict         # matplotlib's settings where the figure was made (sizes given relative to the font resolve at draw)


#: figures rendered inside :func:`deferred_figures` wait here (None: render at once)
_DEFERRED: list | None = None


@contextmanager
def deferred_figures():
    """Within the block, :func:`figure_png` pickles its figure (and closes it) and returns a :class:`PendingFigure`;
    :func:`render_deferred` then renders them all at once, e.g. on a study's workers.  A figure that cannot be
    pickled is rendered at once."""
    global _DEFERRED
    outer, _DEFERRED = _DEFERRED, []
    try:
        yield
    finally:
        _DEFERRED = outer


def render_deferred(sections, map=None) -> int:
    """Render every :class:`PendingFigure` of ``sections``' figures with ``map(fn, tasks) -> results in order``
    (:meth:`rvtol.mc.Evaluator.map`: on the workers; default in this process); the number rendered."""
    blocks = [b for sec in sections for b in sec.blocks if isinstance(b, Figure) and isinstance(b.png, PendingFigure)]
    tasks = [(b.png.data, b.png.dpi, b.png.rc) for b in blocks]
    pngs = map(_render_pickled, tasks) if map is not None else [_render_pickled(*t) for t in tasks]
    for b, png in zip(blocks, pngs):
        b.png = png
    return len(blocks)


def _render_pickled(data: bytes, dpi: int, rc: dict) -> bytes:
    import matplotlib

    matplotlib.use("Agg")
    with matplotlib.rc_context(rc):
        return _png(pickle.loads(data), dpi)


def figure_png(fig, dpi: int = 130) -> bytes:
    """The figure as PNG bytes (and closed); inside :func:`deferred_figures`, a :class:`PendingFigure`."""
    if _DEFERRED is not None:
        try:
            data = pickle.dumps(fig)
        except Exception:        # an artist that does not pickle: render it here
            data = None
        if data is not None:
            import matplotlib
            import matplotlib.pyplot as plt

            plt.close(fig)
            out = PendingFigure()
            out.data, out.dpi = data, dpi
            out.rc = {k: v for k, v in matplotlib.rcParams.items() if not k.startswith("backend")}
            return out
    return _png(fig, dpi)


def _png(fig, dpi: int) -> bytes:
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()
