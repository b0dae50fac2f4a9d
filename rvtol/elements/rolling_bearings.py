"""Rolling bearings: doc 004's closed-form roller bearing deflection, and bearings with their roller load
distribution — a preloaded pair of tapered roller bearings (the crank support bearings) and a needle roller bearing
with radial clearance (the turning-arm bearing).

**Roller–raceway contact (Palmgren).**  The normal approach of one roller and one
raceway in line contact, for steel (Palmgren 1959, as given by Harris & Kotzalas,
*Rolling Bearing Analysis*, 5th ed., vol. 1 *Essential Concepts of Bearing
Technology*, ch. 6 "Contact stress and deformation", line contact)::

    δ_c = 3.84·10⁻⁵ · Q^0.9 / l^0.8          (δ_c mm, Q N, l effective length mm)

A roller between two raceways of equal length deforms at both contacts, so its
total approach is ``δ = 7.68·10⁻⁵ Q^0.9 / l^0.8`` (the same law with twice the
constant).  Inverted, ``Q = K δ^(10/9)`` with ``K = [3.84·10⁻⁵ (l_o^-0.8 + ρ^0.9 l_i^-0.8)]^(-10/9)``
(``ρ = Q_i/Q_o``, 1 for a needle bearing).  The constant is for steel
(``E ≈ 207 GPa``, ``ν = 0.3``) and straight (or logarithmically crowned) rollers
without edge loading; it is not adjusted to anything here.

**Tapered roller (roller statics).**  Cup (outer raceway) contact angle ``α_o``
(the catalogue's ``α``, ``e = 1.5 tan α_o``), cone angle ``α_i``, cone-rib
normal at ``β_f`` to the bearing axis (default the roller axis, ``(α_o+α_i)/2``).
Force balance of a roller in its axial plane (Harris & Kotzalas, vol. 1, ch. 7
"Distribution of internal loading…", tapered roller bearings)::

    Q_i = Q_o cos(α_o − β_f) / cos(α_i − β_f),      Q_f = Q_o sin(α_o − α_i) / cos(α_i − β_f)

The net force on the cone (raceway + rib) equals ``Q_o`` along the cup normal,
so the rings exchange ``Q_o`` at the contact angle ``α = α_o``.  The roller's
approach is measured along the cup normal: ``δ = δ_o + δ_i`` (the cone contact
is inclined by ``α_o − α_i`` ≈ 2–4°, a projection error below 0.3 %).

**Doc 004's turning-arm bearing (closed form).**  :func:`radial_deflection` is the needle roller bearing on the
eccentric as doc 004's model takes it: the most loaded roller carries Stribeck's ``Q_max = 4.08 F_r / Z`` (line
contact, zero clearance; Harris & Kotzalas, the load integral ``J_r(0.5)`` below) and its two contacts (eccentric
and cycloid bore) are in series, so the bearing's radial deflection is ``δ_r = 2 · 3.84·10⁻⁵ · Q_max^0.9 / l^0.8``.

**Load distribution (rigid rings, Jones/Harris).**  Roller ``k`` at azimuth
``ψ_k`` of a bearing centred at ``z_j`` on a shaft with small displacements
``q = (u_x, u_y, u_z, θ_x, θ_y)`` (inner ring relative to outer ring, rotations
about the ``x`` and ``y`` axes through the origin) is compressed by::

    δ_k = cos α [(u_x + θ_y z_j) cos ψ_k + (u_y − θ_x z_j) sin ψ_k]
          − s_j sin α [u_z + R (θ_x sin ψ_k − θ_y cos ψ_k)] + δ_0j

with ``s_j = ±1`` the axial direction in which the bearing pushes the shaft,
``R`` the pitch radius and ``δ_0j`` the approach from mounting (``> 0``:
preload, ``< 0``: clearance).  ``δ_k = B_k · q + δ_0j``; the roller carries
``Q_k = K δ_k^(10/9)`` if ``δ_k > 0`` and nothing otherwise, and equilibrium of
the shaft under the external load vector ``f = (F_x, F_y, F_z, M_x, M_y)``
(moments about the origin) reads ``Σ_k Q_k B_k = f``.  It is solved for ``q``
with ``scipy.optimize.root`` and the analytic Jacobian ``Σ (10/9) K δ_k^(1/9) B_kᵀ B_k``,
which is also the tangent stiffness matrix.  Checks (tests): Harris' load
integrals ``J_r(ε)``, ``J_a(ε)`` (``Q_max = F_r / (Z J_r(0.5) cos α) = 4.08 F_r/(Z cos α)``
for line contact at zero clearance), a single roller's Palmgren law,
symmetry, and the preload loss of a pair at ``F_a = 2^(10/9) F_pre``.

**Arrangement.**  ``"X"`` (face-to-face, indirect): the cups are pushed
towards each other by the housing, the pressure centres lie between the
bearings; ``"O"`` (back-to-back): pressure centres outside.  The RV-E crank
bearings are an X pair: the cups sit in the carrier's two flanges and are
preloaded when the input-side end plate is bolted to the pillars of the output
flange; the cones sit on the crank journals against the shoulders of the
(larger) eccentric section.

Neglected: ring and housing deformation, roller tilting and skewing, the rib
contact compliance, centrifugal and gyroscopic forces (output speeds are low),
friction.  Units: mm, N, rad.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import integrate
from scipy.optimize import brentq

from ..errors import SolverError, SpecError
from . import _checks

PALMGREN_LINE = 3.84e-5      # mm · N^-0.9 · mm^0.8, one roller–raceway line contact, steel
LOAD_EXPONENT = 10.0 / 9.0   # Q = K δ^(10/9), line contact
STRIBECK_LINE = 4.08         # Q_max Z / F_r for line contact and zero clearance


# ------------------------------------------------------------------------------------------------
# single contacts and closed forms
# ------------------------------------------------------------------------------------------------

def palmgren_approach(Q, length, constant: float = PALMGREN_LINE):
    """``δ_c = c Q^0.9 / l^0.8`` (mm): approach of one roller–raceway line contact under ``Q`` (N)."""
    Q = _checks.nonnegative("Q", Q)
    return constant * Q ** 0.9 / _checks.positive("length", length) ** 0.8


def radial_deflection(F_r, rollers: int, length: float):
    """Radial deflection (mm) of a roller bearing under radial load ``F_r`` (N), doc 004's closed form (module doc)."""
    q = STRIBECK_LINE * np.abs(np.asarray(F_r, dtype=float)) / rollers
    return 2.0 * PALMGREN_LINE * q ** 0.9 / length ** 0.8


