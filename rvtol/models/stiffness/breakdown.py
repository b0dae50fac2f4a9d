"""The elastic torsion angle of one reducer at a torque: its components and the cycloid–pin load distribution.

:func:`stiffness_breakdown` returns a :class:`StiffnessAtTorque` of two results: a
:class:`TorsionAngleBreakdown` (θ_Σ = θ1 + … + θ5 at the output by component, the equivalent rigidity,
the components against the torque) and a :class:`PinLoads` (the pins on the loaded side with their
clearance, force and single-pair stiffness; the largest pin force and the contact pairs against the
torque).
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from ... import units
from ...records import frame_records
from .torsion_angle import LABELS, ReducerStiffness, TorsionAngles


@dataclass
class TorsionAngleBreakdown:
    """``components``: θ per component and the total at the output (arcsec); ``versus_torque``: the
    components and the rigidity at fractions of the torque; ``tangential_theta3``: θ3 with the bearings'
    tangential deflection only (arcsec)."""

    components: pd.DataFrame
    versus_torque: pd.DataFrame
    rigidity: float                  # T/θ_Σ, N·m/arcmin
    tangential_theta3: float
    torque: float                    # N·mm
    disc_torque: float               # N·mm
    modifications: tuple[float, float]
    angles: TorsionAngles

    def to_frame(self) -> pd.DataFrame:
        return self.components

    def plot(self):
        return self.angles.plot()

    def summary(self) -> dict:
        return {"torque_Nm": float(units.from_base(self.torque, "N*m")), "components": frame_records(self.components),
                "rigidity_Nm_per_arcmin": self.rigidity, "versus_torque": frame_records(self.versus_torque)}


@dataclass
class PinLoads:
    """``pins``: the pins on the loaded side (clearance, force, k_b); ``versus_torque``: the largest pin
    force and the contact pairs at fractions of the torque; ``contact``: the contact solution at the torque."""

    pins: pd.DataFrame
    versus_torque: pd.DataFrame
    contact: object

    def to_frame(self) -> pd.DataFrame:
        return self.pins

    def plot(self):
        return self.contact.plot(0)

    def summary(self) -> dict:
        return {"pins": frame_records(self.pins), "versus_torque": frame_records(self.versus_torque)}


@dataclass
class StiffnessAtTorque:
    angles: TorsionAngleBreakdown
    contact: PinLoads

    def to_frame(self) -> pd.DataFrame:
        return self.angles.components

    def summary(self) -> dict:
        return self.angles.summary()

    def plot(self, which: str = "angles"):
        """The report's figure of ``which``: ``angles`` (the torsion-angle components) or ``contact`` (the pin
        forces and initial clearances)."""
        parts = {"angles": self.angles, "contact": self.contact}
        if which not in parts:
            raise ValueError(f"unknown figure {which!r} (expected angles or contact)")
        return parts[which].plot()


def torsion_angle_breakdown(rs: ReducerStiffness, T: float, mods: tuple[float, float],
                            fractions) -> TorsionAngleBreakdown:
    """θ_Σ of ``rs`` at the output torque ``T`` (N·mm) with the profile modifications ``mods`` (mm), and
    at the ``fractions`` of ``T``."""
    res = rs.evaluate(T, *mods)
    tang = replace(rs, bearing_kinematics="tangential").evaluate(T, *mods)
    fr = np.asarray(fractions) * T
    curve = rs.evaluate(fr, *mods)
    cf = pd.DataFrame({"torque (N·m)": units.from_base(fr, "N*m"),
                       **{f"{LABELS[c]} (arcsec)": units.from_base(curve.component(c), "arcsec")
                          for c in curve.components},
                       "θ_Σ (arcsec)": units.from_base(curve.total, "arcsec"),
                       "rigidity T/θ_Σ (N·m/arcmin)": units.from_base(curve.rigidity, "N*m/arcmin")})
    return TorsionAngleBreakdown(res.to_frame(), cf, float(units.from_base(res.rigidity[0], "N*m/arcmin")),
                                 float(units.from_base(tang.component("crank_bearings")[0], "arcsec")), T,
                                 rs.disc_torque(T), tuple(mods), res)


def pin_loads(rs: ReducerStiffness, T: float, mods: tuple[float, float], fractions) -> PinLoads:
    """The cycloid–pin load distribution of ``rs`` at ``T`` (doc 004's iterative contact solution)."""
    res = rs.evaluate(T, *mods)
    rows, cs = res.contacts[0]
    pins = cs.to_frame(0)
    pins = pins[pins["arm l_k (mm)"] > 0]
    fr = np.asarray(fractions) * T
    load = rs.evaluate(fr, *mods)
    lf = pd.DataFrame({"torque (N·m)": units.from_base(fr, "N*m"), "max pin force (N)": load.extra["max_pin_force"],
                       "contact pairs": load.extra["contact_pairs"].astype(int)})
    return PinLoads(pins, lf, cs)


def stiffness_breakdown(rs: ReducerStiffness, T: float, mods: tuple[float, float], fractions) -> StiffnessAtTorque:
    """:func:`torsion_angle_breakdown` and :func:`pin_loads` of one reducer."""
    return StiffnessAtTorque(torsion_angle_breakdown(rs, T, mods, fractions), pin_loads(rs, T, mods, fractions))
