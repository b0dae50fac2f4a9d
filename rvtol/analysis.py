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
