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

from dataclasses import dataclass

from ... import units
from ...errors import InputError, did_you_mean
from ...model import LinearModel, Quantity
from ...model_kind import ModelKind
from ...options import REQUIRED, option
from ...params import check_number


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


@dataclass
class OutputOptions:
    """One ``[[model.output]]`` of a linear model."""

    name: str = option(REQUIRED, "the output's name")
    unit: str = option("1", "the output's unit (its dimension fixes the base unit the coefficients give)")
    display_unit: str | None = option(None, "the unit to report in (default: unit)")
    constant: float = option(0.0, "the constant term, in unit")
    coefficients: object = option(
        REQUIRED, 'factor -> coefficient in base-unit ratios (absent factors: 0), or "spec": each factor\'s direction')


@dataclass
class Options:
    """The keys of ``[model] kind = "linear"``."""

    output: list[OutputOptions] = option(REQUIRED, "the outputs: a constant plus coefficients times the factors",
                                         min_length=1)


def build(o: Options, design, spec, error) -> LinearModel:
    quantities, rows, consts = [], [], []
    for i, t in enumerate(o.output):
        where = f"output[{i}]"
        try:
            unit = units.canonical(t.unit)
            disp = units.canonical(t.display_unit or unit, units.dimension(unit))
            units.require_dimension(disp, units.dimension(unit))
        except InputError as exc:
            key = "unit" if t.display_unit is None or exc.key == "unit" else "display_unit"
            raise error(f"{where}.{key}", exc.reason) from None
        consts.append(float(units.to_base(t.constant, unit)))
        if t.coefficients == "spec":
            try:
                row = spec_directions(spec)
            except InputError as exc:
                raise error(f"{where}.coefficients", exc.reason) from None
        elif isinstance(t.coefficients, dict):
            unknown = sorted(set(t.coefficients) - set(spec.names))
            if unknown:
                raise error(f"{where}.coefficients.{unknown[0]}", f"unknown factor name {unknown[0]!r}"
                                                                   f"{did_you_mean(unknown[0], spec.names)} "
                                                                   f"(spec has: {', '.join(spec.names)})")
            row = [check_number(t.coefficients.get(f, 0.0), error, f"{where}.coefficients.{f}") for f in spec.names]
        else:
            raise error(f"{where}.coefficients", f'expected "spec" or a table of coefficients, got {t.coefficients!r}')
        quantities.append(Quantity(t.name, units.base_unit(unit), disp))
        rows.append(row)
    if len({q.name for q in quantities}) != len(quantities):
        raise error("output", "duplicate output name")
    return LinearModel(spec.names, [units.base_unit(u) for u in spec.units], quantities, rows, consts)


from_study = ModelKind(Options, build, "a linear stack: outputs = constant + Σ coefficient × factor")
