"""Writing a run's report folder (:func:`write_outputs`) atomically: summary.json, the samples, the report's
HTML and PDF, the tables and every analysis' own files."""
from __future__ import annotations

import json
import os
import secrets
import shutil
from pathlib import Path

from ..blocks import Section
from .folder import MANIFEST, check_out_dir
from .run import StudyResult


def _write_section_files(sections: list[Section], folder: Path) -> None:
    """The files analyses add to the report folder (:meth:`rvtol.blocks.Section.add_file`)."""
    for s in sections:
        for name, content in s.files.items():
            if (folder / name).exists():
                raise ValueError(f"analysis {s.key!r}: report file {name!r} exists already")
            (folder / name).write_bytes(content)




def write_tables(result: StudyResult, samples, folder: Path) -> None:
    """``samples.csv|xlsx`` and ``statistics.csv|xlsx`` (statistics, and the requirements' figures) in ``folder``."""
    from ..inputs.sheets import write_frames

    if not result.study.options.tables:
        return
    import pandas as pd

    stats = result.mc.statistics().reset_index()
    reqs = pd.DataFrame([{k: (", ".join(map(str, v)) if isinstance(v, list) else v) for k, v in
                          v.to_dict().items()} for v in result.mc.verdicts()])
    for ext in result.study.options.tables:
        write_frames(folder / f"samples.{ext}", {"samples": samples})
        if ext == "xlsx":
            write_frames(folder / "statistics.xlsx", {"statistics": stats, "requirements": reqs})
        else:
            write_frames(folder / "statistics.csv", {"statistics": stats})
            if len(reqs):
                write_frames(folder / "requirements.csv", {"requirements": reqs})


def write_outputs(result: StudyResult, out_dir: str | Path, extra_files: dict[str, str] | None = None) -> Path:
    """Write summary.json, samples.parquet, report.html (and report.pdf) atomically into ``out_dir``.

    ``extra_files`` (name -> text) go into the same folder in the same atomic step (e.g. comparison.json).
    """
    from ..report.render import PDF_MAX_ROWS, render_html, render_pdf, render_summary_html

    out = check_out_dir(out_dir)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.parent / f".{out.name}.tmp-{secrets.token_hex(6)}"
    tmp.mkdir()  # mode 0777 & ~umask, like any folder the user makes
    try:
        (tmp / "summary.json").write_text(json.dumps(result.summary(), indent=2, ensure_ascii=False, allow_nan=False))
        result.mc.write_parquet(tmp / "samples.parquet")      # a chunk at a time: memory of a chunk, not of n
        if result.study.options.tables:
            write_tables(result, result.mc.to_frame(), tmp)
        (tmp / "report.html").write_text(render_html(result), encoding="utf-8")
        if result.study.options.pdf:
            render_pdf(render_html(result, PDF_MAX_ROWS), tmp / "report.pdf")
            if result.signoff:
                render_pdf(render_summary_html(result), tmp / "summary.pdf")     # the first page alone
        for fname, text in (extra_files or {}).items():
            (tmp / fname).write_text(text, encoding="utf-8")
        _write_section_files(result.sections, tmp)
        (tmp / MANIFEST).write_text("\n".join(sorted([MANIFEST, *(p.name for p in tmp.iterdir())])), encoding="utf-8")
        old = out.parent / f".{out.name}.old-{secrets.token_hex(6)}"
        try:
            if out.exists():
                os.replace(out, old)
            os.replace(tmp, out)
        except BaseException:   # stopped between the two renames: the previous folder goes back in place
            if old.exists() and not out.exists():
                os.replace(old, out)
            raise
        shutil.rmtree(old, ignore_errors=True)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return out