def roller_constant(length_outer, length_inner=None, inner_ratio=1.0, constant: float = PALMGREN_LINE):
    """``K`` (N/mm^(10/9)) of a roller between two raceways: ``Q_o = K (δ_o + δ_i)^(10/9)``.

    ``δ = c Q_o^0.9 (l_o^-0.8 + ρ^0.9 l_i^-0.8)`` with ``ρ = Q_i / Q_o`` (``inner_ratio``).
    """
    lo = _checks.positive("length_outer", length_outer)
    li = lo if length_inner is None else _checks.positive("length_inner", length_inner)
    rho = _checks.positive("inner_ratio", inner_ratio)
    return (constant * (lo ** -0.8 + rho ** 0.9 * li ** -0.8)) ** (-LOAD_EXPONENT)


def tapered_force_ratios(alpha_outer, alpha_inner, rib_angle=None):
    """``(Q_i/Q_o, Q_f/Q_o)`` of a tapered roller from its force balance (see the module doc).

    Angles in rad; ``rib_angle`` = angle of the rib contact normal to the bearing axis (default
    the roller axis, ``(α_o + α_i)/2``).
    """
    ao = _checks.angle("alpha_outer", alpha_outer)
    ai = _checks.angle("alpha_inner", alpha_inner, lower=-0.5 * np.pi)
    if np.any(ai > ao):
        raise SpecError("the cone angle must not exceed the cup angle", key="alpha_inner")
    bf = 0.5 * (ao + ai) if rib_angle is None else _checks.finite("rib_angle", rib_angle)
    den = np.cos(ai - bf)
    return np.cos(ao - bf) / den, np.sin(ao - ai) / den


