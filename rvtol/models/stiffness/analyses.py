"""Report analysis of the torsional-stiffness model (``[[analysis]] kind = "stiffness_breakdown"``).

::

    [[analysis]]
    kind = "stiffness_breakdown"
    torque = { value = 784, unit = "N*m" }        # default: the model's torque (rated)
    torque_fractions = [0.25, 0.5, 0.75, 1.0]     # of the torque, for the curves against load

Sections: the elastic torsion angle θ_Σ = θ1 + … + θ5 at the output by
component (and against the torque), and the cycloid–pin load distribution.
Doc 004's parameter studies and printed figures are in
:mod:`rvtol.reproduction.doc004_stiffness` (``stiffness_reproduction``).
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd

from ... import units
from ...analysis import Analysis
from ...report.sections import Section, frame_records
from .model import TorsionalStiffnessModel
from .torsion_angle import LABELS, ReducerStiffness


class StiffnessBreakdown(Analysis):
    def setup(self, params, study):
        if study.design is None:
            raise params.error("kind", f"{params.data.get('kind', 'this analysis')} needs a design "
                                       "([study] design = ...)")
        self.torque = params.quantity("torque", "N*m", None, positive=True)
        self.fractions = params.floats("torque_fractions", [0.25, 0.5, 0.75, 1.0], positive=True, min_length=1)
        model = study.model
        if isinstance(model, TorsionalStiffnessModel):
            self.rs = model.stiffness
            self.torque = self.torque or model.torque
        else:
            self.rs = ReducerStiffness.from_design(study.design)
        self.torque = self.torque or study.design["reducer.rated_torque"]
        d = study.design
        self.mods = (d["cycloid.equidistance_modification"], d["cycloid.moved_distance_modification"])
        self.read(params, study)

    def read(self, params, study) -> None:
        """Further parameters (subclasses)."""

    def header(self) -> str:
        T = self.torque
        Tnm = units.from_base(T, "N*m")
        return (f"All figures at the output torque T = {Tnm:g} N·m (input locked), per disc "
                f"T_c = {units.from_base(self.rs.disc_torque(T), 'N*m'):.1f} N·m; Table 1 modifications "
                f"Δr_p = {self.mods[0] * 1e3:g} µm, ΔR_p = {self.mods[1] * 1e3:g} µm unless stated. "
                "Doc 004 does not state its torque.")

    def run(self, ctx) -> list[Section]:
        results = {}
        return [self.breakdown(self.torque, self.header(), results), self.contact(self.torque, results)]

    def annotate_breakdown(self, df: pd.DataFrame) -> None:
        """Add columns to the component table (the reproduction adds the document's values)."""

    def breakdown(self, T, head, out) -> Section:
        res = self.rs.evaluate(T, *self.mods)
        df = res.to_frame()
        self.annotate_breakdown(df)
        tang = self._tangential().evaluate(T, *self.mods)
        out["table5"] = df
        out["table5_tangential_theta3"] = float(units.from_base(tang.component("crank_bearings")[0], "arcsec"))
        rig = float(units.from_base(res.rigidity[0], "N*m/arcmin"))
        out["rigidity"] = rig
        fr = np.asarray(self.fractions) * T
        curve = self.rs.evaluate(fr, *self.mods)
        cf = pd.DataFrame({"torque (N·m)": units.from_base(fr, "N*m"),
                           **{f"{LABELS[c]} (arcsec)": units.from_base(curve.component(c), "arcsec")
                              for c in curve.components},
                           "θ_Σ (arcsec)": units.from_base(curve.total, "arcsec"),
                           "rigidity T/θ_Σ (N·m/arcmin)": units.from_base(curve.rigidity, "N*m/arcmin")})
        s = Section("stiffness_breakdown", "Elastic torsion angle θ_Σ = θ1 + … + θ5 (doc 004, Table 5)")
        s.add_text(head + f" Equivalent torsional rigidity T/θ_Σ = {rig:.1f} N·m/arcmin. With doc 004's literal "
                   f"θ3 (tangential bearing deflection only) θ3 would be {out['table5_tangential_theta3']:.2f} arcsec.")
        s.add_table(df, "Torsion-angle components at the output: rvtol against doc 004's Table 5", "{:.4g}")
        s.add_figure(res.plot(), "Components of the elastic torsion angle (rvtol)")
        s.add_table(cf, "Components against the output torque", "{:.4g}")
        s.summary = {"torque_Nm": float(units.from_base(T, "N*m")), "components": frame_records(df),
                     "rigidity_Nm_per_arcmin": rig, "versus_torque": frame_records(cf)}
        return s

    def _tangential(self) -> ReducerStiffness:
        return replace(self.rs, bearing_kinematics="tangential")

    def contact(self, T, out) -> Section:
        res = self.rs.evaluate(T, *self.mods)
        rows, cs = res.contacts[0]
        pins = cs.to_frame(0)
        pins = pins[pins["arm l_k (mm)"] > 0]
        fr = np.asarray(self.fractions) * T
        load = self.rs.evaluate(fr, *self.mods)
        lf = pd.DataFrame({"torque (N·m)": units.from_base(fr, "N*m"),
                           "max pin force (N)": load.extra["max_pin_force"],
                           "contact pairs": load.extra["contact_pairs"].astype(int)})
        out["contact_vs_torque"] = lf
        s = Section("stiffness_contact", "Cycloid–pin load distribution (doc 004's iterative contact solution)")
        s.add_text(f"Loaded pins {int(cs.contacts[0])}, largest force {cs.max_force[0]:.1f} N, "
                   f"F_max at the largest arm {cs.F_ref[0]:.1f} N, elastic cycloid rotation "
                   f"{units.from_base(cs.beta[0], 'arcsec'):.2f} arcsec; equilibrium residual "
                   f"{cs.equilibrium_residual()[0]:.1e}.")
        s.add_table(pins, "Pins on the loaded side: clearance, force and single-pair stiffness k_b", "{:.4g}")
        s.add_figure(cs.plot(0), "Pin forces and initial clearances")
        s.add_table(lf, "Largest pin force and contact pairs against the torque", "{:.4g}")
        s.summary = {"pins": frame_records(pins), "versus_torque": frame_records(lf)}
        return s
