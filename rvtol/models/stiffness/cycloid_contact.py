"""Cycloid–pin contact with profile modifications and errors (doc 004).

Geometry (Li Lixing's notation, as in doc 004).  Pin ``k`` sits at angle
``φ_k`` from the line of centres ``O→O_c`` (pin circle centre to cycloid
centre); ``K1 = a z_p / R_p``; ``S = 1 + K1² - 2 K1 cos φ``.  The common
normal of pin ``k`` passes through the pitch point, at the arm

    l_k = r_c' sin φ_k / √S_k,       r_c' = a z_c  (cycloid pitch radius)

from the cycloid centre; ``l_k`` is largest (``= r_c'``) at ``φ0 = arccos K1``.

**Initial clearance** (doc 004, as written)::

    Δ(φ) = Δ1(φ) - Δ2(φ)
    Δ1 = -ΔR_p (1 - K1' cos φ - √(1-K1'²) sin φ) S^-½ + Δr_p (1 - S^-½ sin φ)
    Δ2 =  δR_p (1 - K1' cos φ - √(1-K1'²) sin φ) S^-½ + δr_p (1 - S^-½ sin φ)
    K1' = a z_p / (R_p + ΔR_p)

It is the normal clearance ``n(φ) = Δr - ΔR (1 - K1 cos φ)/√S`` left after
the rigid rotation ``β0 = n(φ0)/r_c'`` that closes the gap at ``φ0``
(``Δ = n - l β0``, an identity rvtol's tests check).  So the document's
``Δ`` is measured from first contact; the *normal clearance*
``n0 = Δr - √(1-K1'²) ΔR`` and the angular backlash ``2 n0 / r_c'``
(cycloid rotation from flank to flank, rad) follow from the same terms.  With
errors, ``Δr`` stands for ``Δr_p - δr_p`` and ``ΔR`` for ``ΔR_p + δR_p``
(the document's sign: a positive ``δR_p`` *closes* the clearance).

**Loaded contact** (doc 004's iteration).  The cycloid turns by ``β``; the
approach at pin ``k`` is ``Δδ_k = l_k β`` with ``β = Δδ_max / r_c'`` and
``Δδ_max = w(F_max)``, the Hertz approach (:mod:`.hertz`) of the pin and the
cycloid at ``φ0`` under ``F_max`` (plus, where the design gives the pin grooves, the
pin's approach in its groove: :mod:`rvtol.elements.pin_groove`, in series).  Pins with ``Δδ_k > Δ(φ_k)`` carry::

    F_k = F_max (Δδ_k - Δ(φ_k)) / Δδ_max

and ``F_max`` solves the equilibrium ``Σ F_k l_k = T_c``.  The left side is
continuous and strictly increasing in ``F_max`` (its derivative per loaded
pin is ``l_k/r_c' - Δ_k/(w X) > 0`` with ``X > 1`` the logarithmic factor of
``w``), so rvtol brackets it and bisects in ``log F`` to machine precision
(the equilibrium then holds to ~1e-15 relative).  rvtol first removes the
rigid rotation ``min_k Δ_k / l_k`` (nanometres over the arm when no pin sits
exactly at ``φ0``) so the first pin to touch has zero gap; that rotation is
backlash, not elasticity.  Where the formula itself gives a negative
clearance at some pin (radial clearance ``Δr - ΔR < 0``), the profiles
interfere and the solution flags ``interference`` (the models report those
samples as failed).  A negative normal clearance ``n0`` with ``Δ ≥ 0``
everywhere is a preloaded mesh; doc 004's formula measures from first contact
and cannot see it, so rvtol solves it like the document and reports the
negative backlash.

**Single-pair stiffness** (doc 004)::

    k_b = π b E R_p' S^{3/2} / (4 (1-μ²) (R_p' S^{3/2} + 2 T' r_p')),   K_B = Σ k_b l_k²

over the loaded pins, ``R_p' = R_p + δR_p``, ``r_p' = r_p + δr_p``.  The
document calls ``T'`` "a geometric term"; rvtol takes the denominator of the
cycloid's curvature radius ``ρ0 = R_p' S^{3/2} / T'`` (Li Lixing),
``T' = K1 (1 + z_p) cos φ - (1 + z_p K1²)``, **in absolute value**: with its
sign the formula is singular where ``ρ0 = -2 r_p'`` (φ ≈ 46° for the RV-80E,
inside the loaded zone) and negative beyond, which cannot be meant.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ...errors import SpecError
from ...elements import hertz

#: a clearance below -1 nm somewhere is an interference (preloaded mesh), outside doc 004's model
INTERFERENCE_TOL = 1e-6

#: bisection steps in log F (the bracket spans < e^10; 2^-64 of that is below machine precision)
BISECTION_STEPS = 64


@dataclass(frozen=True)
class PinGear:
    """Nominal cycloid–pin geometry and material (base units: mm, MPa)."""

    z_p: int          # pins
    z_c: int          # cycloid teeth
    R_p: float        # pin circle radius
    r_p: float        # pin radius
    a: float          # eccentricity
    b: float          # cycloid width (contact length)
    E: float          # Young's modulus (pins and cycloid)
    nu: float         # Poisson's ratio
    groove: object = None        # pin-in-groove contact in series (rvtol.elements.reducer_chain.GrooveContact)
    approach_scale: float = 1.0  # compliance scale of the disc–pin approach (compliance_scale.cycloid_pin)
    groove_scale: float = 1.0    # and of the groove's (compliance_scale.pin_groove)

    def groove_approach(self, F):
        """The groove contact's approach (mm) at pin force ``F`` (0 without a groove)."""
        if self.groove is None:
            return np.zeros(np.shape(F))
        return self.groove_scale * self.groove.approach(np.asarray(F, dtype=float))

    @property
    def K1(self) -> float:
        return self.a * self.z_p / self.R_p

    @property
    def r_c(self) -> float:
        """Cycloid pitch radius ``r_c' = a z_c`` (the largest arm)."""
        return self.a * self.z_c

    @property
    def phi0(self) -> float:
        """Pin angle of the largest arm, ``arccos K1``."""
        return float(np.arccos(self.K1))

    @classmethod
    def from_design(cls, design, **override) -> "PinGear":
        """The design's pin gear; bad numbers raise :class:`SpecError` naming the design file and key."""
        d = design
        z_p, z_c = design_number(d, "pin.count", integer=True), design_number(d, "cycloid.teeth", integer=True)
        if z_p != z_c + 1:
            raise SpecError(f"the cycloid needs z_p = z_c + 1 pins, got {z_p} and {z_c}", file=d.file,
                            key="pin.count")
        vals = dict(z_p=z_p, z_c=z_c, R_p=design_number(d, "pin.circle_radius"), r_p=design_number(d, "pin.radius"),
                    a=design_number(d, "cycloid.eccentricity"),
                    b=design_number(d, first_key(d, "cycloid.width", "cycloid.face_width")),
                    E=design_number(d, "material.youngs_modulus"),
                    nu=design_number(d, "material.poisson_ratio", upper=0.5))
        if not vals["a"] * z_p < vals["R_p"]:
            raise SpecError("K1 = a z_p / R_p must be < 1 (no cycloid profile otherwise)", file=d.file,
                            key="cycloid.eccentricity")
        vals.update(override)
        return cls(**vals)