def load_integrals(eps, n: float = LOAD_EXPONENT):
    """Harris' (Sjövall's) load-distribution integrals ``(J_r(ε), J_a(ε))`` of a single-row bearing.

    ``Q(ψ) = Q_max [1 − (1 − cos ψ)/(2ε)]^n`` over the loaded arc; ``F_r = Z Q_max J_r cos α``,
    ``F_a = Z Q_max J_a sin α`` (Harris & Kotzalas, vol. 1, ch. 7).  ``n = 10/9`` line contact,
    ``3/2`` point contact.  ``ε`` > 0 (≥ 1: all rollers loaded).
    """
    eps = float(_checks.positive("eps", eps))
    lim = np.pi if eps >= 1.0 else float(np.arccos(1.0 - 2.0 * eps))

    def q(psi):
        return max(1.0 - (1.0 - np.cos(psi)) / (2.0 * eps), 0.0) ** n

    Jr = integrate.quad(lambda p: q(p) * np.cos(p), -lim, lim, epsabs=1e-12, epsrel=1e-12, limit=200)[0]
    Ja = integrate.quad(q, -lim, lim, epsabs=1e-12, epsrel=1e-12, limit=200)[0]
    return Jr / (2.0 * np.pi), Ja / (2.0 * np.pi)


# ------------------------------------------------------------------------------------------------
# roller sets
# ------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class TaperedRollerBearing:
    """Internal geometry of a single-row tapered roller bearing.

    ``rollers`` Z; ``alpha`` cup contact angle (rad); ``length`` effective roller contact length
    (mm); ``pitch_diameter`` d_m (mm); optional ``alpha_inner`` cone angle, ``length_inner``,
    ``rib_angle``; ``phase`` = azimuth of roller 0 in roller pitches.
    """

    rollers: int
    alpha: float
    length: float
    pitch_diameter: float
    alpha_inner: float | None = None
    length_inner: float | None = None
    rib_angle: float | None = None
    phase: float = 0.0
    constant: float = PALMGREN_LINE

    def __post_init__(self):
        object.__setattr__(self, "rollers", _checks.whole("rollers", self.rollers))
        _checks.angle("alpha", self.alpha, lower=-1e-300)   # 0 allowed (cylindrical/needle rollers)
        _checks.positive("length", self.length)
        _checks.positive("pitch_diameter", self.pitch_diameter)
        _checks.finite("phase", self.phase)
        _checks.positive("constant", self.constant)
        if self.length_inner is not None:
            _checks.positive("length_inner", self.length_inner)

    @property
    def inner_ratio(self) -> float:
        if self.alpha_inner is None:
            return 1.0
        return float(tapered_force_ratios(self.alpha, self.alpha_inner, self.rib_angle)[0])

    @property
    def K(self) -> float:
        """Roller constant ``Q_o = K δ^(10/9)`` (N/mm^(10/9))."""
        return float(roller_constant(self.length, self.length_inner, self.inner_ratio, self.constant))

    @property
    def azimuths(self) -> np.ndarray:
        return 2.0 * np.pi * (np.arange(self.rollers) + self.phase) / self.rollers

    def B(self, z: float, s: int) -> np.ndarray:
        """``B[k] = ∂δ_k/∂q``, ``q = (u_x, u_y, u_z, θ_x, θ_y)``, for the bearing at ``z`` pushing along ``s``."""
        psi = self.azimuths
        c, sa, R = np.cos(self.alpha), np.sin(self.alpha), 0.5 * self.pitch_diameter
        cp, sp = np.cos(psi), np.sin(psi)
        return np.column_stack([c * cp, c * sp, np.full_like(psi, -s * sa),
                                -z * c * sp - s * R * sa * sp, z * c * cp + s * R * sa * cp])

    def axial_force_at_approach(self, delta0):
        """Axial force (N) of the bearing when every roller is compressed by ``delta0`` (mm)."""
        d = np.maximum(_checks.finite("delta0", delta0), 0.0)
        return self.rollers * self.K * d ** LOAD_EXPONENT * np.sin(self.alpha)


def _roller_loads(K, delta):
    """``Q = K δ^(10/9)`` for ``δ > 0``, and ``dQ/dδ``."""
    d = np.maximum(delta, 0.0)
    return K * d ** LOAD_EXPONENT, LOAD_EXPONENT * K * d ** (LOAD_EXPONENT - 1.0)


#: Armijo's sufficient-decrease constant δ and the Wolfe curvature constant σ of :func:`_step_accepted`
ARMIJO, WOLFE = 1e-4, 0.9


def _energy_rounding(size: float, terms: int) -> float:
    """The rounding error of a sum of ``terms`` + 1 floating-point terms whose magnitudes add to ``size``:
    (terms + 1)·u·size with u the unit round-off (Higham, Accuracy and Stability of Numerical Algorithms,
    2nd ed., §4.2: |error| ≤ (n − 1) u Σ|x_i| to first order)."""
    return (terms + 1) * np.finfo(float).eps * size


