"""Studies: a TOML file names a design, a spec, a model, analyses and requirements.

::

    [study]
    name = "lost_motion_rv80e"            # output folder reports/<name>/
    title = "..."
    description = "..."
    design = "../data/designs/rv80e_te.toml"      # optional, relative to this file
    spec = "../data/specs/rv80e_lost_motion.toml" # TOML, CSV or XLSX; or [[factor]] tables in this file; or a
                                          # list of files read as one spec (the product's and a test rig's)
    requirements = "../data/requirements/x.toml"  # optional; [[requirement]] here too
    # extends = "base.toml"               # or: take design, spec, mapping, models and requirements from a
                                          # study in this folder; give name, title, analyses, options here
    exploratory = false                   # true: the study checks no requirement on purpose (verdict
                                          # EXPLORATORY, exit 0); without requirements and without
                                          # it the verdict is NO REQUIREMENTS (exit 4)

    [model]
    kind = "lost_motion"                  # see rvtol.registry.MODELS
    # ... model parameters

    # or several models on the same samples (a composed study, rvtol.models.composite):
    # [study] mapping = "mapping.toml"    # optional file of [[quantity]] tables (or give them here)
    # [study] build = "build.toml"        # optional: how the reducer is built (rvtol.production.build):
                                          # selective fits, shim preloads, gauges; false: the parts as drawn
    # [[model]]
    # name = "torsion"                    # its outputs are named "torsion.<output>"
    # kind = "torsion_curve"
    # outputs = ["lost_motion"]           # optional: the outputs to keep
    # [model.inputs]                      # the declared mapping: input = expression of factors,
    # "delta_b[1,1]" = "needle_clearance" # quantities and earlier models' outputs (base units)

    [sampling]
    n = 10000
    method = "lhs"                        # random | lhs | sobol
    seed = 20261121
    # until_decided = true                # sample batches of n until every requirement is decided (rvtol.sequential)
    # max_n = 200000                      # ... or this many samples are drawn (default 20 n)

    [execution]
    executor = "process"                  # serial | process | dask
    workers = 2                           # default: every core
    chunk_size = 0                        # 0: automatic

    [report]
    pdf = true
    confidence = 0.95
    tables = ["xlsx"]                     # optional: samples and statistics also as csv and/or xlsx

    [[analysis]]
    kind = "local_sensitivity"            # see rvtol.registry.ANALYSES
    # ... analysis parameters

    [[gate]]                              # what a change may do against the accepted baseline
    kind = "requirements"                 # (rvtol run --baseline, rvtol compare): see rvtol.ci.gates

Loading (:func:`load_study`) reads and checks *everything* — files, keys,
units, names, the model and every analysis' parameters — before anything is
computed; :func:`run_study` then runs Monte Carlo and the analyses and
:func:`write_outputs` writes the report folder atomically.
"""
from __future__ import annotations

import json
import os
import secrets
import shutil
import time
from contextlib import nullcontext
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path


from .ci.gates import read_gates
from .design import Design, load_design
from .errors import InputError, SpecError, did_you_mean
from .executors import Executor, make_executor
from .mc import (EvaluationCache, Evaluator, MonteCarloResult, parallel_seconds, recording_calls, run_monte_carlo,
                 run_until_decided)
from .model import Model
from .options import read_options
from .params import Params, read_toml
from .run_options import TABLES as RUN_TABLES
from .run_options import ExecutionOptions, SamplingOptions, default
from .patterns import feature_spec, with_patterns
from .runguard import NAME_MAX_BYTES
from .analysis import in_dependency_order
from .registry import analysis_function, model_factory
from .blocks import Section, deferred_figures, render_deferred
from .sampling import METHODS
from .spec import (Requirement, ToleranceSpec, load_spec, merge_specs, read_requirements_file,
                   requirements_from_tables, spec_from_table)

#: the longest report folder name: ``.NAME.tmp-<12 hex>`` and ``.NAME.old-<12 hex>`` are made beside it
MAX_FOLDER_NAME_BYTES = NAME_MAX_BYTES - len(".") - len(".tmp-") - 12


