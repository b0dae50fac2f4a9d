"""Tolerance specification: factors, their distributions, correlation, requirements.

File format (``data/specs/*.toml``)::

    [spec]
    name = "rv80e_lost_motion"
    description = "..."

    [[factor]]
    name = "dr_p"              # any name; the model decides which names it knows
    unit = "um"                # the unit every number of this factor is written in
    dist = "normal"            # see rvtol.distributions
    mean = 3.0
    tolerance = 1.0            # band ±T/2 read at sigma_level (3 by default)
    nominal = 3.0              # optional: nominal value for local sensitivity (default: the mean)
    part = "pin housing"       # optional: the drawing (part) the feature belongs to
    feature = "pin-groove circle ⌀153 js3"   # optional: the drawing feature and its callout
    group = "pin gear"         # optional: for group-wise sensitivity and allocation (default: the part)
    source = "..."             # optional: where the number comes from

    [[factor]]                 # drawing notation (rvtol.inputs.notation) instead of numbers:
    name = "bore"
    nominal = 25               # optional when the text has it ("25 H7")
    tolerance = "H7"           # "+0.10/-0.00", "±0.05", "5%", "24.95..25.05", "max 0.02", "H7/g6",
                               # "±0.05 Cpk 1.33 k 0.25", "1.000\" ±0.002\"", ...
    dist = "normal"            # optional (normal): the kind read over the drawing's band; any
                               # distribution key (sigma, shift, shape, ...) refines it
    unit = "mm"                # optional when the text has one ("25 H7" is in mm)
    direction = -1             # optional: the factor's sign/coefficient in a 1-D stack

    [[factor]]                 # ISO 2768 general tolerances (rvtol.inputs.iso2768)
    name = "flange_angle"
    unit = "deg"
    nominal = 30
    tolerance = "ISO 2768-m"   # an angle: ISO 2768-1 Table 3, by the length of its shorter side
    shorter_side = 35          # mm (required for an angle); broken_edge = true: a chamfer height or
                               # an external radius, Table 2 (a length)

    [[factor]]                 # a circular position zone: two coordinates of one zone
    name = "hole.x"            # (and a second factor "hole.y" with the same zone and tolerance)
    unit = "mm"
    tolerance = "⌀0.05"        # the zone's diameter: each coordinate normal, the radius Rayleigh
    zone = "hole"              # with 99.73 % inside the zone (rvtol.inputs.notation)

    [[factor]]                 # measured values (rvtol.inputs.measured)
    name = "bore_measured"
    unit = "mm"
    dist = "measured"
    data = "cmm/bores.csv"     # relative to this file; column = "bore", sheet = "CMM"
    method = "fit"             # fit (AIC-ranked families) | empirical | kde; measurement_sigma = 0.001
    tolerance = "25 H7"        # optional: the drawing's worst-case limits

A factor written in drawing notation keeps the drawing's worst-case limits (``Factor.limits``):
its tolerance band (:attr:`Factor.band`: worst case, five-point steps, allocation) is the
drawing's even when a process spec shifts the mean (``Cpk 1.33 k 0.25``).

A spec may also be a table (``.csv``/``.tsv``/``.xlsx``, :mod:`rvtol.inputs.table_spec`): one row
per factor, the same keys as columns; :func:`load_spec` reads either.

    [[factor]]                 # a FAMILY: N exchangeable features (40 pins, 40 pin grooves, ...)
    name = "pins[k].diameter_in_lot"   # the name holds "[k]" once
    multiplicity = 40          # -> N independent, identically distributed factors
    ...                        #    "pins[1].diameter_in_lot" ... "pins[40].diameter_in_lot"

A family table stands for ``multiplicity`` factors with the same distribution, drawn independently
(each copy is its own column of the sample; the copies are uncorrelated unless a
``[[correlation]]`` names them one by one).  ``[k]`` is replaced by ``[1]`` … ``[N]``; each copy
remembers its family (``Factor.family``) so a report can show the family as one row "×N"
(``ToleranceSpec.to_frame(families=True)``).  A name with ``[k]`` needs ``multiplicity`` and
``multiplicity`` needs a name with ``[k]``.

    [[correlation]]            # optional Gaussian copula, a pair or a block
    factors = ["a", "b"]
    matrix = [[1.0, 0.6], [0.6, 1.0]]

Requirements (in a study or ``data/requirements/*.toml``)::

    [[requirement]]
    output = "lost_motion"
    upper = 1.0
    unit = "arcmin"            # default: the output's display unit
    min_yield = 0.9973         # and/or min_cpk = 1.33; neither: yield >= 0.9973 (DEFAULT_MIN_YIELD); in (0, 1):
                               # 1 itself cannot be demonstrated by a finite sample and is refused
    confidence = 0.95          # of the bound the verdict uses
    basis = "lower_bound"      # pass on the lower confidence bound (default) or the "estimate"
    bound = "one-sided"        # the bound: one-sided at `confidence` (default), or "two-sided": the
                               # lower end of the two-sided interval (a (1 + confidence)/2 one-sided bound)
    interval = "clopper-pearson"   # yield interval: "clopper-pearson" (exact) or "wilson"
    cpk_method = "normal"      # the Cpk min_cpk judges: "normal" (normal theory, Bissell's bound) or
                               # "percentile" (ISO 22514-2 from the 0.135/50/99.865 % points, bootstrap bound)
    reading = "..."            # optional: how the figure is read (the maker's definition the output follows)
    source = "..."             # optional: where the limit comes from
    status = "assumed"         # optional: "confirmed" (read in the source), "recalled" (remembered, not
                               # read), "assumed" (an engineering assumption, its reasoning in `source`)

A requirement on a **population statistic** — a catalogue's typical (central) value, not a limit every
unit must meet — names it (``statistic = "median"`` or ``"mean"``) and the band it must lie in
(``lower``/``upper``); it takes no ``min_yield``/``min_cpk``.  It is judged on the statistic's confidence
interval (each end a one-sided bound at ``confidence``, or the two-sided interval with ``bound =
"two-sided"``): PASS when the interval lies inside the band, FAIL when it lies outside, UNDECIDED between
(:func:`rvtol.verdict.judge_statistic`)::

    [[requirement]]
    output = "torsion.torsional_rigidity"
    statistic = "median"
    lower = 156.8
    upper = 235.2
    unit = "N*m/arcmin"
"""
from __future__ import annotations

from collections import Counter

import re
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path

import numpy as np

