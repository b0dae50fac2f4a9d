"""The physics of rvtol: every :class:`rvtol.model.Model`, one package per capability.

Each package has the same shape: its solvers (pure functions and small
classes; numba only in ``_kernels.py`` with a NumPy twin), ``model.py`` (the
Model and its study factory ``from_study(params, design, spec)``, registered
in :data:`rvtol.registry.MODELS`), its capabilities (plain functions returning
result dataclasses with ``to_frame()``, ``plot()``, ``summary()``),
``analyses.py`` (thin :class:`rvtol.analysis.Analysis` adapters: declared
options, one call; registered in :data:`rvtol.registry.ANALYSES`) and
``texts.py`` (the report's prose and the layout of each result).

======================  ============================================  =========================
package                 physics                                       ``[model] kind``
======================  ============================================  =========================
``reducer_20dof``       doc 000: the 20-DOF reducer (quasi-static,     (none: the core the next
                        Newmark-β), its contacts, compliance chain     five build on)
                        and friction
``transmission_error``  the 20-DOF reducer over one output            ``transmission_error``
                        revolution: transmission error, orders
``torsion_curve``       the hysteresis curve of the 20-DOF model       ``torsion_curve``
                        (maker's lost motion, backlash, rigidity)
``pin_ring``            the discs' fit in the pin ring; the ring's     ``pin_ring_fit``,
                        preload and drag (20-DOF, no load)             ``pin_ring_preload``
``calibration``         the 20-DOF model's parameters fitted to        (analysis ``calibration``)
                        measured curves
``screening``           doc 001's screening beside the 20-DOF torsion  (analysis
                        curve on the same reducers (the bridge)        ``lost_motion_screening``)
``linear``              ``Y = c + X·Aᵀ`` (the engine's reference)      ``linear``
``lost_motion``         doc 001: per-stage geometric lost motion      ``lost_motion``
                        (screening estimate; document / consistent)
``stiffness``           doc 004: elastic torsion angles θ1…θ5          ``torsional_stiffness``
``stackup``             doc 003: 6-DOF deviations through the          ``stackup``
                        assembly graph
``adjustment``          doc 002: state-space assembly, finite-         ``adjusted_assembly``
                        horizon LQR adjustment
``vector_loop``         closed 2-D / 3-D vector loops solved per       ``vector_loop``
                        sample (dependent variables)
``formula``             outputs as formulas of the factors written     ``formula``
                        in the study (exact derivatives)
``custom``              a Python factory named ``module:function``     ``python`` (and kinds of
                        in the study                                   installed entry points)
``composite``           several models on the same samples            several ``[[model]]``
======================  ============================================  =========================

Closed-form machine elements (Hertz contacts, the pin in its groove, rolling bearings, shafts, carrier)
shared by several models are in :mod:`rvtol.elements`.
"""
