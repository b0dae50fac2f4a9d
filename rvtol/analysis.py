"""The analysis plug-in contract: what a study's ``[[analysis]]`` table becomes.

An analysis is a thin adapter between a study and one capability of the library:

* **declarative options** — a dataclass ``Options`` (:mod:`rvtol.options`): every key the
  ``[[analysis]]`` table may hold, with its type, default, constraints and meaning — a schema only
  (its ``complete`` checks keys against each other and the study; it reads no file and builds
  nothing); the table is read and checked when the study *loads* (``Analysis(params, study)``), so a
  study fails before anything is computed, and ``rvtol kinds KIND`` lists the keys;
* **a plan** — what the capability loads or builds from the options (a measured curve, the model it
  runs, a design's stiffness chain): :meth:`Analysis.prepare` returns it once, when the study loads
  (a frozen dataclass; bad input found there is a located error too), and ``compute`` reads it as
  ``self.plan`` (a ``title`` field of the plan is the section's default title; an ``inputs`` field, role ->
  ``{"path", "sha256"}``, names the files it read, which the loader records in the study's inputs);
* **one library call** — ``compute(ctx)`` calls the capability's plain function, which returns a
  result dataclass (``to_frame()``, ``plot()``, ``summary()``); ``ctx`` is the
  :class:`rvtol.study.StudyContext` (the study, its Monte Carlo result ``ctx.mc`` and
  ``ctx.evaluator``, the one way to evaluate a model);
* **one generic report** — :meth:`Analysis.report` puts the blocks of the capability's layout
  (``layout(result, options)``, in the capability's ``texts`` module, where its prose lives;
  :meth:`Analysis.blocks` calls it, and an analysis whose layout also reads the plan overrides that)
  into a :class:`rvtol.blocks.Section`, and ``result.summary()`` into ``summary.json`` under
  ``analyses.<key>``.

Everything a report shows is computed in ``run`` (a timed phase of the study); rendering
only renders.  Register the class in :data:`rvtol.registry.ANALYSES` (or through the
``rvtol.analyses`` entry-point group of an installed package) under the ``kind`` a study names.

A plug-in analysis (built in or from an installed package) derives from :class:`Analysis` and
declares ``Options``: :func:`rvtol.registry.analysis_function` refuses any other class, and there is
no hand-read form of the ``[[analysis]]`` table.  It may override ``run(ctx)`` (returning one Section
or a list), ``report(result)`` (several sections) or ``summary(result)``; the study runner only calls
``Analysis(params, study)`` and ``run(ctx)``.
"""
from __future__ import annotations

from abc import ABC
from dataclasses import dataclass
from typing import Any, Callable, ClassVar, Protocol, runtime_checkable

from .options import option, read_options

# type names in quotes: rvtol.params.Params, rvtol.blocks.Section, rvtol.study.Study / StudyContext
# (not imported: the study layer imports the analyses, not the other way round)


@runtime_checkable
class AnalysisProtocol(Protocol):
    """What the study runner relies on."""

    def run(self, ctx: "StudyContext") -> "Section | list[Section]": ...


@dataclass
class CommonOptions:
    """The keys every analysis takes."""

    key: str | None = option(None, "summary.json key and report anchor of this analysis (default: its kind; "
                                   "give one to run a kind twice)")
    title: str | None = option(None, "the report section's title (default: the kind's title)")


class Analysis(ABC):
    """Base class of every study analysis (see the module docstring)."""

    #: the ``kind`` a study names
    kind: ClassVar[str] = ""
    #: the report section's default title
    title: ClassVar[str] = ""
    #: the declarative options (a dataclass, usually derived from :class:`CommonOptions`)
    Options: ClassVar[type | None] = None
    #: ``layout(result, options) -> list of report blocks`` (in the capability's ``texts`` module)
    layout: ClassVar[Callable[[Any, Any], list] | None] = None
    #: what it consumes: option -> the kind of the analysis whose key that option names (None: any kind); the
    #: loader checks the key and the kind and runs that analysis first, and ``compute`` reads its result as
    #: ``ctx.results[key]`` (e.g. ``requires = {"allocation": "allocation"}``)
    requires: ClassVar[dict[str, str | None]] = {}

    def __init__(self, params: "Params", study: "Study"):
        if self.Options is None:
            raise TypeError(f"{type(self).__name__} declares no Options (the keys of its [[analysis]] table)")
        self.options = read_options(self.Options, params, study)
        self.plan = self.prepare(self.options, study, params.error)
        self.key = getattr(self.options, "key", None) or self.kind
        self.title = getattr(self.options, "title", None) or getattr(self.plan, "title", None) or type(self).title

    def prepare(self, options, study: "Study", error):
        """What the capability loads or builds from ``options``, made once when the study loads: a frozen
        dataclass (the plan), or None when the options are all it needs.  ``error(key, reason)`` is the table's
        located one-line error."""
        return None

    def required(self) -> dict[str, str]:
        """Option -> the key of the analysis it names, for the :attr:`requires` options given."""
        return {opt: getattr(self.options, opt) for opt in type(self).requires
                if getattr(self.options, opt, None) is not None}

    def run(self, ctx: "StudyContext") -> "Section | list[Section]":
        """Compute (one library call), keep the result for the analyses that require it (``ctx.results``) and
        report (the generic section of the result)."""
        result = self.compute(ctx)
        ctx.results[self.key] = result
        return self.report(result)

    def compute(self, ctx: "StudyContext"):
        """The capability's result for this study (one call of a library function)."""
        raise TypeError(f"{type(self).__name__} defines neither compute() nor run()")

    def report(self, result) -> "Section":
        """The generic report: the capability's layout of ``result`` and its summary."""
        from .blocks import Section

        blocks = self.blocks(result)
        fixes = result.fixes(self.key) if hasattr(result, "fixes") else []
        sec = Section(self.key, self.title, blocks, self.summary(result), fixes=fixes)
        for name, content in self.files(result).items():
            sec.add_file(name, content)
        return sec

    def blocks(self, result) -> list:
        """The report blocks of ``result``: the capability's layout, ``layout(result, options)`` (an analysis whose
        layout also reads its plan overrides this, e.g. ``layout(result, self.options, self.plan)``)."""
        layout = type(self).layout
        if layout is None:
            raise TypeError(f"{type(self).__name__} has no layout (set layout = texts.<function>)")
        return list(layout(result, self.options))

    def summary(self, result) -> dict:
        """What summary.json records under ``analyses.<key>`` (default: ``result.summary()``)."""
        return result.summary()

    def files(self, result) -> dict[str, "bytes | str"]:
        """Files the report folder gets beside report.html (name -> content; default none)."""
        return {}


