"""The adjusted assembly as a Model: part errors and measurement noise -> final KC errors, effort.

Study usage::

    [model]
    kind = "adjusted_assembly"
    assembly = "../data/assemblies/bx40e_2d.toml"   # relative to the study file
    accuracy_weight = 10        # optional: overrides the file's Q ("inf": terminal constraint)
    adjust = true               # optional: false = the unadjusted assembly (same outputs, u = 0)

Inputs are the spec's factors; each must be a part-error factor
(``dtheta_1`` or ``dtheta_1x`` in 3-D) or a measurement-noise factor
(``v{step}_{KC}``) of the description — those the spec does not name stay
at zero (nominal).  Outputs: the final observations ``delta_<name>`` (each
KC relative to the datum by default), ``final_error`` (their root sum of
squares) and ``effort`` (``sqrt(Σ_k |u(k)|²)``), all angles (rad, shown in
mrad).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ... import units
from ...errors import InputError
from ...model import Model, Quantity
from ...model_kind import ModelKind, existing
from ...options import REQUIRED, option
from .adjuster import Adjuster
from .description import AssemblyDescription, load_assembly, weight_of


class AdjustedAssemblyModel(Model):
    """``X[n, k]`` (spec factors, rad) -> final KC errors, final error norm, adjustment effort."""

    def __init__(self, desc: AssemblyDescription, inputs=None, accuracy: float | None = None,
                 adjust: bool = True, display_unit: str = "mrad"):
        self.description = desc
        self.adjuster = Adjuster.from_assembly(desc, accuracy).fit()
        self.adjust = adjust
        self.w_names = tuple(desc.part_error_names())
        self.v_names = tuple(desc.noise_names())
        known = self.w_names + self.v_names
        self.inputs = tuple(known if inputs is None else inputs)
        for name in self.inputs:
            if name not in known:
                raise InputError(f"unknown factor name {name!r} for assembly {desc.name!r} "
                                 f"(part errors: {', '.join(self.w_names)}; noise: {self.v_names[0]} ...)",
                                 key="factor")
        self.input_units = ("rad",) * len(self.inputs)
        self._w_cols = [(j, self.w_names.index(n)) for j, n in enumerate(self.inputs) if n in self.w_names]
        self._v_cols = [(j, self.v_names.index(n)) for j, n in enumerate(self.inputs) if n in self.v_names]
        obs = [Quantity(f"delta_{n}", "rad", display_unit, f"final error of {n} relative to the datum")
               for n in desc.observation_names()]
        self.outputs = tuple(obs) + (
            Quantity("final_error", "rad", display_unit, "root sum of squares of the final KC errors"),
            Quantity("effort", "rad", display_unit, "adjustment effort sqrt(Σ|u(k)|²)"),
        )

    @property
    def accuracy(self) -> float:
        return self.adjuster.accuracy

    def split(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Part errors ``w[n, n_w]`` and noise ``v[n, n_v]`` (zeros where the spec names none)."""
        X = self.check_input(X)
        w = np.zeros((len(X), len(self.w_names)))
        v = np.zeros((len(X), len(self.v_names)))
        for j, i in self._w_cols:
            w[:, i] = X[:, j]
        for j, i in self._v_cols:
            v[:, i] = X[:, j]
        return w, v

    def simulate(self, X: np.ndarray):
        w, v = self.split(X)
        return self.adjuster.simulate(w, v, adjust=self.adjust)

    def evaluate(self, X):
        """Final observations, their RSS and the effort, through the closed-loop linear map.

        The adjusted assembly is linear in (w, v), so the final state and every
        adjustment are fixed linear combinations of the inputs; the map is built
        once from :meth:`Adjuster.simulate` on unit inputs (exact) and applied
        row by row (einsum, no BLAS).  ``simulate`` gives the step-by-step
        trajectories; tests hold the two together.
        """
        w, v = self.split(X)
        Z = np.einsum("nk,rk->nr", np.hstack([w, v]), self._map)
        m = self._n_final
        final, u = Z[:, :m], Z[:, m:]
        return np.column_stack([final, np.sqrt((final * final).sum(axis=1)), np.sqrt((u * u).sum(axis=1))])

    @property
    def _map(self) -> np.ndarray:
        """``[final; u(0..N-1)]`` per unit ``[w, v]`` (rows), built on first use."""
        if getattr(self, "_G", None) is None:
            a = self.adjuster
            I = np.eye(a.n_w + a.n_v)
            run = a.simulate(I[:, :a.n_w], I[:, a.n_w:], adjust=self.adjust)
            self._G = np.hstack([run.final, run.u.reshape(len(I), -1)]).T.copy()
            self._n_final = run.final.shape[1]
        return self._G

    def with_accuracy(self, accuracy: float, adjust: bool = True) -> "AdjustedAssemblyModel":
        """The same assembly with another accuracy weight Q (or unadjusted)."""
        return AdjustedAssemblyModel(self.description, self.inputs, accuracy, adjust,
                                     self.outputs[0].display_unit)


@dataclass
class Options:
    """The keys of ``[model] kind = "adjusted_assembly"``."""

    assembly: Path = option(REQUIRED, "the assembly's state-space description (TOML: stations, parts, adjusters)")
    accuracy_weight: object = option(None, 'the LQR accuracy weight Q: a number >= 0 or "inf" (default: the '
                                           "assembly file's)")
    adjust: bool = option(True, "apply the finite-horizon LQR adjustments (false: the unadjusted assembly)")
    display_unit: str = option("mrad", "the angle unit the report shows the deviations in")


def build(o: Options, design, spec, error) -> AdjustedAssemblyModel:
    desc = load_assembly(existing(o.assembly, "assembly", error))
    accuracy = None if o.accuracy_weight is None else weight_of(o.accuracy_weight, error, "accuracy_weight",
                                                                allow_inf=True)
    try:
        disp = units.canonical(o.display_unit, "angle")
        units.require_dimension(disp, "angle")
    except InputError as exc:
        raise error("display_unit", exc.reason) from None
    return AdjustedAssemblyModel(desc, spec.names, accuracy, o.adjust, disp)


from_study = ModelKind(Options, build, "an assembly adjusted station by station (state space, finite-horizon LQR)")
