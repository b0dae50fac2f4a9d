"""The documents a user reads: shipped with the package (``rvtol docs``), and no broken reference in any of them.

The reference check reads README.md, the shipped guides (``rvtol/docs/``) and every Markdown document of the
repository they reach by relative links or by naming its path: every relative link must reach a file or folder of
the repository (and its ``#anchor`` a heading of that file, as GitHub names it), and every code span that is a
repository path (``studies/build.md``, ``data/products/rv80e/``, ``tests/cli/test_cli.py``) must exist — relative to
the repository or to the document's folder.  Illustrative paths (a user's own files, a run's output) are listed in
:data:`ILLUSTRATIVE`; the reference documents themselves are outside the repository (``../shared/``: the project's
folder beside the checkout, which the write-ups cite the seeds and REFERENCE.md from).
"""
from __future__ import annotations

import re
import tomllib
from fnmatch import fnmatch
from pathlib import Path

import pytest

from rvtol import docs
from rvtol.cli import main

from conftest import ROOT

DOCS = ROOT / "rvtol" / "docs"

#: code spans that name files a user or a run makes, not files of the repository
ILLUSTRATIVE = ("reports/", "my_study/", "cmm/", ".DIR.rvtol-run/")
#: outside the repository: the project's shared folder beside the checkout (the reference documents)
EXTERNAL = ("../shared/",)

_LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)|<(?:img|a)\s[^>]*?(?:src|href)=\"([^\"]+)\"")
_SPAN = re.compile(r"`([^`\n]+)`")
_PATH = re.compile(r"[A-Za-z0-9_.][\w.\-/]*")
_SUFFIXES = (".md", ".toml", ".py", ".csv", ".json", ".yml", ".yaml", ".xlsx", ".png", ".tsv")
_FENCE = re.compile(r"^```.*?^```", re.S | re.M)


