"""Deviation domains (doc 003): where a feature's deviation vector may lie, and its moments.

Three domains, each with closed-form mean vector and covariance for a
uniform distribution and for a truncated normal inside the domain, and
deterministic samplers for both (all 6-DOF, fixed DOFs are zero):

* :class:`ParallelPlaneZone` — a planar face ``L`` (along x) × ``W`` (along
  y) inside two parallel planes at ``w = t1`` and ``w = t2`` (``Δt = t2 − t1``).
  A small rotation turns the face into ``z = w − Δβ·x + Δα·y``, so the zone
  holds the face iff every corner does: the **exact domain**
  ``|w − m| + |Δα|·W/2 + |Δβ|·L/2 ≤ Δt/2`` (``m = (t1 + t2)/2``), an
  octahedron.  Its bounding **box** is ``|w − m| ≤ Δt/2``, ``|Δα| ≤ Δt/W``,
  ``|Δβ| ≤ Δt/L``.
* :class:`CylindricalZone` — an axis of length ``L`` inside a cylinder of
  diameter ``t``: both end points ``p(±L/2) = (u ± Δβ·L/2, v ∓ Δα·L/2)`` lie
  in the disc of radius ``t/2``.  The map (u, v, Δα, Δβ) → (p₊, p₋) is
  linear, so uniform in the domain ⇔ both end points uniform in their
  discs, independently.
* :class:`ClearanceFit` — a shaft in a hole: the shaft axis floats in a
  cylindrical domain of diameter ``c⁺ = max(c0 + δD − δd, 0)`` over the
  engagement length, the clearance itself random through the sizes.

Truncated normal conventions (stated, since "a normal inside the domain"
needs one): plane — independent normals on (w, Δα, Δβ) centred in the box,
each with σ = box half-width / k, conditioned on the exact domain; axis —
each end point an isotropic normal with σ = (t/2)/k truncated to its disc.
``k = 3`` by default.

The clearance float used by the chain model maps factors ``(a, b) ∈ [-1, 1]²``
to the unit disc with the Shirley–Chiu concentric map (area-preserving:
uniform square → uniform disc), so "uniform in the clearance domain" is a
plain spec of uniform factors and the model stays deterministic.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import integrate, stats

from ...distributions import Distribution
from ...errors import InputError
from ...sampling import rng, substream
from .transforms import DOF

DISTRIBUTIONS = ("uniform", "truncnorm")


def _positive(name: str, v: float) -> float:
    v = float(v)
    if not (np.isfinite(v) and v > 0):
        raise InputError(f"{name} must be a finite number > 0, got {v}", key=name)
    return v


def _dist(dist: str) -> str:
    if dist not in DISTRIBUTIONS:
        raise InputError(f"unknown domain distribution {dist!r} (expected one of: {', '.join(DISTRIBUTIONS)})",
                         key="distribution")
    return dist


def moments_frame(mean, cov, dofs=range(6)):
    import pandas as pd

    dofs = list(dofs)
    return pd.DataFrame({"dof": [DOF[i] for i in dofs], "unit": ["mm" if i < 3 else "rad" for i in dofs],
                         "mean": np.asarray(mean)[dofs], "std": np.sqrt(np.diag(cov))[dofs]})


# --------------------------------------------------------------------------- planar face
@dataclass(frozen=True)
class ParallelPlaneZone:
    """Planar face ``L × W`` between the planes ``w = t1`` and ``w = t2`` (mm)."""

    t1: float
    t2: float
    L: float
    W: float
    k: float = 3.0  # truncated normal: σ = box half-width / k

    dofs = (2, 3, 4)

    def __post_init__(self):
        if not (np.isfinite(self.t1) and np.isfinite(self.t2) and self.t2 > self.t1):
            raise InputError(f"zone limits need t1 < t2, got t1={self.t1}, t2={self.t2}", key="t2")
        _positive("L", self.L)
        _positive("W", self.W)
        _positive("k", self.k)

    @classmethod
    def symmetric(cls, t: float, L: float, W: float, k: float = 3.0) -> "ParallelPlaneZone":
        """A zone of thickness ``t`` centred on the nominal plane."""
        return cls(-0.5 * t, 0.5 * t, L, W, k)

    @property
    def dt(self) -> float:
        return self.t2 - self.t1

    @property
    def centre(self) -> float:
        return 0.5 * (self.t1 + self.t2)

    @property
    def _lever(self) -> np.ndarray:
        """Corner lever arms of (w, Δα, Δβ): |w−m|·1 + |Δα|·W/2 + |Δβ|·L/2 ≤ Δt/2."""
        return np.array([1.0, 0.5 * self.W, 0.5 * self.L])

    def box(self) -> np.ndarray:
        """Half-widths of the bounding box of the exact domain, on all six DOFs."""
        hw = np.zeros(6)
        hw[[2, 3, 4]] = 0.5 * self.dt / self._lever
        return hw

    def contains(self, E, tol: float = 1e-12) -> np.ndarray:
        E = np.asarray(E, dtype=float)
        s = np.abs(E[..., 2] - self.centre) + np.abs(E[..., 3]) * self._lever[1] + np.abs(E[..., 4]) * self._lever[2]
        others = np.all(E[..., [0, 1, 5]] == 0.0, axis=-1)
        return others & (s <= 0.5 * self.dt * (1.0 + tol))

    # -- moments -------------------------------------------------------------
    def mean(self, dist: str = "uniform") -> np.ndarray:
        """``(0, 0, (t1+t2)/2, 0, 0, 0)``: the domain is symmetric in Δα → −Δα, Δβ → −Δβ, w−m → m−w."""
        _dist(dist)
        m = np.zeros(6)
        m[2] = self.centre
        return m

    def scaled_variance(self, dist: str = "uniform") -> float:
        """Variance of each scaled coordinate ``x_i = lever_i·E_i`` in the octahedron ``Σ|x_i| ≤ h``.

        Uniform: the marginal density is ``3(h−|x|)²/(2h³)``, so ``E[x²] = h²/10``.
        Truncated normal (iid N(0, (h/k)²) conditioned on the octahedron):
        ``E[x²] = ∫x²φ(x)G(h−|x|)dx / ∫φ(x)G(h−|x|)dx`` with
        ``G(r) = P(|y|+|z| ≤ r) = ∫φ(y)(2Φ((r−|y|)/s)−1)dy`` (nested quadrature).
        """
        h = 0.5 * self.dt
        if _dist(dist) == "uniform":
            return h * h / 10.0
        s = h / self.k
        phi = stats.norm(scale=s)

        def G(r):
            if r <= 0:
                return 0.0
            f = lambda y: phi.pdf(y) * (2.0 * phi.cdf(r - abs(y)) - 1.0)  # noqa: E731
            return 2.0 * integrate.quad(f, 0.0, r, epsabs=0, epsrel=1e-11)[0]

        num = 2.0 * integrate.quad(lambda x: x * x * phi.pdf(x) * G(h - x), 0.0, h, epsabs=0, epsrel=1e-10)[0]
        den = 2.0 * integrate.quad(lambda x: phi.pdf(x) * G(h - x), 0.0, h, epsabs=0, epsrel=1e-10)[0]
        return num / den

    def cov(self, dist: str = "uniform") -> np.ndarray:
        """Diagonal: ``Δt²/40``, ``Δt²/(10W²)``, ``Δt²/(10L²)`` for uniform; cross terms 0 by symmetry."""
        P = np.zeros((6, 6))
        v = self.scaled_variance(dist)
        for i, lev in zip(self.dofs, self._lever):
            P[i, i] = v / lev**2
        return P

    def box_cov(self) -> np.ndarray:
        """Independent uniforms on the bounding box: ``Δt²/12``, ``Δt²/(3W²)``, ``Δt²/(3L²)``."""
        return np.diag(self.box() ** 2 / 3.0)

    # -- sampling --------------------------------------------------------------
    def sample(self, n: int, dist: str = "uniform", seed: int | None = None) -> np.ndarray:
        g = rng(seed)
        h = 0.5 * self.dt
        if _dist(dist) == "uniform":
            # uniform in the octahedron Σ|x_i| ≤ h: |x| = h·(first 3 of a flat Dirichlet(1,1,1,1)), random signs
            ex = g.exponential(size=(n, 4))
            x = h * ex[:, :3] / ex.sum(axis=1, keepdims=True)
            x *= np.where(g.random((n, 3)) < 0.5, -1.0, 1.0)
        else:
            x = _rejection(lambda m: g.normal(0.0, h / self.k, size=(m, 3)),
                           lambda y: np.abs(y).sum(axis=1) <= h, n)
        E = np.zeros((n, 6))
        E[:, [2, 3, 4]] = x / self._lever
        E[:, 2] += self.centre
        return E


def _rejection(draw, accept, n: int) -> np.ndarray:
    """``n`` accepted rows of ``draw(m)`` (loops over batches, never over samples)."""
    parts, got = [], 0
    while got < n:
        y = draw(max(1024, int(1.6 * (n - got))))
        y = y[accept(y)]
        parts.append(y)
        got += len(y)
    return np.concatenate(parts)[:n]


# --------------------------------------------------------------------------- axis in a cylinder
def axis_from_ends(p_plus, p_minus, L):
    """(u, v, Δα, Δβ) of an axis whose points at z = +L/2 and −L/2 are ``p_plus``, ``p_minus`` (…, 2)."""
    p_plus, p_minus = np.asarray(p_plus, float), np.asarray(p_minus, float)
    L = np.asarray(L, dtype=float)
    u = 0.5 * (p_plus[..., 0] + p_minus[..., 0])
    v = 0.5 * (p_plus[..., 1] + p_minus[..., 1])
    beta = (p_plus[..., 0] - p_minus[..., 0]) / L
    alpha = -(p_plus[..., 1] - p_minus[..., 1]) / L
    return np.stack([u, v, alpha, beta], axis=-1)


def ends_from_axis(E, L):
    """Inverse of :func:`axis_from_ends` for ``E[..., 6]``: ``(p_plus, p_minus)``."""
    E = np.asarray(E, dtype=float)
    h = 0.5 * L
    pp = np.stack([E[..., 0] + E[..., 4] * h, E[..., 1] - E[..., 3] * h], axis=-1)
    pm = np.stack([E[..., 0] - E[..., 4] * h, E[..., 1] + E[..., 3] * h], axis=-1)
    return pp, pm


def concentric_disk(a, b):
    """Shirley–Chiu concentric map of ``[-1, 1]²`` onto the unit disc (area-preserving, continuous)."""
    a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
    big_a = np.abs(a) > np.abs(b)
    r = np.where(big_a, a, b)
    with np.errstate(divide="ignore", invalid="ignore"):
        phi = np.where(big_a, (np.pi / 4) * (b / a), (np.pi / 2) - (np.pi / 4) * (a / b))
    phi = np.where(r == 0.0, 0.0, phi)
    return np.stack([r * np.cos(phi), r * np.sin(phi)], axis=-1)


def truncated_rayleigh_ms(R: float, s: float) -> float:
    """``E[r²]`` of an isotropic 2-D normal (σ = s) truncated to the disc of radius R."""
    q = np.exp(-0.5 * (R / s) ** 2)
    return 2.0 * s * s - R * R * q / (1.0 - q)


def _disc_points(g, n: int, R, dist: str, k: float) -> np.ndarray:
    phi = g.uniform(0.0, 2.0 * np.pi, n)
    u = g.random(n)
    if dist == "uniform":
        r = R * np.sqrt(u)
    else:
        s = R / k
        q = np.exp(-0.5 * k * k)
        r = s * np.sqrt(-2.0 * np.log1p(-u * (1.0 - q)))
    return np.stack([r * np.cos(phi), r * np.sin(phi)], axis=-1)


@dataclass(frozen=True)
class CylindricalZone:
    """Axis of length ``L`` in a cylindrical zone of diameter ``t`` (mm)."""

    t: float
    L: float
    k: float = 3.0

    dofs = (0, 1, 3, 4)

    def __post_init__(self):
        _positive("t", self.t)
        _positive("L", self.L)
        _positive("k", self.k)

    @property
    def R(self) -> float:
        return 0.5 * self.t

    def box(self) -> np.ndarray:
        hw = np.zeros(6)
        hw[[0, 1]] = self.R
        hw[[3, 4]] = self.t / self.L
        return hw

    def contains(self, E, tol: float = 1e-12) -> np.ndarray:
        E = np.asarray(E, dtype=float)
        pp, pm = ends_from_axis(E, self.L)
        lim = (self.R * (1.0 + tol)) ** 2
        others = np.all(E[..., [2, 5]] == 0.0, axis=-1)
        return others & ((pp**2).sum(-1) <= lim) & ((pm**2).sum(-1) <= lim)

    def end_mean_square(self, dist: str = "uniform") -> float:
        """``E[p_x²] = E[p_y²]`` of one end point: ``R²/4`` (uniform) or half the truncated Rayleigh ``E[r²]``."""
        if _dist(dist) == "uniform":
            return self.R**2 / 4.0
        return 0.5 * truncated_rayleigh_ms(self.R, self.R / self.k)

    def mean(self, dist: str = "uniform") -> np.ndarray:
        _dist(dist)
        return np.zeros(6)

    def cov(self, dist: str = "uniform") -> np.ndarray:
        """``var u = var v = E[p²]/2``, ``var Δα = var Δβ = 2E[p²]/L²`` (uniform: t²/32 and t²/(8L²)); no cross terms."""
        m2 = self.end_mean_square(dist)
        return _axis_cov(m2, self.L)

    def sample(self, n: int, dist: str = "uniform", seed: int | None = None) -> np.ndarray:
        g = rng(seed)
        _dist(dist)
        pp = _disc_points(g, n, self.R, dist, self.k)
        pm = _disc_points(g, n, self.R, dist, self.k)
        return _axis_E(axis_from_ends(pp, pm, self.L))


def _axis_cov(end_ms, L) -> np.ndarray:
    P = np.zeros((6, 6))
    P[0, 0] = P[1, 1] = 0.5 * end_ms
    P[3, 3] = P[4, 4] = 2.0 * end_ms / L**2
    return P


def _axis_E(uvab) -> np.ndarray:
    E = np.zeros(uvab.shape[:-1] + (6,))
    E[..., [0, 1, 3, 4]] = uvab
    return E


# --------------------------------------------------------------------------- hole / shaft clearance fit
def positive_part_mean_square(c0: float, hole: Distribution, shaft: Distribution) -> float:
    """``E[max(c0 + δD − δd, 0)²]`` for independent size deviations (normal: closed form)."""
    if hole.kind == "normal" and shaft.kind == "normal":
        mu = c0 + hole.mean - shaft.mean
        s = float(np.hypot(hole.std, shaft.std))
        z = mu / s
        return float((mu * mu + s * s) * stats.norm.cdf(z) + mu * s * stats.norm.pdf(z))
    # general sizes: E_y[ ∫_{y−c0}^∞ (c0 + x − y)² f_D(x) dx ], in units of the clearance's σ; the outer
    # integrand has kinks where y − c0 meets an end of the hole's support, given to quad as break points
    s = float(np.hypot(hole.std, shaft.std))
    hlo, hhi = (float(v) for v in hole.frozen.support())
    ylo, yhi = (float(v) for v in shaft.frozen.support())

    def inner(y):
        lo = max(y - c0, hlo)
        if lo >= hhi:
            return 0.0
        return integrate.quad(lambda x: ((c0 + x - y) / s) ** 2 * hole.pdf(x), lo, hhi, epsabs=1e-14, epsrel=1e-11)[0]

    ylo = ylo if np.isfinite(ylo) else float(shaft.ppf(1e-15))
    yhi = yhi if np.isfinite(yhi) else float(shaft.ppf(1 - 1e-15))
    kinks = [v + c0 for v in (hlo, hhi) if np.isfinite(v) and ylo < v + c0 < yhi]
    val = integrate.quad(lambda y: inner(y) * shaft.pdf(y), ylo, yhi, points=kinks or None, epsabs=1e-14,
                         epsrel=1e-10, limit=200)[0]
    return float(val) * s * s


@dataclass(frozen=True)
class ClearanceFit:
    """A shaft floating in a hole: nominal diametral clearance ``c0``, size deviations, engagement ``L``.

    ``hole`` and ``shaft`` are the distributions of the diameter deviations
    from nominal (mm).  Where ``c = c0 + δD − δd ≤ 0`` the fit is tight and
    the shaft is centred.
    """

    c0: float
    hole: Distribution
    shaft: Distribution
    L: float
    k: float = 3.0

    dofs = (0, 1, 3, 4)

    def __post_init__(self):
        if not np.isfinite(self.c0):
            raise InputError("nominal clearance must be finite", key="c0")
        _positive("L", self.L)
        _positive("k", self.k)

    def clearance_mean_square(self) -> float:
        return positive_part_mean_square(self.c0, self.hole, self.shaft)

    def max_clearance(self, tolerance_band: bool = True) -> float:
        """Largest clearance over the size bands (mean ± T/2): the worst case."""
        h = self.hole.mean + 0.5 * self.hole.tolerance
        s = self.shaft.mean - 0.5 * self.shaft.tolerance
        return max(self.c0 + h - s, 0.0)

    def worst_case(self) -> dict[str, float]:
        """Largest radial offset (both ends pushed to one side) and tilt (ends opposite), mm and rad."""
        c = self.max_clearance()
        return {"radial_offset": 0.5 * c, "tilt": c / self.L}

    def mean(self, dist: str = "uniform") -> np.ndarray:
        _dist(dist)
        return np.zeros(6)

    def cov(self, dist: str = "uniform") -> np.ndarray:
        """Conditional on c the float is a :class:`CylindricalZone` of diameter c⁺: ``E[p²] ∝ E[c⁺²]``.

        uniform: ``E[p_x²] = E[c⁺²]/16``; truncated normal (σ = (c/2)/k):
        ``E[p_x²] = E[c⁺²]/4 · (2/k² − q/(1−q))/2`` with ``q = exp(−k²/2)``.
        """
        c2 = self.clearance_mean_square()
        if _dist(dist) == "uniform":
            m2 = c2 / 16.0
        else:
            m2 = 0.25 * c2 * 0.5 * truncated_rayleigh_ms(1.0, 1.0 / self.k)
        return _axis_cov(m2, self.L)

    def clearances(self, n: int, seed: int | None = None) -> np.ndarray:
        g = substream(seed, "clearance_fit_sizes")
        c = self.c0 + self.hole.ppf(g.random(n)) - self.shaft.ppf(g.random(n))
        return np.maximum(c, 0.0)

    def sample(self, n: int, dist: str = "uniform", seed: int | None = None) -> np.ndarray:
        _dist(dist)
        R = 0.5 * self.clearances(n, seed)
        g = substream(seed, "clearance_fit_positions")
        pp = _disc_points(g, n, R, dist, self.k)
        pm = _disc_points(g, n, R, dist, self.k)
        return _axis_E(axis_from_ends(pp, pm, self.L))
