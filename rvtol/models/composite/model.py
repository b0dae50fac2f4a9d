"""Several models on the same samples, wired by declared mappings: one :class:`~rvtol.model.Model`.

One reducer, one drawing-level tolerance spec, every physics::

    drawing factors ──► quantities ──► stage "stackup" ──► stage "torsion" ──► ...
      (the spec)        (expressions)   (its inputs are     (its inputs: expressions of factors,
                                         expressions)        quantities and earlier stages' outputs)

A :class:`CompositeModel` has the spec's factors as inputs and, as outputs, every stage's outputs
(named ``<stage>.<output>``) and the quantities declared as outputs — so intermediate results
(crank-axis offsets from the stack-up, the clearances the torsion curve sees) stay visible.  Monte
Carlo, five-point and global sensitivity, allocation and the report see it as one Model: a drawing
tolerance drives every model consistently, and no tolerance is written twice.

Study file (several ``[[model]]`` tables instead of one ``[model]``)::

    [[quantity]]                       # optional, in the study or in [study] mapping = "file.toml"
    name = "n0_1"
    value = "disc_1.equidistance_mod - 0.62036 * disc_1.moved_distance_mod"   # base units (mm, rad)
    unit = "mm"                        # unit of the value (base unit); display_unit = "um" to show it
    output = true                      # report it as an output too
    description = "normal clearance of disc 1's modified profile at φ0"

    [[model]]
    name = "torsion"                   # outputs torsion.lost_motion, torsion.rigidity, ...
    kind = "torsion_curve"             # any MODELS kind; its own keys as in a one-model study
    outputs = ["lost_motion", "backlash", "rigidity"]    # optional: the outputs to keep (default all)
    [model.inputs]                     # the declared mapping: every input of this model
    "delta_b[1,1]" = "needles.disc_1.crank_1.clearance"
    "E_c[1,1]" = "hypot(stackup.cam_11.u, stackup.cam_11.v)"

    [[model]]
    name = "te"
    kind = "transmission_error"
    same_inputs_as = "torsion"         # the mapping of an earlier model; a [model.inputs] beside it adds
                                       # inputs of this model's own (it cannot remap the earlier model's)

Every expression (:mod:`rvtol.expressions`) reads names in base units: factors, quantities
declared before it, outputs of stages declared before it (``stage.output``) and numbers of the
study's design as ``design.<key>`` (e.g. ``design.cycloid.eccentricity``, in base units: a mapping
that needs a geometry number reads it from the design instead of writing it twice).  An input a
stage does not list stays at the model's nominal (as for a factor a one-model spec does not name).

A sample that any stage cannot evaluate fails with that stage's reason (``<stage>: <reason>``);
later stages skip it.  The model is row-deterministic when its stages are.

**Build.**  A composition may carry the rules by which the reducer is built (``[study] build``,
:mod:`rvtol.production.build`): any object with ``sets`` (the factors it gives their as-built values),
``outputs`` (its own :class:`~rvtol.model.Quantity` outputs), ``reads()`` (set factor or output -> the
names its rule reads) and ``apply(env, n) -> (as-built factor values, named values)``.  It runs between
the drawing factors and the physics: the quantities are computed on the as-drawn factors, the build reads
them, and every quantity and stage then sees the as-built factors (the sample ``X`` itself is not changed).
:meth:`CompositeModel.without_build` is the same composition on the parts as drawn.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, replace
from typing import Callable

import numpy as np

from ... import units
from ...design import DESIGN_PREFIX, design_numbers
from ...errors import InputError
from ...params import Params
from ...expressions import Expression
from .tables import QuantityTable
from ...options import read_options
from ...model import STATUS_NONFINITE, STATUS_OK, Model, Quantity

#: status codes of stage s are STAGE_CODES * (s + 1) + the stage model's own code
STAGE_CODES = 1000


@dataclass(frozen=True)
class MappedQuantity:
    """A named intermediate value: an expression of factors, earlier quantities and stage outputs."""

    name: str
    expression: Expression
    unit: str = "1"                     # base unit of the value
    display_unit: str | None = None
    output: bool = False
    description: str = ""

    @property
    def quantity(self) -> Quantity:
        return Quantity(self.name, self.unit, self.display_unit, self.description)


@dataclass(frozen=True)
class Stage:
    """One model of the composition, its inputs as expressions, the outputs it exposes."""

    name: str
    model: Model
    inputs: tuple[Expression, ...]      # one per model input, in the model's input order
    keep: tuple[int, ...]               # indices of the model's outputs that are exposed
    kind: str = ""

    def output_name(self, j: int) -> str:
        return f"{self.name}.{self.model.outputs[j].name}"


@dataclass(frozen=True)
class StageInputs:
    """What a stage's factory sees in place of a spec: its input names (the declared mapping's keys).

    ``factors`` are the drawing factors that feed an input unchanged (an identity mapping), renamed
    to the input, so factory checks that need a distribution (e.g. the stack-up's zones) still
    apply to them; a computed input has no distribution of its own.
    """

    names: tuple[str, ...]
    units: tuple[str, ...]
    factors: tuple = ()
    file: str | None = None
    correlation: None = None

    def factor(self, name: str):
        for f in self.factors:
            if f.name == name:
                return f
        raise InputError(f"input {name!r} is computed by the mapping; it has no distribution of its own",
                         file=self.file, key=name)

    def index(self, name: str) -> int:
        return self.names.index(name)

    def __len__(self) -> int:
        return len(self.names)


class CompositeModel(Model):
    """Factors -> quantities -> stages, evaluated in declaration order (see the module docstring)."""

    def __init__(self, inputs, input_units, quantities: list[MappedQuantity], stages: list[Stage], build=None,
                 build_outputs: tuple[str, ...] | None = None, constants: dict[str, float] | None = None):
        self.inputs = tuple(inputs)
        self.constants = dict(constants or {})     # named values fixed for every row (a build's values as drawn)
        self.input_units = tuple(input_units)
        self.quantities = tuple(quantities)
        self.stages = tuple(stages)
        self.build = build
        if build is not None:
            unknown = [f for f in build.sets if f not in self.inputs]
            if unknown:
                raise InputError(f"the build sets {unknown[0]!r}, which is not a factor", key="build")
        own = tuple(build.outputs) if build is not None else ()
        self.build_outputs = tuple(q.name for q in own) if build_outputs is None else tuple(build_outputs)
        known = set(self.inputs) | set(self.constants)
        seen_outputs: list[str] = []
        for q in self.quantities:
            _check_names(q.expression, known, f"quantity {q.name!r}", key=f"quantity.{q.name}")
            if q.name in known:
                raise InputError(f"quantity {q.name!r} has the name of a factor or an earlier quantity",
                                 key=f"quantity.{q.name}")
            known.add(q.name)
        known |= {q.name for q in own}
        for st in self.stages:
            if len(st.inputs) != len(st.model.inputs):
                raise InputError(f"stage {st.name!r}: {len(st.inputs)} input expressions for "
                                 f"{len(st.model.inputs)} model inputs", key=f"model.{st.name}.inputs")
            for name, e in zip(st.model.inputs, st.inputs):
                _check_names(e, known, f"input {name!r} of model {st.name!r}")
            for j in range(len(st.model.outputs)):
                known.add(st.output_name(j))
                seen_outputs.append(st.output_name(j))
        self.outputs = tuple([q.quantity for q in self.quantities if q.output]
                             + [q for q in own if q.name in self.build_outputs]
                             + [_renamed(o, f"{st.name}.{o.name}") for st in self.stages
                                for o in (st.model.outputs[j] for j in st.keep)])
        self.status_reasons = {STATUS_NONFINITE: Model.status_reasons[STATUS_NONFINITE]}
        for s, st in enumerate(self.stages):
            for code, why in st.model.status_reasons.items():
                self.status_reasons[STAGE_CODES * (s + 1) + int(code)] = f"{st.name}: {why}"

    # -- evaluation ---------------------------------------------------------------------------
    def environment(self, X: np.ndarray, stages: set[str] | None = None) -> tuple[dict[str, np.ndarray], np.ndarray]:
        """Every named value of the composition for the rows of ``X`` (base units), and the status;
        ``stages``: evaluate only these stages (their outputs alone are in the environment)."""
        X = self.check_input(X)
        n = len(X)
        env: dict[str, np.ndarray] = {name: X[:, j] for j, name in enumerate(self.inputs)}
        env.update({name: np.full(n, float(v)) for name, v in self.constants.items()})
        status = np.zeros(n, dtype=np.int16)
        self._quantities(env, n)
        if self.build is not None:                  # the reducer as built from this sample's parts
            changed, named = self.build.apply(env, n)
            env.update(changed)
            self._quantities(env, n)
            env.update(named)
        for s, st in enumerate(self.stages):
            if stages is not None and st.name not in stages:
                continue
            Xs = self.stage_matrix(st, env, n)
            good = (status == STATUS_OK) & np.all(np.isfinite(Xs), axis=1)
            status[(status == STATUS_OK) & ~good] = STATUS_NONFINITE
            Ys = np.full((n, len(st.model.outputs)), np.nan)
            if good.any():
                y, ss = _distinct_rows(st.model, Xs[good])
                rows = np.flatnonzero(good)
                Ys[rows] = y
                bad = ss != STATUS_OK
                status[rows[bad]] = STAGE_CODES * (s + 1) + ss[bad]
                Ys[rows[bad]] = np.nan
            for j in range(len(st.model.outputs)):
                env[st.output_name(j)] = Ys[:, j]
        return env, status

    def _quantities(self, env: dict, n: int) -> None:
        for q in self.quantities:
            env[q.name] = _column(q.expression.evaluate(env), n)

    def without_build(self) -> "CompositeModel":
        """The same composition on the parts as drawn (no build rules applied); a build value a stage reads takes
        its value as drawn (a shim-set preload: its target, :meth:`rvtol.production.build.BuildRules.as_drawn`)."""
        drawn = self.build.as_drawn() if self.build is not None and hasattr(self.build, "as_drawn") else {}
        return CompositeModel(self.inputs, self.input_units, list(self.quantities), list(self.stages),
                              constants={**self.constants, **drawn})

    @staticmethod
    def stage_matrix(st: Stage, env: dict, n: int) -> np.ndarray:
        """The input matrix of stage ``st`` (base units) from the named values ``env``."""
        if not st.inputs:
            return np.zeros((n, 0))
        return np.column_stack([_column(e.evaluate(env), n) for e in st.inputs])

    def evaluate_with_status(self, X):
        env, status = self.environment(X)
        n = len(status)
        if not self.outputs:
            return np.zeros((n, 0)), status
        Y = np.column_stack([_column(env[q.name], n) for q in self.outputs])
        Y[status != STATUS_OK] = np.nan
        return Y, status

    def evaluate(self, X):
        return self.evaluate_with_status(X)[0]

    # -- introspection ------------------------------------------------------------------------
    def stage(self, name: str) -> Stage:
        for st in self.stages:
            if st.name == name:
                return st
        raise InputError(f"unknown model {name!r} (the study's models: {', '.join(s.name for s in self.stages)})")

    def stage_inputs(self, name: str, X: np.ndarray) -> np.ndarray:
        """The inputs (base units) stage ``name`` receives for the rows of ``X`` (only the stages whose
        outputs they read are evaluated)."""
        st = self.stage(name)
        env, _ = self.environment(X, self.upstream(name))
        return self.stage_matrix(st, env, len(X))

    def upstream(self, name: str) -> set[str]:
        """The stages whose outputs the inputs of stage ``name`` read, directly or through earlier stages."""
        producer = {st.output_name(j): st for st in self.stages for j in range(len(st.model.outputs))}
        need: set[str] = set()
        todo = [self.stage(name)]
        while todo:
            for e in todo.pop().inputs:
                for m in e.names:
                    src = producer.get(m)
                    if src is not None and src.name not in need:
                        need.add(src.name)
                        todo.append(src)
        return need

    def restricted(self, outputs) -> "CompositeModel":
        """The same composition with only ``outputs`` (names of this model's outputs) and the stages they
        need (the stages that give them and, transitively, the stages whose outputs feed those) — to
        evaluate a few outputs without paying for the stages that do not reach them."""
        outputs = list(outputs)
        for o in outputs:
            self.output(o)
        of_stage = {st.output_name(j): st.name for st in self.stages for j in range(len(st.model.outputs))}
        need: set[str] = set()
        for o in outputs:
            if o in of_stage:
                need |= {of_stage[o]} | self.upstream(of_stage[o])
        stages = [replace(st, keep=tuple(j for j in range(len(st.model.outputs)) if st.output_name(j) in outputs))
                  for st in self.stages if st.name in need]
        quantities = [replace(q, output=q.output and q.name in outputs) for q in self.quantities]
        return CompositeModel(self.inputs, self.input_units, quantities, stages, self.build,
                              tuple(o for o in self.build_outputs if o in outputs), self.constants)

    def mapping_table(self) -> list[dict]:
        """Every stage input and quantity with the expression that feeds it (for the report)."""
        rows = [{"model": "(quantity)", "input": q.name, "expression": q.expression.text,
                 "unit": units.label(q.unit)} for q in self.quantities]
        for st in self.stages:
            for name, unit, e in zip(st.model.inputs, st.model.input_units, st.inputs):
                rows.append({"model": st.name, "input": name, "expression": e.text, "unit": units.label(unit)})
        return rows

    def depends_on(self) -> dict[str, set[str]]:
        """Output name -> the factors it depends on (structurally, through the expressions; inside a
        stage through :meth:`Model.dependencies` where the stage's model knows them, else on all its
        inputs)."""
        deps: dict[str, set[str]] = {n: {n} for n in self.inputs}
        deps.update({c: set() for c in self.constants})     # a build value as drawn: the same for every unit

        def quantities():
            for q in self.quantities:
                deps[q.name] = set().union(set(), *(deps[m] for m in q.expression.names))

        quantities()
        if self.build is not None:      # a set factor and a build output depend on what their rule reads
            built = {name: set().union(set(), *(deps[m] for m in reads)) for name, reads in self.build.reads().items()}
            deps.update(built)
            quantities()
        for st in self.stages:
            feed = {name: set().union(set(), *(deps[m] for m in e.names))
                    for name, e in zip(st.model.inputs, st.inputs)}
            inner = st.model.dependencies() or {}
            for j, o in enumerate(st.model.outputs):
                used = inner.get(o.name, st.model.inputs)
                deps[st.output_name(j)] = set().union(set(), *(feed[n] for n in used))
        return {q.name: deps[q.name] for q in self.outputs}


def _renamed(q: Quantity, name: str) -> Quantity:
    return Quantity(name, q.unit, q.display_unit, q.description)


def _distinct_rows(model: Model, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``model.evaluate_with_status(X)``, each distinct row evaluated once: a stage whose inputs a batch leaves at the
    same values (the five-point stencils and Sobol groups of factors that do not reach it) is not evaluated again for
    them.  Exact: a model's row does not depend on the batch it is in (:class:`rvtol.model.Model`)."""
    if len(X) > 1 and X.shape[1]:
        uniq, inverse = np.unique(X, axis=0, return_inverse=True)
        if len(uniq) < len(X):
            y, ss = model.evaluate_with_status(uniq)
            inverse = inverse.ravel()
            return np.asarray(y, dtype=float)[inverse], np.asarray(ss)[inverse]
    y, ss = model.evaluate_with_status(X)
    return np.asarray(y, dtype=float), np.asarray(ss)


def _column(v, n: int) -> np.ndarray:
    return np.broadcast_to(np.asarray(v, dtype=float), (n,)).astype(float, copy=False)


def _names_of(text) -> tuple[str, ...]:
    try:
        return Expression.parse(text).names
    except InputError:
        return ()          # reported with its key where the expression is read


def _check_names(e: Expression, known: set[str], what: str, key: str | None = None) -> None:
    unknown = [m for m in e.names if m not in known]
    if unknown:
        raise InputError(f"{what}: unknown name {unknown[0]!r} in {e.text!r} (a factor of the spec, a quantity "
                         "declared before, a design number design.<key>, or an output of a model declared before)",
                         key=key)


# --------------------------------------------------------------------------- from a study file
_STAGE_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
#: keys of a [[model]] table that belong to the composition, not to the model's factory
COMPOSITION_KEYS = ("name", "inputs", "same_inputs_as", "outputs")
#: prefix of a design number in an expression
def design_quantities(names, design) -> list[MappedQuantity]:
    """A constant quantity ``design.<key>`` (base units) for every such name used in an expression
    (:func:`rvtol.design.design_numbers`)."""
    return [MappedQuantity(n, Expression.parse(repr(value)), units.base_unit(units.canonical(
                design.param(n[len(DESIGN_PREFIX):]).unit)), description=f"design {n[len(DESIGN_PREFIX):]}")
            for n, value in design_numbers(names, design).items()]


def quantities_from_tables(tables: list[Params]) -> list[MappedQuantity]:
    """``[[quantity]]`` tables (name, value, unit, display_unit, output, description)."""
    out = []
    for t in tables:
        q = read_options(QuantityTable, t)
        t.finish()
        try:
            e = Expression.parse(q.value)
        except InputError as exc:
            raise t.error("value", exc.reason) from None
        unit = t.canonical_unit("unit", q.unit)
        base = units.base_unit(unit)
        if base != unit:
            raise t.error("unit", f"a quantity's value is in base units: write {base!r} (and display_unit = "
                                  f"{unit!r} to show it in {unit})")
        disp = None if q.display_unit is None else t.canonical_unit("display_unit", q.display_unit)
        if disp is not None and units.dimension(disp) != units.dimension(unit):
            raise t.error("display_unit", f"{disp!r} is not a {units.dimension(unit)}")
        out.append(MappedQuantity(q.name, e, unit, disp, q.output, q.description))
    return out


def from_study_tables(model_tables: list[Params], quantities: list[MappedQuantity], design, spec,
                      build: Callable, rules=None, constants: dict | None = None) -> CompositeModel:
    """A CompositeModel from the study's ``[[model]]`` tables.

    ``build(params, design, inputs)`` builds one model through its registered factory (the study's
    :func:`rvtol.study.build_model`, which also locates its errors); ``inputs`` is a
    :class:`StageInputs` standing in for the spec.  ``rules``: the reducer's build rules (module
    docstring; ``spec`` then holds their gauge factors).  ``constants``: named values every unit has (a build's
    values as drawn, :meth:`CompositeModel.without_build`).
    """
    if not model_tables:
        raise InputError("a composed study needs at least one [[model]]", key="model")
    used = [n for q in quantities for n in q.expression.names]
    if rules is not None:
        used += [n for names in rules.reads().values() for n in names]
    for t in model_tables:
        raw = t.data.get("inputs")
        if isinstance(raw, dict):
            used += [n for v in raw.values() if isinstance(v, (str, int, float)) for n in _names_of(v)]
    quantities = design_quantities(used, design) + list(quantities)
    known = set(spec.names) | {q.name for q in quantities}
    if rules is not None:
        known |= {q.name for q in rules.outputs}
    known |= set(constants or {})
    qunits = {q.name: q.unit for q in quantities}
    stages: list[Stage] = []
    for t in model_tables:
        name = t.str("name")
        if not _STAGE_NAME.match(name):
            raise t.error("name", f"invalid model name {name!r} (a letter, then letters, digits or _)")
        if any(st.name == name for st in stages):
            raise t.error("name", f"two models are named {name!r}")
        exprs: dict[str, Expression] = {}
        if "same_inputs_as" in t:
            other = t.str("same_inputs_as")
            src = next((st for st in stages if st.name == other), None)
            if src is None:
                raise t.error("same_inputs_as", f"no model {other!r} is declared before this one")
            exprs = dict(zip(src.model.inputs, src.inputs))
        inp = t.sub("inputs", {})
        for k in inp.keys():
            if k in exprs:
                raise inp.error(k, f"already mapped by same_inputs_as = {t.str('same_inputs_as')!r} ([model.inputs] "
                                   "beside same_inputs_as adds inputs; it does not remap them)")
            try:
                exprs[k] = Expression.parse(inp.raw(k))
            except InputError as exc:
                raise inp.error(k, exc.reason) from None
            unknown = [m for m in exprs[k].names if m not in known]
            if unknown:
                raise inp.error(k, f"unknown name {unknown[0]!r} in {exprs[k].text!r} (a factor of the spec, a "
                                   "quantity, a design number design.<key>, or an output of a model declared before)")
        inp.finish()
        keep_names = t.strs("outputs", None)
        rest = Params({k: v for k, v in t.data.items() if k not in COMPOSITION_KEYS}, file=t.file, key=t.key)
        for k in rest.keys():
            t.raw(k)
        identity = []
        unit_of = []
        for k, e in exprs.items():
            if e.is_name and e.names[0] in spec.names:
                f = spec.factor(e.names[0])
                identity.append(replace(f, name=k))
                unit_of.append(f.unit)
            else:
                unit_of.append(qunits.get(e.names[0], "1") if e.is_name else "1")
        stage_inputs = StageInputs(tuple(exprs), tuple(unit_of), tuple(identity), spec.file)
        model = build(rest, design, stage_inputs)
        if tuple(model.inputs) != tuple(exprs):
            raise t.error("inputs", f"model {name!r} took the inputs {list(model.inputs)} for the mapped "
                                    f"{list(exprs)}")
        outs = [o.name for o in model.outputs]
        if keep_names is None:
            keep = tuple(range(len(outs)))
        else:
            bad = [o for o in keep_names if o not in outs]
            if bad:
                raise t.error("outputs", f"model {name!r} has no output {bad[0]!r} (it has: {', '.join(outs)})")
            keep = tuple(outs.index(o) for o in keep_names)
        stage = Stage(name, model, tuple(exprs.values()), keep, rest.data.get("kind", ""))
        stages.append(stage)
        known |= {stage.output_name(j) for j in range(len(outs))}
    return CompositeModel(spec.names, [units.base_unit(u) for u in spec.units], quantities, stages, rules,
                          constants=constants or {})
