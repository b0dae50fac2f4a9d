"""The pin in its housing groove: a line contact after doc 004's formula, in series with the disc–pin contact, and
the same contact as a **conforming** one (the pin-in-hole problem of Persson) where the groove is tight.

**Line contact (the same formula as the disc–pin contact of** :mod:`rvtol.elements.hertz` **).**  Two
parallel cylinders of contact length ``b`` (mm) pressed by ``F`` (N) approach by::

    w = 2F/(π b) · Σ_i (1 − ν_i²)/E_i · (1/3 + ln(4 d_i / L))

    L = √(4 F R_e / (π b E*)),   1/R_e = 1/R_1 + 1/R_2,   1/E* = Σ (1 − ν_i²)/E_i

with signed radii (convex > 0, concave < 0).  This is doc 004's formula; the
bracket is the classical plane-strain approach of a cylinder's reference
point to its Hertz contact (Roark's *Formulas for Stress and Strain*, 7th ed.,
Table 14.1, cylinder between two plates: ``ΔD = 4p(1−ν²)/(πE) (1/3 + ln(2D/b_w))``,
``b_w`` the full contact width).  ``d_i`` is the **reference depth** of body
``i``: the distance behind its contact surface of the point whose approach is
measured.  rvtol's disc–pin contact takes ``d_i = |R_i|`` (the pin's centre,
the centre of curvature of the cycloid flank) and ``L`` = the Hertz
**half-width** (``hertz.py``); the groove contact here uses the same
conventions by default, so the two approaches add along the pin's force:

* disc–pin: pin term ``(1/3 + ln(4 r_p / L_1))`` + disc term;
* pin–groove: pin term ``(1/3 + ln(4 r_p / L_2))`` + housing term
  ``(1/3 + ln(4 d_h / L_2))``, ``d_h = r_g`` by default (a point one groove
  radius deep in the housing).

The two pin terms together are the pin's compression between its two line
loads (centre to each contact).  Note: with ``L`` the **full** width ``2a``
(``width="full"``) the bracket is Roark's; the half-width convention of
``hertz.py`` adds ``ln 2`` to every body's bracket (≈ 10 % more approach).
Both are offered; keep one convention along a series chain.

**Pin in a groove.**  Pin radius ``r_p`` (convex), groove radius
``r_g > r_p`` (concave): ``1/R_e = 1/r_p − 1/r_g``, i.e. ``R_e = r_p r_g / (r_g − r_p)``
— a conforming contact.  Hertz theory needs the contact arc to be small: the
half-angle ``a / r_p`` is returned by :func:`groove_half_angle`; beyond
~0.3 rad the contact is conformal (Persson's pin-in-hole solution, Johnson,
*Contact Mechanics*, 1985, §5.6) and this formula over-estimates the approach.
A zero clearance is outside the formula and raises :class:`SpecError`.
The limit ``r_g → ∞`` (with a fixed housing depth) is the cylinder-on-flat
contact.

**Series.**  Disc–pin and pin–groove carry the same pin force, so their
approaches add (:func:`pin_path_approach`); the force for a given total
approach is found numerically (:func:`rvtol.elements.chain.series_force`).

**The pin in its groove as a conforming contact (Persson).**  At the product's fit (radial clearance ``ΔR`` of a few
µm) the Hertz half-width of the pin–groove contact is a large fraction of the pin radius (half-angle ≈ 0.6–0.8 rad at
rated load): Hertz's half-space and parabolic-gap assumptions fail.  The plane-strain problem of a pin of radius ``a``
in a hole of radius ``a + ΔR`` in a large plate, both of the same material, frictionless, was solved by Persson (A.
Persson, *On the stress distribution of cylindrical elastic bodies in contact*, Diss., Chalmers, Göteborg 1964; see K.
L. Johnson, *Contact Mechanics*, CUP 1985, §5.6 "conforming surfaces"; M. Ciavarella & P. Decuzzi, *Int. J. Solids
Struct.* 38 (2001) 4507).  Two of its published results are this module's tests: the Hertz limit at small loads and,
for a neat fit (``ΔR = 0``), a contact arc of ±90° at any load.

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

**Approach for the chain.**  doc 004's Hertz formula (:func:`groove_approach`) measures the
approach from the pin centre to a housing point one groove radius deep; its mode-1 part depends only on
``P``.  The conforming approach is that formula plus the difference ``Δc`` of ``c`` between the exact solution
and the same solution under Hertz's assumptions (half-space kernel ``a(κ+1)/(4Gn)`` per body for n ≥ 2,
parabolic gap ``ΔR θ²/2``) less its linear part ``F Δc(F0)/F0`` at a load ``F0`` inside Hertz's range
(half-angle 0.15 rad): that linear part is the two bodies' global compliance, which doc 004's formula
already represents by its reference depths; what remains is the conformity.  The correction is zero in
Hertz's range and lowers the approach of a tight groove (:func:`conforming_groove_approach`).

Units: N, mm, MPa (``P`` of :class:`PinInHole` in N per mm of contact length).  The line-contact functions
broadcast over the force.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.optimize import brentq, nnls

from ..errors import SpecError
from . import _checks, chain

WIDTHS = ("half", "full")


def reduced_modulus(E1, nu1, E2=None, nu2=None):
    """``E*`` (MPa) with ``1/E* = (1−ν1²)/E1 + (1−ν2²)/E2`` (second body defaults to the first)."""
    E1 = _checks.positive("E1", E1)
    nu1 = _checks.poisson("nu1", nu1)
    E2 = E1 if E2 is None else _checks.positive("E2", E2)
    nu2 = nu1 if nu2 is None else _checks.poisson("nu2", nu2)
    return 1.0 / ((1.0 - nu1 ** 2) / E1 + (1.0 - nu2 ** 2) / E2)


def effective_radius(R1, R2):
    """``R_e`` (mm) from signed radii (``inf`` = flat); must be positive (the bodies touch on a line)."""
    R1 = _checks.array("R1", R1)
    R2 = _checks.array("R2", R2)
    if np.any(R1 == 0) or np.any(R2 == 0):
        raise SpecError("radii must be non-zero (use inf for a flat)", key="R1" if np.any(R1 == 0) else "R2")
    curv = 1.0 / R1 + 1.0 / R2
    if np.any(curv <= 0):
        raise SpecError("1/R1 + 1/R2 must be > 0: a concave body must be larger than the convex one it holds "
                        "(zero clearance is a conforming contact outside Hertz theory)", key="R2")
    return 1.0 / curv


def half_width(F, b, R1, R2, E1, nu1, E2=None, nu2=None):
    """Hertz half-width ``a = √(4 F R_e / (π b E*))`` (mm) of a line contact."""
    F = _checks.nonnegative("F", F)
    b = _checks.positive("b", b)
    return np.sqrt(4.0 * F * effective_radius(R1, R2) / (np.pi * b * reduced_modulus(E1, nu1, E2, nu2)))


def line_contact_approach(F, b, R1, R2, E1, nu1, E2=None, nu2=None, *, depth1=None, depth2=None,
                          width: str = "half"):
    """Approach ``w`` (mm) of two line-contacting bodies under ``F`` (N), see the module doc.

    ``R1``, ``R2`` signed radii (mm, ``inf`` flat); ``depth1``, ``depth2`` reference depths (mm,
    default ``|R_i|``; required for a flat body); ``width`` = ``"half"`` (``L = a``, as
    ``hertz.py``) or ``"full"`` (``L = 2a``, Roark).  ``w(0) = 0``.
    """
    if width not in WIDTHS:
        raise SpecError(f"must be 'half' (hertz.py) or 'full' (Roark), got {width!r}", key="width")
    E2v = E1 if E2 is None else E2
    nu2v = nu1 if nu2 is None else nu2
    F = _checks.nonnegative("F", F)
    d1 = _depth("depth1", depth1, R1)
    d2 = _depth("depth2", depth2, R2)
    Fpos = np.where(F > 0, F, 1.0)
    L = half_width(Fpos, b, R1, R2, E1, nu1, E2v, nu2v) * (2.0 if width == "full" else 1.0)
    c1 = (1.0 - np.asarray(nu1) ** 2) / np.asarray(E1) * (1.0 / 3.0 + np.log(4.0 * d1 / L))
    c2 = (1.0 - np.asarray(nu2v) ** 2) / np.asarray(E2v) * (1.0 / 3.0 + np.log(4.0 * d2 / L))
    return np.where(F > 0, 2.0 * Fpos / (np.pi * np.asarray(b, float)) * (c1 + c2), 0.0)


def _depth(name, depth, R):
    if depth is None:
        R = _checks.array(name.replace("depth", "R"), R)
        if np.any(~np.isfinite(R)):
            raise SpecError("a flat body (infinite radius) needs an explicit reference depth", key=name)
        return np.abs(R)
    return _checks.positive(name, depth)


def groove_approach(F, b, r_pin, r_groove, E_pin, nu_pin, E_housing=None, nu_housing=None, *,
                    housing_depth=None, width: str = "half"):
    """Approach (mm) of a pin (radius ``r_pin``) pressed by ``F`` (N) into a housing groove of radius
    ``r_groove > r_pin`` over the length ``b`` (mm): pin centre to the housing point at
    ``housing_depth`` (default ``r_groove``) behind the contact.
    """
    rp = _checks.positive("r_pin", r_pin)
    rg = _checks.positive("r_groove", r_groove, allow_inf=True)
    if np.any(rg <= rp):
        raise SpecError(f"must be larger than the pin radius ({rp} mm): zero clearance is a conforming contact "
                        "outside Hertz theory", key="r_groove")
    if np.any(np.isinf(rg)) and housing_depth is None:
        raise SpecError("a flat seat (r_groove = inf) needs housing_depth", key="housing_depth")
    return line_contact_approach(F, b, rp, -rg, E_pin, nu_pin, E_housing, nu_housing, depth1=rp,
                                 depth2=rg if housing_depth is None else housing_depth, width=width)


def groove_half_angle(F, b, r_pin, r_groove, E_pin, nu_pin, E_housing=None, nu_housing=None):
    """Half-angle ``a / r_pin`` (rad) of the pin's contact arc in the groove: Hertz needs it ≪ 1."""
    rp = _checks.positive("r_pin", r_pin)
    return half_width(F, b, rp, -_checks.positive("r_groove", r_groove, allow_inf=True), E_pin, nu_pin,
                      E_housing, nu_housing) / rp


