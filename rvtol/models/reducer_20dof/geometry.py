"""Derived geometry of the RV reducer for the 20-DOF transmission-error model.

The document (doc 000, section 1) writes its force formulas with symbols it
never defines (α', R_bp, R_dc, R_e, R_d, α_jk, φ_i, ψ_j, φ_ijk, φ_djk).  They are
filled here from gear and cycloid geometry:

* **α'** (operating pressure angle of the sun–planet pair) from the profile
  shifts: inv α' = inv α + 2 tan α (x_s + x_p)/(z_s + z_p)  (standard, ISO 21771);
  operating centre distance a' = m (z_s + z_p)/2 · cos α / cos α'.
* **R_bs, R_bp**: base radii m z cos α / 2.
* **R_dc = a'**: in the cycloid–crank and crank–carrier bearing formulas R_dc
  multiplies a rotation of the disc/carrier and moves a crank hole
  tangentially, so it is the radius of the circle the crank centres lie on —
  the operating centre distance of the planetary stage.  (This is also what
  makes the nominal motion kinematically consistent; see ``tests``.)
* **R_e = e**: it multiplies the crank rotation and the orbital angle of the
  disc centre, i.e. it is the cam eccentricity.
* **R_d = z_c·e**: the disc's pitch radius, |O_d P|, where P = z_b·e·u_e is the
  pitch point (instant centre of the disc relative to the pin ring).  Every
  contact normal passes through P (Willis), so the moment arm of pin force k
  about the disc centre is R_d sin α_jk.
* **α_jk**: the angle from the eccentric direction u_e (= direction θ_p + ψ_j)
  to the contact normal n (from P to the centre of pin k):
  cos α = (cos φ − K1)/S, sin α = sin φ/S, S = √(1 − 2 K1 cos φ + K1²),
  K1 = z_b e / R_p (short-width coefficient), φ = φ_ijk = θ_k − θ_p − ψ_j the pin
  angle measured from u_e.
* **φ_djk**: the direction, from the disc centre and measured from u_e, of the
  contact point C = pin centre − r_rp·n (disc tooth-error fields are evaluated
  at the disc-fixed angle of C).
* **φ_i** = 2π(i−1)/3 (cranks evenly spaced), **ψ_j** = π(j−1) (discs 180°
  apart), pins at θ_k = 2π(k−1)/z_b.

Nominal motion (θ_c carrier angle, all counter-clockwise): sun θ_s = i θ_c with
i = 1 + z_b z_p/z_s; crank (absolute) θ_p = (1 − z_b) θ_c; disc spin = θ_c.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ...design import Design
from ...elements.reducer_chain import ChainElements, compliance_scale
from ...errors import SpecError
from . import layout as L
from .compliance import ContactChain, reduce_chain
from .friction import Friction, friction_from_design


#: how far a written crank circle (crank_bearing.centre_radius) may lie from a' (mm): written to the µm
CIRCLE_TOLERANCE = 1e-3


def involute(a: float) -> float:
    return math.tan(a) - a


def inverse_involute(v: float) -> float:
    """Solve tan a − a = v (Newton from the Cheng approximation)."""
    a = (3.0 * v) ** (1.0 / 3.0) if v > 0 else 0.0
    for _ in range(60):
        f = involute(a) - v
        a_new = a - f / math.tan(a) ** 2
        if abs(a_new - a) < 1e-15:
            return a_new
        a = a_new
    return a


@dataclass(frozen=True)
class RVGeometry:
    """Numbers the kernels need, in base units (mm, rad, N, t)."""

    z_s: int
    z_p: int
    z_c: int
    z_b: int
    module: float
    alpha: float
    x_s: float
    x_p: float
    ecc: float
    r_pin_circle: float
    r_pin: float
    k_s: float
    k_sp: float
    k0_dc: float
    k0_oc: float
    k0_pin: float
    k0_ca: float
    hertz: float
    rated_torque: float
    # derived
    alpha_w: float
    a_w: float
    r_bs: float
    r_bp: float
    ratio: float
    # inertia (None where the design gives none: quasi-static only)
    m_sun: float | None = None
    m_planet: float | None = None
    i_planet: float | None = None
    m_disc: float | None = None
    i_disc: float | None = None
    m_carrier: float | None = None
    i_carrier: float | None = None
    zeta: float | None = None
    # compliance chain reduced to the contacts (None: doc 000's rigid chain), see .compliance
    chain: "ContactChain | None" = None
    # Coulomb friction at the sliding contacts (None: none given), see .friction; the torsion curve uses it
    friction: "Friction | None" = None

    @property
    def K1(self) -> float:
        return self.z_b * self.ecc / self.r_pin_circle

    @property
    def r_disc_pitch(self) -> float:
        return self.z_c * self.ecc

    @property
    def force_exponent(self) -> float:
        return 1.0 / (1.0 - self.hertz)

    @property
    def has_inertia(self) -> bool:
        return None not in (self.m_sun, self.m_planet, self.i_planet, self.m_disc, self.i_disc,
                            self.m_carrier, self.i_carrier, self.zeta)

    # -- arrays for the kernels ----------------------------------------------------------------
    def prm(self, omega_c: float = 0.0) -> np.ndarray:
        p = np.zeros(L.NPRM)
        p[L.P_ZS], p[L.P_ZP], p[L.P_ZC], p[L.P_ZB] = self.z_s, self.z_p, self.z_c, self.z_b
        p[L.P_ECC], p[L.P_RP], p[L.P_RRP] = self.ecc, self.r_pin_circle, self.r_pin
        p[L.P_RDC], p[L.P_ALPHAW], p[L.P_RBS], p[L.P_RBP] = self.a_w, self.alpha_w, self.r_bs, self.r_bp
        p[L.P_RATIO] = self.ratio
        p[L.P_KS], p[L.P_KSP] = self.k_s, self.k_sp
        p[L.P_K0DC], p[L.P_K0OC], p[L.P_K0PIN], p[L.P_K0CA] = self.k0_dc, self.k0_oc, self.k0_pin, self.k0_ca
        p[L.P_PW] = self.force_exponent
        p[L.P_OMEGA_C] = omega_c
        p[L.P_COSA] = math.cos(self.alpha)
        return p

    def arc_radii(self) -> np.ndarray:
        """Per DOF, the radius turning a rotation into an arc length (1 for translations).

        Used to scale residuals (N·mm → N) and steps (rad → mm) in the Newton solver.
        """
        r = np.ones(L.NDOF)
        for i in range(L.N_CRANK):
            r[L.planet(i) + 2] = self.r_bp
        for j in range(L.N_DISC):
            r[L.disc(j) + 1] = self.ecc
            r[L.disc(j) + 2] = self.r_disc_pitch
        r[L.THCA] = self.a_w
        return r

    def mass_matrix(self) -> np.ndarray:
        if not self.has_inertia:
            raise SpecError("the Newmark solver needs mass.* and damping.modal_ratio in the design "
                            "(see data/designs/rv80e_te.toml)", key="mass")
        m = np.zeros(L.NDOF)
        m[L.XS] = m[L.YS] = self.m_sun
        for i in range(L.N_CRANK):
            b = L.planet(i)
            m[b] = m[b + 1] = self.m_planet
            m[b + 2] = self.i_planet
        for j in range(L.N_DISC):
            b = L.disc(j)
            m[b] = self.m_disc
            m[b + 1] = self.m_disc * self.ecc ** 2   # tangential displacement of the centre = e·θ_do
            m[b + 2] = self.i_disc
        m[L.XCA] = m[L.YCA] = self.m_carrier
        m[L.THCA] = self.i_carrier
        return np.diag(m)

    # -- report --------------------------------------------------------------------------------
    def to_frame(self) -> pd.DataFrame:
        deg = math.degrees
        rows = [
            ("α'", "operating pressure angle, sun–planet", deg(self.alpha_w), "deg",
             "inv α' = inv α + 2 tan α (x_s + x_p)/(z_s + z_p)"),
            ("a' = R_dc", "operating centre distance = crank circle radius", self.a_w, "mm",
             "m (z_s + z_p)/2 · cos α / cos α'"),
            ("R_bs", "sun base radius", self.r_bs, "mm", "m z_s cos α / 2"),
            ("R_bp", "planet base radius", self.r_bp, "mm", "m z_p cos α / 2"),
            ("R_e", "cam eccentricity", self.ecc, "mm", "= e (Table 1)"),
            ("R_d", "disc pitch radius (moment-arm base)", self.r_disc_pitch, "mm", "z_c · e"),
            ("K1", "short-width coefficient", self.K1, "1", "z_b e / R_p"),
            ("i", "reduction ratio", self.ratio, "1", "1 + z_b z_p / z_s"),
            ("φ_i", "crank phase angles", "0, 120, 240", "deg", "three cranks evenly spaced"),
            ("ψ_j", "disc phase angles", "0, 180", "deg", "two discs opposed"),
            ("p", "Hertz force exponent", self.force_exponent, "1",
             "k = k0·P^h (Table 2) with P = k·δ ⇒ P = (k0·δ)^(1/(1−h))"),
        ]
        return pd.DataFrame(rows, columns=["symbol", "meaning", "value", "unit", "how"])


def _written(design: Design, name: str) -> str:
    """A design number as the file writes it (value and unit), for error messages."""
    p = design.param(name)
    unit = "" if p.unit == "1" else f" {p.unit}"
    return (f"{p.value:g}" if isinstance(p.value, float) else f"{p.value}") + unit


def _int(design: Design, name: str) -> int:
    v = design[name]
    if abs(v - round(v)) > 1e-9 or v < 1:
        raise SpecError(f"expected a positive whole number, got {v}", file=design.where(name), key=name)
    return int(round(v))


def geometry_from_design(design: Design, chain: bool = True) -> RVGeometry:
    """Read Tables 1–2 (and the estimated inertias) from ``design`` and derive the rest.

    ``chain``: add the compliance elements the design provides (:mod:`.compliance`); False gives doc
    000's rigid chain (its contact laws only) for the same design.  A family's
    ``compliance_scale.<family>`` multiplies its compliance either way (doc 000's laws: ``k0 / scale``).
    """
    def pos(name):
        v = float(design[name])
        if not v > 0:
            raise SpecError(f"must be > 0, got {_written(design, name)}", file=design.where(name), key=name)
        return v

    z_s, z_p, z_c, z_b = (_int(design, n) for n in ("sun.teeth", "planet.teeth", "cycloid.teeth", "pin.count"))
    if z_b != z_c + 1:
        raise SpecError(f"the model needs z_pins = z_cycloid + 1, got {z_b} and {z_c}",
                        file=design.where("pin.count"), key="pin.count")
    m = pos("sun.module")
    if "planet.module" in design and abs(design["planet.module"] - m) > 1e-12:
        raise SpecError("sun and planet modules differ", file=design.where("planet.module"), key="planet.module")
    alpha = pos("sun.pressure_angle")
    if not alpha < 0.5 * math.pi:
        raise SpecError(f"pressure angle must lie below 90°, got {math.degrees(alpha):g}°",
                        file=design.where("sun.pressure_angle"),
                        key="sun.pressure_angle")
    x_s, x_p = float(design.get("sun.profile_shift", 0.0)), float(design.get("planet.profile_shift", 0.0))
    inv_w = involute(alpha) + 2.0 * math.tan(alpha) * (x_s + x_p) / (z_s + z_p)
    if inv_w <= 0:
        raise SpecError("profile shifts give a non-positive operating pressure angle",
                        file=design.where("planet.profile_shift"), key="planet.profile_shift")
    alpha_w = inverse_involute(inv_w)
    a_w = m * (z_s + z_p) / 2.0 * math.cos(alpha) / math.cos(alpha_w)
    ratio = 1.0 + z_b * z_p / z_s
    if "reducer.ratio" in design and abs(design["reducer.ratio"] - ratio) > 1e-9 * ratio:
        raise SpecError(f"ratio {design['reducer.ratio']:g} does not match 1 + z_b z_p / z_s = {ratio:g}",
                        file=design.where("reducer.ratio"), key="reducer.ratio")
    ecc, r_pc, r_pin = pos("cycloid.eccentricity"), pos("pin.circle_radius"), pos("pin.radius")
    if not z_b * ecc < r_pc - r_pin:
        raise SpecError("pitch point outside the pin circle (need z_b·e < R_p − r_rp)",
                        file=design.where("cycloid.eccentricity"), key="cycloid.eccentricity")
    hertz = float(design["stiffness.hertz_exponent"])
    if not 0.0 <= hertz < 0.5:
        raise SpecError(f"Hertz exponent must lie in [0, 0.5), got {hertz}",
                        file=design.where("stiffness.hertz_exponent"),
                        key="stiffness.hertz_exponent")

    def opt(name, nonnegative=False):
        """An optional inertia/damping number (Newmark only): > 0 (>= 0 for damping) when given."""
        if name not in design:
            return None
        v = float(design[name])
        if not (v >= 0 if nonnegative else v > 0) or not math.isfinite(v):
            raise SpecError(f"must be {'>= 0' if nonnegative else '> 0'}, got {_written(design, name)}",
                            file=design.where(name), key=name)
        return v

    r_bs, r_bp, rated = m * z_s * math.cos(alpha) / 2.0, m * z_p * math.cos(alpha) / 2.0, pos("reducer.rated_torque")
    # the compliance elements sit on the crank circle as the design writes it (the value every other model
    # reads: one set of elements, one finite-element solve per design); a' where the design leaves it out
    circle = float(design["crank_bearing.centre_radius"]) if "crank_bearing.centre_radius" in design else a_w
    if abs(circle - a_w) > CIRCLE_TOLERANCE:
        # a crank circle written beside the gears must be theirs (a variant that changes z_s + z_p or the shifts
        # and keeps its base's circle would put the cranks and their elements where the planets are not)
        raise SpecError(f"crank circle {_written(design, 'crank_bearing.centre_radius')} is not the operating centre "
                        f"distance a' = {a_w:.4f} mm of [sun] and [planet] (m (z_s + z_p)/2 · cos α / cos α'): "
                        "write it to the µm or leave it out", file=design.where("crank_bearing.centre_radius"),
                        key="crank_bearing.centre_radius")
    elements = ChainElements.from_design(design, circle)
    contact_chain = None
    if chain:
        try:
            contact_chain = reduce_chain(elements, a_w=a_w, r_bs=r_bs, r_bp=r_bp, ratio=ratio, z_c=z_c, z_b=z_b,
                                         ecc=ecc, rated_torque=rated)
        except SpecError as e:
            raise design.relocate(e.located(file=design.file))

    def scaled(key, family):
        """A doc 000 stiffness divided by its family's compliance scale (k0 / s scales the deflection by s)."""
        return pos(key) / compliance_scale(design, family)

    return RVGeometry(
        z_s=z_s, z_p=z_p, z_c=z_c, z_b=z_b, module=m, alpha=alpha, x_s=x_s, x_p=x_p,
        ecc=ecc, r_pin_circle=r_pc, r_pin=r_pin,
        k_s=scaled("stiffness.sun_support", "sun_support"),
        k_sp=scaled("stiffness.sun_planet_mesh", "sun_planet_mesh"),
        k0_dc=scaled("stiffness.cycloid_crank_bearing_k0", "turning_arm_bearings"),
        k0_oc=scaled("stiffness.crank_carrier_bearing_k0", "crank_support_bearings"),
        k0_pin=scaled("stiffness.cycloid_pin_mesh_k0", "cycloid_pin"),
        k0_ca=scaled("stiffness.carrier_housing_bearing_k0", "carrier_housing_bearing"),
        hertz=hertz, rated_torque=rated,
        alpha_w=alpha_w, a_w=a_w, r_bs=r_bs, r_bp=r_bp,
        ratio=ratio, chain=contact_chain, friction=friction_from_design(design),
        m_sun=opt("mass.sun"), m_planet=opt("mass.planet_crank"), i_planet=opt("mass.planet_crank_inertia"),
        m_disc=opt("mass.disc"), i_disc=opt("mass.disc_inertia"), m_carrier=opt("mass.carrier"),
        i_carrier=opt("mass.carrier_inertia"), zeta=opt("damping.modal_ratio", nonnegative=True),
    )
