"""The cycloid discs' fit in the pin ring, per pin (``MODELS["pin_ring_fit"]``).

:mod:`.fit`: the fit margin of a rigid disc free to turn (a one-variable linear programme in closed form);
:mod:`.model`: :class:`~rvtol.models.pin_ring.model.PinRingFitModel`, the margin of both discs from the
stack-up's disc offsets and the 20-DOF model's pin clearances.
"""
