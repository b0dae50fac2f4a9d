"""A build file's tables, declared (:mod:`rvtol.options`): ``[build]``, ``[[fit]]``, ``[[shim]]`` and ``[[choice]]``
(``[[gauge]]`` and ``[[process]]`` are factor tables in the spec's format) — so ``rvtol kinds fit`` lists their keys
and the common invalid-value test covers them.  What the keys mean together (a fit's target and clearance state
one rule, sizes in whole steps, a choice's value held by the spec and the design) is checked where the rules are
made (:func:`rvtol.production.build.load_build`)."""
from __future__ import annotations

from dataclasses import dataclass

from ..options import REQUIRED, option

_EXPRESSION = "an expression (text, or a number) in base units"


@dataclass
class Steps:
    """Sizes from ``from`` to ``to`` in equal steps of ``step`` (the file's unit)."""

    start: float = option(REQUIRED, "the smallest size", key="from")
    stop: float = option(REQUIRED, "the largest size (a whole number of steps above from)", key="to")
    step: float = option(REQUIRED, "the step between sizes", positive=True)


@dataclass
class BuildHead:
    """``[build]``: the build file's name and what it describes."""

    name: str = option("build", "the build's name, as the report shows it")
    description: str = option("", "how the maker builds the reducer, in a sentence or two")


@dataclass
class FitTable:
    """``[[fit]]``: a selective fit — the largest part on hand whose measured clearance is at least the minimum."""

    name: str = option(REQUIRED, "the rule's name (its outputs are build.<name>.part and build.<name>.clearance)")
    title: str | None = option(None, "the report's name for it (default: the name)")
    sets: str = option(REQUIRED, "the spec factor the fit sets (to value)")
    unit: str = option(REQUIRED, "the unit of sizes and minimum (a length)")
    sizes: list[float] | Steps = option(REQUIRED, "the part sizes on hand: a strictly increasing list, or "
                                                   "{ from, to, step }", min_length=2)
    minimum: float = option(REQUIRED, "the least measured clearance the fitter accepts")
    target: object = option(REQUIRED, f"the part size at which the measured clearance equals minimum: {_EXPRESSION} "
                                      "of the readings and minimum")
    clearance: object = option(REQUIRED, f"the true clearance with the chosen part: {_EXPRESSION} of the true sizes "
                                         "and part")
    value: object = option(REQUIRED, f"what the set factor takes: {_EXPRESSION} of part and clearance")
    rule: str = option(REQUIRED, "the maker's rule, in words")
    source: str = option(REQUIRED, "where the rule comes from")


@dataclass
class ShimTable:
    """``[[shim]]``: a shim-set preload — the shim that gives a tapered roller pair its target preload."""

    name: str = option(REQUIRED, "the rule's name (its outputs are build.<name>.preload, ...)")
    title: str | None = option(None, "the report's name for it (default: the name)")
    unit: str = option(REQUIRED, "the unit of the shims (a length)")
    end_play: object = option(REQUIRED, f"the stack's true axial end play: {_EXPRESSION}")
    measured_end_play: object = option(REQUIRED, f"the end play the fitter reads: {_EXPRESSION}")
    shims: list[float] | Steps = option(REQUIRED, "the shim thicknesses on hand, in equal steps: { from, to, step } "
                                                  "or a list", min_length=2)
    preload: object = option(REQUIRED, "the target preload: a number in N, { value, unit }, or { design = \"key\" } "
                                       "(the design's number)")
    settling: object = option(None, f"the stack's run-in settling, taken off the interference: {_EXPRESSION} "
                                     "(e.g. a process factor)")
    rule: str = option(REQUIRED, "the maker's rule, in words")
    source: str = option(REQUIRED, "where the rule comes from")
    bearing: str = option("crank_support_bearing", "the design's key of the bearing pair (its law)")


@dataclass
class ChoiceTable:
    """``[[choice]]``: a drawing or design value chosen for the build, held by the spec and the design."""

    name: str = option(REQUIRED, "the choice's name")
    unit: str = option(REQUIRED, "the value's unit")
    value: float | str = option(REQUIRED, "the value: a number, or an expression of the nominal build (base units)")
    factors: list[str] = option([], "the spec factors whose mean holds the value")
    design: list[str] = option([], "the design's keys that hold the value")
    rule: str = option(REQUIRED, "the maker's rule, in words")
    source: str = option(REQUIRED, "where the choice comes from")
