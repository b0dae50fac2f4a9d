"""Two-dimensional plane-stress finite-element models of the reducer's plates, built with scikit-fem.

The elements whose geometry has no closed form — a cycloid disc with its crank-bearing holes and centre
bore, a carrier plate with its bearing-cup seats, the housing ring behind the pin grooves — are thin in
the axial direction and loaded in their plane, so they are plane-stress problems (Timoshenko & Goodier,
*Theory of Elasticity*, 3rd ed., ch. 2: ``σ_z = 0``, the in-plane Lamé constant ``λ* = 2λμ/(λ + 2μ)``).
This module only **meshes and loads** them; the finite-element assembly and solution are scikit-fem's
(``skfem.Basis``, ``skfem.models.elasticity.linear_elasticity``, ``skfem.condense``, ``skfem.solve``):
quadratic triangles (``ElementTriP2``), thickness ``t`` multiplying the stiffness and the loads.

**Meshes** (no mesher dependency, both built here):

* :func:`annulus_mesh` — a structured polar mesh of an annulus (``n_r × n_θ`` quadrilaterals, each split
  into two triangles), nodes exactly on both circles;
* :func:`perforated_disc_mesh` — a disc (optionally with a centre bore) with circular holes: nodes on
  rings around every circle (spacing ``h_fine`` at a hole, growing geometrically to ``h``), a hexagonal
  lattice of spacing ``h`` elsewhere, triangulated by SciPy's Delaunay (``scipy.spatial.Delaunay``),
  triangles whose centroid lies outside the material removed.

**Loads** are tractions on boundary circles (:class:`Traction`; :func:`arc_load`: a resultant force spread
over an arc with a given profile, e.g. the ``cos^(10/9)`` roller-load distribution of a bearing seat).  A model
loaded by a **self-equilibrated** set has no supports: the rigid-body part of the assembled load vector
(round-off of the polygonal boundary) is projected out and three degrees of freedom are fixed, so the
reactions there vanish and the work ``W = f·u`` (twice the strain energy) is independent of the rigid
motion.  Otherwise the boundary of ``fixed`` (arcs or a predicate) is clamped.

The work ``W`` under a load set of resultant forces ``F_k`` gives an element's energy-equivalent compliance
``c = W / Σ|F_k|²`` (the reduction the 20-DOF model uses: a linear spring in series with each contact that
stores the same energy under the same loads).

Units: mm, N, MPa.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import Delaunay, cKDTree

from ..errors import SpecError
from . import _checks


# ------------------------------------------------------------------------------------------------ meshes
def _mesh(skfem, p: np.ndarray, t: np.ndarray):
    """skfem's triangle mesh of points ``p`` (2 × N) and triangles ``t`` (3 × M), both C-contiguous (skfem copies and
    logs a warning on the console for a transposed array over 1000 entries)."""
    return skfem.MeshTri(np.ascontiguousarray(p, dtype=float), np.ascontiguousarray(t))


def annulus_mesh(r_inner: float, r_outer: float, n_r: int, n_theta: int, *, geometric: bool = False):
    """Structured triangular mesh of the annulus ``r_inner ≤ r ≤ r_outer`` (skfem ``MeshTri``); ``geometric``:
    radial spacing growing in proportion to the radius (elements of similar shape from the bore outwards)."""
    import skfem

    ri = float(_checks.positive("r_inner", r_inner))
    ro = float(_checks.positive("r_outer", r_outer))
    if not ro > ri:
        raise SpecError(f"must exceed r_inner {ri:g}, got {ro:g}", key="r_outer")
    r = np.geomspace(ri, ro, int(n_r) + 1) if geometric else np.linspace(ri, ro, int(n_r) + 1)
    th = np.linspace(0.0, 2.0 * np.pi, int(n_theta), endpoint=False)
    R, T = np.meshgrid(r, th, indexing="ij")
    p = np.vstack([(R * np.cos(T)).ravel(), (R * np.sin(T)).ravel()])
    nt = th.size
    idx = lambda i, j: i * nt + (j % nt)  # noqa: E731
    tri = []
    for i in range(r.size - 1):
        for j in range(nt):
            a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
            tri += [(a, b, c), (a, c, d)]
    return _mesh(skfem, p, np.array(tri, dtype=np.int64).T)


@dataclass(frozen=True)
class Circle:
    """A circle (hole or boundary) of centre ``(x, y)`` and radius ``r`` (mm)."""

    x: float
    y: float
    r: float

    def distance(self, p) -> np.ndarray:
        """Signed distance of points ``p`` (2, n) from the circle (> 0 outside)."""
        return np.hypot(p[0] - self.x, p[1] - self.y) - self.r


def _ring_points(c: Circle, radii, spacing) -> list[np.ndarray]:
    out = []
    for rho, s in zip(radii, spacing):
        n = max(8, int(math.ceil(2.0 * math.pi * rho / s)))
        a = 2.0 * np.pi * (np.arange(n) + 0.5 * (len(out) % 2)) / n
        out.append(np.vstack([c.x + rho * np.cos(a), c.y + rho * np.sin(a)]))
    return out


def perforated_disc_mesh(r_outer: float, holes, *, bore: float = 0.0, h: float = 2.0, h_fine: float = 0.5,
                         growth: float = 1.3):
    """Triangular mesh of the disc ``r ≤ r_outer`` less a centre bore of radius ``bore`` (0: none) and the
    circular ``holes`` (:class:`Circle`, or ``(x, y, r)``), element size ``h_fine`` at the bore and the holes
    growing by ``growth`` per ring to ``h`` (module doc).  Raises :class:`SpecError` when a hole cuts the
    outer circle, the bore or another hole (no ligament left)."""
    import skfem

    ro = float(_checks.positive("r_outer", r_outer))
    h = float(_checks.positive("h", h))
    hf = float(_checks.positive("h_fine", h_fine))
    cuts = [c if isinstance(c, Circle) else Circle(*map(float, c)) for c in holes]
    if bore > 0:
        cuts.append(Circle(0.0, 0.0, float(bore)))
    for i, c in enumerate(cuts):
        if not np.hypot(c.x, c.y) + c.r < ro:
            raise SpecError(f"a hole (centre ({c.x:g}, {c.y:g}), r {c.r:g}) cuts the outer circle r {ro:g}",
                            key="holes")
        for d in cuts[:i]:
            if not np.hypot(c.x - d.x, c.y - d.y) > c.r + d.r:
                raise SpecError(f"two holes overlap: ({c.x:g}, {c.y:g}, r {c.r:g}) and ({d.x:g}, {d.y:g}, "
                                f"r {d.r:g})", key="holes")
    outer = Circle(0.0, 0.0, ro)

    def inside(p):
        ok = outer.distance(p) < 0.0
        for c in cuts:
            ok &= c.distance(p) > 0.0
        return ok

    fixed = []
    # rings around every circle: spacing h_fine growing to h, going into the material
    for c, sign in [(outer, -1.0)] + [(c, 1.0) for c in cuts]:
        radii, spacing, rho, s = [], [], c.r, hf
        while (s < h or not radii) and len(radii) < 60:
            radii.append(rho)
            spacing.append(s)
            rho += sign * s
            s *= growth
            if rho <= 0:
                break
        pts = _ring_points(c, radii, spacing)
        pts = [pts[0]] + [q[:, inside(q)] for q in pts[1:]]
        fixed += pts
    ring = np.hstack(fixed)
    # hexagonal background lattice, kept away from the rings
    ys = np.arange(-ro, ro + h, h * math.sqrt(3.0) / 2.0)
    xs = np.arange(-ro, ro + h, h)
    lat = np.vstack([np.concatenate([xs + (0.5 * h if k % 2 else 0.0) for k in range(ys.size)]),
                     np.repeat(ys, xs.size)])
    lat = lat[:, inside(lat)]
    d, _ = cKDTree(ring.T).query(lat.T)
    lat = lat[:, d > 0.75 * h]
    p = np.hstack([ring, lat])
    # drop near-duplicates (rings of neighbouring circles)
    tree = cKDTree(p.T)
    drop = set()
    for i, j in sorted(tree.query_pairs(0.3 * hf)):
        if i not in drop:
            drop.add(j)
    keep = np.array([k for k in range(p.shape[1]) if k not in drop])
    p = p[:, keep]
    tri = Delaunay(p.T).simplices
    cen = p[:, tri].mean(axis=2)
    tri = tri[inside(cen)]
    used = np.unique(tri)
    remap = -np.ones(p.shape[1], np.int64)
    remap[used] = np.arange(used.size)
    return _mesh(skfem, p[:, used], remap[tri].T)


# ------------------------------------------------------------------------------------------------ loads
@dataclass(frozen=True)
class Traction:
    """A traction on the boundary lying on ``circle``: ``radial(ψ) e_r + tangential(ψ) e_ψ`` (MPa) applied to
    the body, with ``e_r`` pointing away from the circle's centre at the circle's angle ``ψ`` (a bearing
    pushing a bore's wall outwards: ``radial > 0``; a pressure on an outer rim: ``radial < 0``).  Either
    function may be None (zero)."""

    circle: Circle
    radial: object = None
    tangential: object = None


def arc_load(circle: Circle, force, thickness: float, *, half_angle: float = 0.5 * np.pi,
             exponent: float = 10.0 / 9.0, on_rim: bool = False) -> Traction:
    """The force ``(Fx, Fy)`` (N) as a normal pressure spread over the arc ``|ψ − ψ0| ≤ half_angle`` of
    ``circle`` with the profile ``cos(π/2 · (ψ − ψ0)/half_angle)^exponent`` — for a bore (``on_rim``
    False) ψ0 is the force's direction (a roller bearing pushing the bore's wall: ``exponent = 10/9``, the
    line-contact load distribution ``Q ∝ cos^(10/9) ψ`` of a bearing without clearance, Harris &
    Kotzalas vol. 1 ch. 7, over ±90°); for an outer rim the opposite direction (a pressure pushing
    inwards).  The peak pressure makes the resultant over the thickness exactly ``F``:
    ``F = t r p0 ∫ profile(s) cos s ds``."""
    from scipy.integrate import quad

    F = np.asarray(force, dtype=float)
    mag = float(np.hypot(*F))
    ha = float(half_angle)
    direction = math.atan2(F[1], F[0]) + (math.pi if on_rim else 0.0)
    val = quad(lambda s: math.cos(0.5 * math.pi * s / ha) ** exponent * math.cos(s), -ha, ha)[0]
    p0 = mag / (float(thickness) * circle.r * val)
    sign = -1.0 if on_rim else 1.0

    def radial(psi):
        u = np.angle(np.exp(1j * (psi - direction))) / ha
        return sign * p0 * np.where(np.abs(u) < 1.0, np.cos(0.5 * np.pi * np.clip(u, -1.0, 1.0)) ** exponent, 0.0)

    return Traction(circle, radial=radial)


def patch_load(circle: Circle, angle: float, force, thickness: float, half_angle: float) -> Traction:
    """The force ``(Fx, Fy)`` (N) as a traction of fixed direction spread over the arc
    ``|ψ − angle| ≤ half_angle`` of ``circle`` with a ``cos(π/2 · (ψ − angle)/half_angle)`` profile (a pin
    or a pillar handing a force to a rim: its direction need not be normal to the rim).  The magnitude
    integrates to ``|F|`` over the arc length times the thickness: ``∫ q ds · t = F``."""
    F = np.asarray(force, dtype=float)
    ha = float(half_angle)
    q0 = 1.0 / (float(thickness) * circle.r * 4.0 * ha / np.pi)     # ∫ cos(π s/2ha) ds over ±ha = 4ha/π

    def shape(psi):
        u = np.angle(np.exp(1j * (psi - angle))) / ha
        return q0 * np.where(np.abs(u) < 1.0, np.cos(0.5 * np.pi * np.clip(u, -1.0, 1.0)), 0.0)

    return Traction(circle, radial=lambda psi: shape(psi) * (F[0] * np.cos(psi) + F[1] * np.sin(psi)),
                    tangential=lambda psi: shape(psi) * (-F[0] * np.sin(psi) + F[1] * np.cos(psi)))


# ------------------------------------------------------------------------------------------------ solve
@dataclass
class PlaneStressSolution:
    """Displacement ``u`` (dofs of ``basis``), load vector ``f`` and the work ``W = f·u`` (N·mm)."""

    basis: object
    u: np.ndarray
    f: np.ndarray

    @property
    def work(self) -> float:
        return float(self.f @ self.u)

    def displacement(self, points) -> np.ndarray:
        """Displacement (2, n) at ``points`` (2, n) inside the mesh."""
        pts = np.atleast_2d(np.asarray(points, float))
        P = self.basis.probes(pts)
        v = P @ self.u
        return v.reshape(2, -1)


def facets_on(mesh, circle: Circle, tol: float = 1e-7) -> np.ndarray:
    """Boundary facets of ``mesh`` whose two nodes lie on ``circle`` (within ``tol`` × its radius)."""
    bf = mesh.boundary_facets()
    nodes = mesh.facets[:, bf]
    d = np.abs(circle.distance(mesh.p[:, nodes.ravel()])).reshape(nodes.shape)
    return bf[np.all(d <= tol * max(circle.r, 1.0), axis=0)]


def _dof_components(basis) -> np.ndarray:
    comp = np.zeros(basis.N, dtype=np.int64)
    for name in ("nodal_dofs", "facet_dofs", "edge_dofs", "interior_dofs"):
        d = getattr(basis, name, None)
        if d is not None and d.size:
            comp[d[1]] = 1
    return comp


def rigid_modes(basis) -> np.ndarray:
    """The three in-plane rigid-body modes (N, 3) at the basis' dofs: x, y translations, rotation."""
    comp = _dof_components(basis)
    x, y = basis.doflocs
    R = np.zeros((basis.N, 3))
    R[comp == 0, 0] = 1.0
    R[comp == 1, 1] = 1.0
    R[:, 2] = np.where(comp == 0, -y, x)
    return R


