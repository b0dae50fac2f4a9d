"""``PinRingFitModel``: does each cycloid disc, where the assembly puts it, fit its pin ring? (``kind = "pin_ring_fit"``)

Inputs:

* the disc's deviation from its ideal place in the pin ring (the stack-up's KC of the disc centre relative
  to the pin ring's place for it, housing axes, at the disc's mid-plane): ``disc_u[j]``, ``disc_v[j]`` (mm),
  ``disc_alpha[j]``, ``disc_beta[j]`` (rad, tilts about x and y), j = 1, 2; an input not given is 0;
* the 20-DOF model's error factors (:mod:`rvtol.models.reducer_20dof.factors`; a study passes the torsion
  curve's mapping, ``same_inputs_as``): the ones that reach the cycloid–pin contacts — pin positions and
  clearances, the profile modifications, the discs' profile fields — set each pin's normal clearance; the
  others (cams, bearings, first stage) do not reach the fit and are not read.

Outputs per disc j: ``disc_j.margin`` — the fit margin of :mod:`.fit` (the largest normal clearance the best
turn of the disc leaves at every pin, both faces; < 0: interference) — and ``disc_j.clearance_min``, the
tightest pin's normal clearance with the disc at its ideal place (the margin of a disc with no offset and no
turn).

The position is the assembly's reference position (carrier and crank angle 0, mapping.md §0), where the
stack-up gives the disc's place.  The contact geometry is the 20-DOF kernel's contact table at that position
(:func:`rvtol.models.reducer_20dof.contacts.pin_contacts`).  Each pin's clearance is affine in the error
state, and the error state in the factors (a pattern's amplitude a and phase p through a·cos p and a·sin p),
so the model reads the kernel once per factor when it is built and evaluates a sample as a sum of those
columns (vectorised; a test holds it to the kernel sample by sample).
"""
from __future__ import annotations

import math
import re

import numpy as np

from dataclasses import dataclass

from ...design import Design
from ...errors import InputError
from ...model import Model, Quantity
from ...model_kind import ModelKind, require_design
from ...options import option
from ..stackup.domains import ends_from_axis
from ..reducer_20dof import layout as L
from ..reducer_20dof.contacts import PinContacts, pin_contacts
from ..reducer_20dof.factors import ErrorFactors
from ..reducer_20dof.geometry import RVGeometry, geometry_from_design
from ..reducer_20dof.quasistatic import MIN_PER_CRANK_REV, ContactSolveOptions
from .fit import disc_fit_margin
from .preload import DEFAULT_PER_CRANK_REV

OFFSET = re.compile(r"^disc_(u|v|alpha|beta)\[([12])\]$")
_OFFSET_UNIT = {"u": "mm", "v": "mm", "alpha": "rad", "beta": "rad"}
#: components of the disc's deviation in the stack-up's 6-DOF order (u, v, w, α, β, γ)
_DOF = {"u": 0, "v": 1, "alpha": 3, "beta": 4}


