"""Where study files find models and analyses by ``kind``.

Entries are ``"module:attribute"`` strings, imported only when a study uses
them (so a study does not pay for numba or cvxpy it does not need).

* a **model factory** is ``factory(params, design, spec) -> Model`` where
  ``params`` is the study's ``[model]`` table (:class:`rvtol.params.Params`,
  minus ``kind``), ``design`` the study's Design (or None) and ``spec`` its
  ToleranceSpec; it must call ``params.finish()`` so typos are reported;
* an **analysis** is ``analysis(ctx, params) -> Section | list[Section]``
  where ``ctx`` is the :class:`rvtol.study.StudyContext` (design, spec,
  model, Monte Carlo result, executor, seed...) and ``params`` the
  ``[[analysis]]`` table minus ``kind``.
"""
from __future__ import annotations

import importlib

from .errors import SpecError

MODELS: dict[str, str] = {
    "linear": "rvtol.models.linear.model:from_study",
    "lost_motion": "rvtol.models.lost_motion.model:from_study",
    "adjusted_assembly": "rvtol.models.adjustment.model:from_study",
    "stackup": "rvtol.models.stackup.model:from_study",
    "torsional_stiffness": "rvtol.models.stiffness.model:from_study",
    "torsion_curve": "rvtol.models.torsion_curve.model:from_study",
    "transmission_error": "rvtol.models.transmission.model:from_study",
}

ANALYSES: dict[str, str] = {
    "transmission_error_curve": "rvtol.models.transmission.analyses:TECurve",
    "transmission_error_sensitivity": "rvtol.models.transmission.analyses:TESensitivity",
    "stackup_linear": "rvtol.models.stackup.linearise:StackupLinear",
    "stackup_graph": "rvtol.models.stackup.analyses:StackupGraph",
    "stackup_sequences": "rvtol.models.stackup.analyses:StackupSequences",
    "stackup_domains": "rvtol.models.stackup.analyses:StackupDomains",
    "stackup_shaft_hole": "rvtol.models.stackup.analyses:StackupShaftHole",
    "allocation": "rvtol.allocation.analyses:AllocationAnalysis",
    "local_sensitivity": "rvtol.sensitivity.analyses:LocalSensitivity",
    "sensitivity_curve": "rvtol.sensitivity.analyses:SensitivityCurve",
    "contributions": "rvtol.sensitivity.analyses:Contributions",
    "sobol": "rvtol.sensitivity.analyses:Sobol",
    "morris": "rvtol.sensitivity.analyses:Morris",
    "fast": "rvtol.sensitivity.analyses:Fast",
    "delta": "rvtol.sensitivity.analyses:Delta",
    "lost_motion_breakdown": "rvtol.models.lost_motion.analyses:LostMotionBreakdown",
    "lost_motion_reproduction": "rvtol.models.lost_motion.analyses:LostMotionReproduction",
    "adjustment": "rvtol.models.adjustment.analyses:AdjustmentAnalysis",
    "adjustment_reproduction": "rvtol.reproduction.doc002_adjustment:AdjustmentReproduction",
    "stiffness_reproduction": "rvtol.models.stiffness.analyses:StiffnessReproduction",
    "torsion_curve": "rvtol.models.torsion_curve.analyses:TorsionCurveAnalysis",
}


def _load(table: dict[str, str], kind: str, what: str, file: str | None, key: str):
    if kind not in table:
        raise SpecError(f"unknown {what} kind {kind!r} (known: {', '.join(sorted(table))})", file=file, key=key)
    mod, attr = table[kind].split(":")
    return getattr(importlib.import_module(mod), attr)


def model_factory(kind: str, file: str | None = None):
    return _load(MODELS, kind, "model", file, "model.kind")


def analysis_function(kind: str, file: str | None = None, key: str = "analysis.kind"):
    return _load(ANALYSES, kind, "analysis", file, key)
