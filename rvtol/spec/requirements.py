"""Requirements: what an output must meet (limits, yield or Cpk, or a population statistic's band), how it is
judged, and their reading from ``[[requirement]]`` tables and requirement files."""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

from .. import units
from ..errors import InputError, SpecError
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