def _step_accepted(E: float, En: float, slope: float, slope_new: float, t: float, eps_E: float) -> bool:
    """Armijo's condition, or Hager–Zhang's approximate Wolfe conditions where Π's change is below its rounding
    error ``eps_E`` (:func:`_equilibrium`): ``slope`` = φ'(0) = g·p < 0, ``slope_new`` = φ'(t) = g(q + tp)·p."""
    if En <= E + ARMIJO * t * slope:
        return True
    return En <= E + eps_E and WOLFE * slope <= slope_new <= (2.0 * ARMIJO - 1.0) * slope


def _equilibrium(parts, f, x0, scale, tol, what):
    """Solve ``Σ_k Q_k B_k = f`` for ``q`` by minimising the potential energy

        Π(q) = Σ_k K/(n+1) max(B_k·q + δ0, 0)^(n+1) − f·q        (n = 10/9)

    a convex function (each term is a convex function of an affine map), with a damped
    (Levenberg–Marquardt) Newton method and a backtracking line search: globally convergent
    also when clearances leave rollers unloaded at the start (singular tangent stiffness).
    ``parts`` = [(B, K, δ0)], ``scale`` makes the components of ``q`` comparable (mm).

    The line search accepts a step on Armijo's sufficient decrease of Π, or — once the decrease a step
    can make (≈ r²/2k at residual r) is below the rounding error of Π itself (:func:`_energy_rounding`)
    — on Hager and Zhang's *approximate Wolfe* conditions, which read the slope instead:
    Π(q + tp) ≤ Π(q) + ε_Π and σ φ'(0) ≤ φ'(t) ≤ (2δ − 1) φ'(0), φ(t) = Π(q + tp) (W. W. Hager,
    H. Zhang, SIAM J. Optim. 16 (2005) 170–192, eq. (23); δ = 1e-4 as the Armijo constant, σ = 0.9).
    Armijo alone stalls there: Π no longer resolves the step, every trial reads as "no decrease", and
    the residual stops some orders of magnitude above ``tol`` (a needle row of 8, 9 or 10 mm under a
    few hundred newtons stopped at 1e-7 N against a tolerance of 1e-7 N).
    """
    m = LOAD_EXPONENT + 1.0

    def state(q):
        E, g, H, Qs = -f @ q, -f.copy(), np.zeros((len(q), len(q))), 0.0
        size = abs(f @ q)
        for B, K, d0 in parts:
            d = np.maximum(B @ q + d0, 0.0)
            Q = K * d ** LOAD_EXPONENT
            work = K / m * np.sum(d ** m)
            E += work
            size += work
            g += B.T @ Q
            H += B.T @ ((LOAD_EXPONENT * K * d ** (LOAD_EXPONENT - 1.0))[:, None] * B)
            Qs += Q.sum()
        return E, g, H, Qs, _energy_rounding(size, sum(len(B) for B, _, _ in parts))

    ref = np.abs(f / scale).max()
    Dreg = np.zeros((len(x0), len(x0)))
    for B, K, _ in parts:            # linearisation at 2 µm per roller: regularisation metric
        Dreg += LOAD_EXPONENT * K * 2e-3 ** (LOAD_EXPONENT - 1.0) * B.T @ B
    dg = np.diag(Dreg)
    Dreg = np.diag(np.maximum(dg, 1e-9 * dg.max()))      # directions no roller resists (Z = 1): stay put
    q = np.array(x0, dtype=float)
    E, g, H, Qs, eps_E = state(q)
    mu = 1e-6
    for _ in range(500):
        res = np.abs(g / scale).max()
        if res <= tol * max(ref, Qs, 1.0):
            return q, res
        while True:
            try:
                p = np.linalg.solve(H + mu * Dreg, -g)
                break
            except np.linalg.LinAlgError:
                mu = max(mu * 10.0, 1e-12)
        t, slope = 1.0, g @ p
        while True:
            qn = q + t * p
            En, gn, Hn, Qn, eps_n = state(qn)
            if _step_accepted(E, En, slope, gn @ p, t, max(eps_E, eps_n)) or t < 1e-12:
                break
            t *= 0.5
        if t < 1e-12:
            mu *= 100.0
            if mu > 1e12:
                break
            continue
        q, E, g, H, Qs, eps_E = qn, En, gn, Hn, Qn, eps_n
        mu = max(mu * (0.1 if t == 1.0 else 4.0), 1e-14)
    raise SolverError(f"{what}: no equilibrium for load {f} (residual {np.abs(g / scale).max():.3g} N after "
                      "500 Newton steps)")


