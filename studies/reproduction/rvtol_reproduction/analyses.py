"""The reproduction analyses: each a thin adapter (:mod:`rvtol.analysis`) over one document's comparison.

Registered through the ``rvtol.analyses`` entry-point group (``studies/reproduction/pyproject.toml``);
``rvtol kinds KIND`` lists every key.  Each reads the document's printed figures (``printed``: a
``data/reproduction/docNNN_*.toml`` file, relative to the study) when the study loads.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from rvtol.plugin import (REQUIRED, AdjustmentOptions, Analysis, InputError, LostMotionOptions, ParallelPlaneZone,
                          Params, Section, SpecError, StackupOptions, StiffnessOptions, StiffnessPlan, TESensitivity,
                          TESensitivityOptions, TESensitivityPlan, TransmissionErrorModel, load_assembly,
                          load_design, option, stiffness_plan, te_sensitivity, te_sensitivity_plan, units)

from . import texts
from .doc000_transmission_error import SENSITIVITIES, te_against_document
from .doc001_lost_motion import FIGURES as DOC001_FIGURES
from .doc001_lost_motion import lost_motion_figures
from .doc002_adjustment import FIGURES as DOC002_FIGURES
from .doc002_adjustment import Doc002Inputs, adjustment_figures
from .doc003_stackup import COMPARE, DIMENSION, shaft_hole_figures
from .doc004_stiffness import FIGURES as DOC004_FIGURES
from .doc004_stiffness import stiffness_document
from .printed import load_printed

PRINTED = "the document's printed figures (data/reproduction/docNNN_*.toml, relative to the study)"


def _printed(study, path: str, needs=()):
    printed = load_printed(Path(study.base_dir) / path)
    printed.require(needs)
    return printed


# --------------------------------------------------------------------------- doc 000
class TEReproduction(Analysis):
    """``transmission_error_sensitivity`` with doc 000 beside it: its classes and printed sensitivities."""

    kind, title = "transmission_error_reproduction", TESensitivity.title
    layout = texts.transmission_error

    @dataclass
    class Options(TESensitivityOptions):
        key: str | None = option("transmission_error_sensitivity", "summary.json key and report anchor (the "
                                 "section of transmission_error_sensitivity, with the document beside it)")
        printed: str = option(REQUIRED, PRINTED)

    @dataclass(frozen=True)
    class Plan(TESensitivityPlan):
        """And the document's printed classes and sensitivities."""

        figures: object

    def prepare(self, o, study, error) -> "TEReproduction.Plan":
        p = te_sensitivity_plan(o, study, error)
        return self.Plan(p.target, p.te_model, p.spec, _printed(study, o.printed, SENSITIVITIES))

    def compute(self, ctx):
        o, p = self.options, self.plan
        res = te_sensitivity(p.te_model, p.spec, o.factors, o.magnitudes, percent=o.percent, evaluate=ctx.evaluator)
        return te_against_document(res, self.plan.figures)


# --------------------------------------------------------------------------- doc 001
class LostMotionReproduction(Analysis):
    """Every figure doc 001 prints, against rvtol's computation from the document's formulas and inputs."""

    kind, title = "lost_motion_reproduction", "Reproduction of the document's printed figures (doc 001)"
    layout = texts.lost_motion

    @dataclass
    class Options(LostMotionOptions):
        printed: str = option(REQUIRED, PRINTED)

        def complete(self, study, error):
            super().complete(study, error)
            if study.model.mode != "document":
                raise error("kind", "the reproduction compares doc 001's formulas as printed: the study needs "
                                    "[model] mode = \"document\"")

    @dataclass(frozen=True)
    class Plan:
        """The document's printed figures."""

        figures: object

    def prepare(self, o, study, error) -> "LostMotionReproduction.Plan":
        return self.Plan(_printed(study, o.printed, DOC001_FIGURES))

    def compute(self, ctx):
        return lost_motion_figures(ctx.model, ctx.spec, ctx.mc, self.plan.figures, evaluate=ctx.evaluator,
                                   design=ctx.design)


