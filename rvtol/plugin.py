"""The public plug-in API: the one module a package outside rvtol imports to add analysis kinds.

A plug-in is a distribution of its own that registers its :class:`Analysis` subclasses under the entry-point group
:data:`ANALYSIS_ENTRY_POINT_GROUP` (``rvtol.analyses``; model factories under :data:`MODEL_ENTRY_POINT_GROUP`,
``rvtol.models``) and imports rvtol through this module alone (and the top-level :mod:`rvtol`): every name below
keeps its meaning and signature from release to release; a change to one is a change of this module, said in its
commit.  Nothing of the library imports this module (``tests/architecture/test_architecture.py``), and the reproduction
wing (``studies/reproduction``) imports nothing else of rvtol (checked there too).  The names, each what it is:

**The analysis contract** (``rvtol docs api``, "Adding a capability")

- ``Analysis`` — the base class of a study analysis: ``kind``, ``title``, ``Options``, ``compute(ctx)``, ``layout``
- ``CommonOptions`` — the keys every analysis takes (``key``, ``title``); an analysis' ``Options`` extends it
- ``option`` — one declared key of an ``Options`` dataclass: default, meaning, unit and constraints
- ``REQUIRED`` — the default of a key a study must give
- ``ANALYSIS_ENTRY_POINT_GROUP`` — ``"rvtol.analyses"``: the entry-point group a plug-in registers its analyses in
- ``MODEL_ENTRY_POINT_GROUP`` — ``"rvtol.models"``: the entry-point group of model kinds (a ``ModelKind``, or a plain
  factory ``(params, design, spec)``)
- ``ModelKind`` — a model kind: its ``[model]`` table's ``Options`` (a schema), ``build(options, design, spec, error)``
  and title; ``rvtol kinds KIND`` lists its keys

**Errors** (one located line and exit code 2 for bad input)

- ``InputError`` — bad input in a study table, located by key (the study loader adds the file)
- ``SpecError`` — bad input located by file and key

**Inputs, units and statistics**

- ``Params`` — typed, located access to a TOML table (``str``, ``quantity``, …; ``finish()`` refuses unread keys)
- ``read_toml`` — a TOML file as ``(table, sha256)``, or a located :class:`SpecError`
- ``load_design`` — a design file (nominal geometry, each number with its source) as a ``Design``
- ``units`` — the unit module: mm, N, s, rad inside; ``to_base``, ``from_base``, ``convert``, ``dimension``, ``label``
- ``stats`` — the statistics module: ``mean_ci``, ``percentile_ci`` and the other intervals

**Results and reports**

- ``Section`` — one report section with its ``summary.json`` entry
- ``Table`` — a report table of a data frame, with its caption and number format
- ``Figure`` — a report figure (PNG bytes) with its caption
- ``Text`` — a report paragraph
- ``figure_png`` — a matplotlib figure as PNG bytes (rendered once, after the run)
- ``frame_records`` — a data frame as JSON-ready records for ``summary.json``
- ``COLORS`` — the report's colours by role (``data``, ``fit``, ``limit``, ``ci``, ``ok``); imports matplotlib
- ``new_axes`` — ``(fig, ax)``: the given axes or a fresh figure in the report's style; imports matplotlib

**Model entry points** — the physics of the reference documents that a reproduction sets against their printed
figures, by document:

- ``TESensitivity`` — doc 000: the ``transmission_error_sensitivity`` analysis (its title and options)
- ``TESensitivityOptions`` — doc 000: the keys of the TE sensitivity analysis (model, factors, magnitudes)
- ``TESensitivityPlan`` — doc 000: what the TE sensitivity analysis builds (its model over the factors, their spec)
- ``te_sensitivity_plan`` — doc 000: that plan of the analysis' options (``prepare``)
- ``te_sensitivity`` — doc 000: the TE sensitivity curves of factors over magnitudes (``TESensitivityResult``)
- ``TESensitivityResult`` — doc 000: the sensitivity curves, their ranking and linearity
- ``TransmissionErrorModel`` — doc 000: the 20-DOF transmission-error model of a design
- ``transmission_texts`` — doc 000: the TE sections' layouts (``sensitivity``, ``linearity_and_notes``)
- ``LostMotionOptions`` — doc 001: the keys of an analysis of the lost-motion model
- ``analytic_frame`` — doc 001: the per-stage analytic lost motion with the spec's factor moments (arcmin)
- ``factor_moments`` — doc 001: mean, σ and tolerance of each factor of the lost-motion model (base units)
- ``ARCMIN_PER_RAD`` — doc 001: the lost-motion model's angle factor, 180·60/π
- ``five_point`` — five-point central derivatives of a model's outputs by its factors
- ``AdjustmentOptions`` — doc 002: the keys of an analysis of the adjusted-assembly model
- ``Adjuster`` — doc 002: the finite-horizon LQR adjustment policy of an assembly
- ``load_assembly`` — doc 002: an assembly description file (state-space parts and key characteristics)
- ``StackupOptions`` — doc 003: the keys of an analysis of the stack-up model
- ``StackupModel`` — doc 003: the 6-DOF deviation chain over an assembly graph
- ``ParallelPlaneZone`` — doc 003: a planar face between two parallel planes and its deviation domain
- ``planar_domain`` — doc 003: the plot of a parallel-plane zone's samples and domain; imports matplotlib
- ``StiffnessOptions`` — doc 004: the keys of an analysis of the torsional-stiffness model
- ``StiffnessPlan`` — doc 004: the reducer such an analysis evaluates (torsion-angle model, torque, modifications)
- ``stiffness_plan`` — doc 004: that plan for a study's options (``prepare``'s)
- ``ReducerStiffness`` — doc 004: the torsion-angle model of one reducer (base units)
- ``TorsionAngles`` — doc 004: the torsion-angle components θ1…θ5 of a ``ReducerStiffness`` evaluation
- ``TORSION_ANGLE_COMPONENTS`` — doc 004: the names of the torsion-angle components, in order
- ``TORSION_ANGLE_LABELS`` — doc 004: each component's report label
- ``stiffness_breakdown`` — doc 004: the torsion angles and pin loads of one reducer at a torque
- ``StiffnessAtTorque`` — doc 004: the result of ``stiffness_breakdown`` (``angles``, ``contact``)
- ``pin_angles`` — doc 004: the pin angles φ_k = 2π (k + phase) / z_p (rad)
- ``initial_clearance`` — doc 004: the clearance Δ(φ_k) of each pin, the document's formula as written (mm)
- ``normal_clearance`` — doc 004: the normal clearance n0 at φ0 before the closing rotation (mm)
- ``angular_backlash`` — doc 004: the cycloid's rotation from flank to flank, 2·n0/r_c' (rad)
- ``stiffness_texts`` — doc 004: the stiffness sections' layouts (``header``, ``angles``, ``contact``)
- ``plot_sweep`` — doc 004: lines of a sweep's columns, an optional second axis; imports matplotlib

The plots (``COLORS``, ``new_axes``, ``planar_domain``, ``plot_sweep``) load on first use, so importing this module
does not import matplotlib.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from . import stats, units
from .analysis import Analysis, CommonOptions
from .blocks import Figure, Section, Table, Text, figure_png
from .design import load_design
from .errors import InputError, SpecError
from .models.adjustment.adjuster import Adjuster
from .models.adjustment.analyses import AdjustmentOptions
from .models.adjustment.description import load_assembly
from .models.lost_motion.analyses import LostMotionOptions
from .models.lost_motion.breakdown import analytic_frame
from .models.lost_motion.model import ARCMIN_PER_RAD, factor_moments
from .models.stackup.analyses import StackupOptions
from .models.stackup.domains import ParallelPlaneZone
from .models.stackup.model import StackupModel
from .models.stiffness import texts as stiffness_texts
from .models.stiffness.analyses import StiffnessOptions, StiffnessPlan, stiffness_plan
from .models.stiffness.breakdown import StiffnessAtTorque, stiffness_breakdown
from .models.stiffness.cycloid_contact import angular_backlash, initial_clearance, normal_clearance, pin_angles
from .models.stiffness.torsion_angle import COMPONENTS as TORSION_ANGLE_COMPONENTS
from .models.stiffness.torsion_angle import LABELS as TORSION_ANGLE_LABELS
from .models.stiffness.torsion_angle import ReducerStiffness, TorsionAngles
from .models.transmission_error import texts as transmission_texts
from .models.transmission_error.analyses import (TESensitivity, TESensitivityOptions, TESensitivityPlan,
                                                 te_sensitivity_plan)
from .models.transmission_error.model import TransmissionErrorModel
from .models.transmission_error.sensitivity import TESensitivityResult, te_sensitivity
from .model_kind import ModelKind
from .options import REQUIRED, option
from .params import Params, read_toml
from .records import frame_records
from .registry import ANALYSIS_ENTRY_POINT_GROUP
from .registry import ENTRY_POINT_GROUP as MODEL_ENTRY_POINT_GROUP
from .sensitivity.local import five_point

if TYPE_CHECKING:  # for type checkers and editors; at run time __getattr__ imports them on first use
    from .plotting import COLORS, new_axes
    from .plotting.stackup import planar_domain
    from .plotting.stiffness import plot_sweep

#: the plots, imported on first use (matplotlib): name -> "module:attribute"
_PLOTS = {
    "COLORS": "rvtol.plotting:COLORS",
    "new_axes": "rvtol.plotting:new_axes",
    "planar_domain": "rvtol.plotting.stackup:planar_domain",
    "plot_sweep": "rvtol.plotting.stiffness:plot_sweep",
}

__all__ = [
    # the analysis contract and the registry's entry-point groups
    "Analysis", "CommonOptions", "option", "REQUIRED", "ANALYSIS_ENTRY_POINT_GROUP", "MODEL_ENTRY_POINT_GROUP",
    "ModelKind",
    # errors; inputs, units and statistics
    "InputError", "SpecError", "Params", "read_toml", "load_design", "units", "stats",
    # results and reports
    "Section", "Table", "Figure", "Text", "figure_png", "frame_records", "COLORS", "new_axes",
    # model entry points: doc 000
    "TESensitivity", "TESensitivityOptions", "TESensitivityPlan", "te_sensitivity_plan", "te_sensitivity", "TESensitivityResult", "TransmissionErrorModel",
    "transmission_texts",
    # doc 001
    "LostMotionOptions", "analytic_frame", "factor_moments", "ARCMIN_PER_RAD", "five_point",
    # doc 002
    "AdjustmentOptions", "Adjuster", "load_assembly",
    # doc 003
    "StackupOptions", "StackupModel", "ParallelPlaneZone", "planar_domain",
    # doc 004
    "StiffnessOptions", "StiffnessPlan", "stiffness_plan", "ReducerStiffness", "TorsionAngles", "TORSION_ANGLE_COMPONENTS", "TORSION_ANGLE_LABELS",
    "stiffness_breakdown", "StiffnessAtTorque", "pin_angles", "initial_clearance", "normal_clearance",
    "angular_backlash", "stiffness_texts", "plot_sweep",
]


def __getattr__(name: str):
    """The plots of :data:`_PLOTS`, imported when first asked for (PEP 562)."""
    if name not in _PLOTS:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    import importlib

    module, attr = _PLOTS[name].split(":")
    return getattr(importlib.import_module(module), attr)
