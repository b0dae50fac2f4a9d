"""Closed vector loops with dependent (adjusting) variables: an assembly declared, not solved on paper.

A non-linear stack whose parts *settle* — a roller seated between a hub flat and a ring, a slider pushed by a
crank, a linkage's output angle — has dimensions the assembly decides, not the drawing: the **dependent**
variables.  The Direct Linearization Method (Chase, Gao & Magleby; Gao, Chase & Magleby) writes the assembly as
closed **vector loops**: vectors tip to tail, each a length and a direction, summing to zero around every loop
of the assembly graph.  Each 2-D loop gives two scalar equations (three in 3-D, six when it turns its frame and so
closes its orientation too: below), and the assembly declares as many dependents.

rvtol solves the loop equations **per Monte Carlo sample** (this model) instead of linearising them: for the
factors x of a sample, the dependents d solve

    h(x, d) = Σ_i L_i(x, d) · u(θ_i(x, d), φ_i(x, d)) = 0  for every loop,
    u(θ, φ) = (cos φ cos θ, cos φ sin θ, sin φ)   (2-D: φ = 0, the first two components),

by Newton's method, vectorised over the batch, with the exact Jacobian ∂h/∂d: every length L_i and angle θ_i,
φ_i (the *elevation*, 3-D) is a formula of the factors, the dependents and the model's definitions
(:mod:`rvtol.expressions`, with forward-mode derivatives; units checked as in a formula model), and

    ∂h/∂v = Σ_i u_i ∂L_i/∂v + L_i (∂u/∂θ ∂θ_i/∂v + ∂u/∂φ ∂φ_i/∂v)    (v a factor or a dependent).

Every sample starts from the **nominal assembly** — the dependents solved at the factors' nominal values from
the declared ``start`` — so each sample stays on the declared branch (a linkage has two assembly modes) and
the result of a row does not depend on the others in its batch (converged rows are frozen).  A sample whose
equations do not converge in :data:`MAX_ITERATIONS` steps to :data:`TOLERANCE` (relative to the loop's size;
then one more step, Newton's quadratic convergence taking the dependents to the last bits),
or whose Jacobian is singular, is a failed sample with its reason (the parts cannot be assembled at those
dimensions), never a silent value.

**DLM sensitivities.**  :meth:`VectorLoopModel.gradient` gives the exact derivatives of the outputs with
respect to the factors by the implicit function theorem, dd/dx = −(∂h/∂d)⁻¹ ∂h/∂x — the DLM's
B⁻¹A — and the chain rule through the output formulas; the linearised stack conventions use them (they are
identical in meaning to the derivatives of an explicit formula of the same assembly: ``tests``).

A study declares::

    [model]
    kind = "vector_loop"
    dimensions = 2                       # or 3 (vectors then take an elevation)
    [[model.dependent]]                  # one per loop equation: 2 per 2-D loop
    name = "b"                           # the roller's contact point along the hub flat
    unit = "mm"
    start = 4.5                          # a guess near the nominal assembly (selects the branch)
    [[model.dependent]]
    name = "psi"
    unit = "deg"
    start = 80
    [[model.loop]]                       # vectors tip to tail, angles from the x axis (counter-clockwise)
    name = "roller seat"
    vectors = [
        { length = "a", angle = "pi/2" },
        { length = "b", angle = "0" },
        { length = "c", angle = "pi/2" },
        { length = "c - e", angle = "psi" },
    ]
    [[model.output]]                     # formulas of factors, dependents and definitions (as a formula model)
    name = "phi"
    formula = "pi/2 - psi"
    unit = "deg"

**Joints.**  A 2-D contact can be declared instead of its vectors (``[[model.joint]]``, :data:`JOINTS`): a slider,
a cylinder on a plane, a cylinder in a bore, two cylinders touching; each declares its dependent (the slide along
the surface, the angle of the line of centres) and stands for its vectors where a loop names it
(``{ joint = "roller in ring" }``; ``reverse = true`` walks it backwards, from the mating part to the surface).  In
3-D (:data:`JOINTS_3D`) a sphere, a cylinder, a face or an edge on a plane (two dependent slides in the plane, then
the radius or offset along its normal), a sphere in a bore (a slide along the axis and an angle about it) and a
sphere in a V-groove (a slide along it), each in its surface's frame (:func:`surface_frame`).

**Orientation (3-D).**  A loop entry ``{ rotate = "…", about = "x" | "y" | "z" }`` (:class:`Rotation`) turns the frame
the following vectors are written in (the next part's: R ← R·Q(α), Q the elementary rotation about the frame's own
axis), and a loop that turns closes its orientation as well as its position (Gao, Chase & Magleby 1998: the loop's
rotation matrices multiply to the identity) — three equations more, h = vee(½(R − Rᵀ)) = sin(angle)·axis = 0, with
∂R by the product rule, so three dependents more.  A loop without turns writes every vector in the ground's frame
and closes its position only: the joints' rotational freedoms are not dependents (the parts keep the orientations
the vectors' formulas give them).

References.  K. W. Chase, J. Gao, S. P. Magleby, "General 2-D tolerance analysis of mechanical assemblies with
small kinematic adjustments", J. Design and Manufacturing 5 (1995) 263–274; J. Gao, K. W. Chase, S. P. Magleby,
"Generalized 3-D tolerance analysis of mechanical assemblies with small kinematic adjustments", IIE Trans. 30
(1998) 367–377; the one-way clutch: E. Fortini, Quality Control and Statistics in Engineering Design (1967).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np

from ... import units as _units
from ...errors import InputError, did_you_mean
from ...expressions import ExpressionError
from ...model import STATUS_NONFINITE, STATUS_OK, Model
from ...model_kind import ModelKind
from ...options import option
from ...params import Params
from ..formula.model import FormulaModel, FormulaOutput, OutputTable, read_definitions, read_outputs

#: Newton steps per sample before it is declared not to close
MAX_ITERATIONS = 50
#: converged when every residual is below this fraction of the loop's size (the sum of its vectors' lengths)
TOLERANCE = 1e-12
STATUS_NO_CLOSURE = 2
STATUS_SINGULAR = 3


class LoopError(ExpressionError):
    """A formula (``what``: length, angle, elevation) of vector ``vector`` of loop ``loop`` (indices) that cannot be
    read, for ``why``."""

    def __init__(self, loop: int, vector: int, what: str, why: str):
        super().__init__(f"vector {vector + 1}, {what}: {why}")
        self.loop, self.vector, self.what, self.why = loop, vector, what, why


@dataclass(frozen=True)
class Dependent:
    """A dependent variable: its name, the unit it is written in, the starting guess (in that unit)."""

    name: str
    unit: str
    start: float


@dataclass(frozen=True)
class Vector:
    """One vector of a loop: length, angle from the x axis (counter-clockwise) and, in 3-D, elevation above the
    xy plane — each a formula of the factors, the dependents and the definitions (angles in any angle unit)."""

    length: str
    angle: str
    elevation: str = "0"


@dataclass(frozen=True)
class Rotation:
    """A turn of the loop's frame (3-D) by ``angle`` (a formula) about its own ``about`` axis (x, y or z, right-handed):
    the vectors after it are written in the turned frame — the next part's — and the loop then closes its orientation
    too (the product of its turns is the identity)."""

    angle: str
    about: str


#: an elementary rotation's axis and the two others in cyclic order: Q[i, i] = Q[j, j] = cos α, Q[j, i] = −Q[i, j] = sin α
_AXES = {"x": (0, 1, 2), "y": (1, 2, 0), "z": (2, 0, 1)}


class VectorLoopModel(Model):
    """Closed vector loops solved for their dependents per sample (see the module docstring)."""

    status_reasons = {**Model.status_reasons,
                      STATUS_NO_CLOSURE: "the vector loops do not close (Newton on the loop equations did not "
                                         "converge: the parts cannot be assembled at these dimensions)",
                      STATUS_SINGULAR: "the loop equations are singular here (a dependent is not determined by "
                                       "the loops at this assembly)"}

    def __init__(self, loops: Sequence[Sequence[Vector | Rotation]], dependents: Sequence[Dependent], outputs,
                 inputs: Sequence[str], input_units: Sequence[str], *, dimensions: int = 2,
                 definitions: Mapping[str, str | tuple[str, str]] | None = None, loop_names: Sequence[str] = ()):
        if dimensions not in (2, 3):
            raise ExpressionError(f"dimensions must be 2 or 3, got {dimensions!r}")
        self.dims = dimensions
        self.dependents = tuple(dependents)
        self.loops = [tuple(v) for v in loops]
        self.loop_names = tuple(loop_names) or tuple(f"loop {i + 1}" for i in range(len(self.loops)))
        if not self.loops or any(not any(isinstance(v, Vector) for v in loop) for loop in self.loops):
            raise ExpressionError("a vector-loop model needs at least one loop of at least one vector")
        #: per loop: does it close its orientation (it turns its frame)
        self._turns = [any(isinstance(v, Rotation) for v in loop) for loop in self.loops]
        if dimensions == 2 and any(self._turns):
            raise ExpressionError("a rotation needs dimensions = 3 (in 2-D every angle is from the x axis: a loop's "
                                  "orientation closes by itself)")
        if any(v.about not in _AXES for loop in self.loops for v in loop if isinstance(v, Rotation)):
            raise ExpressionError("a rotation is about x, y or z")
        self.equations = dimensions * len(self.loops) + 3 * sum(self._turns)
        if len(self.dependents) != self.equations:
            turning = f" and {sum(self._turns)} closing their orientation" if any(self._turns) else ""
            raise ExpressionError(f"{len(self.loops)} loop(s) in {dimensions}-D{turning} give {self.equations} "
                                  f"equations: declare as many dependents (there are {len(self.dependents)})")
        if dimensions == 2 and any(v.elevation != "0" for loop in self.loops for v in loop):
            raise ExpressionError("an elevation needs dimensions = 3")
        names = [d.name for d in self.dependents]
        clash = [n for n in names if n in inputs]
        if clash or len(set(names)) != len(names):
            raise ExpressionError(f"dependent {(clash or names)[0]!r} is named like a factor or another dependent")
        for d in self.dependents:
            if _units.dimension(d.unit) not in ("length", "angle"):
                raise ExpressionError(f"dependent {d.name!r}: a length or an angle, not {d.unit!r}")
        self.inputs = tuple(inputs)
        all_units = tuple(input_units) + tuple(d.unit for d in self.dependents)
        # the loops' geometry: per vector its length (mm), angle and elevation (rad), as formulas
        parts = []
        for li, loop in enumerate(self.loops):
            for vi, v in enumerate(loop):
                roles = ((("rotation", v.angle, "rad"),) if isinstance(v, Rotation) else
                         (("length", v.length, "mm"), ("angle", v.angle, "rad"),
                          ("elevation", v.elevation, "rad"))[: 3 if dimensions == 3 else 2])
                for what, text, unit in roles:
                    part = FormulaOutput(f"{li}.{vi}.{what}", text, unit)
                    try:        # one formula at a time, so that an error names its loop, vector and role
                        FormulaModel([part], self.inputs + tuple(names), all_units, definitions=definitions)
                    except ExpressionError as exc:
                        raise LoopError(li, vi, what, exc.reason.split(": ", 1)[-1]) from None
                    parts.append(part)
        self._geometry = FormulaModel(parts, self.inputs + tuple(names), all_units, definitions=definitions)
        self._outputs = FormulaModel(outputs, self.inputs + tuple(names), all_units, definitions=definitions)
        self.input_units = self._geometry.input_units[: len(self.inputs)]
        self.outputs = self._outputs.outputs
        self._d_factor = np.array([_units.factor(d.unit) for d in self.dependents])
        self._nominal_start = np.array([d.start for d in self.dependents]) * self._d_factor
        self._start = None                       # the nominal assembly (set by at_nominal)

    # -- the loop equations ------------------------------------------------------------------
    def _residual(self, X: np.ndarray, D: np.ndarray, columns: slice | None = None):
        """``(h (n, E), J, scale (n, E))`` at factors X and dependents D (base units): the loop equations, their
        Jacobian ``∂h/∂z (n, E, c)`` over the ``columns`` of z = [x, d] (default: the dependents; None: no
        Jacobian) and each equation's size (a position's: the sum of its loop's vectors' lengths; an
        orientation's: 1 rad)."""
        Z = np.concatenate([X, D], axis=1)
        cols = slice(len(self.inputs), None) if columns is None else columns
        V, G = self._geometry.evaluate_with_gradient(Z, [d.name for d in self.dependents] if columns is None else None)
        V, G = V.T, G.transpose(1, 2, 0)[:, cols]      # component-major: each row below is one contiguous array
        n, dims = len(X), self.dims
        h = np.zeros((self.equations, n))
        J = np.zeros((self.equations, G.shape[1], n))
        scale = np.zeros((self.equations, n))
        col = row = 0
        for loop, turns in zip(self.loops, self._turns):
            frame = None              # the loop's frame so far: (R (3, 3, n), ∂R (3, 3, c, n)); None: the ground's
            for v in loop:
                if isinstance(v, Rotation):
                    frame = _turn(frame, v.about, V[col], G[col])
                    col += 1
                    continue
                w, dw = _vector_terms(V, G, col, dims)
                if frame is not None:                     # written in the turned frame: R w, ∂(R w) = ∂R w + R ∂w
                    R, dR = frame
                    w, dw = (np.einsum("ijn,jn->in", R, w),
                             np.einsum("ijcn,jn->icn", dR, w) + np.einsum("ijn,jcn->icn", R, dw))
                h[row: row + dims] += w
                J[row: row + dims] += dw
                scale[row: row + dims] += np.abs(V[col])
                col += dims
            row += dims
            if turns:                 # the orientation closes: R = I, its skew part ½(R − Rᵀ) (sin of the angle) zero
                R, dR = frame
                for k, (i, j) in enumerate(((2, 1), (0, 2), (1, 0))):
                    h[row + k] = (R[i, j] - R[j, i]) / 2
                    J[row + k] = (dR[i, j] - dR[j, i]) / 2
                scale[row: row + 3] = 1.0
                row += 3
        return h.T, J.transpose(2, 0, 1), scale.T

    def solve(self, X: np.ndarray, start: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``(D, status)``: the dependents (base units) closing the loops at every row of ``X`` by Newton's method
        from ``start`` (default: the nominal assembly), each row on its own (converged rows are frozen)."""
        X = np.asarray(X, dtype=float)
        n, m = len(X), len(self.dependents)
        D = np.tile(self._start if start is None else start, (n, 1)).astype(float)
        status = np.full(n, STATUS_NO_CLOSURE, dtype=np.int16)
        active = np.arange(n)
        with np.errstate(all="ignore"):
            for _ in range(MAX_ITERATIONS):
                if active.size == 0:
                    break
                h, Jd, scale = self._residual(X[active], D[active])
                finite = np.isfinite(h).all(axis=1) & np.isfinite(Jd).all(axis=(1, 2))
                det_ok = finite & (np.abs(np.linalg.det(np.where(finite[:, None, None], Jd, np.eye(m)))) > 0)
                status[active[~finite]] = STATUS_NONFINITE
                status[active[finite & ~det_ok]] = STATUS_SINGULAR
                done = det_ok & (np.abs(h) <= TOLERANCE * np.maximum(scale, 1e-300)).all(axis=1)
                status[active[done]] = STATUS_OK
                if det_ok.any():        # a converged row takes one more step (to the last bits), then stops
                    step = np.linalg.solve(Jd[det_ok], -h[det_ok][:, :, None])[:, :, 0]
                    D[active[det_ok]] += step
                active = active[det_ok & ~done]
        D[status != STATUS_OK] = np.nan
        return D, status

    def at_nominal(self, x0: np.ndarray) -> np.ndarray:
        """Solve the nominal assembly (the factors at ``x0``, base units) from the declared starts; every sample
        then starts from it.  Raises :class:`InputError` when the loops do not close there."""
        D, status = self.solve(np.asarray(x0, dtype=float)[None, :], self._nominal_start)
        if status[0] != STATUS_OK:
            why = {STATUS_SINGULAR: "the loop equations are singular there"}.get(
                int(status[0]), "Newton on the loop equations did not converge")
            raise InputError(f"the vector loops do not close at the nominal dimensions from the declared starts "
                             f"({why}): check the loops' vectors and the dependents' start values")
        self._start = D[0]
        return D[0]

    def nominal_dependents(self) -> dict[str, float]:
        """The nominal assembly's dependents, each in its own unit."""
        return {d.name: float(v / k) for d, v, k in zip(self.dependents, self._start, self._d_factor)}

    # -- the Model protocol ------------------------------------------------------------------
    def _ensure_start(self):
        if self._start is None:
            raise InputError("the vector-loop model has no nominal assembly: call at_nominal(x0) first")

    def evaluate_with_status(self, X):
        X = self.check_input(X)
        self._ensure_start()
        D, status = self.solve(X)
        ok = status == STATUS_OK
        Y = np.full((len(X), len(self.outputs)), np.nan)
        if ok.any():
            with np.errstate(all="ignore"):
                Y[ok] = self._outputs.evaluate(np.concatenate([X[ok], D[ok]], axis=1))
        bad = ok & ~np.all(np.isfinite(Y), axis=1)
        status[bad] = STATUS_NONFINITE
        return Y, status

    def evaluate(self, X):
        return self.evaluate_with_status(X)[0]

    def gradient(self, X) -> np.ndarray:
        """Exact ∂Y/∂X ``(n, outputs, inputs)`` by the DLM: dd/dx = −(∂h/∂d)⁻¹ ∂h/∂x through the output formulas
        (NaN where the loops do not close)."""
        X = self.check_input(X)
        self._ensure_start()
        k = len(self.inputs)
        D, status = self.solve(X)
        G = np.full((len(X), len(self.outputs), k), np.nan)
        ok = status == STATUS_OK
        if ok.any():
            with np.errstate(all="ignore"):
                _, J, _ = self._residual(X[ok], D[ok], slice(None))
                dd_dx = -np.linalg.solve(J[:, :, k:], J[:, :, :k])
                _, Go = self._outputs.evaluate_with_gradient(np.concatenate([X[ok], D[ok]], axis=1))
                G[ok] = Go[:, :, :k] + Go[:, :, k:] @ dd_dx
        return G

    def dependencies(self) -> None:
        return None           # the loops couple every factor they name to every dependent


def _vector_terms(V: np.ndarray, G: np.ndarray, col: int, dims: int) -> tuple[np.ndarray, np.ndarray]:
    """``(w (dims, n), ∂w (dims, c, n))``: the vector L·u(θ, φ) whose length, angle (and elevation) are the rows
    ``col…`` of V, and its derivative through their gradients G (module docstring)."""
    L, th = V[col], V[col + 1]
    ct, st = np.cos(th), np.sin(th)
    if dims == 3:
        cp, sp = np.cos(V[col + 2]), np.sin(V[col + 2])
        parts = ((cp * ct, -cp * st, -sp * ct), (cp * st, cp * ct, -sp * st), (sp, 0.0, cp))
    else:
        parts = ((ct, -st, None), (st, ct, None))
    w = np.empty((dims, len(L)))
    dw = np.empty((dims,) + G.shape[1:])
    for c, (u, du_dth, du_dph) in enumerate(parts):          # component c of L·u(θ, φ) and its derivative
        w[c] = L * u
        dw[c] = u * G[col] + (L * du_dth) * G[col + 1]
        if du_dph is not None:
            dw[c] += (L * du_dph) * G[col + 2]
    return w, dw


def _turn(frame, about: str, angle: np.ndarray, grad: np.ndarray):
    """The frame ``(R, ∂R)`` turned by ``angle`` (n) about its own axis ``about``: R Q(α), ∂R Q + R Q'(α) ∂α (Q the
    elementary rotation, right-handed; ``grad`` the angle's gradient (c, n); ``frame`` None: the ground's, R = I)."""
    k, i, j = _AXES[about]
    c, s = np.cos(angle), np.sin(angle)
    Q, dQ = np.zeros((3, 3, len(angle))), np.zeros((3, 3, len(angle)))
    Q[k, k] = 1.0
    Q[i, i] = Q[j, j] = c
    Q[j, i], Q[i, j] = s, -s
    dQ[i, i] = dQ[j, j] = -s
    dQ[j, i], dQ[i, j] = c, -c
    if frame is None:
        return Q, dQ[:, :, None, :] * grad
    R, dR = frame
    return (np.einsum("ijn,jkn->ikn", R, Q),
            np.einsum("ijcn,jkn->ikcn", dR, Q) + np.einsum("ijn,jkn->ikn", R, dQ)[:, :, None, :] * grad)


#: the contacts a joint may declare (2-D): what the assembly leaves free at it, and the vectors that stand for it
JOINTS = {
    "slider": "a part sliding along a direction: {length = slide, angle = direction}; slide is dependent",
    "cylinder_on_plane": "a cylinder (or an edge's radius) on a plane: from the contact point along the plane by the "
                         "dependent slide, then up the plane's normal (side = left | right of the plane's direction) "
                         "by the radius to the cylinder's centre",
    "cylinder_in_cylinder": "a cylinder inside a bore (internal contact): from the inner centre to the outer by "
                            "outer_radius − radius, at the dependent angle (the line of centres)",
    "cylinder_on_cylinder": "two cylinders touching outside: from the first centre to the second by radius + "
                            "outer_radius, at the dependent angle",
}

#: the contacts a joint may declare in 3-D (position closure: the vectors from the surface's datum point to the
#: mating part's), each in the surface's frame (:func:`surface_frame`)
JOINTS_3D = {
    "sphere_on_plane": "a sphere on a plane: along the plane by the two dependent slides, then up the normal by the "
                       "radius to the sphere's centre",
    "cylinder_on_plane": "a cylinder lying on a plane: along the plane by the two dependent slides (to a point of its "
                         "axis's foot), then up the normal by the radius to the axis",
    "planar": "a face on a plane (plane on plane): along the plane by the two dependent slides, then up the normal by "
              "the offset (the mating part's datum above its face; \"0\" if on it)",
    "edge_on_surface": "an edge (or a point) on a plane: along the plane by the two dependent slides to the contact",
    "sphere_in_cylinder": "a sphere in a bore: along the bore's axis by the dependent slide, then out from the axis by "
                          "outer_radius − radius at the dependent angle about it, to the sphere's centre",
    "sphere_in_vee": "a sphere in a V-groove: along the groove's root line by the dependent slide, then up the "
                     "bisector by radius / sin(included_angle / 2) to the sphere's centre",
}


def surface_frame(angle: str, elevation: str) -> tuple[tuple[str, str], tuple[str, str], tuple[str, str]]:
    """``(e1, e2, n)`` as (angle, elevation) formulas: the right-handed frame of a surface whose normal (a plane's; a
    bore's or a groove's axis) is n = u(θ, φ).  e1 = u(θ, φ − π/2) is n tipped down by 90° in its own vertical
    plane and e2 = u(θ + π/2, 0) is horizontal, so that e1 × e2 = n (u as in the module docstring: for n = z,
    θ = 0, the frame is x, y, z)."""
    return (f"({angle})", f"({elevation}) - pi/2"), (f"({angle}) + pi/2", "0"), (f"({angle})", f"({elevation})")


def _formula(t, key: str, default=None) -> str:
    v = t.raw(key) if default is None else t.raw(key, default)
    if not isinstance(v, str):
        raise t.error(key, f"expected a formula in quotes, got {v!r}")
    return v


def _direction(t, key: str) -> tuple[str, str]:
    """A direction ``{ angle = "…", elevation = "…" }`` (formulas: the azimuth from x and the elevation above xy)."""
    d = t.sub(key)
    angle, elevation = _formula(d, "angle"), _formula(d, "elevation")
    d.finish()
    return angle, elevation


def _read_joint_3d(t, kind: str) -> tuple[list[Vector], list[Dependent]]:
    """A 3-D joint (:data:`JOINTS_3D`): its vectors and dependents (slides in mm, angles in deg)."""
    if kind == "sphere_in_vee":
        axis, bisector = _direction(t, "axis"), _direction(t, "bisector")
        slide = t.str("slide")
        dep = Dependent(slide, "mm", t.float("start"))
        height = f"({_formula(t, 'radius')}) / sin(({_formula(t, 'included_angle')}) / 2)"
        return [Vector(slide, *axis), Vector(height, *bisector)], [dep]
    if kind == "sphere_in_cylinder":
        e1, e2, axis = surface_frame(*_direction(t, "axis"))
        slide, angle = t.str("slide"), t.str("angle")
        s0, a0 = t.floats("start", length=2)
        off = f"(({_formula(t, 'outer_radius')}) - ({_formula(t, 'radius')}))"
        return ([Vector(slide, *axis), Vector(f"{off} * cos({angle})", *e1), Vector(f"{off} * sin({angle})", *e2)],
                [Dependent(slide, "mm", s0), Dependent(angle, "deg", a0)])
    e1, e2, normal = surface_frame(*_direction(t, "normal"))
    slides = t.strs("slides")
    if len(slides) != 2:
        raise t.error("slides", f"a {kind} joint slides two ways in the plane: two names, got {len(slides)}")
    starts = t.floats("start", length=2)
    vectors = [Vector(slides[0], *e1), Vector(slides[1], *e2)]
    up = {"sphere_on_plane": "radius", "cylinder_on_plane": "radius", "planar": "offset"}.get(kind)
    if up is not None:
        vectors.append(Vector(_formula(t, up), *normal))
    return vectors, [Dependent(n, "mm", s) for n, s in zip(slides, starts)]


def read_joint(t, dims: int) -> tuple[list[Vector], list[Dependent]]:
    """One ``[[model.joint]]`` table: the vectors it stands for (in the loops that name it) and the dependents it
    declares (:data:`JOINTS`, 2-D; :data:`JOINTS_3D`).  A 2-D joint's dependent is named by ``slide`` (a length along
    ``direction``) or ``angle`` (the line of centres) and started at ``start`` (in ``unit``: mm for a slide, deg for
    an angle unless given); a 3-D joint's by ``slides`` (two names) or ``slide`` and ``angle``, started at ``start``
    (mm and deg, a list when two)."""
    kind = t.str("type", choices=tuple(JOINTS if dims == 2 else JOINTS_3D))
    if dims == 3:
        return _read_joint_3d(t, kind)
    if kind in ("slider", "cylinder_on_plane"):
        slide = t.str("slide")
        dep = Dependent(slide, t.unit("unit", "mm", dimension="length"), t.float("start"))
        along = _formula(t, "direction")
        vectors = [Vector(slide, along)]
        if kind == "cylinder_on_plane":
            side = t.str("side", "left", choices=("left", "right"))
            vectors.append(Vector(_formula(t, "radius"), f"({along}) {'+' if side == 'left' else '-'} pi/2"))
        return vectors, [dep]
    angle = t.str("angle")
    dep = Dependent(angle, t.unit("unit", "deg", dimension="angle"), t.float("start"))
    r, big = _formula(t, "radius"), _formula(t, "outer_radius")
    length = f"({big}) - ({r})" if kind == "cylinder_in_cylinder" else f"({r}) + ({big})"
    return [Vector(length, angle)], [dep]


def _joint_vectors(t, i: int, entry: dict, joints: Mapping[str, list[Vector]]) -> list[Vector]:
    """The vectors a loop's ``{ joint = "<name>" }`` entry stands for; ``reverse = true`` walks the joint backwards
    (from the mating part to the surface: each vector negated, in the reverse order), as a loop that reaches a
    part through one contact and leaves it through another does."""
    name = entry["joint"]
    if not set(entry) <= {"joint", "reverse"} or not isinstance(entry.get("reverse", False), bool):
        raise t.error("vectors", f"vector {i + 1}: a joint entry is {{ joint = \"<name>\" }}, with reverse = true "
                                 f"or false if walked backwards")
    if name not in joints:
        raise t.error("vectors", f"vector {i + 1}: no joint {name!r}{did_you_mean(str(name), joints)} (the model's: "
                                 f"{', '.join(joints) or 'none'})")
    if not entry.get("reverse", False):
        return list(joints[name])
    return [Vector(f"-({v.length})", v.angle, v.elevation) for v in reversed(joints[name])]


def _rotation(t, i: int, entry: dict, dims: int) -> Rotation:
    """A loop's ``{ rotate = "<angle>", about = "x" | "y" | "z" }`` entry (3-D)."""
    if set(entry) != {"rotate", "about"} or entry["about"] not in _AXES or not isinstance(entry["rotate"], str):
        raise t.error("vectors", f"vector {i + 1}: a rotation is {{ rotate = \"<angle formula>\", about = \"x\" | "
                                 f"\"y\" | \"z\" }} (about the turned frame's own axis)")
    if dims != 3:
        raise t.error("vectors", f"vector {i + 1}: a rotation needs dimensions = 3 (in 2-D every angle is from the x "
                                 f"axis: a loop's orientation closes by itself)")
    return Rotation(entry["rotate"], entry["about"])


@dataclass
class Options:
    """The keys of ``[model] kind = "vector_loop"``."""

    dimensions: int = option(2, "a planar (2) or a spatial (3) loop", min=2, max=3)
    define: Params | None = option(None, 'intermediate quantities in order: name = "formula" or {formula, unit}')
    dependent: list[Params] = option([], "each [[model.dependent]]: name, unit (a length or an angle), start (the "
                                         "nominal assembly's value: the branch solved)")
    joint: list[Params] = option([], "each [[model.joint]]: name, type (a contact of JOINTS in 2-D, JOINTS_3D in "
                                     "3-D: slider, sphere_on_plane, ...) and that type's keys; it declares its own "
                                     "dependents")
    loop: list[Params] = option([], 'each [[model.loop]]: name, vectors = [{ length, angle, elevation }, '
                                    '{ joint }, { rotate, about }, ...] (closed)')
    output: list[OutputTable] = option([], "the model's outputs, each a [[model.output]] table")


def build(o: Options, design, spec, error) -> VectorLoopModel:
    """The study factory (``[model] kind = "vector_loop"``); errors name the file and key."""
    dims = o.dimensions
    definitions = read_definitions(o.define)
    deps = []
    for t in o.dependent:
        unit = t.unit("unit", dimension=("length", "angle"))
        deps.append(Dependent(t.str("name"), unit, t.float("start")))
        t.finish()
    joints = {}
    for t in o.joint:
        name = t.str("name")
        if name in joints:
            raise t.error("name", f"a second joint {name!r}")
        joints[name], new = read_joint(t, dims)
        deps += new
        t.finish()
    if not deps:
        raise error("dependent", "a vector-loop model needs its dependents ([[model.dependent]]: name, unit, "
                                        "start; or the joints' own)")
    loops, names, origins, loop_tables = [], [], [], o.loop
    for t in loop_tables:
        names.append(t.str("name", f"loop {len(names) + 1}"))
        raw = t.raw("vectors")
        if not isinstance(raw, list) or not raw or not all(isinstance(v, dict) for v in raw):
            raise t.error("vectors", "expected a list of tables { length = \"…\", angle = \"…\" }")
        vectors, origin = [], []          # origin: the entry each vector comes from, and its joint (None: written)
        for i, v in enumerate(raw):
            if "joint" in v:                  # a declared contact: the vectors it stands for
                new = _joint_vectors(t, i, v, joints)
                vectors += new
                origin += [(i, v["joint"])] * len(new)
                continue
            origin.append((i, None))
            if "rotate" in v:                 # the next part's frame
                vectors.append(_rotation(t, i, v, dims))
                continue
            unknown = sorted(set(v) - {"length", "angle", "elevation"})
            if unknown or "length" not in v or "angle" not in v:
                raise t.error("vectors", f"vector {i + 1}: " + (f"unknown key {unknown[0]!r}" if unknown else
                                                                "needs a length and an angle"))
            for k in ("angle", "elevation"):     # a bare number would be radians: say which unit it is in
                if k in v and not isinstance(v[k], str):
                    raise t.error("vectors", f"vector {i + 1}: the {k} {v[k]!r} is a bare number: write it as a "
                                             f"formula in quotes, in radians (\"pi/2\") or of factors with their units")
            vectors.append(Vector(str(v["length"]), v["angle"], v.get("elevation", "0")))
        loops.append(vectors)
        origins.append(origin)
        t.finish()
    if not loops:
        raise error("loop", "a vector-loop model needs at least one [[model.loop]]")
    outs = [out for _, out in read_outputs(o.output, error, "a vector-loop model")]
    try:
        model = VectorLoopModel(loops, deps, outs, spec.names, spec.units, dimensions=dims,
                                definitions=definitions, loop_names=names)
    except LoopError as exc:
        entry, joint = origins[exc.loop][exc.vector]
        where = (f"vector {entry + 1}, {exc.what}: " if joint is None else
                 f"vector {entry + 1} (joint {joint!r}), its {exc.what}: ")
        raise loop_tables[exc.loop].error("vectors", where + exc.why) from None
    except ExpressionError as exc:
        raise error(None, exc.reason) from None
    try:
        model.at_nominal(np.array([f.nominal_base for f in spec.factors]))
    except InputError as exc:
        raise error("dependent", exc.reason) from None
    return model


from_study = ModelKind(Options, build, "closed loops of vectors (2-D or 3-D) with joints: dependents solved per sample")


__all__ = ["Dependent", "Rotation", "Vector", "VectorLoopModel", "from_study"]
