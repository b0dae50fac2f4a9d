"""A Model whose outputs are formulas of the factors, written in the study file — no Python.

The formulas are :mod:`rvtol.expressions` (the one expression language of rvtol: parsed safely
under a whitelist, never passed to ``eval``; vectorised over the rows of ``X``; exact forward-mode
derivatives).  A row where a formula is undefined (``sqrt`` of a negative, ``log 0``) gives
NaN/inf and the engine counts it as a failed sample.

:class:`FormulaModel` is a :class:`rvtol.model.Model` whose outputs are named formulas::

    model = FormulaModel.from_spec(spec, {"clearance": ("carrier_gap - disc1_width - disc2_width", "mm", "um")})

Factor names are written as they are (``carrier_gap``, ``E_c[1,2]``, ``disc.width``), any other in
braces (``{pin gap}``).  ``units`` says how the factors' units enter the formulas:

* ``"checked"`` (default): every factor carries its unit into the formulas, which are checked by
  dimensional analysis at load time (:mod:`rvtol.models.formula.dimensions`, pint): operands of
  ``+``/``-`` are converted to one unit, ``sin``/``cos``/``tan`` get radians whatever unit the angle
  was given in, a length added to an angle is an error naming the formula, and each output's
  ``unit`` is the unit to give the result in (converted);
* ``"factor"``: each factor enters as the number written in its own unit and each output's ``unit``
  is the unit that number expression yields — unchecked (for empirical formulas whose constants
  carry hidden units); a trigonometric function of an angle not in radians is still refused;
* ``"base"``: as ``"factor"`` with every factor in rvtol's base units (mm, rad, N, s).

``evaluate`` and :meth:`FormulaModel.gradient` (exact ∂Y/∂X, used by the linearised analyses
instead of five-point differences) work in base units like every Model.  A study names it as::

    [model]
    kind = "formula"
    units = "checked"                # default; or "factor" / "base" (unchecked numbers)
    [model.define]                   # optional intermediate quantities, in order
    tilt = "atan2(e1 - e2, L)"
    L = { formula = "25", unit = "mm" }   # a constant with its unit (units = "checked")
    [[model.output]]
    name = "gap"
    formula = "carrier_gap - disc1_width - disc2_width"
    unit = "mm"                      # the output's unit (default "1")
    display_unit = "um"              # optional: the unit to report in
    description = "..."              # optional
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Mapping, Sequence

import numpy as np

from ... import units as _units
from ...errors import InputError
from ...expressions import CONSTANTS, Expression, ExpressionError
from ...model import Model, Quantity
from ...model_kind import ModelKind
from ...options import REQUIRED, option
from ...params import Params, located_unit
from . import dimensions as _dim

#: how the factors' units enter the formulas (module docstring)
UNIT_MODES = ("checked", "factor", "base")


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
    quantities, each usable by later ones and by the outputs (``(formula, unit)``: in that unit);
    ``checked``: dimensional analysis of every formula (``units = "checked"``), else the numbers are
    taken as written (only a trigonometric function of an angle not in radians is refused).
    """

    def __init__(self, outputs, inputs: Sequence[str], input_units: Sequence[str] | None = None, *,
                 definitions: Mapping[str, str | tuple[str, str]] | None = None, checked: bool = True):
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
        self.checked = bool(checked)
        #: what the run's notes say about the formulas (units = "factor": a sum of factors in different units)
        self.warnings: list[str] = []
        known = list(self.inputs)
        scale = {n: _dim.quantity(u) for n, u in zip(self.inputs, self.formula_units)} if checked else {}
        angles = {n: {(n, u)} for n, u in zip(self.inputs, self.formula_units)
                  if _units.dimension(u) == "angle" and _units.factor(u) != 1.0}
        self.definitions: list[tuple[str, Expression]] = []
        for name, value in (definitions or {}).items():
            if not isinstance(name, str) or not name:
                raise ExpressionError(f"definition name must be text, got {name!r}")
            if name in known or name in CONSTANTS:
                raise ExpressionError(f"definition {name!r} has the name of an input, another definition or a "
                                      "constant")
            text, unit = (value if isinstance(value, (tuple, list)) else (value, None))
            what = f"definition {name!r}"
            expr = Expression.parse(text, known, what=what)
            if checked:
                tree, q, number = _dim.check_formula(expr, scale, what)
                tree, scale[name] = _dim.definition_conversion(expr, tree, q, number,
                                                               None if unit is None else _dim.check_unit(unit), what)
                expr = replace(expr, tree=tree)
            else:
                if unit is not None:
                    raise ExpressionError(f"{what}: a unit for a definition needs units = \"checked\"")
                angles[name] = _dim.unchecked_trig(expr, angles, what)
                self.warnings += _dim.mixed_units(expr, dict(zip(self.inputs, self.formula_units)), what)
            self.definitions.append((name, expr))
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
            what = f"output {o.name!r}"
            expr = Expression.parse(o.formula, known, what=what)
            if checked:
                tree, q, number = _dim.check_formula(expr, scale, what)
                expr = replace(expr, tree=_dim.output_conversion(expr, tree, q, number, u, what))
            else:
                _dim.unchecked_trig(expr, angles, what)
                self.warnings += _dim.mixed_units(expr, dict(zip(self.inputs, self.formula_units)), what)
            self.formulas.append(expr)
            outs.append(Quantity(o.name, _units.base_unit(u), disp, o.description))
            self._out_factor.append(_units.factor(u))
        self.outputs = tuple(outs)
        self._out_factor = np.array(self._out_factor)
        self.output_specs = tuple(specs)

    # -- construction from a spec or a study --------------------------------------------
    @classmethod
    def from_spec(cls, spec, outputs, *, definitions: Mapping[str, str] | None = None,
                  units: str = "checked") -> "FormulaModel":
        """Inputs are the spec's factors with their units, dimension-checked (``units="checked"``), or as
        the numbers written in their own unit (``"factor"``) or in base units (``"base"``), unchecked."""
        if units not in UNIT_MODES:
            raise ExpressionError(f"units must be one of {', '.join(map(repr, UNIT_MODES))}, got {units!r}")
        fu = tuple(_units.base_unit(u) for u in spec.units) if units == "base" else tuple(spec.units)
        return cls(outputs, spec.names, fu, definitions=definitions, checked=units == "checked")

    def probe(self, spec, seed: int = 0) -> list:
        """Where an output fails at the nominal or a corner of the bands (:func:`rvtol.models.formula.probe.probe`)."""
        from .probe import probe

        return probe(self, spec, seed)

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

    def dependencies(self) -> dict[str, frozenset[str]]:
        """Each output depends on the inputs its formula names, directly or through the definitions it uses (a
        composed study's ``depends_on``: an output of disc 2 does not list disc 1's factors)."""
        reads: dict[str, frozenset[str]] = {n: frozenset([n]) for n in self.inputs}
        for name, f in self.definitions:
            reads[name] = frozenset().union(*(reads.get(m, frozenset()) for m in f.names))
        return {q.name: frozenset().union(*(reads.get(m, frozenset()) for m in f.names))
                for q, f in zip(self.outputs, self.formulas)}

    def gradient(self, X) -> np.ndarray:
        """Exact ∂Y/∂X, shape ``(n, outputs, inputs)``, in base units (forward-mode AD)."""
        return self.evaluate_with_gradient(X)[1]

    def evaluate_with_gradient(self, X, wrt: Sequence[str] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``(Y, ∂Y/∂X)``; with ``wrt`` (input names) only those columns of the derivative are computed (the others
        are 0): an input left out enters as a constant."""
        X = self.check_input(X)
        n, k = X.shape
        env = self._env(X)
        seeds: dict[str, dict] = {} if wrt is None else {nm: {} for nm in self.inputs if nm not in set(wrt)}
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


def read_definitions(defs_p) -> dict:
    """A ``[model.define]`` table (:class:`rvtol.params.Params`, or None): ``{name: formula or (formula, unit)}``
    in order."""
    definitions: dict = {}
    for name in list(defs_p.keys()) if defs_p is not None else ():
        if isinstance(defs_p.data[name], dict):     # L = { formula = "25", unit = "mm" }
            t = defs_p.sub(name)
            definitions[name] = (t.str("formula"), t.unit("unit"))
            t.finish()
        else:
            definitions[name] = defs_p.str(name)
    return definitions


@dataclass
class OutputTable:
    """``[[model.output]]``: one output of a formula (or vector-loop) model."""

    name: str = option(REQUIRED, "the output's name")
    formula: str = option(REQUIRED, "its expression of the factors and the definitions")
    unit: str = option("1", "the formula's unit (checked against the factors' under units = \"checked\")")
    display_unit: str | None = option(None, "the unit the report shows it in (default: unit; the same dimension)")
    description: str = option("", "what it is, for the report")


def read_outputs(tables: list[OutputTable], error, what: str) -> list[tuple[int, FormulaOutput]]:
    """The ``[[model.output]]`` tables: ``(index, FormulaOutput)`` each, their units checked (``error(key, reason)``:
    the model table's located error, e.g. at ``output[1].unit``); ``what`` names the model in the error when there
    is none."""
    specs = []
    for i, o in enumerate(tables):
        unit = located_unit(o.unit, error, f"output[{i}].unit")
        disp = unit if o.display_unit is None else located_unit(o.display_unit, error, f"output[{i}].display_unit",
                                                                _units.dimension(unit))
        specs.append((i, FormulaOutput(o.name, o.formula, unit, disp, o.description)))
    if not specs:
        raise error("output", f"{what} needs at least one [[model.output]]")
    return specs


@dataclass
class Options:
    """The keys of ``[model] kind = "formula"``."""

    units: str = option("checked", "how the factors' units enter the formulas: checked (dimensional analysis, "
                                   "converted), factor (each factor's number in its own unit, unchecked) or base "
                                   "(in base units, unchecked)", choices=UNIT_MODES)
    define: Params | None = option(None, 'intermediate quantities in order: name = "formula" or {formula, unit}')
    output: list[OutputTable] = option([], "the model's outputs, each a [[model.output]] table")


def build(o: Options, design, spec, error) -> FormulaModel:
    """The study factory (``[model] kind = "formula"``); errors name the file and key."""
    definitions = read_definitions(o.define)
    specs = read_outputs(o.output, error, "a formula model")
    checked = o.units == "checked"
    fu = tuple(_units.base_unit(x) for x in spec.units) if o.units == "base" else tuple(spec.units)
    # build one output at a time after the definitions, so that an error names its own key
    defined: dict = {}
    for name, value in definitions.items():
        defined[name] = value
        try:
            FormulaModel([("_", "0")], spec.names, fu, definitions=defined, checked=checked)
        except ExpressionError as exc:
            raise o.define.error(name, exc.reason) from None
    for i, out in specs:
        try:
            FormulaModel([out], spec.names, fu, definitions=definitions, checked=checked)
        except ExpressionError as exc:
            raise error(f"output[{i}].formula" if exc.reason.startswith(f"output {out.name!r}:") else f"output[{i}]",
                        exc.reason) from None
    try:
        return FormulaModel([out for _, out in specs], spec.names, fu, definitions=definitions, checked=checked)
    except ExpressionError as exc:
        raise error(None, exc.reason) from None


from_study = ModelKind(Options, build, "outputs as formulas of the factors, written in the study (no Python)")


__all__ = ["FormulaModel", "FormulaOutput", "UNIT_MODES", "from_study", "read_definitions", "read_outputs"]