def first_key(design, *names: str) -> str:
    """The first of ``names`` the design has (doc 004's key first, then the 20-DOF model's spelling of the
    same quantity); a missing quantity is reported under the first name."""
    for n in names:
        if n in design:
            return n
    return names[0]


def design_number(design, name: str, *, integer: bool = False, upper: float | None = None,
                  nonnegative: bool = False):
    """``design[name]`` (base units), checked: > 0 (>= 0 with ``nonnegative``), below ``upper``, whole if
    ``integer``; otherwise a :class:`SpecError` naming the design file and the key."""
    v = float(design[name])
    p = design.param(name)
    ok = np.isfinite(v) and (v >= 0 if nonnegative else v > 0) and (upper is None or v < upper)
    if integer:
        ok = ok and abs(v - round(v)) < 1e-9
    if not ok:
        want = ("a whole number " if integer else "") + (">= 0" if nonnegative else "> 0") + (
            f" and < {upper:g}" if upper is not None else "")
        unit = "" if p.unit == "1" else f" {p.unit}"
        raise SpecError(f"must be {want}, got {p.value:g}{unit}", file=design.file, key=name)
    return int(round(v)) if integer else v


def pin_angles(z_p: int, phase: float = 0.0) -> np.ndarray:
    """Pin angles ``φ_k = 2π (k + phase) / z_p``, k = 0..z_p-1 (``phase`` in pin pitches)."""
    return 2.0 * np.pi * (np.arange(z_p) + phase) / z_p


