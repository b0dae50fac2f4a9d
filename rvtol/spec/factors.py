"""The tolerance spec's objects: a :class:`Factor` (one error source: its unit, distribution, nominal, drawing
limits and geometric tolerancing) and a :class:`ToleranceSpec` (ordered factors, their Gaussian copula)."""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np

from .. import units
from ..distributions import Distribution
from ..errors import InputError, SpecError, did_you_mean
from .gdt import check_envelopes, check_zones


@dataclass(frozen=True)
class Factor:
    """One error source: name, unit, distribution (in ``unit``), nominal value."""

    name: str
    unit: str
    dist: Distribution
    nominal: float | None = None
    description: str = ""
    group: str = ""
    source: str = ""
    part: str = ""
    feature: str = ""
    family: str = ""          # the family template ("pins[k].diameter_in_lot") of an expanded copy
    direction: float | None = None                 # sign/coefficient in a 1-D stack (a table's direction)
    limits: tuple[float, float] | None = None      # the drawing's worst-case limits, when written in notation
    measured: object = field(default=None, compare=False)   # rvtol.inputs.measured.factor.Measured: data behind dist
    zone: str = ""                                 # the circular position zone this factor is a coordinate of
    modifier: str = ""                             # a zone's material condition: "" (RFS), "MMC", "LMC"
    size: str = ""                                 # the feature-of-size factor whose departure gives the bonus
    feature_type: str = ""                         # "internal" (a hole) | "external" (a pin) feature of size
    datum_size: str = ""                           # a datum feature of size referenced at MMB: its departure
    datum_type: str = ""                           # shifts the zones that name it, together; its feature type
    separate: bool = False                         # SEP REQT: this frame's datum shift its own, not the pattern's
    frame: str = ""                                # the feature control frame (an nX pattern's zones share one)
    characteristic: str = ""                       # a profile or form tolerance's (rvtol.inputs.geometric)
    datums: tuple[str, ...] = ()                   # the datum letters of its frame
    envelope: str = ""                             # Rule #1: the size factor its form stays within (rvtol.envelopes)
    pattern: str = ""                              # a composite frame's pattern (rvtol.patterns): a feature's own
    locating: float | None = None                  # deviation in the FRTZF; the locating zone ⌀T₁ (factor unit)
    basic: float | None = None                     # a composite feature coordinate's basic value (factor unit)

    @property
    def base_unit(self) -> str:
        return units.base_unit(self.unit)

    @property
    def nominal_value(self) -> float:
        """Nominal in the factor's unit (the distribution mean unless given)."""
        return self.dist.mean if self.nominal is None else self.nominal

    @property
    def nominal_base(self) -> float:
        return float(units.to_base(self.nominal_value, self.unit))

    def ppf_base(self, u: np.ndarray) -> np.ndarray:
        """Inverse CDF, returned in base units."""
        return units.to_base(np.asarray(self.dist.ppf(u), dtype=float), self.unit)

    @property
    def band(self) -> tuple[float, float]:
        """The tolerance band ``(low, high)`` in the factor's unit: the drawing's worst-case
        :attr:`limits` when the factor was written in drawing notation, else :attr:`Distribution.band`."""
        return self.limits if self.limits is not None else self.dist.band

    @property
    def half_band(self) -> float:
        """The tolerance ±t in the factor's unit (:attr:`Distribution.half_band`, or half the drawing's limits;
        for a one-sided magnitude the whole band)."""
        if self.limits is None:
            return self.dist.half_band
        lo, hi = self.limits
        return float(hi - lo) if self.dist.one_sided else 0.5 * float(hi - lo)

    def scaled(self, f: float) -> "Factor":
        """This factor with its tolerance multiplied by ``f`` (the drawing's limits about their middle, or
        above their lower end for a one-sided magnitude, as the distribution scales)."""
        limits = self.limits
        if limits is not None:
            lo, hi = limits
            m = lo if self.dist.one_sided else 0.5 * (lo + hi)
            limits = (m + (lo - m) * f, m + (hi - m) * f)
        return replace(self, dist=self.dist.scaled(f), limits=limits)

    def describe(self) -> str:
        """The distribution with its unit, its numbers resolving the band (:meth:`shown`)."""
        return self.dist.describe(self.unit, self.shown)

    def shown(self, value) -> str:
        """A number in the factor's unit with the decimals that resolve its band (:func:`rvtol.precision.shown`)."""
        from ..precision import shown

        lo, hi = self.band
        return shown(value, hi - lo)


