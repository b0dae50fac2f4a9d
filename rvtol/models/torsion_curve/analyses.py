"""``[[analysis]] kind = "torsion_curve"``: hysteresis curves of the 20-DOF model, compared; and
``kind = "compliance_breakdown"`` (:class:`ComplianceBreakdown`): the output angle per compliance element,
20-DOF and doc 004's model side by side.

::

    [[analysis]]
    kind = "torsion_curve"
    clearances = [0, 1, 2, 5, 10]          # µm, cycloid–crank bearing clearance δ_b (all six bearings)
    pin_clearances = [0, 1, 2, 4]          # µm, pin normal clearance δ (all pins)
    clearance_coefficient = 1.5            # doc 001's K (crank-bearing clearance -> circumferential play)
    stiffness_design = "../data/designs/rv80e_stiffness.toml"   # optional: part 1 (doc 004) beside

Sections: the curves (clearance-free and at the spec's mean errors) with the
maker's figures; lost motion against the crank-bearing and pin clearances
beside the analytical lost-motion model (:mod:`rvtol.models.lost_motion.model`,
doc 001); rigidity beside the elastic torsion-angle model (doc 004) with the
20-DOF angle split by virtual work.

**Analytical rates.**  Doc 001's formula in its two modes
(:mod:`rvtol.models.lost_motion.model`): as printed (``Δφ_b = Δ/(K r)`` with
``K ≈ 1.5``, ``Δφ34 = Δr_c/(a z_c)``, no disc-to-output ratio) and
consistent (``K = 1``: a disc on three bearings 120° apart turns ``Δ / r``
flank to flank; ``2 Δr_c/(a z_c)`` for a normal gap Δr_c at every pin; the
output turns ``i_b = (1 − 1/i) z_c / z_p`` times the disc's rotation).  In the
20-DOF model ``δ_b`` is the radius of a bearing's free-play circle, so the
radial internal clearance is ``Δ = 2 δ_b``; a pin clearance ``δ`` is a normal
gap at every pin, doc 001's per-side ``Δr_c`` (an equidistant modification).
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd

from ...analysis import Analysis, target_model
from ... import units
from ...design import load_design
from ...elements.reducer_chain import FAMILIES
from ...errors import SolverError
from ...report.sections import Section, frame_records
from ..lost_motion.model import LostMotionGeometry, LostMotionModel
from ..transmission import layout as L
from ..transmission.geometry import geometry_from_design
from ..transmission.quasistatic import QuasiStaticSolver
from ..stiffness.cycloid_contact import PinGear
from ..stiffness.torsion_angle import LABELS, ReducerStiffness
from .model import RIGIDITY_READINGS, TorsionCurveModel, compliance_breakdown
from .screening import CAMS

BREAKDOWN_LABELS = {**FAMILIES, "sun_planet_mesh": "sun–planet meshes (≈ θ1)",
                    "cycloid_pin": "cycloid–pin contacts (≈ θ2)", "turning_arm_bearings": "cycloid–crank bearings (≈ θ3)"}


def output_ratio(g) -> float:
    """``i_b``: output rotation per rotation of a disc relative to the carrier."""
    return (1.0 - 1.0 / g.ratio) * g.z_c / g.z_b


def analytic_geometry(g, K: float = 1.5, mode: str = "document") -> LostMotionGeometry:
    """Doc 001's lost-motion geometry for the 20-DOF reducer ``g`` (``K``: doc 001's clearance coefficient,
    used in document mode)."""
    return LostMotionGeometry(pressure_angle=g.alpha, pitch_diameter=g.module * g.z_s, ratio=g.ratio,
                              eccentricity=g.ecc, cycloid_teeth=float(g.z_c), K1=g.K1, bearing_radius=g.a_w,
                              bearing_K=K if mode == "document" else 1.0, mode=mode, working_pressure_angle=g.alpha_w,
                              pins=float(g.z_b), origins={"r": "operating centre distance a' of the 20-DOF geometry"})


def analytic_lost_motion(g, K: float, Delta_b=0.0, Delta_r_c=0.0, mode: str = "document") -> np.ndarray:
    """Doc 001's total lost motion (rad) for crank-bearing clearance ``Δ`` and cycloid clearance ``Δr_c``."""
    m = LostMotionModel(analytic_geometry(g, K, mode), ["Delta_b", "Delta_r_c"])
    X = np.column_stack(np.broadcast_arrays(np.atleast_1d(np.asarray(Delta_b, float)),
                                            np.atleast_1d(np.asarray(Delta_r_c, float))))
    return m.evaluate(X)[:, 0]


