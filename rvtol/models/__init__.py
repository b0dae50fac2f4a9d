"""The physics of rvtol, each a :class:`rvtol.model.Model`."""
