"""A pin in its housing groove as a **conforming** contact (the pin-in-hole problem of Persson).

At the product's fit (radial clearance ``ΔR`` of a few µm) the Hertz half-width of the pin–groove contact
is a large fraction of the pin radius (half-angle ≈ 0.6–0.8 rad at rated load): Hertz's half-space and
parabolic-gap assumptions fail.  The plane-strain problem of a pin of radius ``a`` in a hole of radius
``a + ΔR`` in a large plate, both of the same material, frictionless, was solved by Persson (A. Persson,
*On the stress distribution of cylindrical elastic bodies in contact*, Diss., Chalmers, Göteborg 1964; see
K. L. Johnson, *Contact Mechanics*, CUP 1985, §5.6 "conforming surfaces"; M. Ciavarella & P. Decuzzi,
*Int. J. Solids Struct.* 38 (2001) 4507).  Two of its published results are this module's tests: the
Hertz limit at small loads and, for a neat fit (``ΔR = 0``), a contact arc of ±90° at any load.

**Method (exact plane elasticity, solved numerically).**  A normal boundary pressure
``p(θ) = Σ p_n cos nθ`` on a circle of radius ``a`` (no shear) displaces the boundary radially by
``u_n cos nθ``; from the Airy stress functions ``(A r^n + B r^{n+2}) cos nθ`` of the disk and
``(C r^{-n} + D r^{2-n}) cos nθ`` of an infinite plate with a hole (Michell; Timoshenko & Goodier ch. 4)::

    disk (pin), inward:    λ_n^pin  = a/(4G) · [n(κ+1) − (κ−1)] / (n² − 1)     (n = 0 and n ≥ 2)
    hole (housing), outward: λ_n^hole = a/(4G) · [n(κ+1) + (κ−1)] / (n² − 1)   (n ≥ 2),  a/(2G) (n = 0, Lamé)

(plane strain, ``κ = 3 − 4ν``; for large n both tend to the half-space's ``a(κ+1)/(4Gn)``).  The mode
n = 1 carries the load ``P = π a p_1`` (per unit length) and its displacement depends on the reference
points; it is the unknown rigid approach ``c`` of the contact condition

    h(θ) = ΔR (1 − cos θ) − c cos θ + Σ_{n≠1} (λ_n^pin + λ_n^hole) p_n cos nθ ≥ 0,   p ≥ 0,   p h = 0.

The pressure is piecewise linear on ``nodes`` points over ``[0, π]`` (symmetric about the load), its
Fourier coefficients exact; the contact problem is the quadratic programme of the complementary energy
(``min ½ pᵀ S p + pᵀ g`` over ``p ≥ 0`` with the load ``Bᵀp = P``), solved by SciPy's NNLS for a given ``c``
and bisection on ``c``.

**Approach for the chain.**  doc 004's Hertz formula (:func:`.contacts.groove_approach`) measures the
approach from the pin centre to a housing point one groove radius deep; its mode-1 part depends only on
``P``.  The conforming approach is that formula plus the difference ``Δc`` of ``c`` between the exact solution
and the same solution under Hertz's assumptions (half-space kernel ``a(κ+1)/(4Gn)`` per body for n ≥ 2,
parabolic gap ``ΔR θ²/2``) less its linear part ``F Δc(F0)/F0`` at a load ``F0`` inside Hertz's range
(half-angle 0.15 rad): that linear part is the two bodies' global compliance, which doc 004's formula
already represents by its reference depths; what remains is the conformity.  The correction is zero in
Hertz's range and lowers the approach of a tight groove (:func:`conforming_groove_approach`).

Units: mm, N, MPa; ``P`` in N per mm of contact length.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.optimize import brentq, nnls

from ..errors import SpecError
from . import _checks, contacts


def kernel_pin(n, a, G, nu):
    """Inward radial boundary displacement per unit pressure amplitude, mode ``n`` (0 or ≥ 2) of a disk."""
    n = np.asarray(n, dtype=float)
    k = 3.0 - 4.0 * nu
    return a / (4.0 * G) * (n * (k + 1.0) - (k - 1.0)) / np.where(n == 1, np.inf, n * n - 1.0)


def kernel_hole(n, a, G, nu):
    """Outward radial boundary displacement per unit pressure amplitude, mode ``n`` (0 or ≥ 2) of a circular
    hole in an infinite plate (n = 0: Lamé's ``a/(2G)``)."""
    n = np.asarray(n, dtype=float)
    k = 3.0 - 4.0 * nu
    out = a / (4.0 * G) * (n * (k + 1.0) + (k - 1.0)) / np.where(n == 0, 1.0, np.where(n == 1, np.inf, n * n - 1.0))
    return np.where(n == 0, a / (2.0 * G), out)


def kernel_half_space(n, a, G, nu):
    """Hertz's assumption: each body a half-space, ``a(κ+1)/(4Gn)`` (n ≥ 2)."""
    n = np.asarray(n, dtype=float)
    return a * (4.0 - 4.0 * nu) / (4.0 * G * np.where(n == 0, 1.0, n))


@dataclass(frozen=True)
class ConformingSolution:
    """Contact half-angle ``angle`` (rad), approach ``c`` beyond first touch (mm, mode-1 convention of the
    module doc), nodal pressures ``pressure`` (MPa) at ``theta``."""

    angle: float
    c: float
    theta: np.ndarray
    pressure: np.ndarray


class PinInHole:
    """The pin-in-hole contact of the module doc: pin radius ``a`` (mm), radial clearance ``clearance``
    (mm, ≥ 0), Young's modulus ``E`` (MPa) and Poisson ratio ``nu`` of both bodies (elastic similarity);
    ``nodes`` pressure nodes over [0, π], ``modes`` Fourier modes; ``hertzian`` uses Hertz's half-space
    kernel and parabolic gap instead (the reference of the correction)."""

    def __init__(self, a: float, clearance: float, E: float, nu: float, *, nodes: int = 241, modes: int = 2000,
                 hertzian: bool = False):
        self.a = float(_checks.positive("a", a))
        self.dr = float(_checks.nonnegative("clearance", clearance))
        self.E = float(_checks.positive("E", E))
        self.nu = float(_checks.poisson("nu", nu))
        self.G = self.E / (2.0 * (1.0 + self.nu))
        th = np.linspace(0.0, np.pi, int(nodes))
        self.theta = th
        n = np.arange(int(modes) + 1)
        # Fourier cosine coefficients of the symmetric hat functions on [−π, π]: p(θ) = Σ_j p_j φ_j(θ)
        h = th[1] - th[0]
        nn = n[:, None].astype(float)
        with np.errstate(divide="ignore", invalid="ignore"):
            # ∫_{−π}^{π} φ_j cos nθ dθ for a hat of half-width h centred at θ_j (θ_0 = 0, θ_end = π halves)
            tri = np.where(nn == 0, h, (2.0 - 2.0 * np.cos(nn * h)) / (nn * nn * h))
        cosn = np.cos(nn * th[None, :])
        integ = 2.0 * tri * cosn                       # ±θ_j both
        integ[:, 0] *= 0.5
        integ[:, -1] *= 0.5
        coef = integ / np.pi
        coef[0] *= 0.5                                  # p_0 = (1/2π) ∫ p
        lam = (kernel_half_space(n, self.a, self.G, self.nu) * 2.0 if hertzian
               else kernel_pin(n, self.a, self.G, self.nu) + kernel_hole(n, self.a, self.G, self.nu))
        if hertzian:
            lam[0] = kernel_pin(0, self.a, self.G, self.nu) + kernel_hole(0, self.a, self.G, self.nu)
        lam[1] = 0.0                                    # mode 1: the rigid approach c
        self.coef = coef                                # (modes+1, nodes): p_n of each nodal pressure
        # complementary energy: S_ij = a ∫ φ_i w(φ_j) dθ = a π Σ_n λ_n c_in c_jn (n ≥ 1), 2π a λ_0 c_i0 c_j0
        wts = np.full(n.size, np.pi * self.a)
        wts[0] = 2.0 * np.pi * self.a
        self.S = (coef * (wts * lam)[:, None]).T @ coef
        gap = 0.5 * th ** 2 if hertzian else 1.0 - np.cos(th)
        # g_i = a ∫ φ_i ΔR gap(θ) dθ and B_i = a ∫ φ_i cos θ dθ (trapezoid-consistent: the hat integrals)
        self.B = self.a * integ[1]
        wq = np.full(th.size, h)
        wq[0] = wq[-1] = 0.5 * h
        self.g = self.a * self.dr * 2.0 * wq * gap if self.dr > 0 else np.zeros(th.size)
        self.gap = gap
        ev, V = np.linalg.eigh(0.5 * (self.S + self.S.T))
        ev = np.maximum(ev, 1e-14 * ev.max())
        self.L = (V * np.sqrt(ev)).T                    # S ≈ Lᵀ L
        self.Linv_T = V / np.sqrt(ev)                   # solves Lᵀ d = b: d = (V/√ev)ᵀ b

    def _pressure(self, c: float) -> np.ndarray:
        b = -(self.g - c * self.B)
        d = self.Linv_T.T @ b
        p, _ = nnls(self.L, d, maxiter=20 * self.L.shape[1])
        return p

    def solve(self, P: float) -> ConformingSolution:
        """Contact under the load ``P`` (N/mm) per unit length."""
        P = float(_checks.positive("P", P))
        f = lambda c: float(self.B @ self._pressure(c)) - P  # noqa: E731
        hi = 1e-6
        while f(hi) < 0:
            hi *= 2.0
            if hi > 1.0:
                raise SpecError(f"no contact solution for P = {P:g} N/mm", key="P")
        lo = 0.0 if self.dr > 0 else -hi
        c = brentq(f, lo, hi, xtol=1e-15, rtol=1e-12)
        p = self._pressure(c)
        on = np.flatnonzero(p > 1e-9 * p.max())
        j = int(on.max())
        # the edge lies between the last loaded node and the next: linear extrapolation of the pressure to 0
        if 0 < j < p.size - 1 and p[j - 1] > p[j]:
            edge = self.theta[j] + p[j] / (p[j - 1] - p[j]) * (self.theta[j] - self.theta[j - 1])
            edge = min(edge, self.theta[j + 1])
        else:
            edge = self.theta[j]
        return ConformingSolution(float(edge), float(c), self.theta, p)


@lru_cache(maxsize=64)
def _models(a, dr, E, nu):
    return PinInHole(a, dr, E, nu, nodes=161, modes=1200), PinInHole(a, dr, E, nu, nodes=161, modes=1200,
                                                                    hertzian=True)


#: the correction is computed at this many loads (log-spaced) and interpolated (PCHIP in ln F)
CORRECTION_POINTS = 14
#: Hertz half-angle below which the contact is in Hertz's range: the correction is zero there, and its
#: linear part — the difference of the two solutions' global (mode n ≥ 2 at low n) compliance, which
#: doc 004's formula represents by its reference depths — is taken at this angle and removed
HERTZ_RANGE = 0.15


@lru_cache(maxsize=64)
def _correction_table(a, dr, E, nu, b, F_max):
    from scipy.interpolate import PchipInterpolator

    ex, hz = _models(a, dr, E, nu)
    Es = E / (2.0 * (1.0 - nu * nu))
    F0 = HERTZ_RANGE ** 2 * a * a * math.pi * b * Es * dr / (4.0 * a * (a + dr)) if dr > 0 else 1.0
    F = np.geomspace(F0, max(F_max, 2.0 * F0), CORRECTION_POINTS)
    dc = np.array([ex.solve(Fi / b).c - hz.solve(Fi / b).c for Fi in F])
    corr = dc - F * dc[0] / F[0]
    return F, PchipInterpolator(np.log(F), corr, extrapolate=True)


def conforming_correction(F, length, r_pin, r_groove, E, nu, *, F_max: float = 3.0e4):
    """The conformity correction (mm) to doc 004's Hertz approach at pin forces ``F`` (N) over ``length``
    (mm): ``Δc(F) − F Δc(F0)/F0`` with ``Δc = c_exact − c_hertzian`` (module doc), zero below ``F0`` (Hertz
    half-angle ``HERTZ_RANGE``), interpolated between ``CORRECTION_POINTS`` solutions up to ``F_max``."""
    F = np.atleast_1d(_checks.nonnegative("F", F)).astype(float)
    b = float(_checks.positive("length", length))
    a, dr = float(r_pin), float(r_groove) - float(r_pin)
    if not dr > 0:
        raise SpecError(f"must exceed the pin radius {a:g} mm, got {r_groove!r}", key="r_groove")
    Fk, interp = _correction_table(a, dr, float(E), float(nu), b, float(F_max))
    out = np.where(F > Fk[0], interp(np.log(np.maximum(F, Fk[0]))), 0.0)
    return out
def conforming_groove_approach(F, length, r_pin, r_groove, E, nu):
    """Approach (mm) of the pin centre to the housing point one groove radius deep (module doc): doc 004's
    Hertz formula (:func:`.contacts.groove_approach`) plus :func:`conforming_correction`."""
    scalar = np.ndim(F) == 0
    F = np.atleast_1d(_checks.nonnegative("F", F)).astype(float)
    out = contacts.groove_approach(F, length, r_pin, r_groove, E, nu) + conforming_correction(
        F, length, r_pin, r_groove, E, nu)
    return float(out[0]) if scalar else out


def contact_half_angle(F, length, r_pin, r_groove, E, nu) -> np.ndarray:
    """Half-angle (rad) of the contact arc of the exact conforming solution."""
    F = np.atleast_1d(_checks.positive("F", F)).astype(float)
    ex, _ = _models(float(r_pin), float(r_groove) - float(r_pin), float(E), float(nu))
    return np.array([ex.solve(Fi / float(length)).angle for Fi in F])