class TorsionCurveAnalysis(Analysis):
    def setup(self, params, study):
        if study.design is None:
            raise params.error("kind", "torsion_curve needs a 20-DOF design ([study] design = ...)")
        um = dict(nonnegative=True, min_length=2)
        self.clearances = np.asarray(params.floats("clearances", [0.0, 1.0, 2.0, 5.0, 10.0], **um)) * 1e-3
        self.pin_clearances = np.asarray(params.floats("pin_clearances", [0.0, 1.0, 2.0, 4.0], **um)) * 1e-3
        self.K = params.float("clearance_coefficient", 1.5, positive=True)
        path = params.path_value("stiffness_design", study.base_dir, None)
        self.stiffness_design = load_design(path) if path is not None else None
        self.te_design = study.design
        m = study.model
        self.target = None
        if isinstance(m, TorsionCurveModel) or getattr(m, "stages", None):
            self.target = target_model(params, study, TorsionCurveModel, "torsion_curve")
            self.model = self.target.model
        else:
            self.model = TorsionCurveModel(study.design, ())
        self.spec = study.spec if self.target is not None else None
        params.finish()
        if self.stiffness_design is not None:      # a bad stiffness design fails here, before any computation
            d = self.stiffness_design
            self.part1 = (ReducerStiffness.from_design(d),
                          (d["cycloid.equidistance_modification"], d["cycloid.moved_distance_modification"]))

    def run(self, ctx) -> list[Section]:
        return [self._curves(), self._lost_motion(), self._rigidity()]

    # ------------------------------------------------------------------
    def _metrics_row(self, label, curve) -> dict:
        if not curve.ok:
            return {"reducer": label, "status": curve.reason}
        mt = curve.metrics(self.model.percent)
        return {"reducer": label,
                f"lost motion ±{self.model.percent:g} % (arcmin)": units.from_base(mt.lost_motion, "arcmin"),
                "backlash (arcmin)": units.from_base(mt.backlash, "arcmin"),
                "rigidity b/a (N·m/arcmin)": units.from_base(mt.rigidity, "N*m/arcmin"),
                "rigidity 50–100 % (N·m/arcmin)": units.from_base(mt.rigidity_50_100, "N*m/arcmin"),
                "rigidity b/a less backlash (N·m/arcmin)": units.from_base(mt.rigidity_clearance_free, "N*m/arcmin"),
                "angle at +rated (arcmin)": units.from_base(mt.angle_at_rated, "arcmin"),
                "largest hysteresis width (arcsec)": units.from_base(mt.hysteresis_width, "arcsec"),
                f"friction width ±{self.model.percent:g} % (arcsec)": units.from_base(mt.friction_width, "arcsec")}

    def _curves(self) -> Section:
        from ...plotting import new_axes

        m = self.model
        free = TorsionCurveModel(m.geometry, (), percent=m.percent, points=m.points, torque=m.torque).curve()
        rows = [self._metrics_row("clearance-free, error-free", free)]
        curves = [("clearance-free", free)]
        if self.spec is not None and len(self.model.inputs):
            mean = self.target.inputs(self.spec.mean_base())[0]
            c = m.curve(mean)
            rows.append(self._metrics_row("all factors at the spec's mean", c))
            curves.append(("spec mean", c))
        df = pd.DataFrame(rows)
        fig, ax = new_axes(None, figsize=(6.4, 4.0))
        for label, c in curves:
            if c.ok:
                ax.plot(c.torque_Nm, c.angle_arcmin, "-o", ms=2, lw=1, label=label)
        lim = m.percent / 100.0 * units.from_base(m.torque, "N*m")
        ax.axvspan(-lim, lim, color="0.6", alpha=0.2, label=f"±{m.percent:g} % rated")
        ax.set_xlabel("output torque [N·m]")
        ax.set_ylabel("output torsion angle [arcmin]")
        ax.legend(loc="best")
        zoom, zax = new_axes(None, figsize=(6.4, 3.2))
        for label, c in curves:
            if c.ok:
                sel = np.abs(c.torque) <= 0.1 * c.rated
                zax.plot(c.torque_Nm[sel], c.angle_arcmin[sel], "o-", ms=2, lw=1, label=label)
        zax.axvspan(-lim, lim, color="0.6", alpha=0.2)
        zax.set_xlabel("output torque [N·m]")
        zax.set_ylabel("torsion angle [arcmin]")
        zax.legend(loc="best")
        s = Section("torsion_curve", "Torsion (hysteresis) curve of the 20-DOF model, input locked")
        s.add_text(f"Carrier torque 0 → +{units.from_base(m.torque, 'N*m'):g} → −… → 0 N·m in {m.points} steps per "
                   "quarter, each equilibrium warm-started from the previous one (doc 000's 20-DOF model, "
                   "quasi-static). Figures by the maker's definitions (REFERENCE): rigidity b/a between the "
                   f"rated-torque end points, lost motion between the mid-points at ±{m.percent:g} % rated, "
                   "backlash = width at zero torque. "
                   + ("Coulomb friction of the design's [friction] coefficients opens the loop (friction width at "
                      f"±{m.percent:g} %, rvtol/models/transmission/friction.py): lost motion reads the mid-points, "
                      "backlash the width at zero torque, free play and friction together." if m.friction else
                      "The model has no friction, so the branches coincide away from zero (hysteresis width ~0) "
                      "and the curve jumps across the clearances at zero torque."))
        s.add_table(df, "Maker's figures of the simulated curves", "{:.4g}")
        s.add_figure(fig, "Torsion curves (whole cycle)")
        s.add_figure(zoom, "Torsion curves within ±10 % of rated torque")
        s.summary = {"curves": frame_records(df)}
        return s

    def _lost_motion(self) -> Section:
        from ...plotting.stiffness import plot_sweep

        g = self.model.geometry
        ib = output_ratio(g)
        sub = TorsionCurveModel(g, CAMS, percent=self.model.percent, points=self.model.points,
                                torque=self.model.torque)
        Y = sub.evaluate(np.repeat(self.clearances[:, None], 6, axis=1))
        amin = lambda v: units.from_base(v, "arcmin")  # noqa: E731
        lm, bl = Y[:, 0], Y[:, 2]
        Delta = 2.0 * self.clearances
        doc_label, con_label = f"doc 001 as printed, K = {self.K:g} (arcmin)", "doc 001, consistent mode (arcmin)"
        cam = pd.DataFrame({
            "δ_b (µm)": self.clearances * 1e3, "Δ = 2δ_b (µm)": Delta * 1e3,
            "20-DOF lost motion (arcmin)": amin(lm), "20-DOF backlash (arcmin)": amin(bl),
            doc_label: amin(lm[0] + analytic_lost_motion(g, self.K, Delta)),
            con_label: amin(lm[0] + analytic_lost_motion(g, self.K, Delta, mode="consistent")),
        })
        pin = TorsionCurveModel(g, ("delta_pin",), percent=self.model.percent, points=self.model.points,
                                torque=self.model.torque)
        Yp = pin.evaluate(self.pin_clearances[:, None])
        pins = pd.DataFrame({
            "pin clearance δ = Δr_c (µm)": self.pin_clearances * 1e3,
            "20-DOF lost motion (arcmin)": amin(Yp[:, 0]), "20-DOF backlash (arcmin)": amin(Yp[:, 2]),
            doc_label: amin(Yp[0, 0] + analytic_lost_motion(g, self.K, 0.0, self.pin_clearances)),
            con_label: amin(Yp[0, 0] + analytic_lost_motion(g, self.K, 0.0, self.pin_clearances, mode="consistent")),
        })

        def slope(x, y):
            return float(np.polyfit(x, y, 1)[0])

        sel = self.clearances >= 0.002 - 1e-12
        if sel.sum() < 2:
            sel = np.ones_like(self.clearances, bool)
        doc = analytic_geometry(g, self.K).output_coefficients()
        con = analytic_geometry(g, mode="consistent").output_coefficients()
        per_um = lambda c: amin(c) * 1e-3  # noqa: E731
        rates = pd.DataFrame({
            "rate": ["d(lost motion)/dδ_b, crank bearings", "d(backlash)/dδ_b, crank bearings",
                     "d(lost motion)/dδ, pins", "d(backlash)/dδ, pins"],
            "20-DOF (arcmin/µm)": [1e-3 * slope(self.clearances[sel], amin(lm[sel])),
                                   1e-3 * slope(self.clearances, amin(bl)),
                                   1e-3 * slope(self.pin_clearances, amin(Yp[:, 0])),
                                   1e-3 * slope(self.pin_clearances, amin(Yp[:, 2]))],
            f"doc 001 as printed, K = {self.K:g} (arcmin/µm)": [per_um(2 * doc["Delta_b"])] * 2
                                                                + [per_um(doc["Delta_r_c"])] * 2,
            "doc 001 consistent: K = 1, × i_b (arcmin/µm)": [per_um(2 * con["Delta_b"])] * 2
                                                            + [per_um(con["Delta_r_c"])] * 2,
        })
        s = Section("torsion_curve_lost_motion", "Lost motion against clearances: 20-DOF beside the analytical "
                    "model (doc 001)")
        s.add_text("Clearances set on all six cycloid–crank bearings (δ_b, the radius of each bearing's free-play "
                   "circle: radial internal clearance Δ = 2δ_b) and, separately, as a normal clearance δ at every "
                   "pin (doc 001's per-side profile clearance Δr_c, an equidistant modification). The analytical "
                   "columns add doc 001's geometric lost motion to the 20-DOF's clearance-free lost motion (the "
                   "elastic part, which doc 001 ignores). As printed (K = "
                   f"{self.K:g}, Δr_c/(a z_c), no disc-to-output ratio) doc 001 predicts "
                   f"{doc['Delta_b'] / con['Delta_b']:.3f} of the 20-DOF's growth with δ_b and "
                   f"{doc['Delta_r_c'] / con['Delta_r_c']:.3f} with δ; its consistent mode (three bearings 120° apart"
                   f" give K = 1; flank to flank 2δ/(a z_c); the output turns i_b = {ib:.4f} times the disc's rotation)"
                   " gives the backlash rates. The lost-motion rate is a little higher than the backlash rate: with "
                   "clearance, the soft low-load range of the Hertz-type bearing laws (doc 000: k = k0·P^0.1) is "
                   f"re-entered within ±{self.model.percent:g} % rated. The lost-motion rate is fitted from δ_b ≥ 2 µm "
                   "(at zero clearance the bearings' zero-load stiffness vanishes).")
        s.add_table(rates, "First-order rates", "{:.4g}")
        s.add_table(cam, "Crank-bearing clearance", "{:.4g}")
        s.add_figure(plot_sweep(cam, "δ_b (µm)", [c for c in cam.columns if "arcmin" in c],
                                ylabel="lost motion / backlash [arcmin]"), "Lost motion against δ_b")
        s.add_table(pins, "Pin clearance", "{:.4g}")
        s.summary = {"rates": frame_records(rates), "crank_bearing": frame_records(cam), "pins": frame_records(pins)}
        return s

    def _rigidity(self) -> Section:
        g = self.model.geometry
        free = TorsionCurveModel(g, (), percent=self.model.percent, points=self.model.points,
                                 torque=self.model.torque, friction=False).curve()     # virtual work: no friction
        T = self.model.torque
        k = int(np.flatnonzero(np.isclose(free.torque, T))[0])
        bd = compliance_breakdown(g, None, free.q[k], T)
        asec = lambda v: float(units.from_base(v, "arcsec"))  # noqa: E731
        rows = [{"element": BREAKDOWN_LABELS[n], "20-DOF at +rated (arcsec)": asec(v)} for n, v in bd.items()]
        total20 = sum(bd.values())
        rows.append({"element": "total", "20-DOF at +rated (arcsec)": asec(total20)})
        df = pd.DataFrame(rows)
        mt = free.metrics(self.model.percent)
        lines = [f"20-DOF, clearance-free: b/a = {units.from_base(mt.rigidity, 'N*m/arcmin'):.1f} N·m/arcmin, "
                 f"secant at +rated T/θ = {units.from_base(T / total20, 'N*m/arcmin'):.1f} N·m/arcmin "
                 f"(θ = {asec(total20):.2f} arcsec; virtual-work sum {asec(sum(bd.values())):.2f} arcsec against the "
                 f"solver's {asec(free.angle[k]):.2f} arcsec)."]
        comp = None
        if self.stiffness_design is not None:
            comp = self._part1(T)
            own = comp["doc 004 RV-80E (arcsec)"].iloc[-1]
            same = comp["doc 000 geometry (arcsec)"].iloc[-1]
            lines.append(f"Elastic torsion-angle model (doc 004, part 1) at the same torque: θ_Σ = {own:.2f} arcsec "
                         f"on its own RV-80E ({units.from_base(T, 'N*m') / (own / 60):.1f} N·m/arcmin), {same:.2f} "
                         f"arcsec with doc 000's pin-gear and first-stage geometry and no profile modification "
                         f"({units.from_base(T, 'N*m') / (same / 60):.1f} N·m/arcmin).")
        if g.chain is None:
            lines.append("Why they differ: the 20-DOF model treats cranks and carrier as rigid bodies (no θ4, θ5) "
                         "but has the crank–carrier and carrier–housing bearings, which doc 004 leaves out; its contact "
                         "laws are doc 000's k = k0·P^0.1 (force ∝ deflection^1.11) for pins and bearings, against "
                         "doc 004's Hertz line contact with logarithmic terms and Palmgren's needle-bearing formula; "
                         "its involute mesh is doc 000's constant 1.58e5 N/mm against ISO 6336 at low load.")
        else:
            lines.append("Both models carry the design's compliance elements (crankshafts, crank support pair, "
                         "carrier, pin grooves, disc webs, input shaft: kind compliance_breakdown compares them "
                         "element by element); they differ in doc 000's contact laws k = k0·P^0.1 for pins and "
                         "needle bearings against doc 004's Hertz line contact and Palmgren's needle-bearing "
                         "formula, doc 000's constant mesh stiffness against ISO 6336, and in how the load is "
                         "shared (the 20-DOF solves it, doc 004 takes it from statics).")
        s = Section("torsion_curve_rigidity", "Rigidity: 20-DOF beside the elastic torsion-angle model (doc 004)")
        s.add_text(" ".join(lines))
        s.add_table(df, "20-DOF torsion angle at +rated split by virtual work (T θ = Σ f·d)", "{:.4g}")
        if comp is not None:
            s.add_table(comp, "Elastic torsion-angle model (doc 004) components at the same torque", "{:.4g}")
        readings = {k: float(units.from_base(v, "N*m/arcmin")) for k, v in mt.readings().items()}
        s.add_table(pd.DataFrame({"output": list(RIGIDITY_READINGS), "reading": list(RIGIDITY_READINGS.values()),
                                  "clearance-free reducer (N·m/arcmin)": [readings[k] for k in RIGIDITY_READINGS]}),
                    "Rigidity under each reading of the maker's b/a (the Monte Carlo reports each output)", "{:.4g}")
        s.summary = {"breakdown_20dof": frame_records(df),
                     "rigidity_b_over_a_Nm_per_arcmin": float(units.from_base(mt.rigidity, "N*m/arcmin")),
                     "rigidity_readings_clearance_free_Nm_per_arcmin": readings,
                     "rigidity_readings": dict(RIGIDITY_READINGS),
                     "part1": frame_records(comp) if comp is not None else None}
        return s

    def _part1(self, T) -> pd.DataFrame:
        own, mods = self.part1
        g = self.model.geometry
        pins = PinGear(z_p=g.z_b, z_c=g.z_c, R_p=g.r_pin_circle, r_p=g.r_pin, a=g.ecc,
                       b=float(self.te_design.get("cycloid.face_width", own.pins.b)), E=own.pins.E, nu=own.pins.nu)
        same = replace(own, pins=pins, z1=g.z_s, z2=g.z_p, module=g.module, pressure_angle=g.alpha)
        a = own.evaluate(T, *mods)
        b = same.evaluate(T, 0.0, 0.0)
        asec = lambda v: units.from_base(v, "arcsec")  # noqa: E731
        return pd.DataFrame({"component": [LABELS[c] for c in a.components] + ["Total θ_Σ"],
                             "doc 004 RV-80E (arcsec)": np.append(asec(a.theta[0]), asec(a.total[0])),
                             "doc 000 geometry (arcsec)": np.append(asec(b.theta[0]), asec(b.total[0]))})