@dataclass
class RunOptions:
    """What a run does: the study's run tables (:mod:`rvtol.run_options`, whose declared defaults these are) with
    the command line's values over them."""

    n: int = default(SamplingOptions, "n")
    method: str = "lhs"
    seed: int | None = default(SamplingOptions, "seed")
    executor: str = "process"
    workers: int | None = None
    scheduler: str | None = None
    chunk_size: int | None = None
    pdf: bool = True
    confidence: float = 0.95
    progress: bool = True
    tables: tuple[str, ...] = ()       # also write samples/statistics as these table formats (csv, xlsx)
    until_decided: bool = False        # sequential run: batches of n until every requirement is decided (or max_n)
    max_n: int | None = None           # a sequential run's sample budget (default: MAX_N_PER_BATCH × n)
    tails: bool = False                # undecided yield requirements decided by tail estimators (rvtol.tail_decision)
    tail_samples: int = 2000           # model runs per tail estimator and limit


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


@dataclass
class StudyContext:
    """What an analysis sees when it runs."""

    study: Study
    executor: Executor
    mc: MonteCarloResult
    cache: EvaluationCache = field(default_factory=EvaluationCache)   # rows the analyses evaluated
    store: object = None  # rvtol.checkpoint.ChunkStore of the run (checkpoint / resume), or None
    results: dict = field(default_factory=dict)   # analysis key -> what its compute returned (Analysis.requires)

    @property
    def design(self):
        return self.study.design

    @property
    def spec(self):
        return self.study.spec

    @property
    def model(self):
        return self.study.model

    @property
    def options(self):
        return self.study.options

    @property
    def seed(self):
        return self.study.options.seed

    @property
    def evaluator(self) -> Evaluator:
        """Evaluate any model through the study's executor, chunking and progress bar (base units)."""
        o = self.study.options
        return Evaluator(self.executor, o.chunk_size, o.progress, self.cache, self.store)


# --------------------------------------------------------------------------- loading
class NotRunModel(Model):
    """Stands for a model whose code ``rvtol check`` did not run (a ``kind = "python"`` factory): its outputs are unknown, so requirements' outputs, gates and analyses are not checked.
    ``notes`` say what was checked without running."""

    def __init__(self, spec: ToleranceSpec, notes: list[str]):
        from . import units as _units

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
            from .models.custom.model import check_without_running

            notes.append(check_without_running(t))
    return notes or None


