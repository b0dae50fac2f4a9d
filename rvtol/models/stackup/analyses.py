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

from dataclasses import dataclass, field

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
class StackupGraph(Analysis):
    kind, title = "stackup_graph", "Stack-up: assembly graph"
    layout = texts.graph

    @dataclass
    class Options(StackupOptions):
        def complete(self, study, error):
            super().complete(study, error)
            if self.title is None:
                self.title = f"Stack-up: assembly graph of {study.model.assembly.name}"

    def compute(self, ctx):
        return assembly_overview(ctx.model)


# --------------------------------------------------------------------------- sequences
class StackupSequences(Analysis):
    kind, title = "stackup_sequences", "Stack-up: assembly sequences compared on the same samples"
    layout = texts.sequences

    @dataclass
    class Options(StackupOptions):
        sequences: list[str] | None = option(None, "the assembly sequences (default: every one of the assembly's)",
                                             min_length=2)
        outputs: list[str] | None = option(None, "the outputs the figure shows (default: those all sequences share)",
                                           min_length=1)
        models: dict = field(init=False, default_factory=dict)

        def complete(self, study, error):
            super().complete(study, error)
            m = study.model
            asm = m.assembly
            self.sequences = self.sequences or list(asm.sequences)
            for s in self.sequences:
                if s not in asm.sequences:
                    raise error("sequences", f"unknown sequence {s!r} (assembly has: {', '.join(asm.sequences)})")
            if len(set(self.sequences)) != len(self.sequences):
                raise error("sequences", "a sequence is named twice")
            try:
                self.models = sequence_models(m, self.sequences)
            except InputError as exc:  # e.g. a fit that locates only in another sequence needs float factors
                if exc.key == "factor":
                    raise exc.located(file=study.spec.file) from None
                raise error("sequences", exc.reason) from None
            common = [n for n in self.models[self.sequences[0]].output_names
                      if all(n in mm.output_names for mm in self.models.values())]
            self.outputs = self.outputs or common
            for o in self.outputs:
                if o not in common:
                    raise error("outputs", f"{o!r} is not an output of every sequence (common: {', '.join(common)})")

    def compute(self, ctx):
        return compare_sequences(self.options.models, ctx.mc.samples.values, ctx.evaluator, self.options.outputs)


# --------------------------------------------------------------------------- domains
class StackupDomains(Analysis):
    kind, title = "stackup_domains", "Stack-up: deviation domains — derived moments against sampling"
    layout = texts.domains

    @dataclass
    class Options(CommonOptions):
        n: int = option(200_000, "samples per check", min=1000)
        domain: list[Params] = option([], "[[analysis.domain]] tables: kind = \"plane\" (t1, t2, length, width), "
                                        "\"cylinder\" (t, length) or \"clearance\" (clearance, length, hole, shaft); "
                                        "k (3), name")
        domains: list = field(init=False, default_factory=list)

        def complete(self, study, error):
            if not self.domain:
                raise error("domain", "give at least one [[analysis.domain]]")
            self.domains = [domain_from_table(t) for t in self.domain]

    def compute(self, ctx):
        return check_domains(self.options.domains, self.options.n, ctx.seed)


# --------------------------------------------------------------------------- linearised chain vs Monte Carlo
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
            model = study.model
            self.outputs = self.outputs or list(model.output_names)
            self.figures = self.outputs[:4] if self.figures is None else self.figures
            for o in self.figures:
                if o not in self.outputs:
                    raise error("figures", f"{o!r} is not among the analysed outputs")
            try:
                check_linearisable(model)
            except InputError as exc:
                raise error("kind", exc.reason) from None

    def compute(self, ctx):
        o = self.options
        return linear_stackup(ctx.model, ctx.spec, ctx.mc, o.outputs, o.top, o.figures)