def in_dependency_order(analyses: list, tables: list) -> list:
    """``analyses`` (with their ``[[analysis]]`` tables, for located errors) checked and ordered by what they
    require (:attr:`Analysis.requires`): each named key must be another analysis of the study, of the kind
    required; an analysis runs after those it requires, otherwise in the study's order; a cycle is an error."""
    by_key = {}
    for a in analyses:
        by_key.setdefault(getattr(a, "key", None), a)
    needs = {}
    for a, t in zip(analyses, tables):
        needs[id(a)] = []
        for opt, key in (a.required() if isinstance(a, Analysis) else {}).items():
            other = by_key.get(key)
            if other is None or other is a:
                known = ", ".join(repr(k) for k in by_key if by_key[k] is not a) or "none"
                raise t.error(opt, f"no other analysis has the key {key!r} (the study's: {known})")
            want = type(a).requires[opt]
            if want is not None and other.kind != want:
                raise t.error(opt, f"analysis {key!r} is a {other.kind!r} analysis, not {want!r}")
            needs[id(a)].append(other)
    ordered, done = [], set()
    while len(ordered) < len(analyses):
        ready = [a for a in analyses if id(a) not in done and all(id(o) in done for o in needs[id(a)])]
        if not ready:
            i, a = next((i, a) for i, a in enumerate(analyses) if id(a) not in done)
            raise tables[i].error(next(iter(a.required())), "the analyses require each other in a cycle: "
                                  + " → ".join(x.key for x in analyses if id(x) not in done))
        ordered.append(ready[0])
        done.add(id(ready[0]))
    return ordered


class ModelTarget:
    """The model an analysis works on, in a one-model study or as one stage of a composed study.

    ``model``: the target model; ``stage``: its name in a composed study (None otherwise);
    ``output(name)``: the name its output has in the study's Monte Carlo result;
    ``inputs(X)``: the target's input rows (base units) for rows ``X`` of the study's samples.
    """

    def __init__(self, study_model, model, stage: str | None):
        self.study_model, self.model, self.stage = study_model, model, stage

    def output(self, name: str) -> str:
        return f"{self.stage}.{name}" if self.stage else name

    def inputs(self, X):
        import numpy as np

        X = np.atleast_2d(np.asarray(X, dtype=float))
        return self.study_model.stage_inputs(self.stage, X) if self.stage else X

    @property
    def input_names(self) -> tuple[str, ...]:
        return tuple(self.model.inputs)

    @property
    def input_units(self) -> tuple[str, ...]:
        return tuple(self.model.input_units)


def target_model(study: "Study", cls, what: str, name: str | None, error, key: str = "model") -> ModelTarget:
    """The study's model if it is a ``cls``; in a composed study the stage ``name`` (the value of the
    analysis' option ``key``, default ``model``; None: the only stage that is a ``cls``).  ``what`` names the
    kind for errors; ``error(key, reason)`` makes the located one-line error (an options class'
    ``complete``)."""
    model = study.model
    stages = getattr(model, "stages", None)
    if stages is None:
        if name is not None:
            raise error(key, "a one-model study has no stages to choose from")
        if not isinstance(model, cls):
            raise error("kind", f"this analysis needs a {what} model ([model] kind = \"{what}\")")
        return ModelTarget(model, model, None)
    fitting = [s for s in stages if isinstance(s.model, cls)]
    if name is None:
        if len(fitting) != 1:
            raise error(key, f"name the {what} model this analysis works on (the study's {what} models: "
                             f"{', '.join(s.name for s in fitting) or 'none'})")
        return ModelTarget(model, fitting[0].model, fitting[0].name)
    for s in stages:
        if s.name == name:
            if not isinstance(s.model, cls):
                raise error(key, f"model {name!r} is not a {what} model")
            return ModelTarget(model, s.model, s.name)
    raise error(key, f"unknown model {name!r} (the study's models: {', '.join(s.name for s in stages)})")