def load_study(path: str | Path, *, execute: bool = True, design: Design | None = None, analyses: bool = True,
               **overrides) -> Study:
    """Read and validate a study file and everything it names. Raises :class:`InputError`.

    ``execute=False`` (``rvtol check`` without ``--execute``): a model made by the user's code is validated
    without running that code (:class:`NotRunModel`), and what depends on its outputs is not checked.
    ``design``: a variant of the study's design to build everything on instead of the file's (the epistemic band,
    :mod:`rvtol.epistemic`); ``analyses=False``: the study's analyses are not read (only its models)."""
    variant = design
    path = Path(path)
    data, sha = read_toml(path)
    file = str(path)
    base = path.parent
    data, parent = _extended(data, path)
    root = Params(data, file=file)
    head = root.sub("study")
    name = head.str("name", path.stem, single_line=True)
    if not name or any(c in name for c in "/\\") or name.startswith("."):
        raise head.error("name", f"invalid study name {name!r} (used as a folder name)")
    if len(name.encode()) > MAX_FOLDER_NAME_BYTES:
        raise head.error("name", f"the study name is {len(name.encode())} bytes long, and it names the report folder: "
                                 f"at most {MAX_FOLDER_NAME_BYTES} (a file name's {NAME_MAX_BYTES}, less the temporary "
                                 "names rvtol gives beside it); give a shorter name")
    title = head.str("title", name, single_line=True)
    desc = head.str("description", "")
    inputs = {"study": {"path": file, "sha256": sha}}
    if parent is not None:
        inputs["extends"] = parent

    design = None
    dpath = head.path_value("design", base, None)
    if variant is not None:
        design = variant
        inputs["design"] = {"path": str(dpath) if dpath is not None else variant.file, "sha256": None,
                            "variant": True}
    elif dpath is not None:
        design = load_design(dpath)
        inputs["design"] = {"path": str(dpath), "sha256": design.sha256}
        if design.base is not None:           # a variant: the base design it changes
            inputs["design_base"] = {"path": design.base[0], "sha256": design.base[1]}

    spaths = _spec_paths(head, base)
    if spaths:
        if "factor" in root:
            raise root.error("factor", "give the factors either in the spec file or here, not both")
        sheets = _spec_sheets(head, spaths)
        parts = []
        for sp, sheet in zip(spaths, sheets):
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
            spec = merge_specs(parts)
        except InputError as exc:
            raise exc.located(file=file) from None
    else:
        if "spec_sheet" in head.data:
            raise head.error("spec_sheet", "names the worksheet of [study] spec, and there is no spec file")
        if "factor" not in root:
            raise head.error("spec", "missing required key (or give [[factor]] tables in the study file)")
        spec = spec_from_table({k: data[k] for k in ("factor", "correlation") if k in data}, file=file, name=name)
        root.raw("factor")
        root.raw("correlation", None)

    reqs: list[Requirement] = []
    rpath = head.path_value("requirements", base, None)
    if rpath is not None:
        rfile, rsha = read_requirements_file(rpath)
        reqs += rfile
        inputs["requirements"] = {"path": str(rpath), "sha256": rsha}
    reqs += requirements_from_tables(root.tables("requirement"))
    mapping = head.path_value("mapping", base, None)
    build_path = None if head.raw("build", False) is False else head.path_value("build", base)
    exploratory = head.bool("exploratory", False)
    head.finish()

    options = _options(root, overrides)

    rules = None
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
            model, spec, rules = _composite(root, mapping, design, spec, file, inputs, build_path, drawn)
        else:
            if mapping is not None or "quantity" in root:
                raise head.error("mapping", "a mapping ([[quantity]] tables) needs several [[model]] tables")
            if build_path is not None:
                raise head.error("build", "a build (how the reducer is assembled) needs a composed study: "
                                          "several [[model]] tables")
            mp = root.sub("model")
            model = build_model(mp, design, spec, file)
            mp.finish()
    except InputError as exc:
        raise (design.relocate(exc) if design is not None else exc) from None   # a variant's base number: its file
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

    study = Study(name, title, desc, file, base, design, spec, model, reqs, options, [], inputs, exploratory)
    check_sequential(study)
    study.build = rules
    study.notes = model_warnings(model)
    study.gates = read_gates(root.tables("gate"), model)  # [[gate]] tables (rvtol.ci: --baseline, compare)
    if not analyses:
        root.raw("analysis", None)
    tables = list(root.tables("analysis") if analyses else ())
    for t in tables:
        akind = t.str("kind")
        cls = analysis_function(akind, file, t.path("kind"))
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
    root.finish()
    return study


def model_warnings(model) -> list[str]:
    """What a model (or the stages of a composed one) found worth a note in its inputs (``Model.warnings``: a
    formula that sums factors of different units under units = "factor")."""
    out = list(getattr(model, "warnings", ()))
    for stage in getattr(model, "stages", ()):
        out += [f"model {stage.name!r}: {w}" for w in getattr(stage.model, "warnings", ())]
    return out


def _spec_paths(head: Params, base: Path) -> list[Path]:
    """``[study] spec``: one file, or a list of files read as one spec (e.g. the product's drawing tolerances and
    a test rig's, :func:`rvtol.spec.merge_specs`)."""
    v = head.raw("spec", None)
    if v is None:
        return []
    if isinstance(v, list):
        if not v or not all(isinstance(x, str) and x for x in v):
            raise head.error("spec", "expected a file name or a list of file names")
        return [Path(x) if Path(x).is_absolute() else base / x for x in v]
    return [head.path_value("spec", base)]


def check_output_names(model: Model, spec: ToleranceSpec, data: dict, file: str) -> None:
    """Every output's name is one line without control characters (a model made by code names its own), and no
    output shares its name with a factor: samples.parquet, the statistics and the report could not tell the two
    apart (one column replaced the other).  Blamed at ``[[model.output]]``'s name where the study gives it."""
    from .safetext import control_character

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


def _spec_sheets(head: Params, spaths: list[Path]) -> list[str | None]:
    """``[study] spec_sheet``: the worksheet of a workbook spec (a list beside a list of specs, ``""`` for a file
    read as by default); without it each workbook is read from the sheet :func:`rvtol.inputs.sheets.read_rows`
    can tell without guessing."""
    v = head.raw("spec_sheet", None)
    if v is None:
        return [None] * len(spaths)
    listed = isinstance(head.data.get("spec"), list)
    sheets = head.strs("spec_sheet") if listed else [head.str("spec_sheet")]
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