# --------------------------------------------------------------------------- doc 002
class AdjustmentReproduction(Analysis):
    """Every printed number of doc 002 against rvtol (the example, the linear map, Table 5, the claims)."""

    kind, title = "adjustment_reproduction", "Doc 002: printed numbers against rvtol"
    layout = texts.adjustment

    @dataclass
    class Options(AdjustmentOptions):
        printed: str = option(REQUIRED, PRINTED)
        assembly_3d: str = option(REQUIRED, "the 3-D assembly of the linear map (P1 = 0.3069 v1x ...)")
        accuracy_weight: float = option(10.0, "the Q of the linear map (doc 002's worked value)", nonnegative=True)
        allocation: str = option(REQUIRED, "key of the study's allocation analysis (Table 5; it runs first)")
        allocation_unadjusted: str | None = option(None, "key of the study's allocation analysis without adjustment (it runs first)")
        te_design: str | None = option(None, "a 20-DOF design: the example's TE against Q through rvtol's mapping")
        te_lever_arm: float = option(6.0, "the lever arm L of the mapping", unit="mm", positive=True)

        def complete(self, study, error):
            super().complete(study, error)
            if study.design is None:
                raise error("kind", "needs the BX40E design (study design = data/designs/bx40e.toml)")
            if "example.part_errors" not in study.design:
                raise error("kind", "the design has no parameter 'example.part_errors' (doc 002's Table 3)")

    requires = {"allocation": "allocation", "allocation_unadjusted": "allocation"}

    def prepare(self, o, study, error) -> Doc002Inputs:
        """The comparison's inputs but the allocations (their analyses run first: ``compute`` adds them)."""
        from .doc002_adjustment import te_inputs

        base = Path(study.base_dir)
        te = None
        if o.te_design is not None:
            te = TransmissionErrorModel(load_design(base / o.te_design), inputs=te_inputs())
        return Doc002Inputs(study.model, study.design, _printed(study, o.printed, DOC002_FIGURES),
                            load_assembly(base / o.assembly_3d), o.accuracy_weight, None, None, te, o.te_lever_arm)

    def compute(self, ctx):
        o = self.options
        return adjustment_figures(replace(self.plan, alloc=ctx.results.get(o.allocation),
                                          alloc_free=ctx.results.get(o.allocation_unadjusted)))


# --------------------------------------------------------------------------- doc 003
class StackupShaftHole(Analysis):
    """Doc 003's shaft–hole example (and, with ``planar_zone``, its planar-zone formulas) against rvtol."""

    kind, title = "stackup_shaft_hole", "Stack-up: doc 003 shaft–hole example — printed figures against rvtol"
    layout = texts.shaft_hole

    @dataclass
    class Options(StackupOptions):
        printed: str = option(REQUIRED, PRINTED)
        fit: str | None = option(None, "a clearance fit of the study's assembly (default: the first)")
        kc: str | None = option(None, "the KC whose ‖e‖, ‖ε‖ and tilt are compared (default: the first)")
        planar_zone: dict | None = option(None, "{t1, t2, length, width (mm), name}: a parallel-plane zone whose "
                                                "printed formulas (doc 003) are set against the derivation")

        def complete(self, study, error):
            super().complete(study, error)
            if self.kc is not None and self.kc not in {k.name for k in study.model.kcs}:
                raise error("kc", f"unknown KC {self.kc!r}")

    @dataclass(frozen=True)
    class Plan:
        """The printed file and its figures (checked against the model), the clearance fit and the KC compared (the
        table's, else the assembly's first), and the planar zone with its name (None, "": none)."""

        printed: object
        figures: list
        fit: object
        kc: str
        zone: object
        zone_name: str

    def prepare(self, o, study, error) -> "StackupShaftHole.Plan":
        m = study.model
        P = _printed(study, o.printed)
        fits = [f for f in m.assembly.fits.values() if f.is_clearance]
        fit = m.assembly.fits.get(o.fit if o.fit is not None else (fits[0].name if fits else ""))
        if fit is None or not fit.is_clearance:
            raise error("fit", "name a clearance fit of the assembly")
        kc = o.kc if o.kc is not None else m.kcs[0].name
        figures = [_figure(m, P, kc, key, fig, error) for key, fig in P.figures.items()]
        if not figures:
            raise SpecError("no figures", file=P.path, key="figure")
        name, zone = _zone(o.planar_zone, error) if o.planar_zone is not None else ("", None)
        return self.Plan(P, figures, fit, kc, zone, name)

    def compute(self, ctx):
        p = self.plan
        return shaft_hole_figures(ctx.model, ctx.spec, ctx.mc, p.fit, p.kc, p.figures, p.printed, planar=p.zone,
                                  seed=ctx.seed)

    def blocks(self, result) -> list:
        return texts.shaft_hole(result, self.options, self.plan)


