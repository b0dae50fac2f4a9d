"""Custom Python models in a study: ``[model] kind = "python"`` with ``factory = "module:function"``
(:mod:`rvtol.models.custom.model`), or a kind registered by an installed package's entry point
(``[project.entry-points."rvtol.models"]``, found by :func:`rvtol.registry.model_factory`).
Either way the model keeps the CLI, the report and the gate.
"""
