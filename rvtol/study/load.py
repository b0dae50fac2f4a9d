"""Loading a study (:func:`load_study`): the study file and everything it names read and checked before
anything is computed."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from ..analysis import in_dependency_order
from ..ci.gates import read_gates
from ..design import Design, load_design
from ..errors import InputError, SpecError, did_you_mean
from ..model import Model
from ..model_kind import Where
from ..options import read_options
from ..params import Params, read_toml
from ..registry import analysis_function
from ..runguard import NAME_MAX_BYTES
from ..spec import (Requirement, ToleranceSpec, load_spec, merge_specs, read_requirements_file,
                    requirements_from_tables, spec_from_table)
from .folder import MAX_FOLDER_NAME_BYTES
from .head import StudyHead
from .model import build_model, composed_model
from .options import XLSX_MAX_COLUMNS, RunOptions, run_options


@dataclass
class Study:
    name: str
    title: str
    description: str
    file: str
    base_dir: Path
    design: Design | None
    spec: ToleranceSpec
    model: Model
    requirements: list[Requirement]
    options: RunOptions
    analyses: list = field(default_factory=list)  # prepared analysis objects (have .run(ctx))
    inputs: dict[str, dict] = field(default_factory=dict)  # role -> {path, sha256}
    exploratory: bool = False  # checks no requirement on purpose ([study] exploratory)
    gates: list = field(default_factory=list)  # rvtol.ci.gates.Gate: [[gate]] tables, for --baseline
    build: object = None  # rvtol.production.build.BuildRules of a composed study's [study] build, or None
    notes: list = field(default_factory=list)  # what the inputs' reading noticed: the report's run table, summary.json


class NotRunModel(Model):
    """Stands for a model whose code ``rvtol check`` did not run (a ``kind = "python"`` factory): its outputs are unknown, so requirements' outputs, gates and analyses are not checked.
    ``notes`` say what was checked without running."""

    def __init__(self, spec: ToleranceSpec, notes: list[str]):
        from .. import units as _units

        self.inputs = tuple(spec.names)
        self.input_units = tuple(_units.base_unit(u) for u in spec.units)
        self.outputs = ()
        self.notes = notes

    def evaluate(self, X):   # pragma: no cover - never run
        raise RuntimeError("a model rvtol check did not run cannot be evaluated")


def _user_code(root: Params) -> list[str] | None:
    """``[model]`` tables that run the study's own code (``kind = "python"``): validated without running it
    (:func:`rvtol.models.custom.model.check_without_running`); notes, or None if there are none.  (A kind of an
    installed package is loaded like a built-in one: installing it was the decision to run it.)"""
    raw = root.data.get("model")
    tables = root.tables("model") if isinstance(raw, list) else [root.sub("model")]
    notes = []
    for t in tables:
        kind = t.data.get("kind")
        if kind == "python":
            from ..models.custom.model import check_without_running

            notes.append(check_without_running(t))
    return notes or None


def load_study(path: str | Path, *, execute: bool = True, design: Design | None = None, analyses: bool = True,
               **overrides) -> Study:
    """Read and validate a study file and everything it names. Raises :class:`InputError`.

    ``execute=False`` (``rvtol check`` without ``--execute``): a model made by the user's code is validated
    without running that code (:class:`NotRunModel`), and what depends on its outputs is not checked.
    ``design``: a variant of the study's design to build everything on instead of the file's (the epistemic band,
    :mod:`rvtol.epistemic`); ``analyses=False``: the study's analyses are not read (only its models)."""
    path = Path(path)
    data, sha = read_toml(path)
    file, base = str(path), path.parent
    data, parent = _extended(data, path)
    root = Params(data, file=file)
    head = root.sub("study")
    h = read_options(StudyHead, head, Where(base))
    head.finish()
    name, title, desc = _names(h, head, path)
    inputs = {"study": {"path": file, "sha256": sha}, **({"extends": parent} if parent is not None else {})}
    design = _design(h.design, design, inputs)
    spec = _spec(root, h, head, base, name, inputs)
    reqs = _requirements(root, h.requirements, inputs)
    mapping, build_path, exploratory = h.mapping, h.build_path(), h.exploratory
    options = run_options(root, overrides)

    notes = None if execute else _user_code(root)
    if notes is not None:       # rvtol check: no user code runs; nothing that needs its outputs is checked
        check_requirement_names(reqs)
        study = Study(name, title, desc, file, base, design, spec, NotRunModel(spec, notes), reqs, options, [],
                      inputs, exploratory)
        for k in ("model", "quantity", "gate", "analysis"):
            root.raw(k, None)
        root.finish()
        return study
    try:
        if isinstance(data.get("model"), list):          # [[model]] tables: a composed study
            drawn = Path(parent["build_as_drawn"]) if build_path is None and "build_as_drawn" in (parent or {}) else None
            model, spec, rules = composed_model(root, mapping, design, spec, file, inputs, build_path, drawn)
        else:
            model, rules = _single_model(root, head, mapping, build_path, design, spec, file), None
    except InputError as exc:
        raise (design.relocate(exc) if design is not None else exc) from None   # a variant's base number: its file
    _check_against_model(model, spec, reqs, options, data, file)

    study = Study(name, title, desc, file, base, design, spec, model, reqs, options, [], inputs, exploratory)
    check_sequential(study)
    study.build = rules
    study.notes = model_warnings(model)
    study.gates = read_gates(root.tables("gate"), model)  # [[gate]] tables (rvtol.ci: --baseline, compare)
    if not analyses:
        root.raw("analysis", None)
    _read_analyses(study, root.tables("analysis") if analyses else [], file)
    root.finish()
    return study


