"""The linear model ``Y = c + X·Aᵀ`` from a study file (``MODELS["linear"]``).

The class itself, :class:`rvtol.model.LinearModel`, sits beside the Model
protocol because the engine's tests use it as their reference.
"""
