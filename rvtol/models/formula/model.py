"""A Model whose outputs are formulas of the factors, written in the study file — no Python.

The formulas are :mod:`rvtol.expressions` (the one expression language of rvtol: parsed safely
under a whitelist, never passed to ``eval``; vectorised over the rows of ``X``; exact forward-mode
derivatives).  A row where a formula is undefined (``sqrt`` of a negative, ``log 0``) gives
NaN/inf and the engine counts it as a failed sample.

:class:`FormulaModel` is a :class:`rvtol.model.Model` whose outputs are named formulas::

    model = FormulaModel.from_spec(spec, {"clearance": ("carrier_gap - disc1_width - disc2_width", "mm", "um")})

Factor names are written as they are (``carrier_gap``, ``E_c[1,2]``, ``disc.width``), any other in
braces (``{pin gap}``).  Inside the formulas each factor is in its own unit (``units="factor"``, the unit written in
the spec) or in rvtol's base units (``units="base"``); each output declares the unit its
formula yields.  ``evaluate`` and :meth:`FormulaModel.gradient` (exact ∂Y/∂X, used by the
linearised analyses instead of five-point differences) work in base units like every Model.
A study names it as::

    [model]
    kind = "formula"
    units = "factor"                 # or "base"
    [model.define]                   # optional intermediate quantities, in order
    tilt = "atan2(e1 - e2, L)"
    [[model.output]]
    name = "gap"
    formula = "carrier_gap - disc1_width - disc2_width"
    unit = "mm"                      # the unit the formula yields (default "1")
    display_unit = "um"              # optional: the unit to report in
    description = "..."              # optional
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np

from ... import units as _units
from ...errors import InputError
from ...expressions import CONSTANTS, Expression, ExpressionError
from ...model import Model, Quantity


# --------------------------------------------------------------------------- the model
@dataclass(frozen=True)
class FormulaOutput:
    """A named output: its formula, the unit the formula yields, the unit to report in."""

    name: str
    formula: str
    unit: str = "1"
    display_unit: str | None = None
    description: str = ""


def _outputs(outputs) -> list[FormulaOutput]:
    if isinstance(outputs, Mapping):
        items = []
        for name, v in outputs.items():
            if isinstance(v, str):
                items.append(FormulaOutput(name, v))
            elif isinstance(v, (tuple, list)) and 1 <= len(v) <= 3:
                items.append(FormulaOutput(name, *v))
            else:
                raise ExpressionError(f"output {name!r}: expected a formula or (formula, unit[, display unit])")
        return items
    out = []
    for v in outputs:
        if isinstance(v, FormulaOutput):
            out.append(v)
        elif isinstance(v, (tuple, list)) and 2 <= len(v) <= 4:
            out.append(FormulaOutput(*v))
        else:
            raise ExpressionError(f"expected FormulaOutput or (name, formula[, unit[, display unit]]), got {v!r}")
    return out


class FormulaModel(Model):
    """A Model whose outputs are formulas of its inputs (see the module docstring).

    ``inputs``: factor names (the columns of ``X``); ``input_units``: the unit each input has
    *inside the formulas* (default ``"1"``; the model's :attr:`input_units` are their base
    units, as for every Model); ``definitions``: ordered ``{name: formula}`` intermediate
    quantities, each usable by later ones and by the outputs.
    """

    def __init__(self, outputs, inputs: Sequence[str], input_units: Sequence[str] | None = None, *,
                 definitions: Mapping[str, str] | None = None):
        self.inputs = tuple(inputs)
        if len(set(self.inputs)) != len(self.inputs):
            raise ExpressionError("an input name is given twice")
        fu = tuple(input_units) if input_units is not None else ("1",) * len(self.inputs)
        if len(fu) != len(self.inputs):
            raise ExpressionError(f"{len(self.inputs)} inputs but {len(fu)} input units")
        try:
            self.formula_units = tuple(_units.canonical(u) for u in fu)
            self.input_units = tuple(_units.base_unit(u) for u in self.formula_units)
        except InputError as exc:
            raise ExpressionError(exc.reason) from None
        self._in_factor = np.array([_units.factor(u) for u in self.formula_units])
        known = list(self.inputs)
        self.definitions: list[tuple[str, Expression]] = []
        for name, text in (definitions or {}).items():
            if not isinstance(name, str) or not name:
                raise ExpressionError(f"definition name must be text, got {name!r}")
            if name in known or name in CONSTANTS:
                raise ExpressionError(f"definition {name!r} has the name of an input, another definition or a "
                                      "constant")
            self.definitions.append((name, Expression.parse(text, known, what=f"definition {name!r}")))
            known.append(name)
        specs = _outputs(outputs)
        if not specs:
            raise ExpressionError("a formula model needs at least one output")
        names = [o.name for o in specs]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise ExpressionError(f"duplicate output name {dup[0]!r}")
        self.formulas: list[Expression] = []
        outs, self._out_factor = [], []
        for o in specs:
            try:
                u = _units.canonical(o.unit)
                disp = _units.require_dimension(o.display_unit, _units.dimension(u)) if o.display_unit else u
            except InputError as exc:
                raise ExpressionError(f"output {o.name!r}: {exc.reason}") from None
            self.formulas.append(Expression.parse(o.formula, known, what=f"output {o.name!r}"))
            outs.append(Quantity(o.name, _units.base_unit(u), disp, o.description))
            self._out_factor.append(_units.factor(u))
        self.outputs = tuple(outs)
        self._out_factor = np.array(self._out_factor)
        self.output_specs = tuple(specs)

    # -- construction from a spec or a study --------------------------------------------
    @classmethod
    def from_spec(cls, spec, outputs, *, definitions: Mapping[str, str] | None = None,
                  units: str = "factor") -> "FormulaModel":
        """Inputs are the spec's factors, in the formulas in their own unit (``units="factor"``)
        or in base units (``"base"``)."""
        if units not in ("factor", "base"):
            raise ExpressionError(f"units must be 'factor' or 'base', got {units!r}")
        fu = tuple(spec.units) if units == "factor" else tuple(_units.base_unit(u) for u in spec.units)
        return cls(outputs, spec.names, fu, definitions=definitions)

    # -- evaluation -------------------------------------------------------------------
    def _env(self, X: np.ndarray) -> dict:
        Xf = X / self._in_factor   # base → the units written in the formulas
        return {n: Xf[:, j] for j, n in enumerate(self.inputs)}

    def evaluate(self, X):
        X = self.check_input(X)
        env = self._env(X)
        n = X.shape[0]
        with np.errstate(all="ignore"):
            for name, f in self.definitions:
                env[name] = np.broadcast_to(np.asarray(f.evaluate(env), dtype=float), (n,))
            Y = np.empty((n, len(self.formulas)))
            for i, f in enumerate(self.formulas):
                Y[:, i] = f.evaluate(env)
        return Y * self._out_factor

    def gradient(self, X) -> np.ndarray:
        """Exact ∂Y/∂X, shape ``(n, outputs, inputs)``, in base units (forward-mode AD)."""
        return self.evaluate_with_gradient(X)[1]

    def evaluate_with_gradient(self, X) -> tuple[np.ndarray, np.ndarray]:
        X = self.check_input(X)
        n, k = X.shape
        env = self._env(X)
        seeds: dict[str, dict] = {}
        with np.errstate(all="ignore"):
            for name, f in self.definitions:
                v, d = f.gradient(env, seeds)
                env[name] = np.broadcast_to(np.asarray(v, dtype=float), (n,))
                seeds[name] = d
            Y = np.empty((n, len(self.formulas)))
            G = np.zeros((n, len(self.formulas), k))
            col = {nm: j for j, nm in enumerate(self.inputs)}
            for i, f in enumerate(self.formulas):
                v, d = f.gradient(env, seeds)
                Y[:, i] = v
                for nm, g in d.items():
                    G[:, i, col[nm]] = g
        Y *= self._out_factor
        G *= self._out_factor[None, :, None] / self._in_factor[None, None, :]
        return Y, G


def from_study(params, design, spec) -> FormulaModel:
    """The study factory (``[model] kind = "formula"``); errors name the file and key."""
    u = params.str("units", "factor", choices=("factor", "base"))
    defs_p = params.sub("define", {})
    definitions = {}
    for name in list(defs_p.keys()):
        definitions[name] = defs_p.str(name)
    outs = params.tables("output")
    if not outs:
        raise params.error("output", "a formula model needs at least one [[model.output]]")
    specs = []
    for t in outs:
        name = t.str("name")
        formula = t.str("formula")
        unit = t.unit("unit", "1")
        disp = t.unit("display_unit", unit, dimension=_units.dimension(unit))
        desc = t.str("description", "")
        t.finish()
        specs.append((t, FormulaOutput(name, formula, unit, disp, desc)))
    params.finish()
    fu = tuple(spec.units) if u == "factor" else tuple(_units.base_unit(x) for x in spec.units)
    known = list(spec.names)
    for name, text in definitions.items():   # locate errors before building
        try:
            Expression.parse(text, known, what=f"definition {name!r}")
        except ExpressionError as exc:
            raise defs_p.error(name, exc.reason) from None
        known.append(name)
    for t, o in specs:
        try:
            Expression.parse(o.formula, known, what=f"output {o.name!r}")
        except ExpressionError as exc:
            raise t.error("formula", exc.reason) from None
    try:
        return FormulaModel([o for _, o in specs], spec.names, fu, definitions=definitions)
    except ExpressionError as exc:
        raise params.error(None, exc.reason) from None


__all__ = ["FormulaModel", "FormulaOutput", "from_study"]