def _names(h: StudyHead, head: Params, path: Path) -> tuple[str, str, str]:
    """``[study]``'s name (it names the report folder: one path component, short enough for the temporary names
    beside it), title and description."""
    name = path.stem if h.name is None else h.name
    if not name or any(c in name for c in "/\\") or name.startswith("."):
        raise head.error("name", f"invalid study name {name!r} (used as a folder name)")
    if len(name.encode()) > MAX_FOLDER_NAME_BYTES:
        raise head.error("name", f"the study name is {len(name.encode())} bytes long, and it names the report folder: "
                                 f"at most {MAX_FOLDER_NAME_BYTES} (a file name's {NAME_MAX_BYTES}, less the temporary "
                                 "names rvtol gives beside it); give a shorter name")
    return name, name if h.title is None else h.title, h.description


def _design(dpath: Path | None, variant: Design | None, inputs: dict) -> Design | None:
    """``[study] design``, or the ``variant`` given instead of it (recorded in ``inputs``)."""
    if variant is not None:
        inputs["design"] = {"path": str(dpath) if dpath is not None else variant.file, "sha256": None,
                            "variant": True}
        return variant
    if dpath is None:
        return None
    design = load_design(dpath)
    inputs["design"] = {"path": str(dpath), "sha256": design.sha256}
    if design.base is not None:           # a variant: the base design it changes
        inputs["design_base"] = {"path": design.base[0], "sha256": design.base[1]}
    return design


def _spec(root: Params, h: StudyHead, head: Params, base: Path, name: str, inputs: dict) -> ToleranceSpec:
    """The tolerance spec: ``[study] spec`` (one file or several read as one, a workbook's ``spec_sheet``) or the
    study's own ``[[factor]]`` tables (recorded in ``inputs``)."""
    file, data = root.file, root.data
    spaths = h.spec_paths(base)
    if not spaths:
        if "factor" not in root:
            raise head.error("spec", "missing required key (or give [[factor]] tables in the study file)")
        spec = spec_from_table({k: data[k] for k in ("factor", "correlation") if k in data}, file=file, name=name)
        root.raw("factor")
        root.raw("correlation", None)
        return spec
    if "factor" in root:
        raise root.error("factor", "give the factors either in the spec file or here, not both")
    parts = []
    for sp, sheet in zip(spaths, _spec_sheets(h, head, spaths)):
        try:
            parts.append(load_spec(sp, sheet=sheet))
        except InputError as exc:
            if exc.key == "sheet" and sheet is not None:    # the study's key named a sheet the file lacks
                raise head.error("spec_sheet", f"{sp}: {exc.reason}") from None
            raise
    for k, (sp, part) in enumerate(zip(spaths, parts)):
        inputs["spec" if k == 0 else f"spec_{k + 1}"] = {"path": str(sp), "sha256": part.sha256,
                                                           **({"sheet": part.sheet} if part.sheet else {})}
    try:
        return merge_specs(parts)
    except InputError as exc:
        raise exc.located(file=file) from None


def _requirements(root: Params, rpath: Path | None, inputs: dict) -> list[Requirement]:
    """``[study] requirements`` (a file, recorded in ``inputs``) and the study's ``[[requirement]]`` tables."""
    reqs: list[Requirement] = []
    if rpath is not None:
        rfile, rsha = read_requirements_file(rpath)
        reqs += rfile
        inputs["requirements"] = {"path": str(rpath), "sha256": rsha}
    return reqs + requirements_from_tables(root.tables("requirement"))


