"""Where study files find models and analyses by ``kind``.

Entries are ``"module:attribute"`` strings, imported only when a study uses
them (so a study does not pay for numba or cvxpy it does not need).  The
contract (tested over every entry by ``tests/architecture/test_architecture.py``):

* a **model factory** is ``factory(params, design, spec) -> Model``: ``params``
  is the study's ``[model]`` table (:class:`rvtol.params.Params`, ``kind``
  already read), ``design`` the study's Design (or None), ``spec`` its
  ToleranceSpec.  It reads its keys from ``params`` (the study loader reports
  keys nobody read) and may raise :class:`rvtol.errors.InputError`; the study
  loader (:func:`rvtol.study.build_model`) locates an error without a file:
  ``factor…`` keys in the spec file, anything else in the ``[model]`` table;
* an **analysis** is a subclass of :class:`rvtol.analysis.Analysis`:
  ``cls(params, study)`` validates the ``[[analysis]]`` table when the study
  loads, ``run(ctx)`` returns report Sections after the Monte Carlo.

Installed packages add model kinds of their own through entry points in the group
``rvtol.models`` (``[project.entry-points."rvtol.models"] my_kind = "mypkg.models:from_study"``),
found with :mod:`importlib.metadata` when a study names a kind that is not built in (a built-in
kind wins over an entry point of the same name); a study can also name a factory directly
(``kind = "python"``, :mod:`rvtol.models.custom.model`).

Installed packages add analysis kinds the same way (group ``rvtol.analyses``, the class as the
entry point's object): the reproduction wing (``studies/reproduction``, distribution
``rvtol-reproduction``) registers its five analyses so; a built-in kind wins here too.
"""
from __future__ import annotations

import importlib

from .errors import SpecError, did_you_mean

MODELS: dict[str, str] = {
    "linear": "rvtol.models.linear.model:from_study",
    "lost_motion": "rvtol.models.lost_motion.model:from_study",
    "transmission_error": "rvtol.models.transmission_error.model:from_study",
    "torsional_stiffness": "rvtol.models.stiffness.model:from_study",
    "torsion_curve": "rvtol.models.torsion_curve.model:from_study",
    "stackup": "rvtol.models.stackup.model:from_study",
    "pin_ring_fit": "rvtol.models.pin_ring.model:from_study",
    "pin_ring_preload": "rvtol.models.pin_ring.model:preload_from_study",
    "adjusted_assembly": "rvtol.models.adjustment.model:from_study",
    "formula": "rvtol.models.formula.model:from_study",
    "vector_loop": "rvtol.models.vector_loop.model:from_study",
    "python": "rvtol.models.custom.model:from_study",
}

#: the entry-point group of model kinds registered by installed packages
ENTRY_POINT_GROUP = "rvtol.models"
#: the entry-point group of analysis kinds registered by installed packages
ANALYSIS_ENTRY_POINT_GROUP = "rvtol.analyses"

ANALYSES: dict[str, str] = {
    # model-specific
    "lost_motion_breakdown": "rvtol.models.lost_motion.analyses:LostMotionBreakdown",
    "lost_motion_screening": "rvtol.models.screening.analyses:LostMotionScreening",
    "transmission_error_curve": "rvtol.models.transmission_error.analyses:TECurve",
    "transmission_error_sensitivity": "rvtol.models.transmission_error.analyses:TESensitivity",
    "stiffness_breakdown": "rvtol.models.stiffness.analyses:StiffnessBreakdown",
    "torsion_curve": "rvtol.models.torsion_curve.analyses:TorsionCurveAnalysis",
    "compliance_breakdown": "rvtol.models.torsion_curve.analyses:ComplianceBreakdown",
    "stackup_linear": "rvtol.models.stackup.analyses:StackupLinear",
    "stackup_graph": "rvtol.models.stackup.analyses:StackupGraph",
    "stackup_sequences": "rvtol.models.stackup.analyses:StackupSequences",
    "stackup_domains": "rvtol.models.stackup.analyses:StackupDomains",
    "adjustment": "rvtol.models.adjustment.analyses:AdjustmentAnalysis",
    # any model
    "local_sensitivity": "rvtol.sensitivity.analyses:LocalSensitivity",
    "sensitivity_curve": "rvtol.sensitivity.analyses:SensitivityCurve",
    "contributions": "rvtol.sensitivity.analyses:Contributions",
    "sobol": "rvtol.sensitivity.analyses:Sobol",
    "morris": "rvtol.sensitivity.analyses:Morris",
    "fast": "rvtol.sensitivity.analyses:Fast",
    "delta": "rvtol.sensitivity.analyses:Delta",
    "given_data": "rvtol.sensitivity.analyses:GivenData",
    "pce": "rvtol.sensitivity.analyses:PCE",
    "sensitivity_matrix": "rvtol.sensitivity.analyses:SensitivityMatrix",
    "allocation": "rvtol.allocation.analyses:AllocationAnalysis",
    "stack_conventions": "rvtol.stacking.analyses:StackConventionsAnalysis",
    "tail_probability": "rvtol.stacking.analyses:TailProbabilityAnalysis",
    "calibration": "rvtol.models.calibration.analyses:CalibrationAnalysis",
    "validation": "rvtol.validation.analyses:ValidationAnalysis",
    "epistemic_band": "rvtol.epistemic.analyses:EpistemicBand",
    "per_unit_prediction": "rvtol.production.analyses:PerUnitPrediction",
    "per_serial_update": "rvtol.production.analyses:PerSerialUpdate",
    "selective_assembly": "rvtol.production.analyses:SelectiveAssembly",
}


