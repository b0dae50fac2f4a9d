"""The assembly chain as a Model: factors in, named KC deviations out.

:class:`StackupModel` compiles an :class:`~rvtol.models.stackup.graph.Assembly`
and one of its sequences into a deviation program (:mod:`.program`):

* every pose deviation term of a feature is a *slot* ``E = A·x`` (linear in
  its factors); every clearance fit has a float slot, the mate's axis ends
  placed in the clearance disc (radius ``c⁺/2``, ``c = c0 + δD_hole −
  δd_shaft − form_base − form_mate``) through the concentric map of the
  factors ``<fit>.a1, b1, a2, b2 ∈ [-1, 1]`` (uniform factors → uniform in
  the clearance domain; ``worst_offset``/``worst_tilt`` push both ends to the
  wall, same side / opposite sides, in the direction of ``(a1, b1)``);
* a part placed through fit (a → b) gets the pose
  ``P_b = P_a · N_a · D_a · G · D_b⁻¹ · N_b⁻¹`` (N nominal frames, D the
  features' deviation products, G the float);
* a KC is the deviation of feature f relative to feature g,
  ``extract((W_g⁰⁻¹ W_f⁰)⁻¹ · W_g⁻¹ · W_f)`` — expressed at f, in f's nominal frame (a tilt of
  g about its own origin shows as an offset of f by the lever arm between them) — and its
  components (signed DOFs, radial = √(u²+v²), tilt = √(α²+β²), ‖e‖, ‖ε‖,
  and the assembly margin of a closing clearance fit: c⁺/2 − the larger
  end-point offset).

Deterministic and row-independent: all chance is in the factors.  Factors
the spec does not name stay at zero (nominal); factors the graph does not
know are an error.

:meth:`StackupModel.jacobian` linearises the chain analytically: the
first-order deviation is carried through the program by small-displacement
torsor adjoints (``Ad = [[Rᵀ, −Rᵀ[p]×], [0, Rᵀ]]``); only the float map's
own derivative is taken by a central difference of that (explicit) map.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ... import units
from ...errors import InputError, did_you_mean
from ...model import Model, Quantity
from ...model_kind import ModelKind, existing
from ...options import REQUIRED, option
from . import _kernels as K
from .deviation import linear_magnitude, rotational_magnitude
from .domains import axis_from_ends, concentric_disk, ends_from_axis
from .graph import KC, Assembly, Fit, Sequence
from .program import Program
from .transforms import DOF, MODES, adjoint, inverse

BACKENDS = ("numba", "numpy")
STATUS_BAD_INPUT = 2
STATUS_SINGULAR = 3


@dataclass(frozen=True)
class Slot:
    kind: str  # "term" | "float"
    owner: str  # feature id or fit name
    name: str
    cols: tuple[int, ...]  # columns of X (−1: factor not in the spec, held at 0)
    A: np.ndarray | None = None  # term: 6 × len(cols)


class StackupModel(Model):
    """A deviation chain over an assembly graph (see module docstring)."""

    status_reasons = {**Model.status_reasons,
                      STATUS_BAD_INPUT: "non-finite deviation (factor value or clearance)",
                      STATUS_SINGULAR: "singular transform in a small-angle inversion"}

    def __init__(self, assembly: Assembly, sequence: str | None, inputs, input_units=None,
                 rotation: str = "exact", backend: str = "numba", floats: dict[str, str] | None = None,
                 outputs: list[str] | None = None):
        if rotation not in MODES:
            raise InputError(f"unknown rotation {rotation!r} (expected one of: {', '.join(MODES)})", key="rotation")
        if backend not in BACKENDS:
            raise InputError(f"unknown backend {backend!r} (expected one of: {', '.join(BACKENDS)})", key="backend")
        self.assembly = assembly
        self.sequence: Sequence = assembly.sequence(sequence)
        self.rotation, self.backend = rotation, backend
        self.inputs = tuple(inputs)
        known = assembly.factor_units()
        for n in self.inputs:
            if n not in known:
                raise InputError(f"unknown factor name {n!r}: the assembly {assembly.name!r} has no such "
                                 f"deviation, size, form or float factor", key="factor")
        self.input_units = tuple(known[n] for n in self.inputs) if input_units is None else tuple(input_units)
        self.float_modes = self._float_modes(floats or {})
        self.kcs = assembly.kcs_for(self.sequence)
        self._col = {n: i for i, n in enumerate(self.inputs)}
        self.slots, self._feature_slots, self._float_slot = self._make_slots()
        self.program, self._kc_out = self._compile()
        self.outputs, self._out_src = self._make_outputs(outputs)

    # ------------------------------------------------------------------ construction
    def _float_modes(self, override: dict[str, str]) -> dict[str, str]:
        modes = {}
        for name, fm in override.items():
            if name not in self.assembly.fits or not self.assembly.fits[name].is_clearance:
                raise InputError(f"{name!r} is not a clearance fit of the assembly", key=f"floats.{name}")
        for fit in self.assembly.fits.values():
            if not fit.is_clearance:
                continue
            mode = override.get(fit.name, fit.float_mode)
            if mode not in ("uniform", "worst_tilt", "worst_offset", "centred"):
                raise InputError(f"unknown float mode {mode!r}", key=f"floats.{fit.name}")
            locates = fit.name in self.sequence.locating
            if locates and mode != "centred":
                missing = [f for f in fit.float_factors[: 4 if mode == "uniform" else 2] if f not in self.inputs]
                if missing:
                    raise InputError(
                        f"clearance fit {fit.name!r} floats ({mode}) in sequence {self.sequence.name!r}: the spec "
                        f"needs factor {missing[0]!r} (uniform from -1 to 1 for a uniform float), or set its float "
                        f"to 'centred'", key="factor")
            modes[fit.name] = mode
        return modes

    def _cols(self, names) -> tuple[int, ...]:
        return tuple(self._col.get(n, -1) for n in names)

    def _make_slots(self):
        slots, by_feature, by_fit = [], {}, {}
        for f in self.assembly.features.values():
            idx = []
            for t in f.terms:
                idx.append(len(slots))
                slots.append(Slot("term", f.id, t.name, self._cols(t.factors), t.A))
            by_feature[f.id] = idx
        for fit in self.assembly.fits.values():
            if fit.is_clearance and fit.name in self.sequence.locating:
                by_fit[fit.name] = len(slots)
                slots.append(Slot("float", fit.name, "float", self._cols(fit.float_factors)))
        return slots, by_feature, by_fit

    def _compile(self) -> tuple[Program, dict[str, int]]:
        asm, seq = self.assembly, self.sequence
        p = Program(n_slots=max(1, len(self.slots)))
        reg = {asm.ground: p.register()}
        p.set(reg[asm.ground])
        for part, fname in seq.steps:
            fit = asm.fits[fname]
            forward = fit.part_of("mate") == part  # placing the mate onto the base
            here, there = (fit.base, fit.mate) if forward else (fit.mate, fit.base)
            a, b = asm.features[here], asm.features[there]
            r = reg[part] = p.register()
            p.copy(r, reg[a.part])
            p.mul_const(r, a.frame)
            for s in self._feature_slots[a.id]:
                p.mul_dev(r, s)
            if fname in self._float_slot:
                p.mul_dev(r, self._float_slot[fname], inverse=not forward)
            for s in reversed(self._feature_slots[b.id]):
                p.mul_dev(r, s, inverse=True)
            p.mul_const(r, inverse(b.frame))
        poses = asm.nominal_poses(seq)
        r1, r2 = p.register(), p.register()
        kc_out = {}
        for kc in self.kcs:
            f, g = asm.features[kc.feature], asm.features[kc.relative_to]
            nominal_rel = inverse(asm.world_frame(g.id, poses)) @ asm.world_frame(f.id, poses)
            for rr, feat in ((r1, g), (r2, f)):
                p.copy(rr, reg[feat.part])
                p.mul_const(rr, feat.frame)
                for s in self._feature_slots[feat.id]:
                    p.mul_dev(rr, s)
            p.mul_const(r1, nominal_rel)
            p.left_inv(r2, r1)
            kc_out[kc.name] = p.out(r2)
        return p, kc_out

    def _make_outputs(self, wanted):
        qs, src = [], []
        for kc in self.kcs:
            for c in kc.components:
                name = f"{kc.name}.{c}"
                if c in ("u", "v", "w", "radial", "e_norm", "margin"):
                    q = Quantity(name, "mm", kc.length_unit, _describe(kc, c))
                else:
                    q = Quantity(name, "rad", kc.angle_unit, _describe(kc, c))
                qs.append(q)
                src.append((kc, c))
        if wanted:
            names = [q.name for q in qs]
            for w in wanted:
                if w not in names:
                    raise InputError(f"unknown output {w!r} (sequence {self.sequence.name!r} gives: "
                                     f"{', '.join(names)})", key="outputs")
            keep = [names.index(w) for w in wanted]
            qs, src = [qs[i] for i in keep], [src[i] for i in keep]
        return tuple(qs), src

    # ------------------------------------------------------------------ evaluation
    def _x(self, X, cols) -> np.ndarray:
        out = np.zeros((X.shape[0], len(cols)))
        for j, c in enumerate(cols):
            if c >= 0:
                out[:, j] = X[:, c]
        return out

    def clearance(self, fit: Fit, X) -> np.ndarray:
        """Effective diametral clearance ``c0 + δD_hole − δd_shaft − form_base − form_mate`` (mm)."""
        asm = self.assembly
        hole_f = asm.features[fit.base if fit.hole == "base" else fit.mate]
        shaft_f = asm.features[fit.mate if fit.hole == "base" else fit.base]
        c = np.full(X.shape[0], float(fit.clearance))
        for feat, sign in ((hole_f, 1.0), (shaft_f, -1.0)):
            if feat.size and feat.size in self._col:
                c += sign * X[:, self._col[feat.size]]
            if feat.form and feat.form in self._col:
                c -= X[:, self._col[feat.form]]
        return c

    def float_deviation(self, fit: Fit, X) -> np.ndarray:
        """(u, v, α, β) of the mate's axis in the base's clearance, ``(n, 4)``."""
        R = 0.5 * np.maximum(self.clearance(fit, X), 0.0)[:, None]
        ab = self._x(X, self._cols(fit.float_factors))
        mode = self.float_modes[fit.name]
        p1 = concentric_disk(ab[:, 0], ab[:, 1])
        if mode == "uniform":
            p2 = concentric_disk(ab[:, 2], ab[:, 3])
            return axis_from_ends(R * p1, R * p2, fit.length)
        if mode == "centred":
            return np.zeros((X.shape[0], 4))
        norm = np.hypot(p1[:, 0], p1[:, 1])[:, None]
        d = np.where(norm > 0, p1 / np.where(norm > 0, norm, 1.0), np.array([1.0, 0.0]))
        return axis_from_ends(R * d, (R * d) if mode == "worst_offset" else (-R * d), fit.length)

    def deviations(self, X) -> np.ndarray:
        """All slot deviation vectors ``E[n, slots, 6]`` for factor values ``X`` (base units)."""
        X = np.asarray(X, dtype=float)
        E = np.zeros((X.shape[0], self.program.n_slots, 6))
        for s, slot in enumerate(self.slots):
            if slot.kind == "term":
                E[:, s, :] = self._x(X, slot.cols) @ slot.A.T
            else:
                E[:, s, [0, 1, 3, 4]] = self.float_deviation(self.assembly.fits[slot.owner], X)
        return E

    def kc_deviations(self, X) -> tuple[dict[str, np.ndarray], np.ndarray]:
        """6-DOF deviation of every KC, ``{name: (n, 6)}``, and the program status."""
        out, status = self.program.run(self.deviations(X), self.rotation, self.backend)
        return {kc.name: out[:, self._kc_out[kc.name]] for kc in self.kcs}, status

    def evaluate_with_status(self, X):
        X = self.check_input(X)
        devs, st = self.kc_deviations(X)
        Y = np.empty((X.shape[0], len(self.outputs)))
        for j, (kc, comp) in enumerate(self._out_src):
            Y[:, j] = self._component(kc, comp, devs[kc.name], X)
        status = np.zeros(X.shape[0], dtype=np.int16)
        status[st == K.STATUS_NONFINITE_INPUT] = STATUS_BAD_INPUT
        status[st == K.STATUS_SINGULAR] = STATUS_SINGULAR
        bad = (status == 0) & ~np.all(np.isfinite(Y), axis=1)
        status[bad] = STATUS_BAD_INPUT
        Y[status != 0] = np.nan
        return Y, status

    def evaluate(self, X):
        return self.evaluate_with_status(X)[0]

    def _component(self, kc: KC, comp: str, dev: np.ndarray, X) -> np.ndarray:
        if comp in DOF:
            return dev[:, DOF.index(comp)]
        if comp == "radial":
            return np.hypot(dev[:, 0], dev[:, 1])
        if comp == "tilt":
            return np.hypot(dev[:, 3], dev[:, 4])
        if comp == "e_norm":
            return linear_magnitude(dev, kc.radii)
        if comp == "eps_norm":
            return rotational_magnitude(dev, kc.radii)
        fit = self.assembly.fits[kc.fit]
        pp, pm = ends_from_axis(dev, fit.length)
        worst = np.maximum(np.hypot(pp[:, 0], pp[:, 1]), np.hypot(pm[:, 0], pm[:, 1]))
        return 0.5 * np.maximum(self.clearance(fit, X), 0.0) - worst

    def dependencies(self) -> dict[str, frozenset[str]]:
        """Output -> the inputs that move it to first order at the nominal: the non-zero pattern of the
        analytic :meth:`jacobian` (so a deviation common to both ends of a KC — a housing error under two
        carrier features — cancels exactly and is not listed), plus the clearance factors of a floating
        fit whose float moves the output (the float is clearance × position: bilinear) and those of the
        fit an assembly margin belongs to.  Effects only through products of two deviations (second
        order, nanometres at drawing tolerances) are not listed."""
        J = self.jacobian()
        floats = {f: set(self.assembly.fits[f].float_factors) for f, m in self.float_modes.items()
                  if m != "centred" and f in self._float_slot}
        deps = {}
        for q, (kc, comp) in zip(self.outputs, self._out_src):
            rows = {"radial": [0, 1], "tilt": [3, 4], "margin": [0, 1, 3, 4]}.get(comp)
            rows = rows if rows is not None else ([DOF.index(comp)] if comp in DOF else list(range(6)))
            used = {self.inputs[c] for c in np.flatnonzero(np.any(J[kc.name][rows] != 0.0, axis=0))}
            for fit, names in floats.items():
                if used & names:
                    used |= self._clearance_inputs(self.assembly.fits[fit])
            if comp == "margin":
                used |= self._clearance_inputs(self.assembly.fits[kc.fit])
            deps[q.name] = frozenset(used)
        return deps

    def _clearance_inputs(self, fit: Fit) -> set[str]:
        feats = (self.assembly.features[fit.base], self.assembly.features[fit.mate])
        return {n for f in feats for n in (f.size, f.form) if n and n in self._col}

    # ------------------------------------------------------------------ linearisation
    def linear_form(self, name: str):
        """How an output depends on its KC's 6-vector: ``("dof", kc, i)``, ``("norm", kc, (i, j))``,
        ``("weighted", kc, w)`` (√Σ w_i E_i²) or ``("none", kc, None)`` (margin)."""
        kc, comp = self._out_src[self.output_index(name)]
        if comp in DOF:
            return "dof", kc.name, DOF.index(comp)
        if comp in ("radial", "tilt"):
            return "norm", kc.name, (0, 1) if comp == "radial" else (3, 4)
        if comp in ("e_norm", "eps_norm"):
            from .deviation import magnitude_weights

            return "weighted", kc.name, magnitude_weights(kc.radii, "linear" if comp == "e_norm" else "rotational")
        return "none", kc.name, None

    def nonlinear_floats(self) -> list[str]:
        """Locating clearance fits in a worst-case mode (not differentiable in their direction)."""
        return [f for f, m in self.float_modes.items() if m.startswith("worst") and f in self._float_slot]

    def jacobian(self, x0=None, step: float = 1e-7) -> dict[str, np.ndarray]:
        """``{kc: dE_kc/dx (6 × k)}`` at ``x0`` (base units; default all zero).

        Analytic (small-displacement torsor transport) where ``x0`` gives zero pose
        deviations — the drawing's nominal; otherwise central differences of the chain
        (:meth:`jacobian_fd`).
        """
        k = len(self.inputs)
        x0 = np.zeros(k) if x0 is None else np.asarray(x0, dtype=float)
        if np.abs(self.deviations(x0[None, :])[0]).max() > 0:
            return self.jacobian_fd(x0)
        S = self.program.n_slots
        Dx = np.zeros((6 * S, k))  # d(slot deviations)/dx
        for s, slot in enumerate(self.slots):
            if slot.kind == "term":
                for j, c in enumerate(slot.cols):
                    if c >= 0:
                        Dx[6 * s:6 * s + 6, c] += slot.A[:, j]
            else:  # the float map's own derivative: central difference of that explicit map
                fit = self.assembly.fits[slot.owner]
                Xp = np.repeat(x0[None], k, axis=0) + step * np.eye(k)
                Xm = np.repeat(x0[None], k, axis=0) - step * np.eye(k)
                d = (self.float_deviation(fit, Xp) - self.float_deviation(fit, Xm)) / (2 * step)
                Dx[[6 * s + 0, 6 * s + 1, 6 * s + 3, 6 * s + 4], :] = d.T
        Jp = linearise_program(self.program)
        return {kc.name: Jp[self._kc_out[kc.name]] @ Dx for kc in self.kcs}

    def jacobian_fd(self, x0, rel: float = 1e-6) -> dict[str, np.ndarray]:
        """Central differences of the KC deviation vectors, step ``rel·max(1, |x0|)`` (base units)."""
        x0 = np.asarray(x0, dtype=float)
        k = len(x0)
        h = rel * np.maximum(1.0, np.abs(x0))
        X = np.concatenate([x0 + np.diag(h), x0 - np.diag(h)])
        devs, _ = self.kc_deviations(X)
        return {name: (D[:k] - D[k:]).T / (2 * h) for name, D in devs.items()}

    def describe(self) -> str:
        return (f"assembly {self.assembly.name!r}, sequence {self.sequence.name!r} "
                f"({' → '.join([self.assembly.ground] + [p for p, _ in self.sequence.steps])}), "
                f"{self.rotation} rotations, {self.backend} kernel, {len(self.slots)} deviation slots, "
                f"{len(self.program.ops)} program operations")


def _describe(kc: KC, comp: str) -> str:
    what = {"radial": "radial offset √(u²+v²)", "tilt": "tilt √(α²+β²)", "e_norm": "‖e(E)‖",
            "eps_norm": "‖ε(E)‖", "margin": "assembly margin c⁺/2 − end offset"}.get(comp, comp)
    return f"{what} of {kc.feature} relative to {kc.relative_to}"


def linearise_program(program: Program) -> np.ndarray:
    """First-order map ``out[k] ≈ J[k] · vec(E)`` (J: n_out × 6 × 6·slots) at zero deviation."""
    S6 = 6 * program.n_slots
    N = [np.eye(4) for _ in range(program.n_reg)]
    J = [np.zeros((6, S6)) for _ in range(program.n_reg)]
    outs = np.zeros((program.n_out, 6, S6))
    for code, dst, src, arg in program.ops:
        if code == K.OP_SET:
            N[dst] = np.eye(4) if arg < 0 else program.consts[arg].copy()
            J[dst] = np.zeros((6, S6))
        elif code == K.OP_MULC:
            C = program.consts[arg]
            N[dst] = N[dst] @ C
            J[dst] = adjoint(C) @ J[dst]
        elif code in (K.OP_MULD, K.OP_MULDI):
            J[dst] = J[dst].copy()
            J[dst][:, 6 * arg:6 * arg + 6] += np.eye(6) if code == K.OP_MULD else -np.eye(6)
        elif code == K.OP_COPY:
            N[dst], J[dst] = N[src].copy(), J[src].copy()
        elif code == K.OP_LINV:
            M = inverse(N[src]) @ N[dst]
            J[dst] = J[dst] - adjoint(M) @ J[src]
            N[dst] = M
        elif code == K.OP_OUT:
            if not np.allclose(N[src], np.eye(4), atol=1e-9):
                raise ValueError("linearised output of a register that is not nominally the identity")
            outs[arg] = J[src]
    return outs


# =========================================================================== study factory
#: how a float (a fit's free play) is taken when the assembly's fit does not say
FLOATS = ("uniform", "worst_tilt", "worst_offset", "centred")


@dataclass
class Options:
    """The keys of ``[model] kind = "stackup"``."""

    assembly: Path = option(REQUIRED, "the assembly file (parts, features, fits, sequences, KCs)")
    sequence: str | None = option(None, "the assembly sequence (default: the assembly's first)")
    rotation: str = option("exact", "rotations composed exactly or to first order", choices=MODES)
    backend: str = option("numba", "the compiled or the NumPy kernels (the same equations)", choices=BACKENDS)
    floats: dict[str, str] = option({}, "fit name -> how its float is taken: " + ", ".join(FLOATS))
    outputs: list[str] | None = option(None, "the KC outputs kept (default: every one)")


def build(o: Options, design, spec, error) -> StackupModel:
    from .graph import load_assembly

    path = existing(o.assembly, "assembly", error)
    try:
        asm = load_assembly(path, design)
    except InputError as exc:
        raise exc.located(file=str(path)) from None
    if o.sequence is not None and o.sequence not in asm.sequences:
        raise error("sequence", f"unknown sequence {o.sequence!r} (assembly has: {', '.join(asm.sequences)})")
    for k, v in o.floats.items():
        if v not in FLOATS:
            hint = did_you_mean(v, FLOATS).strip(" ()")
            raise error(f"floats.{k}", f"unknown value {v!r} ({hint + '; ' if hint else ''}expected one of: "
                                       f"{', '.join(FLOATS)})")
    model = StackupModel(asm, o.sequence, spec.names, None, o.rotation, o.backend, o.floats, o.outputs)
    _check_zones(model, spec)
    return model


from_study = ModelKind(Options, build, "the 6-DOF stack-up of an assembly: part and fit deviations to its KCs")


def _check_zones(model: StackupModel, spec) -> None:
    """Each factor's band (mean ± T/2) must lie inside its tolerance zone's box; float factors in [-1, 1].

    Only inputs with a distribution are checked (in a composed study an input computed by the mapping
    has none: ``spec.factors`` lists the ones that do).
    """
    has_band = {f.name for f in spec.factors}
    for feat in model.assembly.features.values():
        for t in feat.terms:
            for name, lim in t.band_limits().items():
                if name in has_band:
                    _band_inside(spec, name, lim, f"the {t.kind} zone of {feat.id} ({t.name})")
    for fit in model.assembly.fits.values():
        if fit.is_clearance:
            for name in fit.float_factors:
                if name in has_band:
                    _band_inside(spec, name, 1.0, f"the normalised clearance disc of {fit.name}")


def _band_inside(spec, name: str, limit: float, what: str) -> None:
    f = spec.factor(name)
    lo, hi = f.band
    lo_b, hi_b = units.to_base(lo, f.unit), units.to_base(hi, f.unit)
    if max(abs(lo_b), abs(hi_b)) > limit * (1 + 1e-9):
        shown = units.from_base(limit, f.unit)
        raise InputError(f"factor band [{lo:.6g}, {hi:.6g}] {f.unit} leaves {what} (|value| ≤ {shown:.6g} {f.unit})",
                         file=spec.file, key=f"factor {name!r}")
