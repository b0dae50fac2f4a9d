"""``[[analysis]] kind = "torsion_curve"``: hysteresis curves of the 20-DOF model, compared; and
``kind = "compliance_breakdown"`` (:class:`ComplianceBreakdown`): the output angle per compliance element,
20-DOF and the elastic torsion-angle model side by side.

::

    [[analysis]]
    kind = "torsion_curve"
    clearances = [0, 1, 2, 5, 10]          # µm, cycloid–crank bearing clearance δ_b (all six bearings)
    pin_clearances = [0, 1, 2, 4]          # µm, pin normal clearance δ (all pins)
    clearance_coefficient = 1.5            # doc 001's K (crank-bearing clearance -> circumferential play)
    stiffness_design = "../data/designs/rv80e_stiffness.toml"   # optional: the torsion-angle model beside

Three sections (:func:`.beside_analytical_models.torsion_curve_study`): the curves (clearance-free and at the
spec's mean errors) with the maker's figures; lost motion against the crank-bearing and pin clearances beside
the lost-motion model in both modes; rigidity beside the elastic torsion-angle model with the 20-DOF
angle split by virtual work.  Laid out by :mod:`.texts`.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ... import units
from ...analysis import Analysis, CommonOptions, ModelTarget, target_model
from ...options import option
from ...blocks import Section
from ..stiffness.torsion_angle import ReducerStiffness
from ..reducer_20dof.geometry import geometry_from_design
from . import texts
from .beside_analytical_models import compliance_comparison, torsion_curve_study
from .model import TorsionCurveModel


def _stiffness_of(design) -> tuple:
    """The elastic torsion-angle model of a design and its profile modifications (fails at load time)."""
    return (ReducerStiffness.from_design(design),
            (design["cycloid.equidistance_modification"], design["cycloid.moved_distance_modification"]))


@dataclass(frozen=True)
class TorsionCurvePlan:
    """The torsion-curve model of the study (its stage in a composed study; None: the design's, built at run time) and
    ``part1``: the elastic torsion-angle model shown beside the rigidity, its profile modifications and the face width
    (None: no stiffness design)."""

    target: ModelTarget | None
    part1: tuple | None


class TorsionCurveAnalysis(Analysis):
    kind, title = "torsion_curve", "Torsion (hysteresis) curve of the 20-DOF model, input locked"
    layout = texts.curves

    @dataclass
    class Options(CommonOptions):
        clearances: list[float] = option([0.0, 1.0, 2.0, 5.0, 10.0], "µm: cycloid–crank bearing clearances δ_b (all "
                                         "six bearings)", nonnegative=True, min_length=2)
        pin_clearances: list[float] = option([0.0, 1.0, 2.0, 4.0], "µm: pin normal clearances δ (all pins)",
                                             nonnegative=True, min_length=2)
        clearance_coefficient: float = option(1.5, "doc 001's K of the document mode (crank-bearing clearance -> "
                                                   "circumferential play)", positive=True)
        stiffness_design: str | None = option(None, "a design of the elastic torsion-angle model, shown beside the "
                                                    "rigidity")
        model: str | None = option(None, "composed study: the torsion-curve stage (default: the only one)")

        def complete(self, study, error):
            if study.design is None:
                raise error("kind", "torsion_curve needs a 20-DOF design ([study] design = ...)")
            m = study.model
            if not (isinstance(m, TorsionCurveModel) or getattr(m, "stages", None)) and self.model is not None:
                raise error("model", "a one-model study has no stages to choose from")

    def prepare(self, o, study, error) -> TorsionCurvePlan:
        from ...design import load_design

        m, target, part1 = study.model, None, None
        if isinstance(m, TorsionCurveModel) or getattr(m, "stages", None):
            target = target_model(study, TorsionCurveModel, "torsion_curve", o.model, error)
        if o.stiffness_design is not None:       # a bad stiffness design fails here, before any computation
            rs, mods = _stiffness_of(load_design(Path(study.base_dir) / o.stiffness_design))
            part1 = (rs, mods, float(study.design.get("cycloid.face_width", rs.pins.b)))
        return TorsionCurvePlan(target, part1)

    def compute(self, ctx):
        o, t = self.options, self.plan.target
        model = t.model if t is not None else TorsionCurveModel(ctx.design, ())
        mean = t.inputs(ctx.spec.mean_base())[0] if t is not None and len(model.inputs) else None
        um = 1e-3   # mm per µm
        return torsion_curve_study(model, mean, clearances=[c * um for c in o.clearances],
                                   pin_clearances=[c * um for c in o.pin_clearances], K=o.clearance_coefficient,
                                   part1=self.plan.part1)

    def report(self, res):
        """Three sections, each with its summary.json entry (``<key>``, ``<key>_lost_motion``, ``<key>_rigidity``)."""
        o = self.options
        return [super().report(res.curves),
                Section(f"{self.key}_lost_motion", texts.LOST_MOTION_TITLE, texts.lost_motion(res.clearances, o),
                        res.clearances.summary()),
                Section(f"{self.key}_rigidity", texts.RIGIDITY_TITLE, texts.rigidity(res.rigidity, o),
                        res.rigidity.summary())]


@dataclass(frozen=True)
class CompliancePlan:
    """The 20-DOF reducer (the study's torsion-curve stage's, else the design's geometry), the torque (given, else
    its rated), the section's title at that torque and the elastic torsion-angle model with its profile modifications
    (None: not beside)."""

    geometry: object
    torque: float
    title: str
    stiffness: tuple | None


class ComplianceBreakdown(Analysis):
    """``[[analysis]] kind = "compliance_breakdown"``: the output angle at a torque split per compliance
    family by virtual work — the 20-DOF model with the design's compliance chain, doc 000's rigid chain
    (its contact laws only) and the elastic torsion-angle model side by side
    (:func:`.beside_analytical_models.compliance_comparison`).

    Families: :data:`rvtol.elements.reducer_chain.FAMILIES` (stable names; a design scales one with
    ``compliance_scale.<family>``).  The 20-DOF split is :meth:`QuasiStaticSolver.contact_work` at the
    clearance-free, error-free equilibrium (input locked); the torsion-angle model's is its components,
    θ4 split into crankshaft bending and torsion.  A second table lists how each element is reduced to
    the 20-DOF contacts (:mod:`rvtol.models.reducer_20dof.compliance`).
    """

    kind, title = "compliance_breakdown", "Compliance chain: output angle per element"
    layout = texts.compliance

    @dataclass
    class Options(CommonOptions):
        torque: float | None = option(None, "the output torque (default: the design's rated torque)", unit="N*m",
                                      positive=True)
        rigid_chain: bool = option(True, "the 20-DOF model without the design's compliance chain beside")
        stiffness_model: bool = option(True, "the elastic torsion-angle model beside (needs a design it can read)")
        model: str | None = option(None, "composed study: the torsion-curve stage (default: the only one)")

        def complete(self, study, error):
            if study.design is None:
                raise error("kind", "compliance_breakdown needs a 20-DOF design ([study] design = ...)")

    def prepare(self, o, study, error) -> CompliancePlan:
        m = study.model
        if isinstance(m, TorsionCurveModel) or o.model is not None or any(
                isinstance(s.model, TorsionCurveModel) for s in getattr(m, "stages", None) or ()):
            geometry = target_model(study, TorsionCurveModel, "torsion_curve", o.model, error).model.geometry
        else:
            geometry = geometry_from_design(study.design)
        torque = o.torque if o.torque is not None else geometry.rated_torque
        # a design the torsion-angle model cannot read fails here
        stiffness = _stiffness_of(study.design) if o.stiffness_model else None
        return CompliancePlan(geometry, torque, texts.compliance_title(units.from_base(torque, "N*m")), stiffness)

    def compute(self, ctx):
        p = self.plan
        rigid = geometry_from_design(ctx.design, chain=False) if self.options.rigid_chain else None
        return compliance_comparison(p.geometry, p.torque, rigid=rigid, stiffness=p.stiffness)
