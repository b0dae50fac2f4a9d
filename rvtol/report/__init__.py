"""Report: Sections (tables, figures, text) → one view model → HTML (Jinja2) → PDF (WeasyPrint)."""
from ..blocks import Figure, Section, Table, Text, figure_png, frame_records

__all__ = ["Figure", "Section", "Table", "Text", "figure_png", "frame_records"]