def pin_path_approach(F, *, b_disc, r_pin, rho_disc, b_groove, r_groove, E, nu, E_housing=None,
                      nu_housing=None, housing_depth=None, width: str = "half"):
    """Approach (mm) of the disc's reference point to the housing's along the pin force ``F`` (N):
    disc–pin contact (flank curvature radius ``rho_disc``, signed, length ``b_disc``) in series with
    the pin–groove contact (length ``b_groove``).  Both with the same width convention.
    """
    w1 = line_contact_approach(F, b_disc, r_pin, rho_disc, E, nu, width=width)
    w2 = groove_approach(F, b_groove, r_pin, r_groove, E, nu, E_housing, nu_housing,
                         housing_depth=housing_depth, width=width)
    return w1 + w2


def pin_path_force(approach, **kw):
    """Inverse of :func:`pin_path_approach`: the pin force (N) at a given total approach (mm)."""
    return chain.series_force(approach, [lambda F: pin_path_approach(F, **kw)], force_scale=100.0)


# --------------------------------------------------------------------------- the conforming contact
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
    Hertz formula (:func:`groove_approach`) plus :func:`conforming_correction`."""
    scalar = np.ndim(F) == 0
    F = np.atleast_1d(_checks.nonnegative("F", F)).astype(float)
    out = groove_approach(F, length, r_pin, r_groove, E, nu) + conforming_correction(
        F, length, r_pin, r_groove, E, nu)
    return float(out[0]) if scalar else out


def contact_half_angle(F, length, r_pin, r_groove, E, nu) -> np.ndarray:
    """Half-angle (rad) of the contact arc of the exact conforming solution."""
    F = np.atleast_1d(_checks.positive("F", F)).astype(float)
    ex, _ = _models(float(r_pin), float(r_groove) - float(r_pin), float(E), float(nu))
    return np.array([ex.solve(Fi / float(length)).angle for Fi in F])