from . import units
from .distributions import KINDS, ONE_SIDED, Distribution, from_params
from .errors import InputError, SpecError, did_you_mean
from .inputs.measured import measured_factor
from .inputs.notation import NotationError, Tolerance, parse_tolerance
from .inputs.sheets import READ_SUFFIXES as TABLE_SUFFIXES
from .params import Params, read_toml
from .inputs.geometric import is_geometric, parse_geometric
from .patterns import drawn_zone
from .patterns import expand as expand_patterns

#: yield interval methods a requirement can name -> scipy's binomtest method
YIELD_INTERVALS = {"clopper-pearson": "exact", "wilson": "wilson"}

#: the Cpk a requirement's min_cpk judges (policy: :func:`rvtol.verdict.cpk_figures`)
CPK_METHODS = ("normal", "percentile")
#: the confidence bounds a requirement can be judged on (policy: :func:`rvtol.verdict.bound_level`)
BOUNDS = ("one-sided", "two-sided")
#: what a requirement's minimum is judged on: its lower confidence bound or its point estimate (rvtol.verdict.judge)
BASES = ("lower_bound", "estimate")
#: the population statistics a requirement can judge (policy: :func:`rvtol.verdict.judge_statistic`)
STATISTICS = ("median", "mean")
#: how firmly a requirement's limit is known: read in its source, remembered but not read, an engineering assumption
STATUSES = ("confirmed", "recalled", "assumed")

_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_\[\],.\-+ ]*$")


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
        from .precision import shown

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


@dataclass(frozen=True)
class Requirement:
    """A limit on one output and the yield and/or Cpk it must reach — or, with ``statistic``, the band a
    population statistic of the output (its median or mean) must lie in (module docstring)."""

    output: str
    lower: float | None = None
    upper: float | None = None
    unit: str | None = None  # unit the limits are written in (None: the output's unit)
    min_yield: float | None = None
    min_cpk: float | None = None
    confidence: float = 0.95
    basis: str = "lower_bound"
    name: str = ""
    interval: str = "clopper-pearson"
    file: str | None = field(default=None, compare=False)
    key: str | None = field(default=None, compare=False)
    cpk_method: str = "normal"
    bound: str = "one-sided"
    #: True when min_yield is DEFAULT_MIN_YIELD because the requirement named neither yield nor Cpk
    yield_defaulted: bool = field(default=False, compare=False)
    #: a population statistic judged within [lower, upper] (:data:`STATISTICS`), None: a per-unit limit
    statistic: str | None = None
    reading: str = field(default="", compare=False)
    source: str = field(default="", compare=False)
    status: str = field(default="", compare=False)

    #: minimum yield assumed when a requirement names neither yield nor Cpk (±3σ coverage)
    DEFAULT_MIN_YIELD = 0.9973

    def __post_init__(self):
        key = lambda k: f"{self.key}.{k}" if self.key else k  # noqa: E731
        if self.statistic is not None:
            if self.statistic not in STATISTICS:
                raise SpecError(f"unknown statistic {self.statistic!r} (expected one of: {', '.join(STATISTICS)})",
                                file=self.file, key=key("statistic"))
            if self.min_yield is not None or self.min_cpk is not None:
                raise SpecError(f"a requirement on the {self.statistic} judges its confidence interval against the "
                                "band, not a yield or a Cpk: drop min_yield / min_cpk (or the statistic)",
                                file=self.file, key=key("min_yield" if self.min_yield is not None else "min_cpk"))
        elif self.min_yield is None and self.min_cpk is None:
            object.__setattr__(self, "min_yield", self.DEFAULT_MIN_YIELD)
            object.__setattr__(self, "yield_defaulted", True)
        if self.status and self.status not in STATUSES:
            raise SpecError(f"unknown status {self.status!r} (expected one of: {', '.join(STATUSES)})",
                            file=self.file, key=key("status"))
        if self.basis not in BASES:
            raise SpecError(f"unknown basis {self.basis!r} (expected one of: {', '.join(BASES)})", file=self.file,
                            key=key("basis"))
        if self.bound not in BOUNDS:
            raise SpecError(f"unknown bound {self.bound!r} (expected one of: {', '.join(BOUNDS)})", file=self.file,
                            key=f"{self.key}.bound" if self.key else "bound")
        if self.lower is None and self.upper is None:
            raise SpecError("a requirement needs a lower and/or an upper limit", file=self.file, key=self.key)
        if self.lower is not None and self.upper is not None and not self.lower < self.upper:
            # the study loader says it at the file's key; a requirement made in code is held to the same rule
            raise SpecError(f"limits in the wrong order: lower {self.lower} >= upper {self.upper}", file=self.file,
                            key=key("upper"))
        if self.cpk_method not in CPK_METHODS:
            raise SpecError(f"unknown cpk_method {self.cpk_method!r} (expected one of: {', '.join(CPK_METHODS)})",
                            file=self.file, key=f"{self.key}.cpk_method" if self.key else "cpk_method")
        if self.interval not in YIELD_INTERVALS:
            raise SpecError(f"unknown interval {self.interval!r} (expected one of: {', '.join(YIELD_INTERVALS)})",
                            file=self.file, key=f"{self.key}.interval" if self.key else "interval")

    @property
    def label(self) -> str:
        """The requirement as written: its ``name``, or e.g. ``lost_motion ≤ 1 arcmin``."""
        if self.name:
            return self.name
        from .units import label as unit_label

        u = f" {unit_label(self.unit)}" if self.unit else ""
        what = f"{self.statistic} of {self.output}" if self.statistic else self.output
        if self.lower is not None and self.upper is not None:
            return f"{what} in [{self.lower:g}, {self.upper:g}]{u}"
        if self.upper is not None:
            return f"{what} ≤ {self.upper:g}{u}"
        return f"{what} ≥ {self.lower:g}{u}"

    @property
    def per_unit(self) -> bool:
        """True for a limit every unit must meet (a yield and/or Cpk), False for a population statistic's band."""
        return self.statistic is None

    def in_unit(self, unit: str) -> "Requirement":
        """The same requirement with its limits converted to ``unit`` (the label keeps the written units)."""
        if self.unit is None or self.unit == unit:
            return replace(self, unit=unit)
        if not self.name:
            self = replace(self, name=self.label)
        try:
            conv = lambda v: None if v is None else float(units.convert(v, self.unit, unit))  # noqa: E731
            return replace(self, lower=conv(self.lower), upper=conv(self.upper), unit=unit)
        except InputError as exc:
            raise SpecError(f"limit unit does not fit the output ({exc.reason})", file=self.file,
                            key=f"{self.key}.unit" if self.key else "unit") from None