@dataclass
class PairSolution:
    """Equilibrium of a shaft on a bearing pair, per load case ``i``.

    ``q[i]`` = (u_x, u_y, u_z, θ_x, θ_y) (mm, rad) of the shaft relative to the housing;
    ``roller_load[i, j, k]`` (N) roller ``k`` of bearing ``j``; ``approach`` (mm, negative = gap);
    ``stiffness[i]`` the 5×5 tangent stiffness matrix (N/mm, N, N·mm/rad); ``bearing_force[i, j]``
    the 5-vector each bearing applies to the shaft (about the origin).
    """

    q: np.ndarray
    roller_load: np.ndarray
    approach: np.ndarray
    stiffness: np.ndarray
    bearing_force: np.ndarray

    def axial_force(self, j: int, alpha: float) -> np.ndarray:
        """Axial load carried by bearing ``j`` (N, ≥ 0)."""
        return self.roller_load[:, j].sum(axis=1) * np.sin(alpha)


@dataclass(frozen=True)
class BearingPair:
    """A shaft on two tapered roller bearings at ``positions = (z_A, z_B)`` (mm), ``z_A < z_B``.

    ``arrangement``: ``"X"`` face-to-face (cups pushed inwards) or ``"O"`` back-to-back.
    Preload: ``interference`` = axial interference of the pair (mm, > 0 preload, < 0 end play),
    shared equally between the two bearings as an initial approach ``(Δ/2) sin α`` of every
    roller; :meth:`with_preload_force` finds ``Δ`` for a given preload force.
    """

    bearing_a: TaperedRollerBearing
    bearing_b: TaperedRollerBearing
    positions: tuple
    arrangement: str = "X"
    interference: float = 0.0
    _cache: dict = field(default_factory=dict, repr=False, compare=False)

    def __post_init__(self):
        z = _checks.finite("positions", self.positions)
        if z.shape != (2,) or not z[1] > z[0]:
            raise SpecError(f"must be two positions z_A < z_B, got {self.positions!r}", key="positions")
        if self.arrangement not in ("X", "O"):
            raise SpecError(f"must be 'X' (face-to-face) or 'O' (back-to-back), got {self.arrangement!r}",
                            key="arrangement")
        _checks.finite("interference", self.interference)
        object.__setattr__(self, "positions", (float(z[0]), float(z[1])))

    # -- geometry ---------------------------------------------------------------------------------
    @property
    def signs(self) -> tuple:
        """Axial direction in which each bearing pushes the shaft (X: A towards B, B towards A)."""
        return (1, -1) if self.arrangement == "X" else (-1, 1)

    def _parts(self):
        if "parts" not in self._cache:
            parts = []
            for brg, z, s in zip((self.bearing_a, self.bearing_b), self.positions, self.signs):
                parts.append((brg.B(z, s), brg.K, 0.5 * self.interference * np.sin(brg.alpha)))
            self._cache["parts"] = parts
        return self._cache["parts"]

    def with_preload_force(self, force: float) -> "BearingPair":
        """The same pair with the interference that gives axial preload ``force`` (N) at zero load."""
        F = float(_checks.positive("force", force))

        def g(delta):
            sol = BearingPair(self.bearing_a, self.bearing_b, self.positions, self.arrangement, delta).solve(
                np.zeros(5))
            return float(sol.axial_force(0, self.bearing_a.alpha)[0]) - F

        # both bearings identical: closed form; otherwise bracket around it
        d0 = 2.0 * (F / (self.bearing_a.rollers * self.bearing_a.K * np.sin(self.bearing_a.alpha))) ** (
            1.0 / LOAD_EXPONENT) / np.sin(self.bearing_a.alpha)
        lo, hi = 0.25 * d0, 4.0 * d0
        delta = brentq(g, lo, hi, xtol=1e-15, rtol=1e-13)
        return BearingPair(self.bearing_a, self.bearing_b, self.positions, self.arrangement, delta)

    # -- equilibrium ------------------------------------------------------------------------------
    def solve(self, loads, *, tol: float = 1e-11) -> PairSolution:
        """Equilibrium under ``loads`` = (F_x, F_y, F_z, M_x, M_y) about the origin, shape (5,) or (n, 5).

        Solved by minimising the potential energy (convex; see :func:`_equilibrium`) to a residual
        below ``tol`` × |load| (forces in N, moments divided by the bearing span).  A load the pair
        cannot carry raises :class:`SolverError`.
        """
        f = _checks.finite("loads", loads)
        single = f.ndim == 1
        f = np.atleast_2d(f)
        if f.shape[1] != 5:
            raise SpecError(f"must have 5 components (F_x, F_y, F_z, M_x, M_y), got shape {f.shape}", key="loads")
        L = self.positions[1] - self.positions[0]
        scale = np.array([1.0, 1.0, 1.0, L, L])      # residual / scale: N, N, N, N·mm / L
        parts = self._parts()
        q = np.zeros((len(f), 5))
        for i in range(len(f)):
            q[i], _ = _equilibrium(parts, f[i], q[i - 1] if i else np.zeros(5), scale, tol, "bearing pair")
        return self._collect(q[0] if single else q, single)

    def _collect(self, q, single):
        q2 = np.atleast_2d(q)
        loads, appr, forces = [], [], []
        Kt = np.zeros((len(q2), 5, 5))
        for B, K, d0 in self._parts():
            d = q2 @ B.T + d0
            Q, dQ = _roller_loads(K, d)
            loads.append(Q)
            appr.append(d)
            forces.append(-Q @ B)
            Kt += np.einsum("nk,ka,kb->nab", dQ, B, B)
        return PairSolution(q2, np.stack(loads, axis=1), np.stack(appr, axis=1), Kt, np.stack(forces, axis=1))

    # -- radial load–deflection at a point ----------------------------------------------------------
    def radial(self, force, z: float):
        """Radial deflection (mm) at ``z`` of the shaft (rigid) under a radial force ``F`` (N) at ``z``.

        Returns ``(u, k_tangent, solution)``: ``u = u_x + θ_y z`` along the force, the tangent radial
        stiffness ``1 / (cᵀ K_t⁻¹ c)`` with ``c = (1, 0, 0, 0, z)`` (N/mm), and the :class:`PairSolution`.
        """
        F = np.atleast_1d(_checks.nonnegative("force", force))
        z = float(_checks.finite("z", z))
        c = np.array([1.0, 0.0, 0.0, 0.0, z])
        sol = self.solve(F[:, None] * c[None, :])
        u = sol.q @ c
        with np.errstate(divide="ignore"):
            comp = np.array([c @ np.linalg.solve(K, c) if np.linalg.cond(K) < 1e14 else np.inf
                             for K in sol.stiffness])
            kt = 1.0 / comp
        return u, kt, sol

    def radial_stiffness(self, force, z: float, kind: str = "tangent"):
        """Radial stiffness (N/mm) at ``z`` under radial force ``F`` at ``z``: ``"tangent"`` dF/du or ``"secant"`` F/u."""
        if kind not in ("tangent", "secant"):
            raise SpecError(f"must be 'tangent' or 'secant', got {kind!r}", key="kind")
        u, kt, _ = self.radial(force, z)
        if kind == "tangent":
            return kt
        F = np.atleast_1d(np.asarray(force, dtype=float))
        u0 = self.radial(0.0, z)[0] if self.interference > 0 else 0.0
        return F / (u - u0)