#: the tables of the study file and of the input files it names, read by a declared schema (not kinds): name -> their
#: declared options (``rvtol kinds NAME`` lists the keys)
TABLES: dict[str, str] = {
    # the study file's own tables
    "study": "rvtol.study.head:StudyHead",
    "sampling": "rvtol.run_options:SamplingOptions",
    "execution": "rvtol.run_options:ExecutionOptions",
    "report": "rvtol.run_options:ReportOptions",
    "requirement": "rvtol.spec.requirements:RequirementTable",
    "gate": "rvtol.ci.gates:GateTable",
    # a spec (TOML, or a table's rows) and a study's own [[factor]] tables (rvtol.spec)
    "spec": "rvtol.spec.tables:SpecHead",
    "factor": "rvtol.spec.tables:FactorTable",
    "correlation": "rvtol.spec.tables:CorrelationTable",
    # a design file (rvtol.design): its [design] head and each number
    "design": "rvtol.design:DesignHead",
    "design_parameter": "rvtol.design:DesignEntry",
    # a composed study's [[quantity]] tables and its mapping file (rvtol.models.composite)
    "quantity": "rvtol.models.composite.tables:QuantityTable",
    "mapping": "rvtol.models.composite.tables:MappingHead",
    # a build file (rvtol.production.build)
    "build": "rvtol.production.build_tables:BuildHead",
    "fit": "rvtol.production.build_tables:FitTable",
    "shim": "rvtol.production.build_tables:ShimTable",
    "choice": "rvtol.production.build_tables:ChoiceTable",
    # a cost file (rvtol.allocation.cost)
    "costs": "rvtol.allocation.cost:CostsHead",
    "curve": "rvtol.allocation.cost:CurveTable",
    # a published-data file (rvtol.validation.published)
    "source": "rvtol.validation.published:SourceTable",
    "figure": "rvtol.validation.published:FigureTable",
    "missing": "rvtol.validation.published:MissingTable",
    # a 6-DOF stack-up's assembly file (rvtol.models.stackup.graph) and its study's [[analysis.domain]]
    "assembly": "rvtol.models.stackup.assembly_tables:AssemblyHead",
    "dimension": "rvtol.models.stackup.assembly_tables:DimensionTable",
    "part": "rvtol.models.stackup.assembly_tables:PartTable",
    "feature": "rvtol.models.stackup.assembly_tables:FeatureTable",
    "deviation": "rvtol.models.stackup.assembly_tables:DeviationTable",
    "assembly_fit": "rvtol.models.stackup.assembly_tables:AssemblyFitTable",
    "sequence": "rvtol.models.stackup.assembly_tables:SequenceTable",
    "kc": "rvtol.models.stackup.assembly_tables:KCTable",
    "domain": "rvtol.models.stackup.assembly_tables:DomainTable",
    # an adjusted assembly's description (rvtol.models.adjustment.description)
    "adjustment_assembly": "rvtol.models.adjustment.description_tables:AdjustmentHead",
    "adjustment_weights": "rvtol.models.adjustment.description_tables:WeightsTable",
    "adjustment_measurement": "rvtol.models.adjustment.description_tables:MeasurementTable",
    "adjustment_chain": "rvtol.models.adjustment.description_tables:ChainTable",
    "adjustment_kc": "rvtol.models.adjustment.description_tables:AdjustmentKCTable",
    "adjustment_step": "rvtol.models.adjustment.description_tables:AdjustmentStepTable",
    "adjustment_observation": "rvtol.models.adjustment.description_tables:ObservationTable",
}


