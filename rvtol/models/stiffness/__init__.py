"""Torsional stiffness of the RV reducer from elastic torsion angles (doc 004).

* :mod:`.hertz` — line-contact approach of two cylinders (doc 004's formula);
* :mod:`.cycloid_contact` — initial clearance Δ(φ_k) from modifications and
  errors, the iterative loaded-contact solution (F_max, F_k), k_b and K_B;
* :mod:`.involute` (ISO 6336-1), :mod:`.bearings` (Palmgren),
  :mod:`.crankshaft` (Timoshenko beam), :mod:`.carrier` (pillars);
* :mod:`.torsion_angle` — θ_Σ = θ1 + … + θ5 at the output, input locked;
* :mod:`.model` — ``MODELS["torsional_stiffness"]``;
* :mod:`.reproduction`, :mod:`.analyses` — doc 004's studies
  (``ANALYSES["stiffness_reproduction"]``).
"""
from .cycloid_contact import ContactSolution, PinGear, solve_contact
from .torsion_angle import COMPONENTS, ReducerStiffness, TorsionAngles

__all__ = ["PinGear", "ContactSolution", "solve_contact", "ReducerStiffness", "TorsionAngles", "COMPONENTS"]