# --------------------------------------------------------------------------- loaders
def load_spec(path: str | Path, *, sheet: str | None = None) -> ToleranceSpec:
    """A spec file: TOML, or a table (``.csv``/``.tsv``/``.xlsx``, see :func:`load_table_spec`; ``sheet``: the
    worksheet of a workbook, by default the one :func:`rvtol.inputs.sheets.read_rows` can tell without guessing)."""
    if Path(path).suffix.lower() == ".txt":     # a TOML spec saved as text, or a table: say which to name it
        raise SpecError("a spec is a TOML file (.toml) or a table (.csv, .tsv or .xlsx), not .txt: rename it after "
                        "what it holds (a tab-separated table: .tsv)", file=str(path), key="-")
    if Path(path).suffix.lower() in TABLE_SUFFIXES + (".ods", ".xls"):   # the last two: "save as .xlsx"
        return load_table_spec(path, sheet=sheet)
    if sheet is not None:
        raise SpecError(f"a sheet ({sheet!r}) is named, but a {Path(path).suffix or 'TOML'} spec has no sheets",
                        file=str(path), key="sheet")
    data, sha = read_toml(path)
    spec = spec_from_table(data, file=str(path))
    return replace(spec, sha256=sha)


def load_table_spec(path: str | Path, *, sheet: str | None = None) -> ToleranceSpec:
    """A spec table (:mod:`rvtol.inputs.table_spec`): its rows read as ``[[factor]]`` tables, every error
    at its sheet, row and column."""
    from .inputs.table_spec import read_spec_table

    table = read_spec_table(path, sheet=sheet)
    try:
        spec = spec_from_table(table.document, file=str(path))
    except InputError as exc:
        raise table.locate(exc) from None
    return replace(spec, sha256=table.sha256, sheet=table.location.sheet)


def spec_from_table(data: dict, *, file: str | None = None, name: str | None = None) -> ToleranceSpec:
    """Build a spec from a parsed TOML document (``[spec]``, ``[[factor]]``, ``[[correlation]]``)."""
    root = Params(data, file=file)
    head = root.sub("spec", {})
    spec_name = head.str("name", name or (Path(file).stem if file else "spec"))
    desc = head.str("description", "")
    head.finish(allow=("source",))
    head.raw("source", None)
    tables = root.tables("factor")
    if not tables:
        raise root.error("factor", "a spec needs at least one [[factor]]")
    factors = [f for t in tables for f in factors_from_params(t)]
    names = [f.name for f in factors]
    origin = [t for t in tables for _ in range(_multiplicity(t))]
    seen: set[str] = set()
    for i, n in enumerate(names):
        if n in seen:
            raise origin[i].error("name", f"duplicate factor name {n!r}")
        seen.add(n)
    factors = expand_patterns(factors, file)        # a composite frame's pattern translations (rvtol.patterns)
    names = [f.name for f in factors]
    corr = correlation_from_tables(root.tables("correlation"), names)
    root.raw("rig", None)       # a test rig's description: its parameters beside its tolerances (transmission_error.rig)
    root.finish()
    return ToleranceSpec(spec_name, tuple(factors), corr, desc, file)


def merge_specs(specs) -> ToleranceSpec:
    """Several specs as one (a study's ``spec = [a, b]``: e.g. the product's drawing tolerances and a test rig's):
    the factors one after the other, each spec's correlation a block of the whole (none between the files);
    a factor name in two files is refused."""
    specs = list(specs)
    if len(specs) == 1:
        return specs[0]
    seen: dict[str, str] = {}
    for s in specs:
        for n in s.names:
            if n in seen:
                raise SpecError(f"factor {n!r} is in {seen[n]} and in {s.file}: a name can be in one spec only",
                                file=s.file, key="factor")
            seen[n] = str(s.file)
    k = sum(len(s) for s in specs)
    corr = None
    if any(s.correlation is not None for s in specs):
        corr = np.eye(k)
        i = 0
        for s in specs:
            if s.correlation is not None:
                corr[i:i + len(s), i:i + len(s)] = s.correlation
            i += len(s)
    return ToleranceSpec(" + ".join(s.name for s in specs), tuple(f for s in specs for f in s.factors), corr,
                         " ".join(s.description for s in specs if s.description), specs[0].file,
                         ";".join(str(s.sha256) for s in specs))


#: the placeholder of a family factor's index
FAMILY_INDEX = "[k]"


def _multiplicity(p: Params) -> int:
    """How many factors a ``[[factor]]`` table stands for (1, or a family's ``multiplicity``)."""
    if "multiplicity" not in p:
        return 1
    return p.int("multiplicity", min=1)


def factors_from_params(p: Params) -> list[Factor]:
    """The factor of one ``[[factor]]`` table, or the N copies of a family (module docstring)."""
    f = factor_from_params(p)
    n = _multiplicity(p)
    p.finish()
    marks = f.name.count(FAMILY_INDEX)
    if "multiplicity" not in p.data:
        if marks:
            raise p.error("multiplicity", f"factor name {f.name!r} holds {FAMILY_INDEX}: a family needs "
                                          "'multiplicity = N' (the number of copies)")
        return [f]
    if marks != 1:
        raise p.error("name", f"a family (multiplicity = {n}) needs {FAMILY_INDEX} exactly once in its name, "
                              f"got {f.name!r}")
    return [replace(f, name=f.name.replace(FAMILY_INDEX, f"[{k}]"), family=f.name) for k in range(1, n + 1)]