def _figure(m, P, kc: str, key, fig, error):
    """A printed figure of doc 003 whose comparison, output and unit the model has."""
    if key not in COMPARE:
        raise SpecError(f"unknown comparison (expected one of: {', '.join(COMPARE)})", file=P.path,
                        key=f"figure.{key}")
    if key != "max_clearance" and f"{kc}.{key}" not in m.output_names:
        raise error("kc", f"the model has no output {kc}.{key}")
    if units.dimension(fig.unit) != DIMENSION[key]:
        raise SpecError(f"expected a {DIMENSION[key]} unit, got {fig.unit!r}", file=P.path,
                        key=f"figure.{key}.unit")
    return fig


def _zone(table: dict, error):
    """``(name, zone)`` of the ``planar_zone`` table."""
    t = Params(table)
    try:
        name = t.str("name", "parallel-plane zone")
        zone = ParallelPlaneZone(t.quantity("t1", "mm"), t.quantity("t2", "mm"),
                                 t.quantity("length", "mm", positive=True),
                                 t.quantity("width", "mm", positive=True))
        t.finish()
    except InputError as exc:
        raise error("planar_zone" + (f".{exc.key}" if exc.key else ""), exc.reason) from None
    return name, zone


# --------------------------------------------------------------------------- doc 004
class StiffnessReproduction(Analysis):
    """``stiffness_reproduction``: doc 004's studies and its printed figures against rvtol."""

    kind, title = "stiffness_reproduction", texts.STIFFNESS_TITLE
    layout = texts.stiffness_reproduction

    @dataclass
    class Options(StiffnessOptions):
        printed: str = option(REQUIRED, PRINTED)
        pin_circle_radii: list[float] | None = option(None, "mm: the pin circle radii (default: Table 2's, from the "
                                                            "printed file)", positive=True, min_length=2)
        eccentricities: list[float] = option([1.2, 1.3, 1.4, 1.5, 1.6, 1.7, 1.8], "mm (Table 4)", positive=True,
                                             min_length=2)
        widths: list[float] = option([10.0, 11.0, 12.0, 13.0, 14.0, 15.0], "mm (Table 4)", positive=True,
                                     min_length=2)
        sweep_points: int = option(5, "points of the modification and error sweeps", min=3, max=101)
        error_range: float = option(0.010, "the errors are swept over ±error_range (default 10 µm)", unit="um",
                                    positive=True)
    @dataclass(frozen=True)
    class Plan:
        """The reducer (the library's stiffness plan), the printed figures and the pin circle radii swept."""

        reducer: StiffnessPlan
        figures: dict
        radii: list

    def prepare(self, o, study, error) -> "StiffnessReproduction.Plan":
        reducer = stiffness_plan(o, study)
        figures = _printed(study, o.printed, DOC004_FIGURES)
        radii = o.pin_circle_radii if o.pin_circle_radii is not None else figures["table2_R_p"].value
        pins = reducer.stiffness.pins
        for name, vals in (("pin_circle_radii", radii), ("eccentricities", o.eccentricities)):
            for v in vals:
                K1 = (v if name == "eccentricities" else pins.a) * pins.z_p / (v if name == "pin_circle_radii"
                                                                               else pins.R_p)
                if K1 >= 1.0:
                    raise error(name, f"value {v:g} mm gives K1 = a z_p / R_p = {K1:.3f} >= 1")
        return self.Plan(reducer, figures, radii)

    def compute(self, ctx):
        o, p = self.options, self.plan
        r = p.reducer
        return stiffness_document(r.stiffness, r.torque, r.modifications, o.torque_fractions, p.figures,
                                  radii=p.radii, eccentricities=o.eccentricities, widths=o.widths,
                                  points=o.sweep_points, error_range=o.error_range)

    def report(self, r):
        """Six sections, each with its summary.json entry: the library's two (torsion angle, pin loads) with the
        document beside them, geometry, modifications, errors, and the reproduction table (this analysis' own)."""
        sections = []
        for key, part in r.parts().items():
            title, layout = texts.STIFFNESS_SECTIONS[key]
            sections.append(Section(key, title, layout(r, self.options), part.summary()))
        return sections + [super().report(r)]