# ------------------------------------------------------------------------------------------------
# needle (cylindrical) roller bearing with radial clearance
# ------------------------------------------------------------------------------------------------

@dataclass
class RadialSolution:
    """Needle/cylindrical roller bearing under radial load: displacement ``u`` (n, 2) mm of the inner
    ring, ``roller_load`` (n, Z) N, ``stiffness`` (n, 2, 2) N/mm tangent."""

    u: np.ndarray
    roller_load: np.ndarray
    stiffness: np.ndarray

    @property
    def deflection(self) -> np.ndarray:
        return np.linalg.norm(self.u, axis=1)

    @property
    def max_roller_load(self) -> np.ndarray:
        return self.roller_load.max(axis=1)


@dataclass(frozen=True)
class NeedleRollerBearing:
    """Radial roller bearing (contact angle 0): ``rollers`` Z, ``length`` effective length (mm, both
    raceways), ``clearance`` diametral internal clearance P_d (mm; negative = interference),
    ``phase`` = azimuth of roller 0 in roller pitches.  Roller ``k`` at ``ψ_k`` is compressed by
    ``δ_k = u_x cos ψ_k + u_y sin ψ_k − P_d/2`` and carries ``Q_k = K δ_k^(10/9)`` (Palmgren, both
    raceways, :func:`roller_constant`).  Equilibrium ``Σ Q_k (cos ψ_k, sin ψ_k) = F`` is solved for
    ``u`` (Harris & Kotzalas, vol. 1, ch. 7, radial roller bearings with clearance)."""

    rollers: int
    length: float
    clearance: float = 0.0
    phase: float = 0.0
    constant: float = PALMGREN_LINE

    def __post_init__(self):
        object.__setattr__(self, "rollers", _checks.whole("rollers", self.rollers))
        _checks.positive("length", self.length)
        _checks.finite("clearance", self.clearance)
        _checks.finite("phase", self.phase)

    @property
    def K(self) -> float:
        return float(roller_constant(self.length, constant=self.constant))

    @property
    def azimuths(self) -> np.ndarray:
        return 2.0 * np.pi * (np.arange(self.rollers) + self.phase) / self.rollers

    def solve(self, force, direction=0.0) -> RadialSolution:
        """Inner-ring displacement under radial force ``force`` (N, ≥ 0) along angle ``direction`` (rad)."""
        F = np.atleast_1d(_checks.nonnegative("force", force))
        beta = np.broadcast_to(_checks.finite("direction", direction), F.shape)
        psi = self.azimuths
        Bm = np.column_stack([np.cos(psi), np.sin(psi)])
        K, half = self.K, 0.5 * self.clearance
        parts = [(Bm, K, -half)]
        u = np.zeros((len(F), 2))
        for i, (Fi, bi) in enumerate(zip(F, beta)):
            if Fi == 0.0 and half >= 0:
                continue                      # free play: any position inside the clearance; take 0
            e = np.array([np.cos(bi), np.sin(bi)])
            u[i], _ = _equilibrium(parts, Fi * e, u[i - 1] if i else np.zeros(2), np.ones(2), 1e-10,
                                   "needle bearing")
        d = u @ Bm.T - half
        Q, dQ = _roller_loads(K, d)
        Kt = np.einsum("nk,ka,kb->nab", dQ, Bm, Bm)
        return RadialSolution(u, Q, Kt)


