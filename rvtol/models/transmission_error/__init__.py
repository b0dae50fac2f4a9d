"""Transmission error of the RV reducer (doc 000): the 20-DOF model (:mod:`rvtol.models.reducer_20dof`) turned
through one output revolution, as a model over error factors and its study analyses.

Modules: :mod:`.model` (:class:`~.model.TransmissionErrorModel`, ``MODELS["transmission_error"]``: quasi-static or
Newmark-β), :mod:`.extremes` (the TE curve's extremes refined between a sweep's positions: Δθ_er), :mod:`.orders`
(which error families produce which orders of the TE spectrum), :mod:`.rig` (a test rig's measurement chain),
:mod:`.curve` (one reducer in full), :mod:`.sensitivity` (Δθ_er against the error magnitudes, doc 000 §3–4),
:mod:`.analyses` (``transmission_error_curve``, ``transmission_error_sensitivity``; laid out by :mod:`.texts`).
"""
