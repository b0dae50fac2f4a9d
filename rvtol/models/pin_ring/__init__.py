"""The cycloid discs in their pin ring (``MODELS["pin_ring_fit"]``, ``MODELS["pin_ring_preload"]``).

:mod:`.fit`: the fit margin of a rigid disc free to turn (a one-variable linear programme in closed form);
:mod:`.model`: :class:`~rvtol.models.pin_ring.model.PinRingFitModel`, the margin of both discs from the
stack-up's disc offsets and the 20-DOF model's pin clearances — the geometric fit, one position;
:mod:`.preload`: :class:`~rvtol.models.pin_ring.preload.PinRingPreloadModel`, the ring as a maker judges it — the
20-DOF reducer turned with no load through one output revolution, each disc on its three cranks: the pins' preload,
its interference and the drag it adds to the no-load running torque (:mod:`._kernels` reads the sweep's contacts).
"""
