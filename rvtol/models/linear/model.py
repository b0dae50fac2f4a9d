"""A linear stack-up model read from a study file (the spine's first study).

::

    [model]
    kind = "linear"

    [[model.output]]
    name = "gap"
    unit = "mm"               # base unit of the output (its dimension fixes the base unit)
    display_unit = "um"       # optional: unit to report in
    constant = 0.10           # in `unit`
    coefficients = { housing = 1.0, spacer = -1.0, bearing = -1.0 }  # base-unit ratios
    # or coefficients = "spec": each factor's `direction` (a spec table's direction column)

Coefficients multiply the factors in base units (mm, rad): a length chain
uses ±1; an angle from a length at radius R uses 1/R (rad/mm).
"""
from __future__ import annotations

from ... import units
from ...errors import InputError, did_you_mean
from ...model import LinearModel, Quantity


def spec_directions(spec) -> list[float]:
    """The ``direction`` of every factor of ``spec`` (0 where a factor has none); an error if none has one."""
    row = [getattr(f, "direction", None) for f in spec.factors]
    if all(d is None for d in row):
        raise InputError("no factor of the spec has a direction (a spec table's direction column, or "
                         "direction = ±1 in a [[factor]])", file=spec.file, key="factor.direction")
    return [0.0 if d is None else float(d) for d in row]


def stack_model(spec, output: str = "stack", unit: str | None = None, display_unit: str | None = None,
                constant: float = 0.0) -> LinearModel:
    """The one-dimensional stack ``Σ direction·factor`` of a spec (base units) as a :class:`LinearModel`.

    ``unit``: the output's unit (default: the first factor's); ``display_unit`` the unit to report in;
    ``constant`` in ``unit``.
    """
    u = units.canonical(unit or spec.factors[0].unit)
    q = Quantity(output, units.base_unit(u), display_unit or u)
    return LinearModel(spec.names, [units.base_unit(x) for x in spec.units], [q], [spec_directions(spec)],
                       [float(units.to_base(constant, u))])


def from_study(params, design, spec) -> LinearModel:
    outs = params.tables("output")
    if not outs:
        raise params.error("output", "a linear model needs at least one [[model.output]]")
    quantities, rows, consts = [], [], []
    for t in outs:
        name = t.str("name")
        unit = t.unit("unit", "1")
        disp = t.unit("display_unit", unit, dimension=units.dimension(unit))
        base = units.base_unit(unit)
        consts.append(float(units.to_base(t.float("constant", 0.0), unit)))
        if t.raw("coefficients") == "spec":
            try:
                row = spec_directions(spec)
            except InputError as exc:
                raise t.error("coefficients", exc.reason) from None
        else:
            coefs = t.sub("coefficients")
            row = []
            for f in spec.names:
                row.append(coefs.float(f, 0.0))
            unknown = sorted(set(coefs.keys()) - set(spec.names))
            if unknown:
                raise coefs.error(unknown[0], f"unknown factor name {unknown[0]!r}"
                                                  f"{did_you_mean(unknown[0], spec.names)} "
                                                  f"(spec has: {', '.join(spec.names)})")
        t.finish()
        quantities.append(Quantity(name, base, disp))
        rows.append(row)
    if len({q.name for q in quantities}) != len(quantities):
        raise params.error("output", "duplicate output name")
    params.finish()
    return LinearModel(spec.names, [units.base_unit(u) for u in spec.units], quantities, rows, consts)
