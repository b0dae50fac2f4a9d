"""Report: Sections (tables, figures, text) → one view model → HTML (Jinja2) → PDF (WeasyPrint).

The blocks a section holds are :mod:`rvtol.blocks` (a base module the capabilities lay their results out with);
this package renders them.
"""