def S_of(phi, K1):
    return 1.0 + K1 ** 2 - 2.0 * K1 * np.cos(phi)


def arm(g: PinGear, phi) -> np.ndarray:
    """Moment arm ``l_k = r_c' sin φ / √S`` (mm); negative on the unloaded side."""
    return g.r_c * np.sin(phi) / np.sqrt(S_of(phi, g.K1))


def equidistance_term(phi, K1):
    """Coefficient of ``Δr_p`` in ``Δ1``: ``1 - sin φ / √S``."""
    return 1.0 - np.sin(phi) / np.sqrt(S_of(phi, K1))


def moved_distance_term(phi, K1):
    """Coefficient of ``-ΔR_p`` in ``Δ1``: ``(1 - K1 cos φ - √(1-K1²) sin φ) / √S``."""
    return (1.0 - K1 * np.cos(phi) - np.sqrt(1.0 - K1 ** 2) * np.sin(phi)) / np.sqrt(S_of(phi, K1))


def _col(x):
    return np.asarray(x, dtype=float).reshape(-1, 1)


def initial_clearance(g: PinGear, phi, dr_p, dR_p, eR_p=0.0, er_p=0.0) -> np.ndarray:
    """``Δ(φ_k)`` (mm), shape ``(n, len(phi))``: doc 004's formula as written (see module doc)."""
    dr_p, dR_p, eR_p, er_p = np.broadcast_arrays(*(np.atleast_1d(np.asarray(v, float)) for v in (dr_p, dR_p, eR_p, er_p)))
    K1p = _col(g.a * g.z_p / (g.R_p + dR_p))
    phi = np.asarray(phi, dtype=float)[None, :]
    ed, md = equidistance_term(phi, K1p), moved_distance_term(phi, K1p)
    delta1 = -_col(dR_p) * md + _col(dr_p) * ed
    delta2 = _col(eR_p) * md + _col(er_p) * ed
    return delta1 - delta2


def normal_clearance(g: PinGear, dr_p, dR_p, eR_p=0.0, er_p=0.0) -> np.ndarray:
    """Normal clearance at ``φ0`` before the closing rotation: ``n0 = Δr - √(1-K1'²) ΔR`` (mm)."""
    dr_p, dR_p, eR_p, er_p = (np.asarray(v, float) for v in (dr_p, dR_p, eR_p, er_p))
    K1p = g.a * g.z_p / (g.R_p + dR_p)
    return (dr_p - er_p) - np.sqrt(1.0 - K1p ** 2) * (dR_p + eR_p)


def angular_backlash(g: PinGear, dr_p, dR_p, eR_p=0.0, er_p=0.0) -> np.ndarray:
    """Cycloid rotation from flank to flank, ``2 n0 / r_c'`` (rad)."""
    return 2.0 * normal_clearance(g, dr_p, dR_p, eR_p, er_p) / g.r_c


def T_prime(phi, K1, z_p):
    """``|K1 (1 + z_p) cos φ - (1 + z_p K1²)|`` — rvtol's reading of doc 004's ``T'`` (module doc)."""
    return np.abs(K1 * (1.0 + z_p) * np.cos(phi) - (1.0 + z_p * K1 ** 2))


