"""A composed study's own tables, declared (:mod:`rvtol.options`): ``[[quantity]]`` (in the study or its mapping
file) and the mapping file's ``[mapping]`` head — so ``rvtol kinds quantity`` lists their keys and the common
invalid-value test covers them.  The expressions are parsed and the units checked where the quantities are made
(:func:`rvtol.models.composite.model.quantities_from_tables`)."""
from __future__ import annotations

from dataclasses import dataclass

from ...options import REQUIRED, option


@dataclass
class QuantityTable:
    """``[[quantity]]``: a named value of a composed study, an expression of what the models read and give."""

    name: str = option(REQUIRED, "the quantity's name, as expressions and [model.inputs] use it")
    value: object = option(REQUIRED, "an expression (text, or a number) of the spec's factors, earlier quantities, "
                                     "design numbers design.<key> and outputs of models declared before; base units")
    unit: str = option("1", "the value's unit: a base unit (mm, N, rad, s, or products of them)")
    display_unit: str | None = option(None, "the unit the report shows it in (of the same dimension)")
    output: bool = option(False, "also one of the study's outputs (statistics, requirements, report)")
    description: str = option("", "what it is, for the report")


@dataclass
class MappingHead:
    """``[mapping]``: the head of a mapping file, whose [[quantity]] tables hold what it maps."""

    name: str = option("", "the mapping's name")
    description: str = option("", "what it maps, and why")
    source: object = option(None, "where it comes from (a citation, a drawing number: any form)")