def _single_model(root: Params, head: Params, mapping, build_path, design, spec, file: str) -> Model:
    """A study's one ``[model]`` table (a mapping or a build needs several)."""
    if mapping is not None or "quantity" in root:
        raise head.error("mapping", "a mapping ([[quantity]] tables) needs several [[model]] tables")
    if build_path is not None:
        raise head.error("build", "a build (how the reducer is assembled) needs a composed study: several [[model]] "
                                  "tables")
    mp = root.sub("model")
    model = build_model(mp, design, spec, file)
    mp.finish()
    return model


def _check_against_model(model: Model, spec: ToleranceSpec, reqs: list[Requirement], options: RunOptions, data: dict,
                         file: str) -> None:
    """What needs the model's outputs, checked before anything is computed: the spec it reads, its outputs' names,
    the samples' table width, every requirement's output and unit."""
    try:
        model.check_spec(spec)
    except InputError as exc:
        raise exc.located(file=spec.file or file) from None
    check_output_names(model, spec, data, file)
    columns = len(spec) + len(model.outputs) + 1       # samples.xlsx: factors, outputs, status
    if "xlsx" in options.tables and columns > XLSX_MAX_COLUMNS:
        raise InputError(f"{columns} columns (factors, outputs, status) do not fit an XLSX sheet "
                         f"({XLSX_MAX_COLUMNS}): write the samples as csv", file=file, key="report.tables")
    check_requirement_names(reqs)
    for r in reqs:
        if r.output not in model.output_names:
            raise SpecError(f"unknown output name {r.output!r}{did_you_mean(r.output, model.output_names)} "
                            f"(model has: {', '.join(model.output_names)})",
                            file=r.file, key=f"{r.key}.output" if r.key else "output")
        r.in_unit(model.output(r.output).shown_unit)  # unit check now, not after the run


def _read_analyses(study: Study, tables: list[Params], file: str) -> None:
    """The study's ``[[analysis]]`` tables, each prepared (its plan made, the files it read recorded in the study's
    inputs), in the order their ``requires`` gives."""
    for t in tables:
        cls = analysis_function(t.str("kind"), file, t.path("kind"))
        try:
            analysis = cls(t, study)
        except InputError as exc:
            raise exc.located(file=file) from None
        study.analyses.append(analysis)
        study.inputs.update(getattr(analysis.plan, "inputs", None) or {})     # the files its plan read
        t.finish()
    try:
        study.analyses = in_dependency_order(study.analyses, tables)
    except InputError as exc:
        raise exc.located(file=file) from None


def model_warnings(model) -> list[str]:
    """What a model (or the stages of a composed one) found worth a note in its inputs (``Model.warnings``: a
    formula that sums factors of different units under units = "factor")."""
    out = list(getattr(model, "warnings", ()))
    for stage in getattr(model, "stages", ()):
        out += [f"model {stage.name!r}: {w}" for w in getattr(stage.model, "warnings", ())]
    return out


def check_output_names(model: Model, spec: ToleranceSpec, data: dict, file: str) -> None:
    """Every output's name is one line without control characters (a model made by code names its own), and no
    output shares its name with a factor: samples.parquet, the statistics and the report could not tell the two
    apart (one column replaced the other).  Blamed at ``[[model.output]]``'s name where the study gives it."""
    from ..safetext import control_character

    factors = set(spec.names)
    tables = data.get("model", {}).get("output", []) if isinstance(data.get("model"), dict) else []
    for q in model.outputs:
        at = [i for i, t in enumerate(tables) if isinstance(t, dict) and t.get("name") == q.name]
        key = f"model.output[{at[0]}].name" if at else "model"
        bad = control_character(q.name, name=True)
        if bad:
            raise SpecError(f"the model's output {q.name!r} {bad}: a name may hold none", file=file, key=key)
        if q.name in factors:
            raise SpecError(f"an output and a factor share the name {q.name!r}: the samples, statistics and report "
                            "could not tell them apart; rename the output", file=file, key=key)


