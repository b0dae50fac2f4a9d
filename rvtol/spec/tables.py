"""The declared keys of a spec's tables (:mod:`rvtol.options`): ``[spec]``, ``[[factor]]`` and ``[[correlation]]``.

One ``[[factor]]`` table holds the keys of every way a factor is written — a distribution and its parameters
(:class:`rvtol.distributions.LawKeys`), a tolerance in drawing notation read over its band, measured values
(``dist = "measured"``), a position zone and its geometric tolerancing (:mod:`rvtol.spec.gdt`), a family of copies —
so many keys apply only to some factors: each one's help says which.  A key a factor gives that its form does not
read (a parameter another law takes) is refused by the reader (:func:`rvtol.spec.read.factor_from_params`).  The
same tables come from a TOML spec, a study's own ``[[factor]]`` tables and the rows of a CSV/XLSX spec
(:mod:`rvtol.inputs.table_spec`); ``rvtol kinds factor`` lists every key.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..distributions import KINDS, LawKeys
from ..inputs.measured.factor import MeasuredKeys
from ..options import REQUIRED, option
from .gdt import FEATURE_TYPES

#: a ``[[factor]]``'s ``dist``: a law, or values measured
FACTOR_KINDS = KINDS + ("measured",)


@dataclass
class SpecHead:
    """``[spec]``: the spec's name and description (``rvtol docs inputs``)."""

    name: str | None = option(None, "the spec's name (default: the file's name without its suffix)")
    description: str = option("", "what the spec describes")
    source: str | None = option(None, "where the spec comes from (a note, not read)")


@dataclass
class FactorTable(MeasuredKeys, LawKeys):
    """``[[factor]]``: one tolerance factor — its name, unit, nominal, and its distribution, given as a law and its
    parameters, as a tolerance in drawing notation read over its band, or as measured values; with a position zone's
    geometric tolerancing or a family's multiplicity (``rvtol docs inputs``)."""

    dist: str | None = option(None, "the distribution: one of the laws, or measured (values read from data); over a "
                                    "drawing tolerance default normal (rayleigh for a form tolerance)",
                              choices=FACTOR_KINDS)
    tolerance: float | str | None = option(
        None, "a number: the band width T of the law (see dist); text: the tolerance in drawing notation "
              "(±0.05, +0.10/-0.00, 25 H7, ⌀0.4 (M) A B, ⏥0.02, ISO 2768-m…), read over its band by dist",
        positive=True)
    location: float | None = option(None, "johnsonsu/johnsonsb location ξ; measured with method fit: the fitted "
                                          "families' location (default 0)")
    unit: str | None = option(None, "the unit of the nominal, the tolerance and the parameters (mm, um, in, deg…); "
                                    "may be left out when the tolerance holds it (25 H7 is in mm)")
    nominal: float | None = option(None, "the nominal value (a drawing tolerance's deviations are from it; a law "
                                         "without mean, lower, upper, median, mode or shift is placed on it)")
    description: str = option("", "what the factor is")
    part: str = option("", "the part it belongs to")
    feature: str = option("", "the part's feature it is")
    group: str | None = option(None, "the group reports gather it in (default: the part)")
    source: str = option("", "where the tolerance comes from (a drawing, a standard)")
    direction: float | str | None = option(None, "its sign or coefficient in a one-dimensional stack: +, - or a "
                                                 "number")
    multiplicity: int | None = option(None, "a family of this many identical factors (the name holds [k] once)",
                                      min=1)
    shorter_side: float | None = option(None, "an ISO 2768 general tolerance of an angle: the shorter side",
                                        unit="mm", positive=True)
    broken_edge: bool = option(False, "an ISO 2768 general tolerance of a chamfer height or an external radius")
    zone: str = option("", "a circular position zone (tolerance \"⌀t\") this factor is one coordinate of: the "
                           "zone's name, the same on its x and y factors")
    size: str = option("", "a zone at MMC/LMC: the size factor whose departure is the bonus")
    feature_type: str = option("", "the feature of size's type (internal: a hole, external: a pin or shaft)",
                               choices=("",) + FEATURE_TYPES)
    datum_size: str = option("", "a zone's datum feature of size referenced at MMB: its size factor (a datum shift)")
    datum_type: str = option("", "the datum feature of size's type", choices=("",) + FEATURE_TYPES)
    separate: bool = option(False, "SEP REQT: the zone's datum shift is its own, not its pattern's (with "
                                   "datum_size)")
    frame: str = option("", "the feature control frame (an nX pattern) whose zones this zone is one of")
    pattern: str = option("", "a composite frame: the pattern the zone belongs to (with feature_relating)")
    feature_relating: str | None = option(None, "a composite frame's second line: the feature-relating zone "
                                                "\"⌀T2 A\" (with pattern)",
                                          expected="a position zone \"⌀T2\"")
    basic: float | None = option(None, "a composite frame's feature: its true position in the pattern (for the "
                                       "framework's rotation)")
    envelope: str = option("", "a form tolerance bounded by its feature's size (Rule #1): the size factor's name "
                               "(with feature_type)")
    name: str = option(REQUIRED, "the factor's name (letters, digits, _ [ ] , . - + and spaces)")


@dataclass
class CorrelationTable:
    """``[[correlation]]``: a Gaussian-copula correlation, of a pair (``pair``, ``rho``) or of several factors
    (``factors``, ``matrix``)."""

    pair: list[str] | None = option(None, "the two factors of a pair")
    rho: float | None = option(None, "the pair's correlation", min=-1.0, max=1.0)
    factors: list[str] | None = option(None, "the factors of a matrix", min_length=2)
    matrix: list | None = option(None, "their correlation matrix: rows of numbers, symmetric, ones on the diagonal, "
                                       "positive definite")
