"""Coulomb friction at the sliding contacts of the 20-DOF model, for the torsion (hysteresis) curve.

**What slides in a torsion test.**  With the input locked, the output turns only by elastic deflection; every
body moves a little and three kinds of contact slide (or roll with a rolling resistance) while it does:

* **pin in its groove / on the disc flank.**  The disc's contact point moves along the flank's tangent
  ``t = ẑ × n`` relative to the housing.  The pin between disc and groove is a free cylinder touched at two
  points on (nearly) one diameter: its moment balance about its axis makes the tangential forces at the two
  contacts equal, ``f_flank = f_groove``, so the pin transmits at most ``min(μ_flank, μ_groove) F`` — it rolls
  on the contact with the higher coefficient and slides on the other.  Both are lubricated steel on steel;
  one coefficient ``μ_pin`` (``friction.pin_sliding``) is used and the flank's rolling resistance (a rolling
  friction coefficient ~10⁻³ of hardened steel line contacts, the order of the bearings' below) is left out:
  it is two orders below the sliding friction.  The disc's slip at pin k (:func:`._kernels.friction_jacobian`),
  in the eccentric frame (u_e, t_e) with α the angle of the contact normal and λ = |P C| the distance from the
  pitch point to the contact point::

      s_k = −sin α · η + e cos α · θ_do + (R_d cos α + λ) · θ_d,   λ = −z_b e cos α + √(R_p² − (z_b e sin α)²) − r_rp

  (η, e θ_do: the disc centre's radial and tangential displacement; θ_d its spin; R_d = z_c e).  The friction
  force ``μ_pin F_k`` acts on the disc along −t against the slip.
* **needle rows** (cycloid–crank bearings): the eccentric turns against the disc's crank hole by
  ``θ_crank − θ_disc`` (absolute crank rotation minus disc spin).  Rolling-bearing friction moment, the
  constant-coefficient estimate ``M = μ P d/2`` (SKF, *Rolling bearings* catalogue, section "Friction —
  Estimating the frictional moment", Table 1: needle roller bearings with a cage μ = 0.0020; JTEKT/Koyo
  catalogue, "Friction coefficient of bearings", Table 4-1: needle roller and cage assembly 0.0020–0.0030),
  P the row's radial load (the contact force the model solves), d its bore = the eccentric's raceway
  diameter ``crank.eccentric_diameter``.
* **tapered crank-support pair**: the crank turns against the carrier by ``θ_crank − θ_carrier``.  The same
  estimate with μ = 0.0018 (SKF Table 1, tapered roller bearings; Koyo 0.0017–0.0025), d = the bore
  ``crank_support_bearing.bore``, and P = the crank resultant R (the contact force: the pair's radial load)
  plus the preload's equivalent load ``P0 = 2 Y F_a0`` (each of the two bearings carries the axial preload
  F_a0: SKF's equivalent load P = 0.4 F_r + Y F_a above e, with ISO 281's Y = 0.4 cot α for a tapered roller
  bearing of cup angle α) — so the pair has a friction moment at zero torque.

The main bearing (carrier–housing) slides too (its moment acts on the output directly), but its load is its
preload, which the product does not give (the model's main bearing is doc 000's law with zero load): left
out and said so.  The sun–planet meshes roll with little sliding near the pitch point: left out.

**Referred to the output.**  Each friction force or moment acts on the bodies it joins; the reducer's
kinematics carries it to the output.  While the output turns by dθ, contact c slides by ``J_c dq`` (the rows
above are rows of the reducer's motion: the crank's rotation, the disc's spin and orbit, the carrier's
rotation) and dissipates ``m_c |J_c dq|``, ``m_c = μ_c (F_c + P0_c) arm_c`` at its normal force ``F_c``; the
work balance gives the friction torque at the output::

    T_f = Σ_c m_c |J_c v| / |v_θ|,     v = K⁻¹ e_θ

with ``v`` the reducer's motion per unit output torque from the tangent stiffness ``K`` of the (frictionless)
equilibrium (:func:`._kernels.friction_torque`): the ratio and the crank and disc motions as the reducer
actually moves in the torsion test, not as it turns when driven.  Every contact's friction opposes its own
motion, whose direction follows the load: on the loading branch (torque rising) the friction torque resists
the rising torque, on the unloading branch the falling one.

**The loop.**  The reducer is then its frictionless torsion curve θ₀(T) with the friction torque in parallel
at the output: on a branch moving in direction d (+1 loading, −1 unloading) the output torque T and the
elastic torque T_e the contacts carry satisfy ``T = T_e + d T_f(T_e)``, and the angle is θ₀(T_e)
(:mod:`rvtol.models.torsion_curve.model` builds the loop from the frictionless curve and solves the reading
points exactly).  At a turning point of the load every contact sticks until the load has turned by 2 T_f
(the vertical segment at the loop's tips).  First order: the friction forces' own redistribution of the
contact loads (a fraction μ of them) is not carried — with μ ≤ 0.15 a correction of a few per cent of the
friction width, far inside the uncertainty of the coefficients.

**What the loop shows.**  For a spring k with a friction torque T_f and a free play 2c, the loop's width is
``2c + 2 T_f/k`` at zero torque and ``2 T_f/k`` where the play is closed
(``tests/models/reducer_20dof/test_friction.py`` holds the loop to it); with friction proportional to the contact load
(μ F, T_f = μ T_e) the width at torque T is ``2 μ T/(k (1 − μ²))``: it vanishes at zero torque.  So in a reducer the
pins' and needles' friction widens the loop in proportion to the torque, and only the preloaded pairs' friction (P0)
leaves a width at zero torque.  The maker's figures read on such a loop (:mod:`rvtol.models.torsion_curve.model`): lost
motion — the angle between the mid-points of the loop's width at ±p % rated: friction shifts the two branches nearly
symmetrically and cancels in the mid-points to first order; backlash — the loop's width at zero torque: free
play plus the width the load-independent friction holds there; rigidity b/a — the loop's tips, which lie on
the loading branches.  The width of the loop at ±p % (``friction_width``) is the friction's own figure
beside them.

**Limits.**  Coulomb's law with one coefficient per contact: no pre-sliding (Dahl) regime — in a real
bearing the first micrometres of a reversal are elastic micro-slip, so the loop's corners are rounded; the
constant-μ bearing estimates are SKF's for normal running (P ≈ 0.1 C, good lubrication), the load-dependent
rolling and sliding friction; at the near-zero speed of a torsion test SKF's detailed model keeps only the
sliding part of the moment, with the boundary coefficient μ_bl ≈ 0.15 (the value ``friction.pin_sliding``
takes).  The transmission-error sweep stays frictionless (friction under rotation adds a nearly constant
torque: a shift of the mean TE, not of its peak-to-peak).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import SpecError
from . import layout as L

#: design keys of the friction coefficients (dimensionless) and what each acts on
KEYS = {"pin": "friction.pin_sliding", "needle": "friction.needle_bearing",
        "crank_support": "friction.crank_support_bearing"}
LABELS = {"pin": "pins: sliding in the groove / on the flank", "needle": "needle rows (cycloid–crank bearings)",
          "crank_support": "tapered crank-support pairs"}


@dataclass(frozen=True)
class Friction:
    """Friction coefficients and the numbers that turn them into forces and moments (mm, N)."""

    pin: float = 0.0
    needle: float = 0.0
    crank_support: float = 0.0
    needle_bore: float = 0.0             # d of the needle rows (mm)
    crank_support_bore: float = 0.0      # d of the tapered pair (mm)
    crank_support_p0: float = 0.0        # preload's equivalent load of the pair, 2 Y F_a0 (N)
    crank_support_p0_per_newton: float = 0.0   # 2 Y: P0 per newton of preload (a crank's own preload)

    @property
    def active(self) -> bool:
        return self.pin > 0.0 or self.needle > 0.0 or self.crank_support > 0.0

    def scaled(self, s: float) -> "Friction":
        """Every coefficient multiplied by ``s``."""
        from dataclasses import replace

        return replace(self, pin=s * self.pin, needle=s * self.needle, crank_support=s * self.crank_support)


def _num(design, key: str, positive: bool = True) -> float:
    v = design[key]
    if isinstance(v, str) or not math.isfinite(v) or not (v > 0 if positive else v >= 0):
        raise SpecError(f"must be {'> 0' if positive else '>= 0'}, got {design.param(key).value!r}",
                        file=design.where(key), key=key)
    return float(v)


def friction_from_design(design) -> Friction | None:
    """The design's friction (``[friction]`` keys, :data:`KEYS`), or None when it gives none."""
    if not any(k in design for k in KEYS.values()):
        return None
    mu = {name: (_num(design, key, positive=False) if key in design else 0.0) for name, key in KEYS.items()}
    for name, v in mu.items():
        if v >= 1.0:
            raise SpecError(f"a friction coefficient must lie in [0, 1), got {v:g}", file=design.where(KEYS[name]),
                            key=KEYS[name])
    needle_bore = _num(design, "crank.eccentric_diameter") if mu["needle"] > 0 else 0.0
    bore = p0 = two_y = 0.0
    if mu["crank_support"] > 0:
        bore = _num(design, "crank_support_bearing.bore")
        preload = _num(design, "crank_support_bearing.preload", positive=False)
        alpha = _num(design, "crank_support_bearing.cup_angle")
        two_y = 2.0 * 0.4 / math.tan(alpha)
        p0 = two_y * preload
    return Friction(mu["pin"], mu["needle"], mu["crank_support"], needle_bore, bore, p0, two_y)


