"""Closed vector loops with dependent variables, solved per sample (``MODELS["vector_loop"]``):
:class:`rvtol.models.vector_loop.model.VectorLoopModel`."""
