"""``[study]``: what the study is and the files it reads, declared like every other table (:mod:`rvtol.options`), so
``rvtol kinds study`` lists its keys and the common invalid-value test covers them.  Relative paths are taken from
the study file's folder; the files are read by :func:`rvtol.study.load.load_study`, not here."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..options import option


@dataclass
class StudyHead:
    """``[study]``: the study's name and the files it reads (relative to the study file's folder)."""

    name: str | None = option(None, "names the report folder reports/<name>/ (default: the study file's name)",
                              single_line=True)
    title: str | None = option(None, "the report's title (default: the name)", single_line=True)
    description: str = option("", "what the study is for: the report's opening paragraph")
    extends: Path | None = option(None, "a base study in the same folder whose design, spec, mapping, models and "
                                        "requirements this one takes (one level only)")
    design: Path | None = option(None, "the design file: the reducer's dimensions, materials and loads")
    spec: list[str] | Path | None = option(None, "the spec: a TOML, CSV or XLSX file, or a list of files read as one "
                                                 "spec (default: the [[factor]] tables of this file)", min_length=1)
    spec_sheet: list[str] | str | None = option(None, "the worksheet of a workbook spec (a list beside a list of "
                                                      "specs, \"\" for a file read as by default)")
    requirements: Path | None = option(None, "a file of [[requirement]] tables (the study's own are added)")
    mapping: Path | None = option(None, "a composed study's file of [[quantity]] tables (or give them here)")
    build: Path | bool | None = option(None, "a composed study's build rules (rvtol.production.build: selective fits, "
                                             "shim preloads, gauges); false: the base study's, not applied")
    exploratory: bool = option(False, "checks no requirement on purpose (verdict EXPLORATORY, exit 0)")

    def complete(self, study, error):
        if self.build is True:
            raise error("build", "expected the build rules' file name, or false (the parts as drawn)")
        if isinstance(self.spec, list) and not all(self.spec):
            raise error("spec", "expected a file name or a list of file names (an empty name is none)")
        if self.spec_sheet is not None and self.spec is None:
            raise error("spec_sheet", "names the worksheet of [study] spec, and there is no spec file")

    def spec_paths(self, base: Path) -> list[Path]:
        """The spec files, relative to ``base`` (none: the study's own ``[[factor]]`` tables; one file was read as a
        path from there already)."""
        if isinstance(self.spec, list):
            return [p if p.is_absolute() else base / p for p in map(Path, self.spec)]
        return [] if self.spec is None else [self.spec]

    def build_path(self) -> Path | None:
        """The build rules' file, or None (no build, or ``false``)."""
        return self.build if isinstance(self.build, Path) else None