def factor_from_params(p: Params) -> Factor:
    """One factor from a ``[[factor]]`` table (a family's template; ``multiplicity`` is read by
    :func:`factors_from_params`)."""
    name = p.str("name")
    if not name or not _NAME.match(name):
        raise p.error("name", f"invalid factor name {name!r} (letters, digits, _ [ ] , . - + and spaces)")
    unit = p.unit("unit", None)
    drawing = drawing_tolerance(p, unit)
    if unit is None:
        if drawing is None or drawing.unit is None:
            raise p.error("unit", "missing unit (the unit of the nominal and the tolerance, e.g. mm, um, in)")
        unit = drawing.unit
    measured = None
    if p.data.get("dist") == "measured":
        dist, measured = measured_distribution(p)
    elif drawing is not None:
        dist = band_distribution(p, drawing)
    else:
        dist = from_params(_located_on_nominal(p))
    nominal = p.float("nominal", None) if drawing is None else drawing.nominal
    desc = p.str("description", "")
    part = p.str("part", "")
    feature = p.str("feature", "")
    group = p.str("group", part)
    source = p.str("source", "")
    direction = stack_direction(p)
    zone = position_zone(p, drawing)
    gdt = material_condition(p, drawing, zone)
    frame = {"characteristic": getattr(drawing, "characteristic", ""), "datums": getattr(drawing, "datums", ()),
             "envelope": envelope_of(p, drawing)}
    composite, relating = composite_position(p, drawing, zone, unit, measured)
    frame.update(composite)
    gdt["frame"] = gdt["frame"] or composite["pattern"]     # a composite frame's features share its frame
    p.finish(allow=("multiplicity",))
    _nominal_stated(p, drawing)
    limits = drawing.limits if drawing is not None else None
    if relating is not None:      # the feature's own deviation is read in the feature-relating zone
        dist, limits = band_distribution(p, relating), relating.limits
    return Factor(name, unit, dist, nominal, desc, group, source, part=part, feature=feature, direction=direction,
                  limits=limits, measured=measured, zone=zone, **gdt, **frame)


#: keys that place a factor's distribution; without any, a non-zero ``nominal`` places it
_LOCATION_KEYS = ("mean", "lower", "upper", "median", "mode", "shift")


def _located_on_nominal(p: Params) -> Params:
    """The factor's table with ``mean = nominal`` when it gives a non-zero nominal and nothing that places the
    distribution: ``nominal = 10.0, dist = "normal", tolerance = 0.06`` is 10 ± 0.03, never 0 ± 0.03 (a distribution
    left at its default mean 0 beside a nominal of 10 is a silent wrong answer).  A one-sided (magnitude) kind has
    no mean to place: it must say where its values start (``shift``)."""
    nominal = p.data.get("nominal")
    if not isinstance(nominal, (int, float)) or isinstance(nominal, bool) or nominal == 0 \
            or any(k in p.data for k in _LOCATION_KEYS):
        return p
    kind = p.data.get("dist")
    if kind in ONE_SIDED:
        raise p.error("nominal", f"a {kind} factor is a magnitude (its values start at 0): with nominal = {nominal} "
                                 "say where they start ('shift'), or give the nominal as 0")
    placed = Params({**p.data, "mean": nominal}, file=p.file, key=p.key)
    placed._probed = p._probed          # one table: what either reads counts as read (p.finish sees it)
    placed._read = p._read
    return placed


# ---- the engineers' input forms of a [[factor]] table (rvtol.inputs) --------------------------
#: distribution keys a factor written in drawing notation may add to refine its band's reading
_REFINING = ("mean", "sigma", "lower", "upper", "mode", "median", "shape", "scale", "shift")


def drawing_tolerance(p: Params, unit: str | None) -> Tolerance | None:
    """The factor's tolerance in drawing notation (``tolerance = "+0.10/-0.00"``, ``"25 H7"``…), or None
    for a number (a band width, read by :func:`rvtol.distributions.from_params`).  An ISO 2768 general tolerance of
    an angle needs ``shorter_side`` (mm, or ``{value, unit}``), one of a chamfer height or an external radius
    ``broken_edge = true`` (:func:`rvtol.inputs.notation.parse_tolerance`)."""
    text = p.data.get("tolerance") if "tolerance" in p else None   # probed: a misspelt 'tolerence' is named
    side = p.quantity("shorter_side", "mm", None, positive=True)
    edge = p.bool("broken_edge", False)
    if not isinstance(text, str):
        if side is not None or edge:
            key = "shorter_side" if side is not None else "broken_edge"
            raise p.error(key, f"{key} belongs to an ISO 2768 general tolerance: give tolerance = \"ISO 2768-m\" (the "
                               "class of the drawing's title block)")
        return None
    p.raw("tolerance")
    nominal = p.float("nominal", None)
    try:
        if is_geometric(text):
            if nominal not in (None, 0):
                raise p.error("nominal", f"a profile or form tolerance ({text!r}) is a deviation from the true "
                                         "profile or a magnitude: give no nominal (or 0)")
            if side is not None or edge:
                raise p.error("shorter_side" if side is not None else "broken_edge",
                              "belongs to an ISO 2768 general tolerance, not to a profile or form tolerance")
            return parse_geometric(text, unit=unit)
        if text.lstrip()[:1] in "⌀Øø∅":   # a position frame's datum letters (⌀0.5 A B C): what locates the zone
            text, _ = frame_datums(p, "tolerance", text)     # (a datum feature of size at MMB: datum_size)
        tol = parse_tolerance(text, nominal=nominal, unit=unit, shorter_side=side, broken_edge=edge)
    except NotationError as exc:
        raise p.error(exc.key or "tolerance", exc.reason) from None
    return tol


def _nominal_stated(p: Params, drawing: Tolerance | None) -> None:
    """Deviations from a nominal the table does not give (``±0.1``, ``+0/-0.12`` without ``nominal``): read about 0
    they would invent one — refused, as a spreadsheet's missing nominal cell is (:mod:`rvtol.inputs.table_spec`)."""
    if drawing is None or "nominal" in p.data or drawing.nominal is not None \
            or drawing.form not in ("symmetric", "deviations") or any(k in p.data for k in ("mean", "median", "mode")):
        return
    raise p.error("nominal", f"missing nominal: the tolerance {p.data['tolerance']!r} is a deviation from it (write "
                             "nominal = 0 for a factor that is itself a deviation from its nominal, e.g. a position "
                             "or form error)")