def _spec_sheets(h: StudyHead, head: Params, spaths: list[Path]) -> list[str | None]:
    """``[study] spec_sheet``: the worksheet of a workbook spec (a list beside a list of specs, ``""`` for a file
    read as by default); without it each workbook is read from the sheet :func:`rvtol.inputs.sheets.read_rows`
    can tell without guessing."""
    if h.spec_sheet is None:
        return [None] * len(spaths)
    if isinstance(h.spec, list) != isinstance(h.spec_sheet, list):
        raise head.error("spec_sheet", "a list of sheets goes beside a list of spec files, one sheet beside one file")
    sheets = h.spec_sheet if isinstance(h.spec_sheet, list) else [h.spec_sheet]
    if len(sheets) != len(spaths):
        raise head.error("spec_sheet", f"{len(spaths)} spec files but {len(sheets)} sheets: give one per file (\"\" "
                                       "for a file read as by default)")
    for sp, sh in zip(spaths, sheets):
        if sh and sp.suffix.lower() not in (".xlsx", ".xlsm"):
            raise head.error("spec_sheet", f"{sp.name} is not a workbook (.xlsx): it has no sheet {sh!r}")
    return [sh or None for sh in sheets]


def check_requirement_names(reqs: list[Requirement]) -> None:
    """Two requirements with one name (or, unnamed, the same output and limits) would be two JUnit cases
    and two rows no reader can tell apart: refused, naming both."""
    seen: dict[str, Requirement] = {}
    for r in reqs:
        first = seen.get(r.label)
        if first is not None:
            where = f"{first.key or 'requirement'}" + (f" of {first.file}" if first.file != r.file else "")
            raise SpecError(f"requirement {r.label!r} is given twice (first as {where}): give each requirement "
                            "its own name", file=r.file, key=f"{r.key}.name" if r.key else "name")
        seen[r.label] = r


#: tables a study that extends another may not give (they come from the base study)
_INHERITED_ONLY = ("model", "quantity", "factor", "correlation")
#: [study] keys that are the derived study's own (never taken from the base)
_OWN = ("name", "title", "description")


def _extended(data: dict, path: Path) -> tuple[dict, dict | None]:
    """A study with ``[study] extends = "base.toml"``: the base study's design, spec, mapping, models and
    requirements, with this file's name, title, description, its [sampling] / [execution] / [report] keys
    over the base's, its requirements added and its own analyses (the base's are not inherited).  The base
    is in the same folder (its relative paths are read from there) and extends nothing itself."""
    head = data.get("study")
    if not isinstance(head, dict) or "extends" not in head:
        return data, None
    file = str(path)
    p = Params(head, file=file, key="study")
    bpath = p.path_value("extends", path.parent)
    if bpath.resolve().parent != path.resolve().parent:
        raise p.error("extends", "the base study must be in the same folder as this one (its relative paths "
                                 "are read from there)")
    if bpath.resolve() == path.resolve():
        raise p.error("extends", "a study cannot extend itself")
    base, bsha = read_toml(bpath)
    if isinstance(base.get("study"), dict) and "extends" in base["study"]:
        raise p.error("extends", f"{bpath.name} extends another study itself (one level only)")
    for k in _INHERITED_ONLY:
        if k in data:
            raise SpecError(f"a study that extends {bpath.name} takes its {k} tables from there", file=file, key=k)
    merged = {k: v for k, v in base.items() if k != "analysis"}
    bstudy = {k: v for k, v in base.get("study", {}).items() if k not in _OWN}
    merged["study"] = {**bstudy, **{k: v for k, v in head.items() if k != "extends"}}
    drawn = None
    if head.get("build", None) is False and isinstance(bstudy.get("build"), str):   # the base's build, not applied
        drawn = Params(bstudy, file=str(bpath), key="study").path_value("build", bpath.parent)
    merged["study"].setdefault("name", path.stem)
    for k in ("sampling", "execution", "report"):
        if k in data:
            merged[k] = {**base.get(k, {}), **data[k]}
    if "requirement" in data:
        merged["requirement"] = list(base.get("requirement", [])) + list(data["requirement"])
    for k, v in data.items():
        if k not in merged or k == "analysis":
            merged[k] = v
    return merged, {"path": str(bpath), "sha256": bsha, **({"build_as_drawn": str(drawn)} if drawn is not None else {})}


def check_sequential(study: Study) -> None:
    """Refuse a sequential run whose requirements or factors the anytime-valid rule cannot decide (InputError at the
    requirement's key, or the spec's factor)."""
    from ..sequential import unsupported

    if not study.options.until_decided:
        return
    for r in study.requirements:
        why = unsupported(r)
        if why is not None:
            raise SpecError(f"until_decided: {why}", file=r.file or study.file,
                            key=r.key or f"requirement {r.label!r}")
    for f in study.spec.factors:
        if f.measured is not None and f.measured.fit is not None:
            raise SpecError("until_decided: a factor fitted to measured parts carries its fit's uncertainty, which more "
                            "samples cannot decide (the sequential rule judges the Monte Carlo's alone): run a fixed n",
                            file=study.spec.file or study.file, key=f"factor {f.name!r}")
