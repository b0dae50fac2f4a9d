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
applies the new run's gates to two report folders.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

from .. import units
from ..errors import InputError, did_you_mean
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


def read_gates(tables: list[Params], model) -> list[Gate]:
    """The study's ``[[gate]]`` tables, checked against the model's outputs. Raises InputError."""
    out = []
    for t in tables:
        kind = t.str("kind", choices=KINDS)
        if kind == "requirements":
            ppm = t.float("max_ppm_increase", 0.0, nonnegative=True)
            name = t.str("name", "no requirement may get worse" + (f" (beyond {ppm:g} ppm)" if ppm else ""),
                         single_line=True)
            t.finish()
            out.append(Gate("requirements", name, max_ppm_increase=ppm))
            continue
        output = t.str("output")
        if output not in model.output_names:
            raise t.error("output", f"unknown output name {output!r}{did_you_mean(output, model.output_names)} "
                                    f"(model has: {', '.join(model.output_names)})")
        shown = model.output(output).shown_unit
        stat = t.str("statistic", choices=STATISTICS)
        unit = t.unit("unit", shown)
        try:
            conv = (lambda v: None if v is None else float(units.convert(v, unit, shown)))  # noqa: E731
            conv(1.0)
        except InputError as exc:
            raise t.error("unit", f"does not fit output {output!r} ({exc.reason})") from None
        inc = t.float("max_increase", None, nonnegative=True)
        dec = t.float("max_decrease", None, nonnegative=True)
        if inc is None and dec is None:
            raise t.error("max_increase", "an output gate needs max_increase and/or max_decrease")
        basis = t.str("basis", "upper_bound", choices=BASES)
        limits = " and ".join(x for x in (f"grow by more than {inc:g} {units.label(unit)}" if inc is not None else "",
                                          f"fall by more than {dec:g} {units.label(unit)}" if dec is not None else "")
                              if x)
        name = t.str("name", f"{stat} of {output} may not {limits}", single_line=True)
        t.finish()
        out.append(Gate("output", name, output, stat, conv(inc), conv(dec), shown, basis))
    return out