def band_distribution(p: Params, tol: Tolerance) -> Distribution:
    """The distribution kind ``dist`` (default normal) read over a drawing tolerance's band
    (:meth:`rvtol.inputs.notation.Tolerance.factor_table`); distribution keys given beside it refine or
    override what the band gives (an explicit ``sigma`` replaces the band's σ)."""
    kind = p.str("dist", "rayleigh" if getattr(tol, "is_form", False) else "normal", choices=KINDS)
    level = p.float("sigma_level", None, positive=True)
    try:
        table = tol.factor_table(kind, sigma_level=level)
    except NotationError as exc:
        raise p.error("sigma_level" if "sigma_level" in exc.reason else "dist", exc.reason) from None
    table.pop("nominal", None)
    given = {k: p.raw(k) for k in _REFINING if k in p}
    if kind == "normal" and "sigma" in given:
        table.pop("tolerance", None)
    table.update(given)
    try:
        dist = from_params(Params(table, file=p.file, key=p.key))
    except InputError as exc:
        if (exc.key or "").rsplit(".", 1)[-1] not in given:   # a number the tolerance gave
            exc.key = p.path("tolerance")
        raise
    lo, hi = tol.limits
    slack = 1e-9 * max(abs(lo), abs(hi), hi - lo)
    if given and not lo - slack <= dist.mean <= hi + slack:
        key = next(iter(given))
        raise p.error(key, f"{key} = {given[key]!r} puts the {kind} distribution's mean at {dist.mean:.6g}, outside the "
                           f"drawing's limits {lo:.6g}..{hi:.6g} ({tol.text!r}): the parts it describes would not meet "
                           "the drawing — check the value (shift and mean are in the factor's unit)")
    return dist


def measured_distribution(p: Params):
    """``dist = "measured"``: the distribution of measured values
    (:func:`rvtol.inputs.measured.factor.measured_factor`; files relative to the spec file) and the record of the data
    behind it."""
    p.str("dist")
    return measured_factor(p, Path(p.file).parent if p.file else Path("."))


def position_zone(p: Params, tol: Tolerance | None) -> str:
    """``zone``: the circular position zone (``tolerance = "⌀t"``) this factor is one coordinate of."""
    zone = p.str("zone", "")
    is_zone = tol is not None and tol.form == "zone"
    if is_zone and not zone:
        raise p.error("tolerance", f"a position zone {tol.text!r} has two coordinates: give zone = NAME on both "
                                   "factors (x and y)")
    if zone and not is_zone:
        raise p.error("zone", "a zone coordinate needs tolerance = \"⌀t\" (the zone's diameter)")
    return zone


FEATURE_TYPES = ("internal", "external")


def material_condition(p: Params, tol: Tolerance | None, zone: str) -> dict:
    """A position zone's material condition (``⌀0.4 (M)``: MMC, ``(L)``: LMC) and the features of size it
    depends on: ``size`` (the toleranced feature's size factor; its departure from MMC/LMC is the bonus) with
    ``feature_type`` (internal: a hole, external: a pin), and ``datum_size``/``datum_type`` (a datum feature of
    size referenced at MMB: its departure from MMB shifts every zone that references it together, one pattern,
    :func:`datum_shifts`)."""
    modifier = tol.modifier if tol is not None and tol.form == "zone" else ""
    size = p.str("size", "")
    ftype = p.str("feature_type", "", choices=("",) + FEATURE_TYPES)
    dsize = p.str("datum_size", "")
    dtype = p.str("datum_type", "", choices=("",) + FEATURE_TYPES)
    separate = p.bool("separate", False)
    frame = p.str("frame", "")
    if frame and not zone:
        raise p.error("frame", "a feature control frame's name groups position zones (an nX pattern): give zone = NAME")
    if separate and not dsize:
        raise p.error("separate", "SEP REQT separates a zone's datum-feature shift from its pattern's: it needs "
                                  "datum_size (a datum feature of size referenced at MMB); without one there is no shift")
    if (size or (ftype and "envelope" not in p.data) or dsize) and not zone:
        raise p.error("size" if size else "feature_type" if ftype else "datum_size",
                      "a material condition belongs to a position zone (tolerance = \"⌀t (M)\", zone = NAME)")
    if modifier and not size:
        raise p.error("size", f"a zone at {modifier} gets its bonus from the feature's actual size: give size = "
                              "the size factor's name and feature_type = \"internal\" (a hole) or \"external\" (a pin)")
    if size and not modifier:
        raise p.error("size", "size names the feature whose departure from MMC/LMC is the bonus: the zone needs a "
                              "modifier (\"⌀t (M)\" or \"⌀t (L)\"); at RFS there is no bonus")
    if size and not ftype:
        raise p.error("feature_type", "the bonus needs the feature type: \"internal\" (a hole: MMC = smallest) or "
                                      "\"external\" (a pin: MMC = largest)")
    if bool(dsize) != bool(dtype):
        raise p.error("datum_type" if dsize else "datum_size",
                      "a datum-feature shift needs both datum_size (the datum feature's size factor) and datum_type")
    return {"modifier": modifier, "size": size, "feature_type": ftype, "datum_size": dsize, "datum_type": dtype,
            "separate": separate, "frame": frame}


def envelope_of(p: Params, tol: Tolerance | None) -> str:
    """``envelope``: the size factor whose departure from MMC a form tolerance stays within (Rule #1, the envelope
    requirement: :mod:`rvtol.envelopes`); with ``feature_type`` (internal: a hole, external: a shaft)."""
    size = p.str("envelope", "")
    if not size:
        return ""
    if not getattr(tol, "is_form", False):
        raise p.error("envelope", "the envelope (Rule #1) bounds a form tolerance by its feature's size: give "
                                  "tolerance = \"⏥t\" (flatness), \"⏤t\", \"○t\" or \"⌭t\"")
    if "feature_type" not in p.data:
        raise p.error("feature_type", "the envelope needs the feature type: \"internal\" (a hole: MMC = smallest) or "
                                      "\"external\" (a shaft: MMC = largest)")
    return size


def composite_position(p: Params, drawing: Tolerance | None, zone: str, unit: str | None,
                       measured) -> tuple[dict, Tolerance | None]:
    """A composite frame's keys of a zone coordinate (:func:`composite_frame`; ``basic``, its true position for the
    framework's rotation) as :class:`Factor` fields, and the feature-relating zone its own deviation is read in (None
    for a plain factor)."""
    pattern, relating, datums = composite_frame(p, drawing, zone, unit)
    basic = p.float("basic", None)
    if basic is not None and not pattern:
        raise p.error("basic", "basic places a composite frame's feature in its pattern (for the framework's rotation): "
                               "give pattern and feature_relating")
    keys = {"pattern": pattern, "basic": basic}
    if relating is not None:
        if measured is not None:
            raise p.error("feature_relating", "a measured position is the feature's location from the datums, not "
                                              "its deviation within the pattern: fit it as a plain zone")
        keys.update(locating=drawing.width, datums=datums)    # the lower line's datums: may the framework rotate
    return keys, relating