class ComplianceBreakdown(Analysis):
    """``[[analysis]] kind = "compliance_breakdown"``: the output angle at a torque split per compliance
    family by virtual work — the 20-DOF model with the design's compliance chain, doc 000's rigid chain
    (its contact laws only) and doc 004's torsion-angle model side by side.

    ::

        [[analysis]]
        kind = "compliance_breakdown"
        torque = { value = 784, unit = "N*m" }   # default: the design's rated torque
        rigid_chain = true                       # the 20-DOF model without the chain beside
        stiffness_model = true                   # doc 004's model beside (needs a design it can read)
        model = "torsion"                        # composed study: the torsion-curve stage (default: the only one)

    Families: :data:`rvtol.elements.reducer_chain.FAMILIES` (stable names; a design scales one with
    ``compliance_scale.<family>``).  The 20-DOF split is :meth:`QuasiStaticSolver.contact_work` at the
    clearance-free, error-free equilibrium (input locked); doc 004's is its components, θ4 split into
    crankshaft bending and torsion.  A second table lists how each element is reduced to the 20-DOF
    contacts (:mod:`rvtol.models.transmission.compliance`).
    """

    def setup(self, params, study):
        if study.design is None:
            raise params.error("kind", "compliance_breakdown needs a 20-DOF design ([study] design = ...)")
        self.design = study.design
        self.torque = params.quantity("torque", "N*m", None, positive=True)
        self.with_rigid = params.bool("rigid_chain", True)
        self.with_stiffness = params.bool("stiffness_model", True)
        m = study.model
        stages = getattr(m, "stages", None) or ()
        if isinstance(m, TorsionCurveModel) or "model" in params or any(isinstance(s.model, TorsionCurveModel)
                                                                         for s in stages):
            self.geometry = target_model(params, study, TorsionCurveModel, "torsion_curve").model.geometry
        else:
            self.geometry = geometry_from_design(study.design)
        params.finish()
        if self.torque is None:
            self.torque = self.geometry.rated_torque
        self.rs = None
        if self.with_stiffness:                    # a design doc 004's model cannot read fails here, at load time
            d = study.design
            self.rs = ReducerStiffness.from_design(d)
            self.mods = (d["cycloid.equidistance_modification"], d["cycloid.moved_distance_modification"])

    def run(self, ctx) -> list[Section]:
        from ...plotting.stiffness import plot_compliance_breakdown

        T = self.torque
        asec = lambda v: float(units.from_base(v, "arcsec"))  # noqa: E731
        cols = {"20-DOF, compliance chain": breakdown_at(self.geometry, T)}
        if self.with_rigid:
            cols["20-DOF, doc 000's rigid chain"] = breakdown_at(geometry_from_design(self.design, chain=False), T)
        if self.rs is not None:
            fam = self.rs.evaluate(T, *self.mods).families()
            cols["doc 004 model"] = {k: float(v[0]) for k, v in fam.items()}
        rows = []
        for f, label in FAMILIES.items():
            if any(f in c for c in cols.values()):
                rows.append({"family": f, "element": label,
                             **{f"{name} (arcsec)": asec(c[f]) if f in c else np.nan for name, c in cols.items()}})
        df = pd.DataFrame(rows)
        totals = {name: sum(c.values()) for name, c in cols.items()}
        total_row = {"family": "total", "element": "θ at the output",
                     **{f"{name} (arcsec)": asec(t) for name, t in totals.items()}}
        rig_row = {"family": "T/θ", "element": "secant rigidity (N·m/arcmin)",
                   **{f"{name} (arcsec)": float(units.from_base(T / t, "N*m/arcmin")) for name, t in totals.items()}}
        table = pd.concat([df, pd.DataFrame([total_row, rig_row])], ignore_index=True)
        fig = plot_compliance_breakdown(list(df["element"]), {name: df[f"{name} (arcsec)"] for name in cols})
        Tnm = units.from_base(T, "N*m")
        s = Section("compliance_breakdown", f"Compliance chain: output angle per element at {Tnm:g} N·m")
        s.add_text(f"Input locked, output torque {Tnm:g} N·m, clearance- and error-free reducer. Each element's share "
                   "of the output angle by virtual work, θ_e = Σ f_e·δ_e / T (the actual forces as the virtual "
                   "system; the shares add up to the angle). 20-DOF: doc 000's contact laws with the design's "
                   "compliance elements in series with the contacts that carry their loads (table 2); doc 004's "
                   "model: its components under its own statics with the same elements. NaN: the model has no such "
                   "element. Differences between the two models come from their contact laws (doc 000's "
                   "k = k0·P^0.1 against doc 004's Hertz/Palmgren/ISO 6336) and load sharing, not from the chain "
                   "elements, which both take from rvtol.elements.")
        s.add_table(table, "Output angle per compliance family (arcsec)", "{:.3g}")
        s.add_figure(fig, f"Output angle per element at {Tnm:g} N·m")
        ch = self.geometry.chain
        summary = {"torque_Nm": float(Tnm), "breakdown": frame_records(table)}
        if ch is not None:
            red = ch.to_frame()
            s.add_table(red, "The compliance elements reduced to the 20-DOF contacts (module "
                             "rvtol.models.transmission.compliance)", "{:.4g}")
            src = pd.DataFrame({"family": list(ch.elements.sources), "element as built": list(ch.elements.sources.values())})
            s.add_table(src, "Elements from the design")
            summary["reductions"] = frame_records(red)
        s.summary = summary
        return [s]


def breakdown_at(g, T: float, steps: int = 8) -> dict[str, float]:
    """Output angle (rad) per family of the clearance- and error-free reducer ``g`` at torque ``T`` (N·mm),
    reached in ``steps`` warm-started load steps."""
    r = QuasiStaticSolver(g, tol_f=1e-8).torsion(np.linspace(0.0, T, steps + 1)[1:])
    if not r.ok:
        raise SolverError(f"no equilibrium of the clearance-free reducer at {T:g} N·mm "
                          f"({L.STATUS_REASONS.get(r.failure, r.failure)})")
    return compliance_breakdown(g, None, r.q[-1], T)