def build_model(mp: Params, design: Design | None, spec: ToleranceSpec, file: str) -> Model:
    """The study's ``[model]`` through its registered factory; the one place factory errors are located.

    A factory (and the Model it builds) raises :class:`InputError` without a
    file: an error about the spec's factors (key ``factor...``) belongs to the
    spec file, any other to the ``[model]`` table of the study file; an error
    that already names its file (a bad number in the design) keeps it.
    """
    kind = mp.str("kind")
    factory = model_factory(kind, file)
    try:
        model = factory(mp, design, feature_spec(spec))    # a composite frame's features at their positions
        if not isinstance(model, Model):   # a plug-in's factory (the built-in ones are tested)
            raise InputError(f"the factory of model kind {kind!r} returned {type(model).__name__}, "
                             "not an rvtol.model.Model", key="kind")
        return with_patterns(model, spec)
    except InputError as exc:
        if exc.file is None:
            if (exc.key or "").split(".")[0].split("[")[0] == "factor":
                exc.located(file=spec.file or file)
            else:
                exc.located(file=file, key=None if (exc.key or "").startswith(mp.key) else mp.key)
        raise exc from None


def _composite(root: Params, mpath: Path | None, design, spec, file: str, inputs: dict,
               build_path: Path | None = None, drawn_build: Path | None = None) -> tuple[Model, ToleranceSpec, object]:
    """Several ``[[model]]`` tables on the same samples (:mod:`rvtol.models.composite`); with a build file,
    its rules (:mod:`rvtol.production.build`) and the spec with its gauge errors.  ``drawn_build``: the build
    of the base study that a study with ``build = false`` does not apply — the values its models read from it
    take their value as drawn (:meth:`rvtol.production.build.BuildRules.as_drawn`: a shim's preload, its target)."""
    from .models.composite.model import design_quantities, from_study_tables, quantities_from_tables

    tables = root.tables("quantity")
    if mpath is not None:
        mdata, msha = read_toml(mpath)
        mroot = Params(mdata, file=str(mpath))
        head_m = mroot.sub("mapping", {})
        head_m.str("name", "")
        head_m.str("description", "")
        head_m.finish(allow=("source",))
        head_m.raw("source", None)
        tables = mroot.tables("quantity") + tables
        mroot.finish()
        inputs["mapping"] = {"path": str(mpath), "sha256": msha}
    try:
        quantities = quantities_from_tables(tables)
    except InputError as exc:
        raise exc.located(file=file) from None

    rules, constants = None, None
    if drawn_build is not None:
        from .production.build import load_build

        used = [n for q in quantities for n in q.expression.names]
        constants = load_build(drawn_build, spec, design, design_quantities(used, design) + list(quantities)).as_drawn()
    if build_path is not None:
        from .production.build import extended_spec, load_build

        used = [n for q in quantities for n in q.expression.names]
        rules = load_build(build_path, spec, design, design_quantities(used, design) + list(quantities))
        inputs["build"] = {"path": str(build_path), "sha256": rules.sha256}
        spec = extended_spec(spec, rules)

    def build(params: Params, design_, stage_inputs) -> Model:
        return build_model(params, design_, stage_inputs, file)

    try:
        return from_study_tables(root.tables("model"), quantities, design, spec, build, rules, constants), spec, rules
    except InputError as exc:
        raise exc.located(file=file) from None


#: a sequential run's default budget, in batches (``max_n = MAX_N_PER_BATCH × n``)
MAX_N_PER_BATCH = 20