def composite_frame(p: Params, tol: Tolerance | None, zone: str,
                    unit: str | None) -> tuple[str, Tolerance | None, tuple[str, ...]]:
    """A composite position frame's second line (:mod:`rvtol.patterns`): ``pattern = NAME`` (the features one
    frame locates) and ``feature_relating = "⌀T₂ A B"`` (the FRTZF, smaller than the zone's ⌀T₁, the PLTZF, and the
    datums it references: orientation only).  Returns the pattern's name, the FRTZF read in the factor's unit (None
    without one) and its datum letters."""
    pattern = p.str("pattern", "")
    text = p.raw("feature_relating", None)
    if not pattern and text is None:
        return "", None, ()
    key = "pattern" if pattern else "feature_relating"
    if not zone:
        raise p.error(key, "a composite frame locates position zones: give tolerance = \"⌀T1\" (the pattern-locating "
                           "zone), zone = NAME, pattern = NAME and feature_relating = \"⌀T2\"")
    if not pattern or text is None:
        raise p.error("feature_relating" if pattern else "pattern",
                      "a composite frame needs both pattern (the pattern's name) and feature_relating (\"⌀T2\", "
                      "the frame's second line)")
    if not _NAME.match(pattern):
        raise p.error("pattern", f"invalid pattern name {pattern!r} (letters, digits, _ [ ] , . - + and spaces)")
    if not isinstance(text, str):
        raise p.error("feature_relating", f"expected a position zone \"⌀T2\", got {text!r}")
    zone_text, datums = frame_datums(p, "feature_relating", text)
    try:
        relating = parse_tolerance(zone_text, unit=unit)
    except NotationError as exc:
        raise p.error("feature_relating", exc.reason) from None
    if relating.form != "zone":
        raise p.error("feature_relating", f"{text!r} is not a position zone: write the frame's second line as \"⌀T2\"")
    relating = relating.in_unit(unit or relating.unit)
    if relating.modifier != tol.modifier:
        raise p.error("feature_relating", f"the frame's two lines have different material conditions "
                                          f"({tol.describe()} and {relating.describe()}): give both the same")
    if not relating.width < tol.width:
        raise p.error("feature_relating", f"the feature-relating zone {relating.describe()} must be smaller than the "
                                          f"pattern-locating zone {tol.describe()} (equal zones are one position "
                                          "tolerance: leave out pattern and feature_relating)")
    return pattern, relating, datums


#: a frame line's datum letters after its tolerance: "⌀0.1 A B", "⌀0.1 (M) | A"
_FRAME_DATUMS = re.compile(r"((?:[\s|]+[A-Z](?![A-Za-z]))+)\s*$")
#: a datum letter with a modifier of its own: "A (M)", "B(L)"
_DATUM_MODIFIER = re.compile(r"[\s|][A-Z]\s*(?:\(\s*[MLS]\s*\)|[ⓂⓁⓈ])")


def frame_datums(p: Params, key: str, text: str) -> tuple[str, tuple[str, ...]]:
    """A position frame line's tolerance and its datum letters (``"⌀0.5 (M) A B C"`` → ``"⌀0.5 (M)"``, A B C).  A
    datum letter may not repeat, a datum's own modifier is not read (a datum feature of size at MMB is
    ``datum_size``), and a lone M, L or S is refused: a material condition written without its brackets would read as a
    datum letter."""
    if _DATUM_MODIFIER.search(text):
        raise p.error(key, f"{text!r}: a datum's material condition is not read from the frame — a datum feature of "
                           "size referenced at MMB is datum_size (and datum_type) beside the zone")
    m = _FRAME_DATUMS.search(text)
    datums = tuple(m.group(1).replace("|", " ").split()) if m else ()
    if len(set(datums)) < len(datums):
        raise p.error(key, f"{text!r} names a datum twice")
    odd = [d for d in datums if d in "MLS"]
    if odd:
        raise p.error(key, f"{text!r}: {odd[0]!r} after the zone reads as a datum letter or as a material condition — "
                           "write the condition as (M), (L) or Ⓜ, Ⓛ")
    return (text[:m.start()] if m else text), datums


def zone_bonus(spec: "ToleranceSpec", zone: str) -> list[tuple[int, float, float]]:
    """How the radius of ``zone`` grows with its feature's size: ``[(factor index, κ, reference)]`` in base units (at
    most one), the radius being r = t/2 + κ (x − reference) ≥ t/2 over the band (ASME Y14.5-2018 §7.3.3 bonus;
    ISO 2692): the toleranced feature at MMC, bonus = the departure of its actual size from MMC (internal: MMC =
    the smallest size, κ = +½ per unit of diameter; external: MMC = the largest, κ = −½); at LMC from LMC
    (internal: the largest, κ = −½; external: the smallest, κ = +½).  Radii are half the diametral bonus.

    A datum-feature shift is not a bonus of one zone: it moves the whole pattern (:func:`datum_shifts`)."""
    fs = [f for f in spec.factors if f.zone == zone]
    if not fs or not fs[0].size or not fs[0].modifier:
        return []
    f = fs[0]
    return [_departure(spec, f.size, f.feature_type, f.modifier)]


@dataclass(frozen=True)
class DatumShift:
    """A datum feature of size referenced at MMB and the position zones it locates: one pattern, shifted together.

    The datum feature may depart from its MMB (taken as its MMC size: a datum feature without a geometric tolerance
    of its own) by d = |x − reference|; the part may then translate on the datum feature simulator by up to d/2 in
    any direction, r = κ (x − reference) ≥ 0 with κ = +½ (an internal datum feature, a bore: reference its smallest
    size) or −½ (external, a boss: its largest).  Every zone that references it moves by the *same* vector s,
    |s| ≤ r — the features of a pattern located from common datum features at MMB are one pattern (the simultaneous
    requirement, ASME Y14.5 — the default unless SEP REQT is written beneath the frames; P. J. Drake Jr. (ed.),
    *Dimensioning and Tolerancing Handbook*, McGraw-Hill 1999, ch. 5; Tec-Ease GD&T tip 223: "the pattern could
    shift as much as 0.6 total").  The shift therefore moves the pattern as a whole: the distance between two of its
    features does not change with it.  Each zone's own tolerance (and bonus) still varies feature by feature.

    A frame marked ``separate = true`` (SEP REQT beneath it) is its own pattern: its zones (those sharing its
    ``frame``, or the one zone without a frame name) shift together, by a disc of their own, ``separate`` naming the
    frame (:attr:`label`: "B (SEP REQT 2X holes)")."""

    datum: str                 # the datum feature's size factor
    index: int
    kappa: float
    reference: float           # base units
    zones: tuple[str, ...]
    separate: str = ""         # SEP REQT: the frame (or the one zone) this shift moves

    @property
    def label(self) -> str:
        """The shift's name in tables and notes: the datum feature, and the zone of a separate requirement."""
        return f"{self.datum} (SEP REQT {self.separate})" if self.separate else self.datum


