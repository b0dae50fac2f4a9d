"""The report building blocks live in :mod:`rvtol.blocks` (a base module the capabilities lay their results out
with); this name stays for the analyses written before the move."""
from ..blocks import Figure, Links, RunTable, Section, Table, Text, figure_png, frame_records  # noqa: F401