#: the tables of :data:`TABLES` by the file they belong to, as ``rvtol kinds`` lists them
TABLE_FILES: dict[str, tuple[str, ...]] = {
    "the study": ("study", "sampling", "execution", "report", "requirement", "gate"),
    "a spec": ("spec", "factor", "correlation"),
    "a design file": ("design", "design_parameter"),
    "a composed study's mapping": ("quantity", "mapping"),
    "a build file": ("build", "fit", "shim", "choice"),
    "a cost file": ("costs", "curve"),
    "a published-data file": ("source", "figure", "missing"),
    "an assembly file": ("assembly", "dimension", "part", "feature", "deviation", "assembly_fit", "sequence", "kc",
                         "domain"),
    "an adjusted assembly": ("adjustment_assembly", "adjustment_weights", "adjustment_measurement", "adjustment_chain",
                             "adjustment_kc", "adjustment_step", "adjustment_observation"),
}


def table_options(name: str):
    """The options class of the study's table ``name`` (:data:`TABLES`)."""
    return _load(TABLES, name, "table", None, name)


def curve_reader():
    """The reader of a measured hysteresis curve by the maker's definitions (the torsion-curve model's): what the
    per-serial update's ``curves`` use (:mod:`rvtol.production.per_serial`, which imports no model)."""
    mod, attr = "rvtol.models.torsion_curve.measured:hysteresis_figures".split(":")
    return getattr(importlib.import_module(mod), attr)


def _load(table: dict[str, str], kind: str, what: str, file: str | None, key: str):
    if kind not in table:
        raise SpecError(f"unknown {what} kind {kind!r}{did_you_mean(kind, table)} (known: {', '.join(sorted(table))})",
                        file=file, key=key)
    mod, attr = table[kind].split(":")
    return getattr(importlib.import_module(mod), attr)


def plugin_models() -> dict[str, object]:
    """Model kinds registered by installed packages: name -> entry point (built-in kinds excluded)."""
    from importlib.metadata import entry_points

    return {ep.name: ep for ep in entry_points(group=ENTRY_POINT_GROUP) if ep.name not in MODELS}


def model_factory(kind: str, file: str | None = None):
    """The factory of a model kind: built in (:data:`MODELS`) or an installed entry point."""
    if kind not in MODELS:
        ep = plugin_models().get(kind)
        if ep is not None:
            try:
                return ep.load()
            except Exception as exc:  # ImportError or an error in the plug-in's module
                raise SpecError(f"model kind {kind!r} is registered by entry point {ep.value!r} "
                                f"({ENTRY_POINT_GROUP}), which cannot be loaded ({type(exc).__name__}: {exc})",
                                file=file, key="model.kind") from None
        plugins = sorted(plugin_models())
        known = sorted(MODELS) + plugins
        raise SpecError(f"unknown model kind {kind!r}{did_you_mean(kind, known)} (known: {', '.join(known)})", file=file,
                        key="model.kind")
    return _load(MODELS, kind, "model", file, "model.kind")


def plugin_analyses() -> dict[str, object]:
    """Analysis kinds registered by installed packages: name -> entry point (built-in kinds excluded)."""
    from importlib.metadata import entry_points

    return {ep.name: ep for ep in entry_points(group=ANALYSIS_ENTRY_POINT_GROUP) if ep.name not in ANALYSES}


def analysis_function(kind: str, file: str | None = None, key: str = "analysis.kind"):
    """The class of an analysis kind: built in (:data:`ANALYSES`) or an installed entry point."""
    if kind not in ANALYSES:
        ep = plugin_analyses().get(kind)
        if ep is not None:
            try:
                cls = ep.load()
            except Exception as exc:  # ImportError or an error in the plug-in's module
                raise SpecError(f"analysis kind {kind!r} is registered by entry point {ep.value!r} "
                                f"({ANALYSIS_ENTRY_POINT_GROUP}), which cannot be loaded ({type(exc).__name__}: {exc})",
                                file=file, key=key) from None
            from .analysis import Analysis

            if not (isinstance(cls, type) and issubclass(cls, Analysis) and cls.Options is not None):
                raise SpecError(f"analysis kind {kind!r} is registered by entry point {ep.value!r}, which is not an "
                                "rvtol analysis (a subclass of rvtol.analysis.Analysis declaring Options)",
                                file=file, key=key)
            return cls
        known = sorted(ANALYSES) + sorted(plugin_analyses())
        raise SpecError(f"unknown analysis kind {kind!r}{did_you_mean(kind, known)} (known: {', '.join(known)})",
                        file=file, key=key)
    return _load(ANALYSES, kind, "analysis", file, key)
