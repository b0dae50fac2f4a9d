"""The user documents shipped with rvtol: ``rvtol docs`` lists them, ``rvtol docs NAME`` prints one.

Each document is a Markdown file of this package (package data, so an installed wheel has them); its name is the
file's stem with ``-`` for ``_`` (``writing_a_study.md`` → ``writing-a-study``) and its title its first ``# ``
heading.  Paths the documents name (``studies/…``, ``data/…``, ``tests/…``) are in the rvtol repository.
"""
from __future__ import annotations

from importlib import resources

from ..errors import InputError, did_you_mean


def _files() -> dict:
    """``{name: the file}`` of every ``.md`` of this package, by name."""
    folder = resources.files(__name__)
    return {f.name[:-3].replace("_", "-"): f for f in sorted(folder.iterdir(), key=lambda f: f.name)
            if f.name.endswith(".md")}


def _title(text: str) -> str:
    return next((line[2:].strip() for line in text.splitlines() if line.startswith("# ")), "")


def documents() -> dict[str, str]:
    """``{name: title}`` of every shipped document, by name."""
    return {name: _title(f.read_text(encoding="utf-8")) for name, f in _files().items()}


def text(name: str) -> str:
    """The Markdown text of the document ``name``; an unknown name is an :class:`InputError` on ``rvtol docs``."""
    files = _files()
    if name not in files:
        raise InputError(f"no document {name!r}{did_you_mean(name, files)} (documents: {', '.join(files)})",
                         file="<command line>", key="docs")
    return files[name].read_text(encoding="utf-8")
