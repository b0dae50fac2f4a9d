"""Composed models: several physics on the same samples, wired by a declared mapping (one Model).

* :mod:`.model` — :class:`CompositeModel` (factors → quantities → stages), built from a study's
  ``[[model]]`` and ``[[quantity]]`` tables (:func:`from_study_tables`).
"""
from .model import CompositeModel, MappedQuantity, Stage, StageInputs

__all__ = ["CompositeModel", "MappedQuantity", "Stage", "StageInputs"]
