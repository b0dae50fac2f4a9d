"""Assembly adjustment (doc 002): state-space assembly model and finite-horizon LQR adjustment.

* :mod:`.description` — the declarative assembly description (KCs, datum flow chains, steps) and
  the matrices A, B, F(k), C(k), R(k), C(N) built from it;
* :mod:`.lqr` — backward Riccati recursion, its Q → ∞ limit, Kalman filter gains;
* :mod:`.adjuster` — :class:`Adjuster` (``fit()`` computes the gains; ``simulate()`` runs assemblies);
* :mod:`.model` — the adjusted assembly as a :class:`rvtol.model.Model` (``MODELS["adjusted_assembly"]``);
* :mod:`.sweep`, :mod:`.assessment` — example runs, Q sweep, the whole assessment as one result;
* :mod:`.analyses` — the ``adjustment`` study analysis, laid out by :mod:`.texts`.

The comparison with doc 002 lives in the reproduction wing (``studies/reproduction``).
"""
from .adjuster import Adjuster, AssemblyRun
from .description import AssemblyDescription, assembly_from_table, load_assembly
from .model import AdjustedAssemblyModel

__all__ = ["Adjuster", "AssemblyRun", "AssemblyDescription", "assembly_from_table", "load_assembly",
           "AdjustedAssemblyModel"]