class PlateModel:
    """A plane-stress plate: ``mesh`` (skfem ``MeshTri``), Young's modulus ``E`` (MPa), Poisson ratio
    ``nu``, thickness (mm); ``fixed``: None (self-equilibrated loads, module doc) or a function of points
    ``x`` (2, n) returning True on the clamped boundary.  The stiffness is assembled and factorised once
    (scipy ``splu``); :meth:`solve` takes any number of load sets."""

    def __init__(self, mesh, E: float, nu: float, thickness: float, *, fixed=None):
        import skfem
        from scipy.sparse.linalg import splu
        from skfem.models.elasticity import lame_parameters, linear_elasticity

        self.E = float(_checks.positive("E", E))
        self.nu = float(_checks.poisson("nu", nu))
        self.t = float(_checks.positive("thickness", thickness))
        self.mesh = mesh
        lam, mu = lame_parameters(self.E, self.nu)
        lam_ps = 2.0 * lam * mu / (lam + 2.0 * mu)          # plane stress
        self.element = skfem.ElementVector(skfem.ElementTriP2())
        self.basis = skfem.Basis(mesh, self.element, intorder=2)   # exact for P2 stiffness on straight triangles
        K = (self.t * skfem.asm(linear_elasticity(lam_ps, mu), self.basis)).tocsc()
        N = self.basis.N
        if fixed is None:
            self.rigid = rigid_modes(self.basis)
            x, y = self.basis.doflocs
            comp = _dof_components(self.basis)
            a = int(np.argmax(np.where(comp == 0, x, -np.inf)))
            b = int(np.flatnonzero((comp == 1) & (x == x[a]) & (y == y[a]))[0])
            c = int(np.argmin(np.where(comp == 1, x, np.inf)))
            D = np.array([a, b, c])
        else:
            self.rigid = None
            bf = mesh.boundary_facets()
            mid = mesh.p[:, mesh.facets[:, bf]].mean(axis=1)
            facets = bf[np.asarray(fixed(mid), bool)]
            if facets.size == 0:
                raise SpecError("the clamped boundary selects no facet", key="fixed")
            D = self.basis.get_dofs(facets).all()
        self.free = np.setdiff1d(np.arange(N), D)
        # K is symmetric positive definite once the rigid motions are held: a minimum-degree ordering of K + Kᵀ
        # preferring diagonal pivots (SuperLU's symmetric mode) halves the factor's fill against the default COLAMD
        # (RV-80E's disc, 42 009 unknowns: 3.6 against 6.9 million nonzeros; its four seats factorised in 0.63
        # against 1.0 s; the solutions agree to 2e-12)
        self.lu = splu(K[self.free][:, self.free].tocsc(), permc_spec="MMD_AT_PLUS_A",
                       options={"SymmetricMode": True})

    def load_vector(self, loads) -> np.ndarray:
        """Assembled load vector of the tractions ``loads`` (:class:`Traction`)."""
        import skfem

        f = np.zeros(self.basis.N)
        groups: dict = {}
        for ld in loads:                               # one facet basis per circle, its tractions summed
            groups.setdefault(ld.circle, []).append(ld)
        for c, lds in groups.items():
            facets = facets_on(self.mesh, c)
            if facets.size == 0:
                raise SpecError(f"no boundary on the circle (centre ({c.x:g}, {c.y:g}), r {c.r:g}) of a load",
                                key="loads")
            fb = skfem.FacetBasis(self.mesh, self.element, facets=facets, intorder=6)

            @skfem.LinearForm
            def traction(v, w, lds=lds, c=c):
                x, y = w.x
                psi = np.arctan2(y - c.y, x - c.x)
                s_r = sum(ld.radial(psi) for ld in lds if ld.radial is not None) + 0.0 * psi
                s_t = sum(ld.tangential(psi) for ld in lds if ld.tangential is not None) + 0.0 * psi
                fx = s_r * np.cos(psi) - s_t * np.sin(psi)
                fy = s_r * np.sin(psi) + s_t * np.cos(psi)
                return fx * v[0] + fy * v[1]

            f += self.t * skfem.asm(traction, fb)
        if self.rigid is not None:
            R = self.rigid
            f = f - R @ np.linalg.solve(R.T @ R, R.T @ f)
        return f

    def solve(self, loads) -> PlaneStressSolution:
        f = self.load_vector(loads)
        u = np.zeros(self.basis.N)
        u[self.free] = self.lu.solve(f[self.free])
        return PlaneStressSolution(self.basis, u, f)


def solve_plane_stress(mesh, E: float, nu: float, thickness: float, loads, *, fixed=None) -> PlaneStressSolution:
    """One load set on a :class:`PlateModel` (``fixed`` as there)."""
    return PlateModel(mesh, E, nu, thickness, fixed=fixed).solve(loads)
