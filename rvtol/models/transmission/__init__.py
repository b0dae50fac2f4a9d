"""Transmission error of the RV reducer: the 20-DOF model of doc 000 (quasi-static and Newmark-β).

Modules: :mod:`.geometry` (derived geometry, undefined symbols filled),
:mod:`.layout` (DOF/contact/array layout), :mod:`.contacts` (contact table),
:mod:`.factors` (error factors and the Table 3 patterns), :mod:`.compliance`
(the design's compliance chain — crankshafts, crank support pairs, carrier,
pin grooves, disc webs, input shaft — in series with the contacts),
:mod:`._kernels` (numba: forces and series laws, Newton, sequences,
Newmark-β; the tests hold them to a NumPy implementation of the same equations, ``tests/numpy_twin.py``),
:mod:`.quasistatic`, :mod:`.extremes` (the TE curve's extremes refined between a
sweep's positions: Δθ_er), :mod:`.newmark`, :mod:`.model` (:class:`TransmissionErrorModel`),
:mod:`.curve` (one reducer in full), :mod:`.sensitivity` (Δθ_er against the error magnitudes),
:mod:`.analyses` (laid out by :mod:`.texts`).

Quasi-static entry point (also for the torsional-stiffness and adjustment
capabilities)::

    from rvtol.design import load_design
    from rvtol.models.transmission.geometry import geometry_from_design
    from rvtol.models.transmission.factors import ErrorFactors
    from rvtol.models.transmission.quasistatic import QuasiStaticSolver

    g = geometry_from_design(load_design("data/designs/rv80e_te.toml"))
    errors = ErrorFactors(["delta_b", "E_c[1,2]"], g.z_b).state([0.005, 0.002])  # mm, or None
    solver = QuasiStaticSolver(g, errors)

    # (a) prescribed input angle + output load torque (TE over one output revolution)
    r = solver.rotation(load_torque=0.03 * g.rated_torque, per_crank_rev=36)
    r.te            # Δθ_ca = θ_ca − θ_c per position (rad); r.theta_c nominal carrier angles
    te_extremes(solver, r).pp   # Δθ_er of the curve, refined between the positions (rvtol...extremes)
    # (b) input locked + prescribed output torque (torsion / hysteresis curve)
    T = 784e3       # N·mm
    r = solver.torsion(np.concatenate([np.linspace(0, T, 21), np.linspace(T, -T, 41), np.linspace(-T, 0, 21)]))
    r.te            # output torsion angle (rad) per torque; r.input_torque = reaction at the sun (N·mm)
    # general: solver.sweep(theta_c[n], torque[n], dth_s=0, q_start=None)

Torques in N·mm about +z, positive in the direction of forward output
rotation (a resisting load is negative); ``r.status`` per position (0 = ok,
codes in :mod:`.layout`), ``r.failed_at`` = first failure or −1;
``r.to_frame()`` gives forces per position.
"""
