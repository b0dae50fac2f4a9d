"""Requirements: what an output must meet (limits, yield or Cpk, or a population statistic's band), how it is
judged, and their reading from ``[[requirement]]`` tables and requirement files."""
from __future__ import annotations

from dataclasses import dataclass, field, fields, replace
from pathlib import Path

from .. import units
from ..errors import InputError, SpecError
from ..options import REQUIRED, option, read_options
from ..params import Params, read_toml

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
        from ..units import label as unit_label

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


@dataclass
class RequirementTable:
    """``[[requirement]]``: a limit on one output and the yield or Cpk it must reach, or the band a population
    statistic of the output must lie in (:class:`Requirement`; ``rvtol docs writing-a-study``)."""

    output: str = option(REQUIRED, "the output the limits apply to (a name the model gives)")
    lower: float | None = option(None, "the lower limit, in unit (lower and/or upper)")
    upper: float | None = option(None, "the upper limit, in unit")
    unit: str | None = option(None, "the unit of the limits (default: the output's display unit)")
    min_yield: float | None = option(None, "the yield the output must reach, in (0, 1) (neither it nor min_cpk: "
                                           f"{Requirement.DEFAULT_MIN_YIELD})")
    min_cpk: float | None = option(None, "the Cpk the output must reach", positive=True)
    confidence: float = option(0.95, "the confidence of the bound the verdict uses, in [0.5, 1)")
    basis: str | None = option(None, "what the minimum is judged on: its lower confidence bound (default "
                                     "lower_bound) or the estimate", choices=BASES)
    name: str = option("", "the requirement's name (default: the output and its limits)", single_line=True)
    interval: str | None = option(None, "the yield's interval (default clopper-pearson, exact)",
                                  choices=tuple(YIELD_INTERVALS))
    cpk_method: str | None = option(None, "the Cpk min_cpk judges (default normal: normal theory, Bissell's bound; "
                                          "percentile: ISO 22514-2)", choices=CPK_METHODS)
    bound: str = option("one-sided", "the bound: one-sided at confidence, or the lower end of the two-sided "
                                     "interval", choices=BOUNDS)
    statistic: str | None = option(None, "a population statistic judged within [lower, upper] instead of a "
                                         "per-unit limit", choices=STATISTICS)
    reading: str = option("", "how the figure is read (the maker's definition the output follows)")
    source: str = option("", "where the limit comes from")
    status: str = option("", "how firmly the limit is known: confirmed (read in its source), recalled, assumed",
                         choices=STATUSES)

    def complete(self, study, error):
        if self.lower is None and self.upper is None:
            raise error("upper", "a requirement needs 'lower' and/or 'upper'")
        if self.lower is not None and self.upper is not None and not self.lower < self.upper:
            raise error("upper", f"limits in the wrong order: lower {self.lower} >= upper {self.upper}")
        if self.unit is not None:
            try:
                self.unit = units.canonical(self.unit)
            except InputError as exc:
                raise error("unit", exc.reason) from None
        if self.min_yield == 1.0:
            raise error("min_yield", YIELD_OF_ONE)
        if self.min_yield is not None and not 0.0 < self.min_yield < 1.0:
            raise error("min_yield", f"must lie in (0, 1), got {self.min_yield}")
        if not 0.5 <= self.confidence < 1.0:
            raise error("confidence", f"must lie in [0.5, 1), got {self.confidence}")
        if self.statistic is not None:
            for k in ("interval", "cpk_method", "basis"):
                if getattr(self, k) is not None:
                    raise error(k, f"a requirement on the {self.statistic} is judged on its confidence interval: "
                                   f"{k!r} does not apply")
        self.basis = self.basis or "lower_bound"
        self.interval = self.interval or "clopper-pearson"
        self.cpk_method = self.cpk_method or "normal"


def requirement_of(table: RequirementTable, file: str | None, key: str) -> Requirement:
    """The requirement a read ``[[requirement]]`` table states; its errors name ``file`` and ``key`` (the table's)."""
    return Requirement(**{f.name: getattr(table, f.name) for f in fields(table)}, file=file, key=key)


def requirements_from_tables(tables: list[Params]) -> list[Requirement]:
    """The requirements of ``[[requirement]]`` tables, each read by :class:`RequirementTable`."""
    out = []
    for t in tables:
        o = read_options(RequirementTable, t)
        t.finish()
        out.append(requirement_of(o, t.file, t.key))
    return out
