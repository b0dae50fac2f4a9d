"""The study's model: its ``[model]`` table through the registered factory (the one place a factory's errors
are located), or several ``[[model]]`` tables composed on the same samples (:mod:`rvtol.models.composite`)."""
from __future__ import annotations

from pathlib import Path

from ..design import Design
from ..errors import InputError
from ..model import Model
from ..options import read_options
from ..params import Params, read_toml
from ..patterns import feature_spec, with_patterns
from ..registry import model_factory
from ..spec import ToleranceSpec


def build_model(mp: Params, design: Design | None, spec: ToleranceSpec, file: str) -> Model:
    """The study's ``[model]`` through its registered factory; the one place factory errors are located.

    A factory (and the Model it builds) raises :class:`InputError` without a
    file: an error about the spec's factors (key ``factor...``) belongs to the
    spec file, any other to the ``[model]`` table of the study file; an error
    that already names its file (a bad number in the design) keeps it.
    """
    kind = mp.str("kind")
    factory = model_factory(kind, file)
    try:
        model = factory(mp, design, feature_spec(spec))    # a composite frame's features at their positions
        if not isinstance(model, Model):   # a plug-in's factory (the built-in ones are tested)
            raise InputError(f"the factory of model kind {kind!r} returned {type(model).__name__}, "
                             "not an rvtol.model.Model", key="kind")
        return with_patterns(model, spec)
    except InputError as exc:
        if exc.file is None:
            if (exc.key or "").split(".")[0].split("[")[0] == "factor":
                exc.located(file=spec.file or file)
            else:
                exc.located(file=file, key=None if (exc.key or "").startswith(mp.key) else mp.key)
        raise exc from None


def composed_model(root: Params, mpath: Path | None, design, spec, file: str, inputs: dict,
               build_path: Path | None = None, drawn_build: Path | None = None) -> tuple[Model, ToleranceSpec, object]:
    """Several ``[[model]]`` tables on the same samples (:mod:`rvtol.models.composite`); with a build file,
    its rules (:mod:`rvtol.production.build`) and the spec with its gauge errors.  ``drawn_build``: the build
    of the base study that a study with ``build = false`` does not apply — the values its models read from it
    take their value as drawn (:meth:`rvtol.production.build.BuildRules.as_drawn`: a shim's preload, its target)."""
    from ..models.composite.model import design_quantities, from_study_tables, quantities_from_tables
    from ..models.composite.tables import MappingHead

    tables = root.tables("quantity")
    if mpath is not None:
        mdata, msha = read_toml(mpath)
        mroot = Params(mdata, file=str(mpath))
        head_m = mroot.sub("mapping", {})
        read_options(MappingHead, head_m)
        head_m.finish()
        tables = mroot.tables("quantity") + tables
        mroot.finish()
        inputs["mapping"] = {"path": str(mpath), "sha256": msha}
    try:
        quantities = quantities_from_tables(tables)
    except InputError as exc:
        raise exc.located(file=file) from None

    rules, constants = None, None
    if drawn_build is not None:
        from ..production.build import load_build

        used = [n for q in quantities for n in q.expression.names]
        constants = load_build(drawn_build, spec, design, design_quantities(used, design) + list(quantities)).as_drawn()
    if build_path is not None:
        from ..production.build import extended_spec, load_build

        used = [n for q in quantities for n in q.expression.names]
        rules = load_build(build_path, spec, design, design_quantities(used, design) + list(quantities))
        inputs["build"] = {"path": str(build_path), "sha256": rules.sha256}
        spec = extended_spec(spec, rules)

    def build(params: Params, design_, stage_inputs) -> Model:
        return build_model(params, design_, stage_inputs, file)

    try:
        return from_study_tables(root.tables("model"), quantities, design, spec, build, rules, constants), spec, rules
    except InputError as exc:
        raise exc.located(file=file) from None