def cycloid_radius(g: PinGear, phi, R_p=None, r_p=None):
    """Signed curvature radius of the cycloid's actual profile, convex > 0 (mm).

    Li Lixing: ``ρ = R_p S^{3/2} / (K1 (1+z_p) cos φ - (1+z_p K1²)) + r_p`` with
    ``ρ > 0`` concave; rvtol returns ``-ρ`` so that convex is positive as in :mod:`.hertz`.
    """
    R_p = g.R_p if R_p is None else R_p
    r_p = g.r_p if r_p is None else r_p
    K1 = g.a * g.z_p / R_p
    S = S_of(phi, K1)
    rho0 = R_p * S ** 1.5 / (K1 * (1.0 + g.z_p) * np.cos(phi) - (1.0 + g.z_p * K1 ** 2))
    return -(rho0 + r_p)


def pair_stiffness(g: PinGear, phi, eR_p=0.0, er_p=0.0) -> np.ndarray:
    """Single-pair meshing stiffness ``k_b`` (N/mm), doc 004's formula with ``|T'|``."""
    Rp = _col(g.R_p + np.atleast_1d(np.asarray(eR_p, float)))
    rp = _col(g.r_p + np.atleast_1d(np.asarray(er_p, float)))
    phi = np.asarray(phi, dtype=float)[None, :]
    K1 = g.a * g.z_p / Rp
    s32 = S_of(phi, K1) ** 1.5
    return np.pi * g.b * g.E * Rp * s32 / (4.0 * (1.0 - g.nu ** 2) * (Rp * s32 + 2.0 * T_prime(phi, K1, g.z_p) * rp))


def reference_approach(g: PinGear, F, eR_p=0.0, er_p=0.0):
    """``Δδ_max = w(F_max)``: Hertz approach of pin and cycloid at ``φ0`` (mm)."""
    Rp = g.R_p + np.asarray(eR_p, float)
    rp = g.r_p + np.asarray(er_p, float)
    rcyc = cycloid_radius(g, g.phi0, Rp, rp)
    w = hertz.approach(F, g.b, rp, rcyc, g.E, g.nu)
    if g.approach_scale != 1.0:
        w = g.approach_scale * w
    if g.groove is not None:                      # the pin's groove contact carries the same force: in series
        w = w + g.groove_approach(F)
    return w


@dataclass
class ContactSolution:
    """Loaded contact of one cycloid disc; arrays over samples ``n`` and pins ``z``."""

    geometry: PinGear
    phi: np.ndarray        # (z,) pin angles, rad
    arm: np.ndarray        # (z,) l_k, mm
    gap: np.ndarray        # (n, z) initial clearance measured from first contact, mm (≥ 0 on loaded pins)
    force: np.ndarray      # (n, z) F_k, N
    F_ref: np.ndarray      # (n,) F_max at the largest arm, N
    approach_ref: np.ndarray  # (n,) Δδ_max, mm
    beta: np.ndarray       # (n,) elastic cycloid rotation Δδ_max / r_c', rad
    beta_rigid: np.ndarray  # (n,) rigid rotation removed so the first pin touches, rad
    torque: np.ndarray     # (n,) disc torque T_c, N·mm
    k_pair: np.ndarray     # (n, z) k_b, N/mm
    interference: np.ndarray  # (n,) True where some pin has a negative clearance (preloaded mesh)

    @property
    def loaded(self) -> np.ndarray:
        return self.force > 0

    @property
    def contacts(self) -> np.ndarray:
        return self.loaded.sum(axis=1)

    @property
    def max_force(self) -> np.ndarray:
        return self.force.max(axis=1)

    @property
    def K_B(self) -> np.ndarray:
        """``Σ k_b l_k²`` over the loaded pins (N·mm/rad)."""
        return np.where(self.loaded, self.k_pair * self.arm ** 2, 0.0).sum(axis=1)

    def resultant(self) -> np.ndarray:
        """Net pin force on the cycloid, ``(n, 2)`` in the (radial ``O→O_c``, tangential) frame (N).

        The normal of pin ``k`` points from the pin to the pitch point:
        ``((K1 - cos φ) e_r - sin φ e_t) / √S``.
        """
        K1 = self.geometry.K1
        s = np.sqrt(S_of(self.phi, K1))
        nr, nt = (K1 - np.cos(self.phi)) / s, -np.sin(self.phi) / s
        return np.stack([self.force @ nr, self.force @ nt], axis=1)

    def equilibrium_residual(self) -> np.ndarray:
        """``(Σ F_k l_k - T_c) / T_c`` per sample."""
        return (self.force @ self.arm - self.torque) / np.where(self.torque > 0, self.torque, 1.0)

    def to_frame(self, row: int = 0) -> pd.DataFrame:
        return pd.DataFrame({
            "pin": np.arange(len(self.phi)),
            "phi (deg)": np.degrees(self.phi),
            "arm l_k (mm)": self.arm,
            "clearance (um)": self.gap[row] * 1e3,
            "force F_k (N)": self.force[row],
            "k_b (N/um)": np.where(self.loaded[row], self.k_pair[row] * 1e-3, np.nan),
        })

    def plot(self, row: int = 0, ax=None):
        from ...plotting.stiffness import plot_pin_forces

        return plot_pin_forces(self, row, ax=ax)


