"""The 20-DOF model of the RV reducer (doc 000, section 1): the core the reducer's models are built on.

Rigid sun, cranks, cycloid discs and carrier (20 coordinates), every contact a row of one contact table,
solved quasi-statically (rotation sweeps and locked-input torsion) or by Newmark-β.  No model of its own: the
transmission error (:mod:`rvtol.models.transmission_error`), the torsion curve
(:mod:`rvtol.models.torsion_curve`), the discs' fit in the pin ring and its preload (:mod:`rvtol.models.pin_ring`),
the calibration against measured curves (:mod:`rvtol.models.calibration`) and the screening bridge
(:mod:`rvtol.models.screening`) build on it; the lost-motion model takes its gear geometry.

Modules: :mod:`.geometry` (derived geometry, undefined symbols filled),
:mod:`.layout` (DOF/contact/array layout, the kernels' status codes), :mod:`.contacts` (contact table),
:mod:`.factors` (error factors and the Table 3 patterns), :mod:`.compliance`
(the design's compliance chain — crankshafts, crank support pairs, carrier,
pin grooves, disc webs, input shaft — in series with the contacts), :mod:`.friction` (Coulomb friction of the
sliding contacts, for the torsion curve's loop),
:mod:`._kernels` (numba: forces and series laws, Newton, sequences,
Newmark-β; the tests hold them to a NumPy implementation of the same equations, ``tests/numpy_twin.py``),
:mod:`.quasistatic` (:class:`~.quasistatic.QuasiStaticSolver`), :mod:`.newmark` (:class:`~.newmark.NewmarkSolver`).

Quasi-static entry point (also for the torsional-stiffness and adjustment
capabilities)::

    from rvtol.design import load_design
    from rvtol.models.reducer_20dof.geometry import geometry_from_design
    from rvtol.models.reducer_20dof.factors import ErrorFactors
    from rvtol.models.reducer_20dof.quasistatic import QuasiStaticSolver

    g = geometry_from_design(load_design("data/designs/rv80e_te.toml"))
    errors = ErrorFactors(["delta_b", "E_c[1,2]"], g.z_b).state([0.005, 0.002])  # mm, or None
    solver = QuasiStaticSolver(g, errors)

    # (a) prescribed input angle + output load torque (TE over one output revolution)
    r = solver.rotation(load_torque=0.03 * g.rated_torque, per_crank_rev=36)
    r.te            # Δθ_ca = θ_ca − θ_c per position (rad); r.theta_c nominal carrier angles
    te_extremes(solver, r).pp   # Δθ_er of the curve, refined between the positions (transmission_error.extremes)
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
