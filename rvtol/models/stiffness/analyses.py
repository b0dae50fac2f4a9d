"""Report analysis of the torsional-stiffness model (``[[analysis]] kind = "stiffness_breakdown"``).

::

    [[analysis]]
    kind = "stiffness_breakdown"
    torque = { value = 784, unit = "N*m" }        # default: the model's torque (rated)
    torque_fractions = [0.25, 0.5, 0.75, 1.0]     # of the torque, for the curves against load

Two sections (:func:`.breakdown.stiffness_breakdown`, laid out by :mod:`.texts`): the elastic torsion
angle θ_Σ = θ1 + … + θ5 at the output by component (and against the torque), and the cycloid–pin
load distribution.
"""
from __future__ import annotations

from dataclasses import dataclass

from ...analysis import Analysis, CommonOptions
from ...options import option
from ...blocks import Section
from . import texts
from .breakdown import stiffness_breakdown
from .model import TorsionalStiffnessModel
from .torsion_angle import ReducerStiffness


@dataclass
class StiffnessOptions(CommonOptions):
    """The keys of an analysis of one reducer's torsional stiffness (the study needs a design)."""

    torque: float | None = option(None, "the output torque (default: the model's, else the design's rated torque)",
                                  unit="N*m", positive=True)
    torque_fractions: list[float] = option([0.25, 0.5, 0.75, 1.0], "fractions of the torque, for the curves against "
                                           "load", positive=True, min_length=1)

    def complete(self, study, error):
        if study.design is None:
            raise error("kind", "this analysis needs a design ([study] design = ...)")


@dataclass(frozen=True)
class StiffnessPlan:
    """The reducer whose stiffness is broken down: its torsion-angle model, the torque and the profile
    modifications (equidistance, moved distance)."""

    stiffness: ReducerStiffness
    torque: float
    modifications: tuple[float, float]


def stiffness_plan(o: StiffnessOptions, study) -> StiffnessPlan:
    """The study's reducer for a stiffness analysis: the study model's torsion-angle model (else the design's), the
    torque (given, else the model's, else rated) and the design's profile modifications."""
    model, d = study.model, study.design
    own = isinstance(model, TorsionalStiffnessModel)
    stiffness = model.stiffness if own else ReducerStiffness.from_design(d)
    torque = o.torque or (model.torque if own else None) or d["reducer.rated_torque"]
    return StiffnessPlan(stiffness, torque, (d["cycloid.equidistance_modification"],
                                             d["cycloid.moved_distance_modification"]))


class StiffnessBreakdown(Analysis):
    kind, title = "stiffness_breakdown", "Elastic torsion angle θ_Σ = θ1 + … + θ5"
    layout = texts.angles
    Options = StiffnessOptions

    def prepare(self, o, study, error) -> StiffnessPlan:
        return stiffness_plan(o, study)

    def compute(self, ctx):
        p = self.plan
        return stiffness_breakdown(p.stiffness, p.torque, p.modifications, self.options.torque_fractions)

    def report(self, res):
        """Two sections, each with its summary.json entry (``<key>`` and ``stiffness_contact``)."""
        return [super().report(res.angles),
                Section("stiffness_contact", texts.CONTACT_TITLE, texts.contact(res.contact, self.options),
                        res.contact.summary())]
