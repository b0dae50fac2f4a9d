"""Study analyses of the stack-up (``[[analysis]] kind = ...``); ``rvtol kinds KIND`` lists every key.

==================  ===========================================================================
kind                what (capability, laid out by :mod:`.texts`)
==================  ===========================================================================
stackup_linear      worst case, RSS and loop signs beside the Monte Carlo
                    (:func:`rvtol.stacking.chain_conventions.linear_stackup`)
stackup_graph       picture of the assembly graph, flows, fits, dimensions with sources
                    (:func:`.overview.assembly_overview`)
stackup_sequences   the same samples through each assembly sequence, side by side
                    (:func:`.sequences.compare_sequences`)
stackup_domains     ``[[analysis.domain]]`` tables with ``kind`` = "plane" (``t1``, ``t2``, ``length``,
                    ``width``), "cylinder" (``t``, ``length``) or "clearance" (``clearance``, ``length``,
                    ``hole`` and ``shaft`` distribution tables in mm), ``k`` (3), ``name``: derived
                    mean/σ beside sampled (:func:`.domain_check.check_domains`)
==================  ===========================================================================
"""
from __future__ import annotations

from dataclasses import dataclass

from ...analysis import Analysis, CommonOptions
from ...errors import InputError
from ...options import option
from ...params import Params
from . import texts
from .domain_check import check_domains, domain_from_table
from ...stacking.chain_conventions import check_linearisable, linear_stackup
from .model import StackupModel
from .overview import assembly_overview
from .sequences import compare_sequences, sequence_models


@dataclass
class StackupOptions(CommonOptions):
    """The keys of an analysis of the stack-up model (the study's model must be one)."""

    def complete(self, study, error):
        if not isinstance(study.model, StackupModel):
            raise error("kind", "this analysis needs a [model] of kind 'stackup'")


# --------------------------------------------------------------------------- graph
@dataclass(frozen=True)
class GraphPlan:
    """The section's title: the assembly's name."""

    title: str


class StackupGraph(Analysis):
    kind, title = "stackup_graph", "Stack-up: assembly graph"
    layout = texts.graph
    Options = StackupOptions

    def prepare(self, o, study, error) -> GraphPlan:
        return GraphPlan(f"{type(self).title} of {study.model.assembly.name}")

    def compute(self, ctx):
        return assembly_overview(ctx.model)


# --------------------------------------------------------------------------- sequences
@dataclass(frozen=True)
class SequencesPlan:
    """The assembly sequences compared (the table's, else every one of the assembly's), the model of each and the
    outputs the figure shows (the table's, else those all sequences share)."""

    models: dict
    outputs: list[str]


class StackupSequences(Analysis):
    kind, title = "stackup_sequences", "Stack-up: assembly sequences compared on the same samples"
    layout = texts.sequences

    @dataclass
    class Options(StackupOptions):
        sequences: list[str] | None = option(None, "the assembly sequences (default: every one of the assembly's)",
                                             min_length=2)
        outputs: list[str] | None = option(None, "the outputs the figure shows (default: those all sequences share)",
                                           min_length=1)

        def complete(self, study, error):
            super().complete(study, error)
            asm = study.model.assembly
            for s in self.sequences or ():
                if s not in asm.sequences:
                    raise error("sequences", f"unknown sequence {s!r} (assembly has: {', '.join(asm.sequences)})")
            if self.sequences and len(set(self.sequences)) != len(self.sequences):
                raise error("sequences", "a sequence is named twice")

    def prepare(self, o, study, error) -> SequencesPlan:
        m = study.model
        sequences = o.sequences or list(m.assembly.sequences)
        try:
            models = sequence_models(m, sequences)
        except InputError as exc:  # e.g. a fit that locates only in another sequence needs float factors
            if exc.key == "factor":
                raise exc.located(file=study.spec.file) from None
            raise error("sequences", exc.reason) from None
        common = [n for n in models[sequences[0]].output_names if all(n in mm.output_names for mm in models.values())]
        for out in o.outputs or ():
            if out not in common:
                raise error("outputs", f"{out!r} is not an output of every sequence (common: {', '.join(common)})")
        return SequencesPlan(models, o.outputs or common)

    def compute(self, ctx):
        p = self.plan
        return compare_sequences(p.models, ctx.mc.samples.values, evaluate=ctx.evaluator, shown=p.outputs)


# --------------------------------------------------------------------------- domains
@dataclass(frozen=True)
class DomainsPlan:
    """The deviation domains checked: ``(name, domain)`` of each ``[[analysis.domain]]`` table."""

    domains: list


class StackupDomains(Analysis):
    kind, title = "stackup_domains", "Stack-up: deviation domains — derived moments against sampling"
    layout = texts.domains

    @dataclass
    class Options(CommonOptions):
        n: int = option(200_000, "samples per check", min=1000)
        domain: list[Params] = option([], "[[analysis.domain]] tables: kind = \"plane\" (t1, t2, length, width), "
                                        "\"cylinder\" (t, length) or \"clearance\" (clearance, length, hole, shaft); "
                                        "k (3), name")

        def complete(self, study, error):
            if not self.domain:
                raise error("domain", "give at least one [[analysis.domain]]")

    def prepare(self, o, study, error) -> DomainsPlan:
        return DomainsPlan([domain_from_table(t) for t in o.domain])

    def compute(self, ctx):
        return check_domains(self.plan.domains, n=self.options.n, seed=ctx.seed)


# --------------------------------------------------------------------------- linearised chain vs Monte Carlo
@dataclass(frozen=True)
class LinearPlan:
    """The outputs analysed (the table's, else every output of the model) and those charted (the table's, else the
    first 4)."""

    outputs: list[str]
    figures: list[str]


class StackupLinear(Analysis):
    """``[[analysis]] kind = "stackup_linear"``: worst case, RSS and loop signs beside the Monte Carlo."""

    kind, title = "stackup_linear", "Stack-up: worst case and RSS of the linearised chain beside Monte Carlo"
    layout = texts.linear

    @dataclass
    class Options(StackupOptions):
        outputs: list[str] | None = option(None, "the outputs (default: all)", names="outputs", min_length=1)
        top: int = option(12, "contributors shown per output", min=1)
        figures: list[str] | None = option(None, "the outputs that get a contribution chart (default: the first 4)")

        def complete(self, study, error):
            super().complete(study, error)
            try:
                check_linearisable(study.model)
            except InputError as exc:
                raise error("kind", exc.reason) from None

    def prepare(self, o, study, error) -> LinearPlan:
        outputs = o.outputs or list(study.model.output_names)
        figures = outputs[:4] if o.figures is None else o.figures
        for out in figures:
            if out not in outputs:
                raise error("figures", f"{out!r} is not among the analysed outputs")
        return LinearPlan(outputs, figures)

    def compute(self, ctx):
        p = self.plan
        return linear_stackup(ctx.model, ctx.spec, ctx.mc, outputs=p.outputs, top=self.options.top, figures=p.figures)