def solve_contact(g: PinGear, torque, dr_p, dR_p, eR_p=0.0, er_p=0.0, phase: float = 0.0) -> ContactSolution:
    """Solve doc 004's loaded contact for disc torque ``torque`` (N·mm, ≥ 0), vectorised over samples."""
    torque, dr_p, dR_p, eR_p, er_p = np.broadcast_arrays(
        *(np.atleast_1d(np.asarray(v, float)) for v in (torque, dr_p, dR_p, eR_p, er_p)))
    phi = pin_angles(g.z_p, phase)
    l = arm(g, phi)
    side = l > 1e-9 * g.r_c                      # pins that can carry this torque direction
    lpos = np.where(side, l, 1.0)
    gap = initial_clearance(g, phi, dr_p, dR_p, eR_p, er_p)
    beta_rigid = np.min(np.where(side, gap / lpos, np.inf), axis=1)
    interference = beta_rigid < -INTERFERENCE_TOL / g.r_c
    gap = np.where(side, np.maximum(gap - beta_rigid[:, None] * l, 0.0), 0.0)  # max: round-off at first contact

    def w(F):
        return reference_approach(g, F, eR_p, er_p)

    def moment(F):
        ratio = np.where(F > 0, F / np.where(F > 0, w(F), 1.0), 0.0)
        Fk = np.maximum(0.0, F[:, None] * (l / g.r_c)[None, :] - gap * ratio[:, None])
        return np.where(side, Fk, 0.0), ratio

    # bracket: all pins touching at zero gap (lower), only the first-contact pin touching (upper)
    l2 = np.where(side, l ** 2, 0.0)
    first = np.where(side[None, :], gap, np.inf).argmin(axis=1)
    lo = torque * g.r_c / l2.sum()
    hi = torque * g.r_c / l2[first]
    active = torque > 0
    x_lo = np.log(np.where(active, lo, 1.0))
    x_hi = np.log(np.where(active, hi, 1.0)) + 1e-12
    for _ in range(BISECTION_STEPS):
        x = 0.5 * (x_lo + x_hi)
        Fk, _ = moment(np.exp(x))
        up = Fk @ l >= torque
        x_hi = np.where(up, x, x_hi)
        x_lo = np.where(up, x_lo, x)
    F_ref = np.where(active, np.exp(0.5 * (x_lo + x_hi)), 0.0)
    Fk, _ = moment(F_ref)
    w_ref = w(F_ref)
    return ContactSolution(g, phi, l, np.where(side, gap, np.nan), Fk, F_ref, w_ref, w_ref / g.r_c,
                           beta_rigid, torque, pair_stiffness(g, phi, eR_p, er_p),
                           interference)
