"""The adjusted assembly's description file (``data/assemblies/bx40e_*.toml``, :mod:`.description`), declared
(:mod:`rvtol.options`): ``[assembly]``, ``[weights]``, ``[measurement]``, ``[[chain]]``, ``[[kc]]``, ``[[step]]`` and
``[[observation]]`` — registered as ``adjustment_<table>`` (the stack-up's assembly file has an ``[assembly]`` and
``[[kc]]`` of its own), so ``rvtol kinds adjustment_kc`` lists their keys and the common invalid-value test covers
them.  What the keys mean together (a KC in one chain, installed once and after the KC before it in its chain, the
KCs a step measures and adjusts installed, a non-singular W) is checked where the description is made
(:func:`rvtol.models.adjustment.description.assembly_from_table`)."""
from __future__ import annotations

from dataclasses import dataclass

from ...options import REQUIRED, option

_SOURCE = "where the numbers come from"
_NOTE = "a remark (how a number was obtained)"


@dataclass
class AdjustmentHead:
    """``[assembly]`` of an adjusted assembly's description: its name, the angular components of a KC, the unit of
    the angles the file writes."""

    name: str = option(REQUIRED, "the description's name")
    title: str | None = option(None, "the report's name for it (default: the name)")
    source: str = option("", _SOURCE)
    description: str = option("", "what the assembly is")
    components: list[str] = option(["x"], 'the angular components per KC: ["x"] (2-D) or ["x", "y", "z"] (3-D), '
                                          "distinct", min_length=1)
    angle_unit: str = option("mrad", "the unit of the sigmas this file writes (an angle)")


@dataclass
class WeightsTable:
    """``[weights]`` of an adjusted assembly's description: the finite-horizon LQR weights (doc 002)."""

    accuracy: object = option(REQUIRED, 'Q, on the final observation: a number >= 0, or "inf" (or TOML inf): a '
                                        "terminal constraint")
    effort_adjustable: float = option(REQUIRED, "R(k) of a KC that may be adjusted at step k", positive=True)
    effort_locked: float = option(REQUIRED, "R(k) of every other KC (not yet installed, or locked)", positive=True)
    source: str = option("", _SOURCE)
    note: str = option("", _NOTE)


@dataclass
class MeasurementTable:
    """``[measurement]`` of an adjusted assembly's description: what the state estimator (a Kalman filter)
    assumes, in the file's angle_unit."""

    noise_sigma: float = option(0.0, "σ of the measurement noise v(k)", nonnegative=True)
    prior_sigma: float = option(1.0, "σ of a part's angular error Δθ (a [[kc]] may override it)", positive=True)
    source: str = option("", _SOURCE)
    note: str = option("", _NOTE)


@dataclass
class ChainTable:
    """``[[chain]]`` of an adjusted assembly's description: a datum flow chain, from the datum outwards."""

    name: str = option(REQUIRED, "the chain's name")
    kcs: list[str] = option(REQUIRED, "its KCs in order (each in one chain, each with its [[kc]])", min_length=1)
    source: str = option("", _SOURCE)
    note: str = option("", _NOTE)


@dataclass
class AdjustmentKCTable:
    """``[[kc]]`` of an adjusted assembly's description: a KC and the part whose installation creates it."""

    name: str = option(REQUIRED, "the KC's name (in a [[chain]])")
    part: str | None = option(None, "the part whose installation creates it (default: the KC's name)")
    error: str = option(REQUIRED, "the factor name of its part's angular error (the component letter appended "
                                  "in 3-D)")
    W: list | None = option(None, "d×d: part frame -> datum frame, a list of d rows (default: identity)")
    prior_sigma: float | None = option(None, "σ of its part's angular error (default: [measurement]'s)",
                                       positive=True)
    source: str = option("", _SOURCE)
    note: str = option("", _NOTE)


@dataclass
class AdjustmentStepTable:
    """``[[step]]`` of an adjusted assembly's description: one installation, in assembly order."""

    install: str = option(REQUIRED, "the KC installed")
    measure: list[str] | None = option(None, "the KCs measured after it (default: the one installed)", min_length=1)
    adjust: list[str] | None = option(None, "the KCs that may be adjusted at this step (default: all installed)")
    note: str = option("", _NOTE)


@dataclass
class ObservationTable:
    """``[[observation]]`` of an adjusted assembly's description: a row of C(N), a final KC relationship (default:
    each KC against the datum)."""

    name: str = option(REQUIRED, "the observation's name")
    terms: dict[str, float] = option(REQUIRED, "{ KC = coefficient, ... }: at least one non-zero")
    note: str = option("", _NOTE)