def _options(root: Params, ov: dict) -> RunOptions:
    """The run's options: the study's ``[sampling]``, ``[execution]`` and ``[report]`` (:mod:`rvtol.run_options`)
    with the command line's values ``ov`` over them."""
    s, e, r = (read_table_options(root, name) for name in ("sampling", "execution", "report"))
    until = bool(ov.get("until_decided")) or s.until_decided
    o = RunOptions(
        n=s.n,
        method=s.method or ("random" if until else "lhs"),
        until_decided=until,
        max_n=s.max_n,
        tails=s.tails or bool(ov.get("tails")),
        tail_samples=s.tail_samples,
        seed=s.seed,
        **execution_keys(e, ov, lambda key, why: root.error(f"execution.{key}", why)),
        chunk_size=e.chunk_size or None,
        pdf=r.pdf,
        confidence=r.confidence,
        tables=r.formats(),
    )
    for k, v in ov.items():
        if v is None or k in _EXECUTION:
            continue
        if not hasattr(o, k):
            raise InputError(f"unknown option {k!r}", key=k)
        setattr(o, k, v)
    if o.n < 2:
        raise InputError(f"n must be >= 2, got {o.n}", file=root.file, key="sampling.n")
    if o.method not in METHODS:
        raise InputError(f"unknown sampling method {o.method!r}", file=root.file, key="sampling.method")
    _sequential_options(o, root.file, ov)
    if "xlsx" in o.tables and o.n + 1 > XLSX_MAX_ROWS:
        raise InputError(f"{o.n} samples do not fit an XLSX sheet ({XLSX_MAX_ROWS - 1} rows): write them as csv",
                         file=root.file, key="report.tables")
    return o


def read_table_options(root: Params, name: str):
    """A run table of the study (``sampling``, ``execution``, ``report``) read by its declared options: every key
    checked, an unknown one refused."""
    p = root.sub(name, {})
    o = read_options(RUN_TABLES[name], p)
    p.finish()
    return o


def _sequential_options(o: RunOptions, file: str, ov: dict) -> None:
    """A sequential run's options checked (and its budget defaulted); ``max_n`` alone asks for nothing."""
    cli = {k: ov.get(k) is not None for k in ("method", "max_n", "n")}
    def where(k: str) -> dict:
        return ({"file": "<command line>", "key": f"--{k.replace('_', '-')}"} if cli.get(k) else
                {"file": file, "key": f"sampling.{k}"})

    if o.tails and o.until_decided:
        raise InputError("tails = true decides what a fixed-n run leaves undecided; a sequential run decides by its "
                         "own rule: choose one", **({"file": "<command line>", "key": "--tails"} if ov.get("tails")
                                                    else {"file": file, "key": "sampling.tails"}))
    if not o.until_decided:
        if o.max_n is not None:
            raise InputError("max_n is the budget of a sequential run: set until_decided = true (or --until-decided), "
                             "or drop it", **where("max_n"))
        return
    if o.method != "random":
        fix = "--method random" if cli["method"] else 'method = "random" (or --method random), or leave it out'
        raise InputError(f"a sequential run draws independent random samples, batch after batch (the anytime-valid "
                         f"rule assumes independent draws; a {o.method} design is neither independent nor extendable): "
                         f"{fix}", **where("method"))
    if o.max_n is None:
        o.max_n = MAX_N_PER_BATCH * o.n
    if o.max_n < o.n:
        raise InputError(f"the budget max_n = {o.max_n} is smaller than one batch (n = {o.n})", **where("max_n"))


def check_sequential(study: "Study") -> None:
    """Refuse a sequential run whose requirements or factors the anytime-valid rule cannot decide (InputError at the
    requirement's key, or the spec's factor)."""
    from .sequential import unsupported

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


#: the keys that choose where the model runs ([execution] and the command line's flags)
_EXECUTION = ("executor", "workers", "scheduler")


def _contradiction(v: dict) -> tuple[str, str, str] | None:
    """Two execution keys that cannot both hold: ``(key, other key, why)`` — ``why`` names the other as ``{other}``
    —, or None."""
    if v["executor"] == "serial" and v["workers"] is not None and v["workers"] > 1:
        return "workers", "executor", (f"{v['workers']} workers with {{other}}, which evaluates everything in this "
                                       "process: ask for the process or dask executor")
    if v["scheduler"] is not None and v["executor"] in ("serial", "process"):
        return "scheduler", "executor", "a Dask scheduler with {other}, which does not use one"
    if v["scheduler"] is not None and v["workers"] is not None:
        return "workers", "scheduler", "workers with {other}: a running Dask cluster has its own (workers start a " \
                                       "local one)"
    return None


