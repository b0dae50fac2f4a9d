"""Torsional stiffness of the RV reducer from elastic torsion angles (doc 004).

* :mod:`.cycloid_contact` — initial clearance Δ(φ_k) from modifications and
  errors, the iterative loaded-contact solution (F_max, F_k), k_b and K_B;
* :mod:`.torsion_angle` — θ_Σ = θ1 + … + θ5 at the output, input locked (the
  elements: :mod:`rvtol.elements` — Hertz contact, ISO 6336-1 mesh, Palmgren
  bearings, Timoshenko crankshaft, carrier pillars);
* :mod:`.model` — ``MODELS["torsional_stiffness"]``;
* :mod:`.breakdown` — the torsion-angle breakdown and load distribution of one reducer;
* :mod:`.analyses` — ``ANALYSES["stiffness_breakdown"]``, laid out by :mod:`.texts`.

Doc 004's parameter studies and the comparison with it live in the reproduction wing
(``studies/reproduction``).
"""
from .cycloid_contact import ContactSolution, PinGear, solve_contact
from .torsion_angle import COMPONENTS, ReducerStiffness, TorsionAngles

__all__ = ["PinGear", "ContactSolution", "solve_contact", "ReducerStiffness", "TorsionAngles", "COMPONENTS"]