def datum_shifts(spec: "ToleranceSpec") -> list[DatumShift]:
    """The datum-feature shifts of the spec's position zones, one per datum feature of size (``datum_size``) with the
    zones that reference it together, one per frame marked ``separate`` (SEP REQT), in the order the zones are written
    (:class:`DatumShift`)."""
    groups: dict[tuple[str, str], list[str]] = {}
    types: dict[str, str] = {}
    for f in spec.factors:
        if f.zone and f.datum_size:
            zs = groups.setdefault((f.datum_size, (f.frame or f.zone) if f.separate else ""), [])
            if f.zone not in zs:
                zs.append(f.zone)
            types[f.datum_size] = f.datum_type
    out = []
    for (name, separate), zones in groups.items():
        i, kappa, ref = _departure(spec, name, types[name], "MMC")
        out.append(DatumShift(name, i, kappa, ref, tuple(zones), separate))
    return out


def _departure(spec: "ToleranceSpec", name: str, feature_type: str, modifier: str) -> tuple[int, float, float]:
    """``(index, κ, reference)`` of a feature of size's departure from its MMC or LMC size (:func:`zone_bonus`)."""
    i = spec.index(name)
    lo, hi = (float(units.to_base(v, spec.factors[i].unit)) for v in spec.factors[i].band)
    at_small = (feature_type == "internal") == (modifier == "MMC")     # the reference is the smallest size
    return i, 0.5 if at_small else -0.5, lo if at_small else hi


def check_zones(factors, file: str | None) -> None:
    """Each position zone has exactly two coordinate factors with the same unit and diameter."""
    zones: dict[str, list] = {}
    for f in factors:
        if f.zone:
            zones.setdefault(f.zone, []).append(f)
    for z, fs in zones.items():
        if len(fs) != 2:
            raise SpecError(f"position zone {z!r} has {len(fs)} coordinate factor(s) "
                            f"({', '.join(f.name for f in fs)}); it needs two (x and y)", file=file, key="factor.zone")
        a, b = fs
        if a.unit != b.unit or a.limits != b.limits:
            raise SpecError(f"the two coordinates of position zone {z!r} ({a.name}, {b.name}) need the same unit "
                            "and diameter", file=file, key="factor.zone")
        gd = lambda f: (f.modifier, f.size, f.feature_type, f.datum_size, f.datum_type, f.separate,  # noqa: E731
                        f.frame, f.pattern, f.locating)
        if gd(a) != gd(b):
            raise SpecError(f"the two coordinates of position zone {z!r} ({a.name}, {b.name}) need the same "
                            "modifier, size, feature_type, datum_size, datum_type, separate, frame, pattern and feature_relating", file=file, key="factor.zone")
        names = {f.name: f for f in factors}
        other = next((g for g in factors if g.datum_size and g.datum_size == a.datum_size
                      and g.datum_type != a.datum_type), None)
        if other is not None:
            raise SpecError(f"datum feature {a.datum_size!r} is {a.datum_type} for zone {z!r} and {other.datum_type} "
                            f"for zone {other.zone!r}: one feature has one type", file=file, key="factor.datum_type")
        for key in ("size", "datum_size"):
            ref = getattr(a, key)
            if not ref:
                continue
            g = names.get(ref)
            if g is None:
                raise SpecError(f"position zone {z!r}: {key} names no factor ({ref!r}){did_you_mean(ref, list(names))}",
                                file=file, key=f"factor.{key}")
            if g.zone:
                raise SpecError(f"position zone {z!r}: {key} {ref!r} is a zone coordinate, not a size", file=file,
                                key=f"factor.{key}")
            if units.dimension(g.unit) != units.dimension(a.unit):
                raise SpecError(f"position zone {z!r}: {key} {ref!r} is in {g.unit}, not a length like the zone",
                                file=file, key=f"factor.{key}")
    check_frames(factors, file)


def check_frames(factors, file: str | None) -> None:
    """The zones of one feature control frame (``frame``, an nX pattern) reference the same datum feature and are all
    a separate requirement or none: SEP REQT is written beneath a frame, not beside one of its features."""
    first: dict[str, object] = {}
    for f in factors:
        if not (f.zone and f.frame):
            continue
        g = first.setdefault(f.frame, f)
        if (g.separate, g.datum_size) != (f.separate, f.datum_size):
            raise SpecError(f"frame {f.frame!r}: zones {g.zone!r} and {f.zone!r} differ in separate or datum_size — the "
                            "zones of one frame share its datums and its SEP REQT", file=file, key="factor.frame")
        if drawn_zone(g) != drawn_zone(f):
            raise SpecError(f"frame {f.frame!r}: zones {g.zone!r} and {f.zone!r} differ in diameter or modifier — one "
                            "frame gives its features one zone", file=file, key="factor.frame")
    check_feature_types(factors, file)


def check_feature_types(factors, file: str | None) -> None:
    """A feature of size has one type wherever the spec names it: as a zone's ``size``, a ``datum_size`` or a form's
    ``envelope`` (internal: a hole, external: a shaft or boss)."""
    seen: dict[str, tuple[str, str]] = {}
    for f in factors:
        for ref, kind, key in ((f.size, f.feature_type, "feature_type"), (f.datum_size, f.datum_type, "datum_type"),
                               (f.envelope, f.feature_type, "feature_type")):
            if not ref or not kind:
                continue
            prev = seen.setdefault(ref, (kind, f.name))
            if prev[0] != kind:
                raise SpecError(f"feature of size {ref!r} is {prev[0]} for {prev[1]!r} and {kind} for {f.name!r}: one "
                                "feature has one type", file=file, key=f"factor.{key}")