def execution_keys(e: ExecutionOptions, ov: dict, error) -> dict:
    """``executor``, ``workers``, ``scheduler``: the command line's values over ``[execution]``'s (``e``; ``error``:
    its table's located error).  Two that contradict each other (:func:`_contradiction`) are refused when one source
    gives both; when the command line gives one and the study file the other, the command line's wins and the file's
    is dropped (``--workers 4`` runs a study written serial on a process pool; ``--scheduler`` one written for a
    process pool on Dask, as ``--executor`` would)."""
    given = {"file": {"executor": e.executor, "workers": e.workers, "scheduler": e.scheduler},
             "cli": {k: ov.get(k) for k in _EXECUTION}}
    src = {k: "cli" if given["cli"][k] is not None else "file" for k in _EXECUTION}
    v = {k: given[src[k]][k] for k in _EXECUTION}
    while (c := _contradiction(v)) is not None:
        key, other, why = c
        if src[key] != src[other]:            # the file's yields to the command line's
            v[key if src[key] == "file" else other] = None
            continue
        if src[key] == "cli":
            raise InputError(why.format(other=f"--{other} {v[other]}"), file="<command line>", key=f"--{key}")
        raise error(key, why.format(other=f"{other} = {v[other]!r}"))
    v["executor"] = v["executor"] or ("dask" if v["scheduler"] else "process")
    return v


def written_files(folder: Path) -> list[str]:
    """The files a written report folder holds besides report.html, as its manifest lists them (what the run wrote:
    the PDFs, tables, the requirements' CSV, comparison.json and every analysis' own files)."""
    names = (Path(folder) / MANIFEST).read_text(encoding="utf-8").split("\n")
    return sorted(n for n in names if n and n not in ("report.html", MANIFEST))


# --------------------------------------------------------------------------- running
@dataclass
class StudyResult:
    """Everything a run computed: the Monte Carlo, the analyses' sections and — computed in the run, so writing
    the report only writes — the sign-off digest, the report's standard sections and the summary."""

    study: Study
    mc: MonteCarloResult
    sections: list[Section]
    elapsed: float
    executor: str
    timings: dict = field(default_factory=dict)   # wall time (s) by phase: "monte_carlo", each analysis' key, ...
    signoff: list = field(default_factory=list)   # per requirement: verdict, drivers, what to change
    standard_sections: list[Section] = field(default_factory=list)   # the report's own sections (verdict, inputs...)
    comparison: object = None                     # rvtol.ci.compare.Comparison with the baseline, if one was given
    build_usage: object = None    # pandas.DataFrame: per build rule, what it did on the Monte Carlo's reducers
    parallel: dict = field(default_factory=dict)  # per phase of ``timings``: the wall time (s) spent in parallel evaluation
    measured_evidence: dict = field(default_factory=dict)   # measured factor -> rvtol.inputs.measured.evidence
    calls: dict | None = None     # per phase of ``timings``, when recorded: its parallel calls (rvtol.mc.recording_calls)
    workers: int = 1              # the executor's workers

    @property
    def passed(self) -> bool:
        return self.mc.passed

    @property
    def verdict(self) -> str:
        """PASS, FAIL, NO REQUIREMENTS or EXPLORATORY (:func:`rvtol.verdict.study_verdict`)."""
        from .verdict import study_verdict

        return study_verdict([v.passed for v in self.mc.verdicts()], self.study.exploratory)

    @cached_property
    def _summary(self) -> dict:
        from .report.summary import build_summary

        return build_summary(self)

    def summary(self) -> dict:
        """summary.json's content (built once: every writer and the CLI read the same dict)."""
        return self._summary


