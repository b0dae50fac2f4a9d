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

from dataclasses import dataclass, field

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
    stiffness: ReducerStiffness | None = field(init=False, default=None)
    modifications: tuple | None = field(init=False, default=None)

    def complete(self, study, error):
        if study.design is None:
            raise error("kind", "this analysis needs a design ([study] design = ...)")
        model = study.model
        if isinstance(model, TorsionalStiffnessModel):
            self.stiffness = model.stiffness
            self.torque = self.torque or model.torque
        else:
            self.stiffness = ReducerStiffness.from_design(study.design)
        self.torque = self.torque or study.design["reducer.rated_torque"]
        d = study.design
        self.modifications = (d["cycloid.equidistance_modification"], d["cycloid.moved_distance_modification"])


class StiffnessBreakdown(Analysis):
    kind, title = "stiffness_breakdown", "Elastic torsion angle θ_Σ = θ1 + … + θ5"
    layout = texts.angles
    Options = StiffnessOptions

    def compute(self, ctx):
        o = self.options
        return stiffness_breakdown(o.stiffness, o.torque, o.modifications, o.torque_fractions)

    def report(self, res):
        """Two sections, each with its summary.json entry (``<key>`` and ``stiffness_contact``)."""
        return [super().report(res.angles),
                Section("stiffness_contact", texts.CONTACT_TITLE, texts.contact(res.contact, self.options),
                        res.contact.summary())]