def crank_support_p0(fric: Friction, preload=None) -> np.ndarray:
    """Each crank support pair's preload equivalent load ``P0 = 2 Y F_a0`` (N): from the crank's own preload
    (``preload[i]``, N) where it is given and finite, else the design's."""
    p0 = np.full(L.N_CRANK, fric.crank_support_p0)
    if preload is not None:
        own = np.isfinite(np.asarray(preload, dtype=float))
        p0[own] = fric.crank_support_p0_per_newton * np.asarray(preload, dtype=float)[own]
    return p0


def friction_table(fric: Friction | None, z_b: int, preload=None) -> np.ndarray | None:
    """``fr[nc, NFR]`` of the contact table (:mod:`.layout`), or None without friction; ``preload``: each crank's
    support preload (N, NaN or None: the design's), whose equivalent load ``2 Y F_a0`` is the pair's P0."""
    if fric is None or not fric.active:
        return None
    fr = np.zeros((L.n_contacts(z_b), L.NFR))
    fr[:, L.FR_B] = -1.0
    for j in range(L.N_DISC):
        for k in range(z_b):
            c = L.C_PIN + j * z_b + k
            fr[c, [L.FR_KIND, L.FR_MU, L.FR_ARM]] = L.FR_PIN, fric.pin, 1.0
        for i in range(L.N_CRANK):
            c = L.C_CAM + 3 * j + i
            fr[c, [L.FR_KIND, L.FR_MU, L.FR_ARM, L.FR_A, L.FR_B]] = (L.FR_ROTATION, fric.needle, 0.5 * fric.needle_bore,
                                                                     L.planet(i) + 2, L.disc(j) + 2)
    for i, p0 in enumerate(crank_support_p0(fric, preload)):
        c = L.C_CRANK + i
        fr[c, [L.FR_KIND, L.FR_MU, L.FR_ARM, L.FR_P0, L.FR_A, L.FR_B]] = (
            L.FR_ROTATION, fric.crank_support, 0.5 * fric.crank_support_bore, p0, L.planet(i) + 2, L.THCA)
    fr[fr[:, L.FR_MU] == 0.0, L.FR_KIND] = L.FR_NONE
    return fr


def group_of(c: int, z_b: int) -> str | None:
    """The friction group (:data:`KEYS`) of contact row ``c``."""
    if c >= L.C_PIN:
        return "pin"
    if L.C_CAM <= c < L.C_CRANK:
        return "needle"
    if L.C_CRANK <= c < L.C_HOUSING:
        return "crank_support"
    return None
