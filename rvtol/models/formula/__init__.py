"""Model outputs as formulas of the factors, written in the study file (``MODELS["formula"]``).

The formulas are :mod:`rvtol.expressions` (parsed safely, never ``eval``; vectorised; exact
derivatives): :class:`rvtol.models.formula.model.FormulaModel`.
"""
