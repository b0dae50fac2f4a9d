"""Gates: what a change against the accepted baseline may do, declared in the study.

::

    [[gate]]                        # no requirement may get worse (the default when a study declares none)
    kind = "requirements"
    max_ppm_increase = 0            # allowance (ppm) on a demonstrated rise of a requirement's
                                    # non-conforming fraction (default 0)

    [[gate]]                        # a statistic of an output may not move by more than stated
    kind = "output"
    output = "lost_motion"
    statistic = "P99.865"           # mean | std | P0.135 | P1 | P5 | P50 | P95 | P99 | P99.865
    max_increase = 0.02             # and/or max_decrease (>= 0)
    unit = "arcmin"                 # of the amounts (default: the output's display unit)
    basis = "upper_bound"           # pass when the whole confidence interval of the change stays
                                    # within the allowance (default), or judge the "estimate"
    name = "P99.865 of lost motion may grow by at most 0.02 arcmin"   # optional

A requirement *gets worse* when it passed in the baseline and fails now, when
it is gone from the new run, or when the rise of its non-conforming fraction
is demonstrated (the lower end of the change's interval) beyond
``max_ppm_increase``.  Gates are read and checked when the study loads
(:func:`read_gates`) and recorded in summary.json, so ``rvtol compare``
applies the new run's gates to two report folders; ``rvtol kinds gate`` lists every key.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

from .. import units
from ..errors import InputError, did_you_mean
from ..options import REQUIRED, option, read_options
from ..params import Params
from ..stats import PERCENTILES

KINDS = ("requirements", "output")
STATISTICS = ("mean", "std") + tuple(f"P{p:g}" for p in PERCENTILES)
BASES = ("upper_bound", "estimate")


@dataclass(frozen=True)
class Gate:
    """One declared gate (amounts in the output's display unit)."""

    kind: str
    name: str
    output: str | None = None
    statistic: str | None = None
    max_increase: float | None = None
    max_decrease: float | None = None
    unit: str | None = None
    basis: str = "upper_bound"
    max_ppm_increase: float = 0.0

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict) -> "Gate":
        return cls(**{k: d.get(k, v.default) for k, v in cls.__dataclass_fields__.items()})


#: the gate applied when a study declares none (a comparison always gates something)
DEFAULT_GATES = (Gate("requirements", "no requirement may get worse"),)


#: the keys of each kind of gate beside ``kind`` and ``name``
KEYS = {"requirements": ("max_ppm_increase",),
        "output": ("output", "statistic", "unit", "max_increase", "max_decrease", "basis")}


@dataclass
class GateTable:
    """``[[gate]]``: what a change against the accepted baseline may do (``rvtol run --baseline``, ``rvtol compare``;
    module docstring)."""

    kind: str = option(REQUIRED, "requirements: no requirement may get worse; output: a statistic of one output may "
                                 "not move by more than stated", choices=KINDS)
    name: str | None = option(None, "the gate's name (default: what it checks, in words)", single_line=True)
    max_ppm_increase: float | None = option(None, "requirements: the demonstrated rise of a requirement's "
                                                  "non-conforming fraction allowed, ppm (default 0)", nonnegative=True)
    output: str | None = option(None, "output: the output")
    statistic: str | None = option(None, "output: the statistic compared", choices=STATISTICS)
    unit: str | None = option(None, "output: the unit of the amounts (default: the output's display unit)")
    max_increase: float | None = option(None, "output: how much the statistic may grow (and/or max_decrease)",
                                        nonnegative=True)
    max_decrease: float | None = option(None, "output: how much the statistic may fall", nonnegative=True)
    basis: str | None = option(None, "output: pass when the whole confidence interval of the change stays within the "
                                     "allowance (default upper_bound), or judge the estimate", choices=BASES)

    def complete(self, study, error):
        other = next(k for k in KEYS if k != self.kind)
        given = [k for k in KEYS[other] if getattr(self, k) is not None]
        if given:
            raise error(given[0], f"belongs to a kind = {other!r} gate, not to a {self.kind!r} one")
        if self.kind == "requirements":
            self.max_ppm_increase = self.max_ppm_increase or 0.0
            return
        for k in ("output", "statistic"):
            if getattr(self, k) is None:
                raise error(k, "missing required key (an output gate names the output and the statistic)")
        if self.max_increase is None and self.max_decrease is None:
            raise error("max_increase", "an output gate needs max_increase and/or max_decrease")
        self.basis = self.basis or "upper_bound"


def read_gates(tables: list[Params], model) -> list[Gate]:
    """The study's ``[[gate]]`` tables (:class:`GateTable`), checked against the model's outputs. Raises
    InputError."""
    out = []
    for t in tables:
        g = read_options(GateTable, t)
        t.finish()
        if g.kind == "requirements":
            ppm = g.max_ppm_increase
            name = g.name or "no requirement may get worse" + (f" (beyond {ppm:g} ppm)" if ppm else "")
            out.append(Gate("requirements", name, max_ppm_increase=ppm))
            continue
        if g.output not in model.output_names:
            raise t.error("output", f"unknown output name {g.output!r}{did_you_mean(g.output, model.output_names)} "
                                    f"(model has: {', '.join(model.output_names)})")
        shown = model.output(g.output).shown_unit
        try:
            unit = units.canonical(g.unit) if g.unit is not None else shown
        except InputError as exc:
            raise t.error("unit", exc.reason) from None
        try:
            conv = (lambda v: None if v is None else float(units.convert(v, unit, shown)))  # noqa: E731
            conv(1.0)
        except InputError as exc:
            raise t.error("unit", f"does not fit output {g.output!r} ({exc.reason})") from None
        inc, dec = g.max_increase, g.max_decrease
        limits = " and ".join(x for x in (f"grow by more than {inc:g} {units.label(unit)}" if inc is not None else "",
                                          f"fall by more than {dec:g} {units.label(unit)}" if dec is not None else "")
                              if x)
        name = g.name or f"{g.statistic} of {g.output} may not {limits}"
        out.append(Gate("output", name, g.output, g.statistic, conv(inc), conv(dec), shown, g.basis))
    return out
