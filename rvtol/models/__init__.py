"""The physics of rvtol: every :class:`rvtol.model.Model`, one package per capability.

Each package has the same shape: its solvers (pure functions and small
classes; numba only in ``_kernels.py`` with a NumPy twin), ``model.py`` (the
Model and its study factory ``from_study(params, design, spec)``, registered
in :data:`rvtol.registry.MODELS`), its capabilities (plain functions returning
result dataclasses with ``to_frame()``, ``plot()``, ``summary()``),
``analyses.py`` (thin :class:`rvtol.analysis.Analysis` adapters: declared
options, one call; registered in :data:`rvtol.registry.ANALYSES`) and
``texts.py`` (the report's prose and the layout of each result).

=================  ============================================  =========================
package            physics                                       ``[model] kind``
=================  ============================================  =========================
``linear``         ``Y = c + X·Aᵀ`` (the engine's reference)      ``linear``
``lost_motion``    doc 001: per-stage geometric lost motion      ``lost_motion``
                   (screening estimate; document / consistent)
``transmission``   doc 000: the 20-DOF reducer (quasi-static,     ``transmission_error``
                   Newmark-β), transmission error
``torsion_curve``  the hysteresis curve of the 20-DOF model       ``torsion_curve``
                   (maker's lost motion, backlash, rigidity)
``stiffness``      doc 004: elastic torsion angles θ1…θ5          ``torsional_stiffness``
``stackup``        doc 003: 6-DOF deviations through the          ``stackup``
                   assembly graph
``adjustment``     doc 002: state-space assembly, finite-         ``adjusted_assembly``
                   horizon LQR adjustment
``formula``        outputs as formulas of the factors written     ``formula``
                   in the study (exact derivatives)
``custom``         a Python factory named ``module:function``     ``python`` (and kinds of
                   in the study                                   installed entry points)
``composite``      several models on the same samples            several ``[[model]]``
``screening``      doc 001's screening beside the 20-DOF torsion  (analysis
                   curve on the same reducers (the bridge)        ``lost_motion_screening``)
=================  ============================================  =========================

Closed-form machine elements (Hertz contacts, bearings, shafts, carrier)
shared by several models are in :mod:`rvtol.elements`.
"""
