"""Report analyses for doc 004's studies (``[[analysis]] kind = "stiffness_reproduction"``).

::

    [[analysis]]
    kind = "stiffness_reproduction"
    torque = { value = 784, unit = "N*m" }        # default: the model's torque (rated)
    pin_circle_radii = [65, 71.25, 77.5, 83.75, 90]   # mm (Table 2)
    eccentricities = [1.2, 1.3, 1.4, 1.5, 1.6, 1.7, 1.8]   # mm (Table 4)
    widths = [10, 11, 12, 13, 14, 15]             # mm (Table 4)
    sweep_points = 5                              # points of the modification / error sweeps
    error_range = 10                              # µm: errors swept over ±error_range
    torque_fractions = [0.25, 0.5, 0.75, 1.0]     # of the torque, for contact pairs vs load

Sections: torsion-angle breakdown (Table 5), cycloid–pin load distribution,
geometry (Tables 2 and 4), modifications (Table 3 and the Δr_p / ΔR_p
sweeps), pin errors (δR_p / δr_p sweeps and the 128.7 N / 82.5 N figures),
and the reproduction table (each printed number against rvtol's).
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from ... import units
from ...report.sections import Section, frame_records
from ...reproduction import doc004_stiffness as rp
from .model import TorsionalStiffnessModel
from .torsion_angle import COMPONENTS, LABELS, ReducerStiffness


class StiffnessReproduction:
    def __init__(self, params, study):
        if study.design is None:
            raise params.error("kind", "stiffness_reproduction needs a design ([study] design = ...)")
        self.torque = params.quantity("torque", "N*m", None, positive=True)
        mm = dict(positive=True, min_length=2)
        self.radii = params.floats("pin_circle_radii", [65.0, 71.25, 77.5, 83.75, 90.0], **mm)
        self.eccentricities = params.floats("eccentricities", [1.2, 1.3, 1.4, 1.5, 1.6, 1.7, 1.8], **mm)
        self.widths = params.floats("widths", [10.0, 11.0, 12.0, 13.0, 14.0, 15.0], **mm)
        self.points = params.int("sweep_points", 5, min=3, max=101)
        self.error_range = params.quantity("error_range", "um", 0.010, positive=True)
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
        for name, vals in (("pin_circle_radii", self.radii), ("eccentricities", self.eccentricities)):
            for v in vals:
                K1 = (v if name == "eccentricities" else self.rs.pins.a) * self.rs.pins.z_p / (
                    v if name == "pin_circle_radii" else self.rs.pins.R_p)
                if K1 >= 1.0:
                    raise params.error(name, f"value {v:g} mm gives K1 = a z_p / R_p = {K1:.3f} >= 1")

    # ------------------------------------------------------------------
    def run(self, ctx) -> list[Section]:
        T = self.torque
        Tnm = units.from_base(T, "N*m")
        head = (f"All figures at the output torque T = {Tnm:g} N·m (input locked), per disc "
                f"T_c = {units.from_base(self.rs.disc_torque(T), 'N*m'):.1f} N·m; Table 1 modifications "
                f"Δr_p = {self.mods[0] * 1e3:g} µm, ΔR_p = {self.mods[1] * 1e3:g} µm unless stated. "
                "Doc 004 does not state its torque.")
        results = {}
        sections = [self._breakdown(T, head, results), self._contact(T, results), self._geometry(T, head, results),
                    self._modifications(T, head, results), self._errors(T, head, results)]
        sections.append(self._reproduction(results))
        return sections

    def _breakdown(self, T, head, out) -> Section:
        res = self.rs.evaluate(T, *self.mods)
        df = res.to_frame()
        printed = rp.PRINTED["table5"]
        df["doc 004 (arcsec)"] = [printed[c] for c in COMPONENTS] + [printed["total"]]
        tang = self._tangential().evaluate(T, *self.mods)
        out["table5"] = df
        out["table5_tangential_theta3"] = float(units.from_base(tang.component("crank_bearings")[0], "arcsec"))
        rig = float(units.from_base(res.rigidity[0], "N*m/arcmin"))
        out["rigidity"] = rig
        fr = np.asarray(self.fractions) * T
        curve = self.rs.evaluate(fr, *self.mods)
        cf = pd.DataFrame({"torque (N·m)": units.from_base(fr, "N*m"),
                           **{f"{LABELS[c]} (arcsec)": units.from_base(curve.component(c), "arcsec")
                              for c in COMPONENTS},
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
        from dataclasses import replace

        return replace(self.rs, bearing_kinematics="tangential")

    def _contact(self, T, out) -> Section:
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

    def _geometry(self, T, head, out) -> Section:
        from ...plotting.stiffness import plot_sweep

        s = Section("stiffness_geometry", "Geometry: pin circle radius, eccentricity, width (Tables 2 and 4)")
        s.add_text(head + " k_b uses |T'| (see the model notes); K_B is summed over the pins loaded at T.")
        s.summary = {}
        for param, vals, what in (("R_p", self.radii, "pin circle radius R_p (Table 2, Table 4)"),
                                  ("a", self.eccentricities, "eccentricity a (Table 4)"),
                                  ("b", self.widths, "cycloid width b (Table 4)")):
            df = rp.geometry_sweep(self.rs, T, self.mods, param, np.asarray(vals) * 1.0)
            out[f"geometry_{param}"] = df
            s.add_table(df, f"Against the {what}", "{:.4g}")
            x = f"{param} (mm)"
            s.add_figure(plot_sweep(df, x, ["max pin force (N)"], ylabel="force [N]", secondary="contact pairs"),
                         f"Largest pin force and contact pairs against {param}")
            s.add_figure(plot_sweep(df, x, ["θ_Σ (arcsec)", "θ2 (arcsec)"], ylabel="torsion angle [arcsec]",
                                    secondary="K_B (N·m/arcmin)", secondary_label="K_B [N·m/arcmin]"),
                         f"θ_Σ, θ2 and K_B against {param}")
            s.summary[param] = frame_records(df)
        return s

    def _modifications(self, T, head, out) -> Section:
        from ...plotting.stiffness import plot_sweep

        t3 = rp.PRINTED["table3"]
        combos = list(zip(t3["combination"], t3["Δr_p (mm)"], t3["ΔR_p (mm)"]))
        df = rp.modification_combinations(self.rs, T, combos)
        df["doc 004 j_C1 (mm)"] = t3["j_C1 (mm)"]
        df["doc 004 force"] = t3["force"]
        df["doc 004 contact pairs"] = t3["contact pairs"]
        pairs = {f"pairs at {f:g}·T": [int(self.rs.evaluate(f * T, dr, dR).extra["contact_pairs"][0])
                                       for _, dr, dR in combos] for f in self.fractions}
        pairs_df = pd.DataFrame({"combination": t3["combination"], **pairs})
        n = self.points
        sw_e = rp.modification_sweep(self.rs, T, "equidistance", np.linspace(0.0, 0.020, n))
        sw_m = rp.modification_sweep(self.rs, T, "moved_distance", np.linspace(-0.020, 0.0, n))
        out.update(table3=df, table3_pairs=pairs_df, sweep_equidistance=sw_e, sweep_moved=sw_m)
        s = Section("stiffness_modifications", "Profile modifications (Table 3 and the Δr_p, ΔR_p sweeps)")
        s.add_text(head + " Table 3 keeps the radial clearance Δr_p − ΔR_p = 0.02 mm. rvtol's 'angular backlash' "
                   "2·n0/r_c' (rad) with n0 = Δr_p − √(1−K1²)·ΔR_p the normal clearance at φ0 = arccos K1 is the "
                   "quantity that matches the document's j_C1 column (printed as mm); the clearance formula Δ(φ_k) "
                   "itself is measured from first contact and is nanometres at the first pin. Each sweep holds the "
                   "other modification at zero.")
        short = ["1: +Δr", "2: −ΔR", "3: +Δr +ΔR", "4: +Δr −ΔR", "5: −Δr −ΔR"]
        clear = pd.DataFrame({"combination": short, "Δr_p (µm)": df["Δr_p (mm)"] * 1e3,
                              "ΔR_p (µm)": df["ΔR_p (mm)"] * 1e3,
                              "radial Δr_p−ΔR_p (µm)": df["radial clearance Δr_p-ΔR_p (mm)"] * 1e3,
                              "normal n0 (µm)": df["normal clearance n0 (mm)"] * 1e3,
                              "2n0/r_c' (rad)": df["backlash angle 2n0/r_c (rad)"],
                              "doc 004 j_C1 ('mm')": df["doc 004 j_C1 (mm)"],
                              "min Δ(φ_k) (nm)": df["min pin clearance Δ(φ_k) (mm)"] * 1e6})
        loads = pd.DataFrame({"combination": short, "max pin force (N)": df["max pin force (N)"],
                              "doc 004 force": df["doc 004 force"], "contact pairs": df["contact pairs"],
                              "doc 004 pairs": df["doc 004 contact pairs"], "K_B (N·m/arcmin)": df["K_B (N·m/arcmin)"],
                              "θ2 (arcsec)": df["θ2 (arcsec)"], "θ_Σ (arcsec)": df["θ_Σ (arcsec)"]})
        legend = "; ".join(f"{i + 1} {name.lower()}" for i, name in enumerate(t3["combination"]))
        s.add_table(clear, f"Doc 004 Table 3, clearances ({legend})", "{:.4g}")
        s.add_table(loads, "Doc 004 Table 3 — largest pin force and contact pairs", "{:.4g}")
        pairs_df["combination"] = short
        s.add_table(pairs_df, "Contact pairs of the five combinations at fractions of the torque "
                    "(doc 004 does not state its torque)")
        s.add_table(sw_e, "θ against the equidistance modification Δr_p (ΔR_p = 0)", "{:.4g}")
        s.add_table(sw_m, "θ against the moved-distance modification ΔR_p (Δr_p = 0)", "{:.4g}")
        for sw, x in ((sw_e, "Δr_p (µm)"), (sw_m, "ΔR_p (µm)")):
            s.add_figure(plot_sweep(sw, x, ["θ_Σ (arcsec)", f"{LABELS['cycloid_pin']} (arcsec)"],
                                    ylabel="torsion angle [arcsec]", secondary="contact pairs"),
                         f"θ_Σ and θ2 against {x}")
        s.summary = {"table3": frame_records(df), "pairs_vs_torque": frame_records(pairs_df),
                     "sweep_equidistance": frame_records(sw_e), "sweep_moved_distance": frame_records(sw_m)}
        return s

    def _errors(self, T, head, out) -> Section:
        from ...plotting.stiffness import plot_sweep

        vals = np.linspace(-self.error_range, self.error_range, self.points)
        e_R = rp.error_sweep(self.rs, T, self.mods, "pin_circle", vals)
        e_r = rp.error_sweep(self.rs, T, self.mods, "pin_radius", vals)
        out.update(error_pin_circle=e_R, error_pin_radius=e_r)
        stats = pd.DataFrame({
            "error": ["δR_p (pin circle radius)", "δr_p (pin radius)"],
            "mean |ΔF| between sweep points (N)": [rp.mean_abs_step(e_R), rp.mean_abs_step(e_r)],
            "F(+range) − F(−range) (N)": [rp.sweep_change(e_R, "max pin force (N)"),
                                          rp.sweep_change(e_r, "max pin force (N)")],
            "θ_Σ(+range) − θ_Σ(−range) (arcsec)": [rp.sweep_change(e_R), rp.sweep_change(e_r)],
            "doc 004 average force change (N)": [rp.PRINTED["error_force_pin_circle"],
                                                 rp.PRINTED["error_force_pin_radius"]],
        })
        out["error_stats"] = stats
        step = 2 * self.error_range / (self.points - 1) * 1e3
        s = Section("stiffness_errors", "Pin circle radius and pin radius errors (δR_p, δr_p)")
        s.add_text(head + f" Errors swept over ±{self.error_range * 1e3:g} µm in {step:g}-µm steps, the other error "
                   "zero. Doc 004's Δ2 subtracts both errors from the clearance, so positive errors close it "
                   "(more pins carry load, smaller θ).")
        s.add_table(stats, "Sensitivity of the largest pin force and of θ_Σ to the pin errors", "{:.4g}")
        s.add_table(e_R, "Against δR_p", "{:.4g}")
        s.add_table(e_r, "Against δr_p", "{:.4g}")
        merged = pd.DataFrame({"error (µm)": vals * 1e3, "δR_p: max pin force (N)": e_R["max pin force (N)"],
                               "δr_p: max pin force (N)": e_r["max pin force (N)"],
                               "δR_p: θ_Σ (arcsec)": e_R["θ_Σ (arcsec)"], "δr_p: θ_Σ (arcsec)": e_r["θ_Σ (arcsec)"]})
        s.add_figure(plot_sweep(merged, "error (µm)", ["δR_p: max pin force (N)", "δr_p: max pin force (N)"],
                                ylabel="largest pin force [N]"), "Largest pin force against the pin errors")
        s.add_figure(plot_sweep(merged, "error (µm)", ["δR_p: θ_Σ (arcsec)", "δr_p: θ_Σ (arcsec)"],
                                ylabel="θ_Σ [arcsec]"), "θ_Σ against the pin errors")
        s.summary = {"stats": frame_records(stats), "pin_circle": frame_records(e_R),
                     "pin_radius": frame_records(e_r)}
        return s

    def _reproduction(self, r) -> Section:
        df = rp.reproduction_table(r)
        s = Section("stiffness_reproduction", "Doc 004's printed figures against rvtol")
        s.add_text("One row per printed figure. 'reproduced' is yes when rvtol's number agrees within 10 % (or "
                   "exactly for counts and orderings), 'partly' when only the direction/ordering agrees or the "
                   "number is within a factor of two, 'no' otherwise; the reason column says why. No constant was adjusted to meet a printed number.")
        s.add_table(df, "Reproduction table", "{:.4g}")
        s.summary = {"rows": frame_records(df)}
        return s
