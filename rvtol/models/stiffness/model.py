"""The torsion-angle model as an rvtol :class:`~rvtol.model.Model` over tolerance factors.

::

    [model]
    kind = "torsional_stiffness"
    torque = { value = 784, unit = "N*m" }   # default: the design's reducer.rated_torque
    pin_phase = 0.0                          # pin angles 2π(k + phase)/z_p (pin pitches)
    crank_angle = { value = 0, unit = "deg" }
    bearing_kinematics = "virtual_work"      # or "tangential" (doc 004's θ3 literally)

Factors it knows (any subset, any order; the rest stay at the design's
nominal): ``equidistance_mod`` (Δr_p), ``moved_distance_mod`` (ΔR_p),
``pin_circle_error`` (δR_p), ``pin_radius_error`` (δr_p), all lengths.
"""
from __future__ import annotations

import numpy as np

from dataclasses import dataclass

from ...errors import InputError, did_you_mean
from ...model import STATUS_NONFINITE, STATUS_OK, Model, Quantity
from ...model_kind import ModelKind
from ...options import option
from .torsion_angle import BEARING_KINEMATICS, COMPONENTS, ReducerStiffness

FACTORS = {
    "equidistance_mod": "equidistance modification Δr_p of the cycloid profile",
    "moved_distance_mod": "moved-distance modification ΔR_p of the cycloid profile",
    "pin_circle_error": "pin circle radius error δR_p (doc 004's sign: positive closes the clearance)",
    "pin_radius_error": "pin radius error δr_p (positive closes the clearance)",
}

STATUS_INTERFERENCE = 2
STATUS_GEOMETRY = 3

def theta_outputs(components) -> tuple[Quantity, ...]:
    return tuple(Quantity(f"theta_{c}", "rad", "arcsec", f"elastic torsion angle, {c.replace('_', ' ')}")
                 for c in components)


THETA_OUTPUTS = theta_outputs(COMPONENTS)
REST = (
    Quantity("theta_total", "rad", "arcsec", "elastic torsion angle θ_Σ at the output"),
    Quantity("torsional_rigidity", "N*mm/rad", "N*m/arcmin", "secant rigidity T / θ_Σ"),
    Quantity("max_pin_force", "N", "N", "largest cycloid–pin force"),
    Quantity("contact_pairs", "1", "1", "loaded pins per disc"),
    Quantity("K_B", "N*mm/rad", "N*m/arcmin", "cycloid–pin torsional stiffness Σ k_b l_k²"),
    Quantity("pin_backlash", "rad", "arcmin", "output backlash of the cycloid–pin clearance"),
)
OUTPUTS = THETA_OUTPUTS + REST


class TorsionalStiffnessModel(Model):
    """θ1..θ5 (and the further components the design provides), θ_Σ, rigidity, pin forces, K_B and pin
    backlash at one output torque."""

    status_reasons = {
        STATUS_NONFINITE: "model returned a non-finite value",
        STATUS_INTERFERENCE: "negative cycloid–pin clearance (preloaded mesh): outside doc 004's model",
        STATUS_GEOMETRY: "K1' = a z_p / (R_p + ΔR_p) >= 1: no cycloid profile exists",
    }
    outputs = OUTPUTS

    def __init__(self, stiffness: ReducerStiffness, inputs, torque: float, nominal: dict[str, float],
                 pin_phase: float = 0.0, crank_angle: float = 0.0):
        unknown = [n for n in inputs if n not in FACTORS]
        if unknown:
            raise InputError(f"unknown factor name {unknown[0]!r}{did_you_mean(unknown[0], FACTORS)} for the "
                             f"torsional_stiffness model "
                             f"(known: {', '.join(FACTORS)})", key="factor")
        self.stiffness = stiffness
        self.outputs = theta_outputs(stiffness.components) + REST     # θ per component the design provides
        self.inputs = tuple(inputs)
        self.input_units = ("mm",) * len(self.inputs)
        self.torque = float(torque)
        self.nominal = dict(nominal)
        self.pin_phase = float(pin_phase)
        self.crank_angle = float(crank_angle)

    def factor_values(self, X: np.ndarray) -> dict[str, np.ndarray]:
        X = self.check_input(X)
        vals = {k: np.full(X.shape[0], v) for k, v in self.nominal.items()}
        for j, name in enumerate(self.inputs):
            vals[name] = X[:, j]
        return vals

    def evaluate(self, X):
        return self.evaluate_with_status(X)[0]

    def evaluate_with_status(self, X):
        vals = self.factor_values(X)
        p = self.stiffness.pins
        geometry_ok = p.R_p + vals["moved_distance_mod"] > p.a * p.z_p      # K1' < 1 (and R_p + ΔR_p > 0)
        vals["moved_distance_mod"] = np.where(geometry_ok, vals["moved_distance_mod"], 0.0)
        res = self.stiffness.evaluate(self.torque, pin_phase=self.pin_phase, crank_angle=self.crank_angle, **vals)
        ex = res.extra
        Y = np.column_stack([res.theta, res.total, res.rigidity, ex["max_pin_force"], ex["contact_pairs"],
                             ex["K_B"], res.pin_backlash])
        status = np.where(np.all(np.isfinite(Y), axis=1), STATUS_OK, STATUS_NONFINITE)
        status = np.where(ex["interference"] > 0, STATUS_INTERFERENCE, status)
        status = np.where(geometry_ok, status, STATUS_GEOMETRY).astype(np.int16)
        Y[status != STATUS_OK] = np.nan
        return Y, status


def nominal_factors(design) -> dict[str, float]:
    """The design's nominal value (base units) of every factor the model knows."""
    return {"equidistance_mod": design["cycloid.equidistance_modification"],
            "moved_distance_mod": design["cycloid.moved_distance_modification"],
            "pin_circle_error": 0.0, "pin_radius_error": 0.0}


@dataclass
class Options:
    """The keys of ``[model] kind = "torsional_stiffness"``."""

    torque: float | None = option(None, "the output torque (default: the design's rated torque)", unit="N*m",
                                  positive=True)
    pin_phase: float = option(0.0, "the pins' angular phase, as a fraction of the pin pitch", min=-1.0, max=1.0)
    crank_angle: float = option(0.0, "the crank angle of the evaluated position", unit="deg")
    bearing_kinematics: str = option("virtual_work", "how the crank bearings' compliance is referred to the output",
                                     choices=BEARING_KINEMATICS)


def build(o: Options, design, spec, error) -> TorsionalStiffnessModel:
    if design is None:
        raise error(None, "the torsional_stiffness model needs a design ([study] design = ...)")
    torque = o.torque if o.torque is not None else design["reducer.rated_torque"]
    rs = ReducerStiffness.from_design(design, bearing_kinematics=o.bearing_kinematics)
    return TorsionalStiffnessModel(rs, spec.names, torque, nominal_factors(design), o.pin_phase, o.crank_angle)


from_study = ModelKind(Options, build, "doc 004's elastic torsion angles: torsional stiffness by element")
