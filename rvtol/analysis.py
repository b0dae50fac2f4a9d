"""The analysis plug-in contract: what a study's ``[[analysis]]`` table becomes.

An analysis is built when the study is *loaded* and run after its Monte Carlo:

1. ``Analysis(params, study)`` — ``params`` is the ``[[analysis]]`` table (a
   :class:`rvtol.params.Params`, ``kind`` already read), ``study`` the loaded
   :class:`rvtol.study.Study` (design, spec, model, requirements, earlier
   analyses).  It reads and checks **every** parameter here and raises
   :class:`rvtol.errors.InputError` (``params.error(key, reason)``) for bad
   input, so a study fails before anything is computed; keys it did not read
   are reported as typos by the study loader.
2. ``run(ctx)`` — ``ctx`` is the :class:`rvtol.study.StudyContext`: the study,
   its Monte Carlo result (``ctx.mc``), and ``ctx.evaluator`` (the one way to
   evaluate a model: the study's executor, chunking and progress bar).  It
   returns one :class:`rvtol.report.Section` or a list of them; their
   ``summary`` dicts go into ``summary.json`` under ``analyses.<key>``.

Subclass :class:`Analysis` and implement :meth:`Analysis.setup` and
:meth:`Analysis.run`; register the class in :data:`rvtol.registry.ANALYSES`
as ``"module:Class"`` under the ``kind`` a study names.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from typing import TYPE_CHECKING, Protocol, runtime_checkable

if TYPE_CHECKING:  # pragma: no cover - types only
    from .params import Params
    from .report.sections import Section
    from .study import Study, StudyContext


@runtime_checkable
class AnalysisProtocol(Protocol):
    """What the study runner relies on."""

    def run(self, ctx: "StudyContext") -> "Section | list[Section]": ...


class Analysis(ABC):
    """Base class of every study analysis (see the module docstring)."""

    def __init__(self, params: "Params", study: "Study"):
        self.setup(params, study)

    @abstractmethod
    def setup(self, params: "Params", study: "Study") -> None:
        """Read and validate the ``[[analysis]]`` parameters (raise InputError); compute nothing heavy."""

    @abstractmethod
    def run(self, ctx: "StudyContext") -> "Section | list[Section]":
        """Compute and return the report section(s)."""


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


def target_model(params: "Params", study: "Study", cls, what: str, key: str = "model") -> ModelTarget:
    """The study's model if it is a ``cls``; in a composed study the stage named by the analysis'
    ``key`` (default ``model``; default stage: the only one that is a ``cls``).  ``what`` names the kind
    for errors."""
    model = study.model
    stages = getattr(model, "stages", None)
    if stages is None:
        if key in params:
            raise params.error(key, "a one-model study has no stages to choose from")
        if not isinstance(model, cls):
            raise params.error("kind", f"this analysis needs a {what} model ([model] kind = \"{what}\")")
        return ModelTarget(model, model, None)
    fitting = [s for s in stages if isinstance(s.model, cls)]
    name = params.str(key, None)
    if name is None:
        if len(fitting) != 1:
            raise params.error(key, f"name the {what} model this analysis works on (the study's {what} models: "
                                    f"{', '.join(s.name for s in fitting) or 'none'})")
        return ModelTarget(model, fitting[0].model, fitting[0].name)
    for s in stages:
        if s.name == name:
            if not isinstance(s.model, cls):
                raise params.error(key, f"model {name!r} is not a {what} model")
            return ModelTarget(model, s.model, s.name)
    raise params.error(key, f"unknown model {name!r} (the study's models: {', '.join(s.name for s in stages)})")