def run_study(study: Study, executor: Executor | None = None, store=None, baseline=None,
              record_calls: bool = False) -> StudyResult:
    """Monte Carlo, the analyses, then what the report shows (timed phases: ``monte_carlo``, each analysis' key,
    ``build_usage`` — what the build rules did —, ``signoff`` — the per-requirement digest —,
    ``measured_factors`` — the measured factors' fits and their goodness-of-fit bootstrap, when a factor is
    measured —, ``comparison`` —
    with the ``baseline`` run (:class:`rvtol.ci.compare.RunData`) if one is given —, ``report`` — the report's
    own sections —, ``figures`` — every figure of the run rendered, on the workers); ``store``
    (:class:`rvtol.checkpoint.ChunkStore`) checkpoints every evaluation.
    Each phase's wall time goes to ``result.timings``, the part of it spent in parallel evaluation
    (:func:`rvtol.mc.parallel_seconds`) to ``result.parallel`` and, with ``record_calls``, its parallel calls and
    their tasks' CPU times (:func:`rvtol.mc.recording_calls`) to ``result.calls``."""
    o = study.options
    own = executor is None
    ex = executor or make_executor(o.executor, o.workers, o.scheduler)
    t0 = time.perf_counter()
    try:
        with recording_calls() if record_calls else nullcontext(None) as calls:
            clock = _PhaseClock(calls)
            result = _phases(study, ex, store, baseline, clock)
    finally:
        if own:
            ex.close()
    result.calls = clock.calls
    result.elapsed = time.perf_counter() - t0
    return result


def _phases(study: Study, ex: Executor, store, baseline, clock: "_PhaseClock") -> StudyResult:
    """:func:`run_study`'s phases, each timed by ``clock``."""
    from .report.standard import standard_sections
    from .signoff import digest

    o = study.options
    # with several workers, figures are pickled as they are made and rendered together on the workers
    with deferred_figures() if ex.workers > 1 else nullcontext():
        if o.until_decided:
            mc = clock.timed("monte_carlo", lambda: run_until_decided(
                study.model, study.spec, o.n, o.max_n, o.seed, study.requirements, ex, o.chunk_size, o.progress,
                o.confidence, store=store))
        else:
            mc = clock.timed("monte_carlo", lambda: run_monte_carlo(study.model, study.spec, o.n, o.method, o.seed,
                                                                    study.requirements, ex, o.chunk_size, o.progress,
                                                                    o.confidence, store=store))
        if o.tails:
            from .tail_decision import decide

            evaluator = StudyContext(study, ex, mc, store=store).evaluator
            mc = clock.timed("tails", lambda: replace(mc, tails=decide(mc, study.model, study.spec, evaluator,
                                                                       seed=o.seed, samples=o.tail_samples)))
        ctx = StudyContext(study, ex, mc, store=store)
        sections: list[Section] = []
        for i, a in enumerate(study.analyses):
            mark = clock.mark()
            res = a.run(ctx)
            res = res if isinstance(res, list) else [res]
            sections.extend(res)
            clock.add(getattr(a, "key", None) or (res[0].key if res else f"analysis[{i}]"), mark)
        result = StudyResult(study, mc, sections, 0.0, ex.describe(), clock.timings, parallel=clock.parallel,
                             workers=ex.workers)
        if study.build is not None:    # what the build rules did on the Monte Carlo's reducers (report, summary)
            from .production.build import usage

            def build_usage():
                env, _ = study.model.without_build().environment(mc.samples.values, set())
                return usage(study.build, env, mc.n)

            result.build_usage = clock.timed("build_usage", build_usage)
        result.signoff = clock.timed("signoff", lambda: digest(mc, study.model, study.spec, o.seed))
        if any(f.measured is not None for f in study.spec.factors):   # the fits' goodness-of-fit bootstrap
            from .inputs.measured import evidence
            from .sampling import substream_seed

            result.measured_evidence = clock.timed("measured_factors", lambda: {
                f.name: evidence(f.measured, f.dist, seed=substream_seed(o.seed, "measured_gof", i))
                for i, f in enumerate(study.spec.factors) if f.measured is not None})
        if baseline is not None:
            from .ci.compare import RunData, compare

            def comparison():
                result.comparison = compare(baseline, RunData.from_result(result), seed=o.seed)
                result.__dict__.pop("_summary", None)   # built for the comparison; rebuilt with every phase's time

            clock.timed("comparison", comparison)
        result.standard_sections = clock.timed("report", lambda: standard_sections(result))
    clock.timed("figures", lambda: render_deferred([*result.sections, *result.standard_sections], ctx.evaluator.map))
    return result