@dataclass(frozen=True)
class ToleranceSpec:
    """An ordered set of factors, optionally correlated through a Gaussian copula."""

    name: str
    factors: tuple[Factor, ...]
    correlation: np.ndarray | None = None  # k×k normal-score correlation, or None
    description: str = ""
    file: str | None = None
    sha256: str | None = None
    sheet: str | None = None    # the worksheet read, for a spec read from a workbook

    def __post_init__(self):
        names = [f.name for f in self.factors]
        dup = {n for n, c in Counter(names).items() if c > 1}
        if dup:
            raise SpecError(f"duplicate factor name {sorted(dup)[0]!r}", file=self.file, key="factor")
        check_zones(self.factors, self.file)
        check_envelopes(self.factors, self.file)
        if self.correlation is not None:
            c = np.asarray(self.correlation, dtype=float)
            if c.shape != (len(names), len(names)):
                raise SpecError("correlation matrix has the wrong size", file=self.file, key="correlation")

    def __len__(self) -> int:
        return len(self.factors)

    def __iter__(self):
        return iter(self.factors)

    @cached_property
    def names(self) -> tuple[str, ...]:
        return tuple(f.name for f in self.factors)

    @cached_property
    def _positions(self) -> dict[str, int]:
        return {n: i for i, n in enumerate(self.names)}

    @property
    def units(self) -> tuple[str, ...]:
        return tuple(f.unit for f in self.factors)

    def index(self, name: str) -> int:
        try:
            return self._positions[name]
        except KeyError:
            raise InputError(f"unknown factor name {name!r}{did_you_mean(name, self.names)} "
                             f"(spec has: {', '.join(self.names)})",
                             file=self.file, key="factor") from None

    def factor(self, name: str) -> Factor:
        return self.factors[self.index(name)]

    def nominal_base(self) -> np.ndarray:
        return np.array([f.nominal_base for f in self.factors], dtype=float)

    def mean_base(self) -> np.ndarray:
        return np.array([units.to_base(f.dist.mean, f.unit) for f in self.factors], dtype=float)

    def std_base(self) -> np.ndarray:
        return np.array([units.to_base(f.dist.std, f.unit) for f in self.factors], dtype=float)

    def with_factors(self, factors) -> "ToleranceSpec":
        return replace(self, factors=tuple(factors))

    def scaled(self, scale: dict[str, float]) -> "ToleranceSpec":
        """A copy with the tolerance of each named factor multiplied by its value."""
        for n in scale:
            self.index(n)
        return self.with_factors(f.scaled(scale[f.name]) if f.name in scale else f for f in self.factors)

    def families(self) -> dict[str, tuple[Factor, ...]]:
        """Family template -> its copies, in spec order (only expanded families)."""
        out: dict[str, list[Factor]] = {}
        for f in self.factors:
            if f.family:
                out.setdefault(f.family, []).append(f)
        return {k: tuple(v) for k, v in out.items()}

    def to_frame(self, families: bool = False):
        """One row per factor; ``families=True``: one row per family (its template name, "×N")."""
        import pandas as pd

        fs, count = list(self.factors), [1] * len(self.factors)
        if families:
            fam = self.families()
            fs = [replace(f, name=f.family) if f.family else f for f in fs
                  if not f.family or f is fam[f.family][0]]
            count = [len(fam[f.name]) if f.family else 1 for f in fs]
        frame = pd.DataFrame({
            "factor": [f.name for f in fs],
            "unit": [f.unit for f in fs],
            "distribution": [f.dist.describe(number=f.shown) for f in fs],
            "nominal": [f.nominal_value for f in fs],
            "mean": [f.dist.mean for f in fs],
            "std": [f.dist.std for f in fs],
            "tolerance T": [f.dist.tolerance for f in fs],
            "part": [f.part for f in fs],
            "feature": [f.feature for f in fs],
            "group": [f.group for f in fs],
        })
        if families:
            frame.insert(1, "multiplicity", [f"×{c}" if c > 1 else "" for c in count])
        return frame