def check_envelopes(factors, file: str | None) -> None:
    """Each envelope (Rule #1) names a size factor of the spec in a length, not a position zone's coordinate nor
    another form tolerance."""
    names = {f.name: f for f in factors}
    for f in factors:
        if not f.envelope:
            continue
        g = names.get(f.envelope)
        if g is None:
            raise SpecError(f"factor {f.name!r}: envelope names no factor ({f.envelope!r})"
                            f"{did_you_mean(f.envelope, list(names))}", file=file, key="factor.envelope")
        if g.zone or g.characteristic or g is f:
            raise SpecError(f"factor {f.name!r}: envelope {f.envelope!r} is not a size (a position zone's "
                            "coordinate, or a profile or form tolerance)", file=file, key="factor.envelope")
        if units.dimension(g.unit) != "length" or units.dimension(f.unit) != "length":
            raise SpecError(f"factor {f.name!r} ({f.unit}) and its envelope {f.envelope!r} ({g.unit}): a form and its "
                            "size must both be lengths", file=file, key="factor.envelope")


def stack_direction(p: Params) -> float | None:
    """``direction``: the factor's sign or coefficient in a one-dimensional stack (``+``, ``-`` or a number)."""
    v = p.raw("direction", None)
    if isinstance(v, str) and v.strip().replace("\u2212", "-") in ("+", "-"):
        return 1.0 if v.strip() == "+" else -1.0
    return None if v is None else p.float("direction")


def correlation_from_tables(tables: list[Params], names: list[str]) -> np.ndarray | None:
    if not tables:
        return None
    k = len(names)
    c = np.eye(k)
    given: dict[tuple[int, int], str] = {}   # pair -> the table that gave it: a second one contradicts or repeats
    for t in tables:
        if "pair" in t:
            fs = t.strs("pair")
            if len(fs) != 2:
                raise t.error("pair", "a pair names exactly two factors")
            rho = t.float("rho", min=-1.0, max=1.0)
            m = np.array([[1.0, rho], [rho, 1.0]])
        else:
            fs = t.strs("factors", min_length=2)
            rows = t.raw("matrix")
            if not isinstance(rows, list) or len(rows) != len(fs):
                raise t.error("matrix", f"expected a {len(fs)}×{len(fs)} matrix")
            m = np.array([Params({"r": r}, file=t.file, key=t.path("matrix")).floats("r", length=len(fs))
                          for r in rows])
            if not np.allclose(m, m.T, atol=1e-12):
                raise t.error("matrix", "correlation matrix is not symmetric")
            if not np.allclose(np.diag(m), 1.0):
                raise t.error("matrix", "correlation matrix needs ones on the diagonal")
            if np.any(np.abs(m) > 1.0):
                raise t.error("matrix", "correlations must lie in [-1, 1]")
        idx = []
        for f in fs:
            if f not in names:
                raise t.error("factors" if "factors" in t else "pair",
                              f"unknown factor name {f!r}{did_you_mean(f, names)}")
            idx.append(names.index(f))
        if len(set(idx)) != len(idx):
            raise t.error("factors", "a factor is named twice")
        t.finish()
        for a, ia in enumerate(idx):
            for b, ib in enumerate(idx):
                if a < b:
                    pair = (min(ia, ib), max(ia, ib))
                    if pair in given:
                        prev = c[ia, ib]
                        same = "the same" if prev == m[a, b] else f"{prev:g} there, {m[a, b]:g} here"
                        raise t.error("factors" if "factors" in t.data else "pair",
                                      f"the correlation of {names[pair[0]]!r} and {names[pair[1]]!r} is given twice "
                                      f"(first in {given[pair]}; {same}): give each pair once")
                    given[pair] = t.key
                if a != b:
                    c[ia, ib] = m[a, b]
    w = np.linalg.eigvalsh(c)
    if w.min() <= 1e-10:
        raise SpecError("correlation matrix is not positive definite", file=tables[0].file, key="correlation")
    return c


def load_requirements(path: str | Path) -> list[Requirement]:
    return read_requirements_file(path)[0]


def read_requirements_file(path: str | Path) -> tuple[list[Requirement], str]:
    """The requirements of a ``[[requirement]]`` file and the file's SHA-256 (one read)."""
    data, sha = read_toml(path)
    root = Params(data, file=str(path))
    tables = root.tables("requirement")
    if not tables:  # a gate that checks nothing must not pass by accident
        raise root.error("requirement", "a requirements file needs at least one [[requirement]] table")
    reqs = requirements_from_tables(tables)
    root.finish()
    return reqs, sha


#: why a requirement may not ask for a yield of exactly 1
YIELD_OF_ONE = ("a yield of exactly 1 cannot be demonstrated by any finite sample (with every sample conforming the "
                "one-sided lower bound is (1 − c)^(1/n), below 1 at every n): write the yield you need, e.g. "
                "0.999999 (1 ppm out)")


def requirements_from_tables(tables: list[Params]) -> list[Requirement]:
    out = []
    for t in tables:
        output = t.str("output")
        lower = t.float("lower", None)
        upper = t.float("upper", None)
        if lower is None and upper is None:
            raise t.error("upper", "a requirement needs 'lower' and/or 'upper'")
        if lower is not None and upper is not None and not lower < upper:
            raise t.error("upper", f"limits in the wrong order: lower {lower} >= upper {upper}")
        unit = t.unit("unit", None)
        min_yield = t.float("min_yield", None)
        if min_yield == 1.0:
            raise t.error("min_yield", YIELD_OF_ONE)
        if min_yield is not None and not 0.0 < min_yield < 1.0:
            raise t.error("min_yield", f"must lie in (0, 1), got {min_yield}")
        min_cpk = t.float("min_cpk", None, positive=True)
        confidence = t.float("confidence", 0.95)
        if not 0.5 <= confidence < 1.0:
            raise t.error("confidence", f"must lie in [0.5, 1), got {confidence}")
        basis = t.str("basis", "lower_bound", choices=BASES)
        name = t.str("name", "", single_line=True)
        interval = t.str("interval", "clopper-pearson", choices=YIELD_INTERVALS)
        cpk_method = t.str("cpk_method", "normal", choices=CPK_METHODS)
        bound = t.str("bound", "one-sided", choices=BOUNDS)
        statistic = t.str("statistic", None, choices=STATISTICS)
        if statistic is not None:
            for k in ("interval", "cpk_method", "basis"):
                if k in t.data:
                    raise t.error(k, f"a requirement on the {statistic} is judged on its confidence interval: "
                                     f"{k!r} does not apply")
        reading, source = t.str("reading", ""), t.str("source", "")
        status = t.str("status", "", choices=STATUSES)
        t.finish()
        out.append(Requirement(output, lower, upper, unit, min_yield, min_cpk, confidence, basis, name,
                               interval=interval, file=t.file, key=t.key, cpk_method=cpk_method, bound=bound,
                               statistic=statistic, reading=reading, source=source, status=status))
    return out