def anchor(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens."""
    text = re.sub(r"[`*_]", "", heading.strip().lower())
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def anchors(path: Path) -> set[str]:
    text = _FENCE.sub("", path.read_text(encoding="utf-8"))
    return {anchor(m.group(1)) for m in re.finditer(r"^#{1,6}\s+(.*)$", text, re.M)}


def links(path: Path) -> list[str]:
    text = _FENCE.sub("", path.read_text(encoding="utf-8"))
    return [a or b for a, b in _LINK.findall(text)]


def path_spans(path: Path) -> list[str]:
    """Code spans outside code blocks that read as a repository path: with a folder, or a Markdown file's name."""
    text = _FENCE.sub("", path.read_text(encoding="utf-8"))
    spans = []
    for span in _SPAN.findall(text):
        if not _PATH.fullmatch(span) or span.startswith(ILLUSTRATIVE + EXTERNAL) or "://" in span:
            continue
        if "/" in span and (span.endswith("/") or span.endswith(_SUFFIXES)) or span.endswith(".md"):
            spans.append(span)
    return spans


def documents() -> list[Path]:
    """README.md, the shipped guides and every Markdown file of the repository they reach (links, `.md` paths)."""
    seen, todo = [], [ROOT / "README.md", *sorted(DOCS.glob("*.md"))]
    while todo:
        doc = todo.pop()
        if doc in seen:
            continue
        seen.append(doc)
        for target in [t.split("#")[0] for t in links(doc) if "://" not in t] + path_spans(doc):
            for file in ((doc.parent / target).resolve(), (ROOT / target).resolve()):
                if file.suffix == ".md" and file.is_file() and ROOT in file.parents:
                    todo.append(file)
    return sorted(seen)


def broken(doc: Path) -> list[str]:
    out = []
    for target in links(doc):
        if "://" in target or target.startswith("mailto:"):
            continue
        name, _, frag = target.partition("#")
        file = (doc.parent / name).resolve() if name else doc
        if not file.exists():
            out.append(f"link {target}: no such file")
        elif frag and file.suffix == ".md" and frag not in anchors(file):
            out.append(f"link {target}: no heading #{frag}")
    for span in path_spans(doc):
        if not ((ROOT / span).exists() or (doc.parent / span).exists()):
            out.append(f"path `{span}`: no such file")
    return out


def test_the_link_check_finds_what_it_should(tmp_path):
    """The checker itself: a dead link, a dead anchor and a dead path are found; live ones are not."""
    (tmp_path / "b.md").write_text("# Sign-off in CI\n")
    doc = tmp_path / "a.md"
    doc.write_text("[ok](b.md#sign-off-in-ci) [gone](c.md) [anchor](b.md#nope) `tests/docs/test_docs.py` "
                   "<img src=\"d.png\"> "
                   "`studies/no_such.toml` `reports/x/summary.json` `b.md`\n```\n[in code](zzz.md)\n```\n")
    assert broken(doc) == ["link c.md: no such file", "link b.md#nope: no heading #nope", "link d.png: no such file",
                           "path `studies/no_such.toml`: no such file"]
    assert anchor("Performance: how a study scales with workers (issue 24)") == \
        "performance-how-a-study-scales-with-workers-issue-24"


def test_every_reference_in_the_documents_resolves():
    found = documents()
    assert ROOT / "README.md" in found and DOCS / "writing_a_study.md" in found
    assert ROOT / "studies" / "benchmarks" / "README.md" in found
    problems = [f"{doc.relative_to(ROOT)}: {p}" for doc in found for p in broken(doc)]
    assert not problems, "\n".join(problems)


def test_the_library_names_only_documents_that_ship():
    """Messages and docstrings that send a reader to ``rvtol docs NAME`` name a shipped document."""
    named = {m for f in (ROOT / "rvtol").rglob("*.py")
             for m in re.findall(r"rvtol docs ([a-z][a-z-]*[a-z])", f.read_text(encoding="utf-8"))}
    assert "writing-a-study" in named
    assert named <= set(docs.documents()), named - set(docs.documents())


def test_rvtol_docs_lists_the_shipped_documents(capsys):
    files = sorted(DOCS.glob("*.md"))
    assert main(["docs"]) == 0
    out = capsys.readouterr().out.splitlines()
    listed = [line.split()[0] for line in out[:-1]]
    assert listed == [f.stem.replace("_", "-") for f in files]
    first = out[listed.index("writing-a-study")]
    assert first.split(None, 1)[1] == "Writing a study"


def test_rvtol_docs_name_prints_the_document(capsys):
    assert main(["docs", "writing-a-study"]) == 0
    assert capsys.readouterr().out == (DOCS / "writing_a_study.md").read_text(encoding="utf-8")


def test_an_unknown_document_is_one_line_and_exit_2(capsys):
    assert main(["docs", "writing-a-studdy"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err == ("rvtol: error: <command line>: docs: no document 'writing-a-studdy' (did you mean "
                                 "'writing-a-study'?) (documents: api, command-line, inputs, measured-parts, reports, "
                                 "writing-a-study)\n")


def test_the_documents_are_package_data():
    """pyproject's package data takes every shipped document into the wheel."""
    data = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]
    patterns = data["rvtol.docs"]
    files = sorted(DOCS.glob("*.md"))
    assert len(files) >= 6
    assert all(any(fnmatch(f.name, p) for p in patterns) for f in files)


@pytest.mark.parametrize("stale", ["studies/WRITING_A_STUDY.md", "README, \"Command line\"",
                                   "README, \"Formula models\""])
def test_no_message_sends_an_installed_user_to_the_repository(stale):
    """An installed rvtol has no README or studies/: its messages name ``rvtol docs`` instead."""
    hits = [str(f.relative_to(ROOT)) for f in (ROOT / "rvtol").rglob("*.py") if stale in f.read_text(encoding="utf-8")]
    assert not hits, hits