class PinRingFitModel(Model):
    """The per-pin fit of both discs in the pin ring (module docstring). ``width``: the disc's face width (mm),
    the distance between the two faces whose offsets must both fit."""

    def __init__(self, design: Design | RVGeometry, inputs, width: float, harmonic: int = 2):
        self.geometry = design if isinstance(design, RVGeometry) else geometry_from_design(design, chain=False)
        if not width > 0:
            raise InputError(f"the disc width must be > 0, got {width}", key="width")
        self.width = float(width)
        self.inputs = tuple(inputs)
        self._offset_col: dict[tuple[int, str], int] = {}
        errors = []
        for c, name in enumerate(self.inputs):
            m = OFFSET.match(name.strip())
            if m:
                self._offset_col[int(m.group(2)) - 1, m.group(1)] = c
            else:
                errors.append(name)
        self.factors = ErrorFactors(errors, self.geometry.z_b, harmonic)
        unit = dict(zip(self.factors.names, self.factors.units))
        self.input_units = tuple(_OFFSET_UNIT[OFFSET.match(n.strip()).group(1)] if OFFSET.match(n.strip())
                                 else unit[n] for n in self.inputs)
        self.outputs = tuple(q for j in range(L.N_DISC) for q in (
            Quantity(f"disc_{j + 1}.margin", "mm", "um",
                     f"disc {j + 1}'s fit margin in the pin ring: the largest normal clearance the best turn leaves "
                     "at every pin, both faces (< 0: interference)"),
            Quantity(f"disc_{j + 1}.clearance_min", "mm", "um",
                     f"the tightest pin's normal clearance against disc {j + 1} at its ideal place")))
        self._build_columns()

    # -- the clearances as a sum of columns, read from the kernel ---------------------------------------------
    def contacts(self, x_errors=None) -> PinContacts:
        """The kernel's pin contacts at the reference position for one row of the error factors (zeros: none)."""
        x = np.zeros(len(self.factors.names)) if x_errors is None else np.asarray(x_errors, dtype=float)
        return pin_contacts(self.geometry, self.factors.state(x))

    def _build_columns(self) -> None:
        nominal = self.contacts()
        self.normal, self.arm, self.eccentric = nominal.normal, nominal.arm, nominal.eccentric
        self.c0 = nominal.clearance
        col = {n: self.inputs.index(n) for n in self.factors.names}
        bindings = self.factors.bindings
        phase_of = {(b.base[:-len("_phase")], b.index): b.name for b in bindings if b.base.endswith("_phase")}
        self._linear: list[tuple[int, np.ndarray]] = []                 # (column, ∂c/∂x)
        self._pairs: list[tuple[int, int, np.ndarray, np.ndarray]] = []  # (amplitude, phase, c of sin, c of cos)
        reads: list[set[str]] = [set() for _ in range(L.N_DISC)]
        names = self.factors.names
        for i, b in enumerate(bindings):
            if b.name in phase_of.values():
                continue
            x = np.zeros(len(names))
            x[i] = 1.0
            g = self.contacts(x).clearance - self.c0
            ph = phase_of.get((b.base, b.index))
            if ph is None:
                if np.any(g != 0.0):
                    self._linear.append((col[b.name], g))
                used = [b.name]
            else:                                  # a sin(nθ + p) = a cos p · sin nθ + a sin p · cos nθ
                x[names.index(ph)] = 0.5 * math.pi
                g2 = self.contacts(x).clearance - self.c0
                if np.any(g != 0.0) or np.any(g2 != 0.0):
                    self._pairs.append((col[b.name], col[ph], g, g2))
                used = [b.name, ph]
                g = np.abs(g) + np.abs(g2)
            for j in range(L.N_DISC):
                if np.any(g[j] != 0.0):
                    reads[j].update(used)
        self._reads = [frozenset(r) for r in reads]

    def clearances(self, X) -> np.ndarray:
        """Each pin's normal clearance against each disc at its ideal place, ``[n, N_DISC, z_b]`` (mm)."""
        X = self.check_input(X)
        C = np.broadcast_to(self.c0, (len(X),) + self.c0.shape).copy()
        for c, g in self._linear:                      # one column at a time: a row never depends on its chunk
            C += X[:, c, None, None] * g
        for ca, cp, gs, gc in self._pairs:
            a, p = X[:, ca, None, None], X[:, cp, None, None]
            C += a * np.cos(p) * gs + a * np.sin(p) * gc
        return C

    def faces(self, X, j: int) -> np.ndarray:
        """Disc j's offset from its ideal place at its two faces, in its eccentric frame, ``[n, 2, 2]`` (mm)."""
        X = self.check_input(X)
        E = np.zeros((len(X), 6))
        for comp, k in _DOF.items():
            c = self._offset_col.get((j, comp))
            if c is not None:
                E[:, k] = X[:, c]
        ends = np.stack(ends_from_axis(E, self.width), axis=1)          # housing axes
        ce, se = math.cos(self.eccentric[j]), math.sin(self.eccentric[j])
        return np.stack([ce * ends[..., 0] + se * ends[..., 1], -se * ends[..., 0] + ce * ends[..., 1]], axis=-1)

    def evaluate(self, X):
        X = self.check_input(X)
        C = self.clearances(X)
        out = []
        for j in range(L.N_DISC):
            out.append(disc_fit_margin(C[:, j], self.normal[j], self.arm[j], self.faces(X, j)))
            out.append(C[:, j].min(axis=1))
        return np.stack(out, axis=1)

    def dependencies(self) -> dict[str, frozenset[str]]:
        """A disc's outputs depend on the factors that move a pin's clearance against it (read from the
        kernel: a non-zero column) and its margin also on that disc's offsets."""
        deps = {}
        for j in range(L.N_DISC):
            own = frozenset(self.inputs[c] for (d, _), c in self._offset_col.items() if d == j)
            deps[f"disc_{j + 1}.margin"] = self._reads[j] | own
            deps[f"disc_{j + 1}.clearance_min"] = self._reads[j]
        return deps


@dataclass
class FitOptions:
    """The keys of ``[[model]] kind = "pin_ring_fit"``."""

    width: float | None = option(None, "the discs' face width (default: the design's cycloid.face_width)", unit="mm",
                                 positive=True)
    harmonic: int = option(2, "the largest harmonic of the profile and pin error patterns (the Table 3 factors)",
                           min=1, max=L.NH - 1)


def build_fit(o: FitOptions, design, spec, error) -> PinRingFitModel:
    require_design(design, error, "the pin-ring fit needs the reducer's design")
    width = o.width
    if width is None:
        if "cycloid.face_width" not in design:
            raise error("width", "give the discs' face width (the design has no cycloid.face_width)")
        width = float(design["cycloid.face_width"])
    return PinRingFitModel(design, spec.names, width, o.harmonic)


from_study = ModelKind(FitOptions, build_fit, "the pin ring's fit: each disc's smallest clearance and margin")


@dataclass
class PreloadOptions(ContactSolveOptions):
    """The keys of ``[[model]] kind = "pin_ring_preload"``."""

    per_crank_rev: int = option(DEFAULT_PER_CRANK_REV, "positions per crank revolution of the no-load sweep",
                                min=MIN_PER_CRANK_REV)


def build_preload(o: PreloadOptions, design, spec, error):
    from .preload import PinRingPreloadModel

    require_design(design, error, "the pin-ring preload needs the reducer's design")
    try:
        return PinRingPreloadModel(design, spec.names, per_crank_rev=o.per_crank_rev, harmonic=o.harmonic,
                                   tol_f=o.tol_force, maxit=o.max_iterations, compliance_chain=o.compliance_chain)
    except InputError as exc:
        raise error(exc.key or "kind", exc.reason) from None


preload_from_study = ModelKind(PreloadOptions, build_preload,
                               "the pin ring's no-load turn: preloaded pins and drag torque (20-DOF contacts)")