def edge_loaded_approach(delta, tilt, length, slices: int = 400, exponent: float = LOAD_EXPONENT):
    """Approach at the middle of a roller (mm) that carries the load of an aligned roller of approach
    ``delta`` (mm) when its raceways are tilted by ``tilt`` (rad) over the contact ``length`` (mm).

    **Slice model** (Harris & Kotzalas vol. 1 ch. 6, misaligned line contact; the slices act
    independently, each with Palmgren's law ``q ∝ δ^(10/9)``): the approach along the roller is
    ``δ0 + tilt·x``, ``|x| ≤ l/2``; the slices with a positive approach carry, and ``δ0`` is chosen so that
    the roller carries what the aligned roller carries::

        mean_x max(δ0 + tilt x, 0)^(10/9) = delta^(10/9)

    so the roller's middle moves in by ``δ0 − delta`` more (the edge loading of a tilted crank: its
    rollers bear on one end).  Tilt 0 gives ``delta``; a linear law (``exponent`` 1) keeps ``δ0 = delta``
    while every slice carries and gives ``δ0 = √(2 δ l |tilt|) − |tilt| l/2`` once one end lifts (``2δ < |tilt| l``)."""
    d = float(_checks.nonnegative("delta", delta))
    g = abs(float(_checks.finite("tilt", tilt)))
    L = float(_checks.positive("length", length))
    if d == 0.0 or g == 0.0:
        return d
    x = (np.arange(int(slices)) + 0.5) / int(slices) * L - 0.5 * L
    target = d ** exponent

    def load(d0):
        return float(np.mean(np.maximum(d0 + g * x, 0.0) ** exponent)) - target

    lo, hi = -0.5 * g * L, d
    while load(hi) < 0:
        hi *= 2.0
    return float(brentq(load, lo, hi, xtol=1e-16, rtol=1e-13))