class _PhaseClock:
    """Each phase's wall time (``timings``), the part of it in parallel evaluation (``parallel``) and — with the
    run's parallel calls recorded (``calls``: the list :func:`rvtol.mc.recording_calls` fills) — its calls."""

    def __init__(self, calls: list | None):
        self.timings: dict = {}
        self.parallel: dict = {}
        self._all = calls
        self.calls: dict | None = None if calls is None else {}

    def mark(self) -> tuple:
        return time.perf_counter(), parallel_seconds(), len(self._all or ())

    def add(self, name: str, mark: tuple) -> None:
        t, p, n = mark
        self.timings[name] = self.timings.get(name, 0.0) + time.perf_counter() - t
        self.parallel[name] = self.parallel.get(name, 0.0) + parallel_seconds() - p
        if self.calls is not None:
            self.calls.setdefault(name, []).extend(self._all[n:])

    def timed(self, name: str, f):
        mark = self.mark()
        try:
            return f()
        finally:
            self.add(name, mark)


def check_out_dir(out_dir: str | Path) -> Path:
    """Check that ``out_dir`` may receive a report; raise :class:`InputError` (key ``--out``) if not.

    A report replaces only an absent or empty folder or an earlier rvtol report folder (one with an
    rvtol ``summary.json``) — never other files, the current folder or one of its parents.
    """
    out = Path(out_dir)
    where = str(out_dir)
    full = out.resolve()
    cwd = Path.cwd().resolve()
    if full == cwd or full in cwd.parents:
        raise InputError("refusing to replace the current folder or one of its parents; name a subfolder",
                         file=where, key="--out")
    if len(out.name.encode()) > MAX_FOLDER_NAME_BYTES:
        raise InputError(f"the folder's name is {len(out.name.encode())} bytes long: at most {MAX_FOLDER_NAME_BYTES} "
                         f"(a file name's {NAME_MAX_BYTES}, less the temporary names rvtol gives beside it)",
                         file=where, key="--out")
    if out.exists():
        if not out.is_dir():
            raise InputError("exists and is not a folder", file=where, key="--out")
        if any(out.iterdir()) and not _is_report_folder(out):
            raise InputError("exists and is not an rvtol report folder (no rvtol summary.json in it); "
                             "choose another --out or empty it", file=where, key="--out")
        foreign = foreign_files(out)
        if foreign:
            shown = ", ".join(foreign[:5]) + (f" and {len(foreign) - 5} more" if len(foreign) > 5 else "")
            raise InputError(f"holds files rvtol did not write ({shown}); a run replaces the whole folder: move them "
                             "elsewhere first", file=where, key="--out")
    return out


#: the list of the files a report folder's run wrote (written last, in the same atomic step)
MANIFEST = ".rvtol-files"
#: files of a report folder written before the manifest existed
_KNOWN = ("summary.json", "samples.parquet", "report.html", "report.pdf", "comparison.json", "requirements.csv",
          "per_unit.csv", "samples.csv", "samples.xlsx", "statistics.csv", "statistics.xlsx")


def foreign_files(folder: Path) -> list[str]:
    """The entries of an rvtol report folder that rvtol did not write (its manifest, or the known names)."""
    try:
        known = set((folder / MANIFEST).read_text(encoding="utf-8").split("\n")) | {MANIFEST}
    except (OSError, UnicodeDecodeError):
        known = set(_KNOWN)
    return sorted(p.name for p in folder.iterdir() if p.name not in known)


def _is_report_folder(path: Path) -> bool:
    try:
        return json.loads((path / "summary.json").read_text()).get("format", "").startswith("rvtol-summary/")
    except (OSError, ValueError, AttributeError, RecursionError):
        return False


def _write_section_files(sections: list[Section], folder: Path) -> None:
    """The files analyses add to the report folder (:meth:`rvtol.blocks.Section.add_file`)."""
    for s in sections:
        for name, content in s.files.items():
            if (folder / name).exists():
                raise ValueError(f"analysis {s.key!r}: report file {name!r} exists already")
            (folder / name).write_bytes(content)


#: the most rows and columns an XLSX sheet holds (Excel's limits, header included)
XLSX_MAX_ROWS, XLSX_MAX_COLUMNS = 1_048_576, 16_384


def write_tables(result: StudyResult, samples, folder: Path) -> None:
    """``samples.csv|xlsx`` and ``statistics.csv|xlsx`` (statistics, and the requirements' figures) in ``folder``."""
    from .inputs.sheets import write_frames

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
    from .report.render import PDF_MAX_ROWS, render_html, render_pdf, render_summary_html

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
