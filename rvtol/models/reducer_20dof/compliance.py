"""The reducer's compliance chain reduced to the contacts of the 20-DOF model (issue 12).

The model keeps its 20 coordinates (rigid sun, cranks, discs and carrier); every element of
:mod:`rvtol.elements.reducer_chain` is put **in series with the contact that carries its load**.  A
contact's law then reads ``δ(f) = Σ δ_i(f)`` (the deflections of springs carrying the same force add),
and the kernels find the force of a given deflection by a scalar Newton iteration
(:func:`._kernels.series_law`).  The terms per contact group (``a'`` crank circle, ``r_bs``, ``r_bp``
base radii, ``i`` ratio, ``i_b = (1 − 1/i) z_c/z_b``):

**Sun–planet mesh** (linear, folded into one stiffness)::

    1/k = 1/k_sp + r_bp² C_tw + 3 r_bs² / K_in

* ``crank_torsion``: the crank torque leaves the eccentrics and reaches the planet gear through the
  journal; the gear turns against the nearer eccentric by ``C_tw · r_bp f`` (``C_tw = ∫dz/GJ`` from the
  gear to the nearer eccentric), which moves the mesh point by ``r_bp`` times that.  Exact for that
  segment; the twist between the two eccentrics (carrying the difference of the two discs' crank
  torques) is left out: < 0.2″ at rated for the RV-80E (doc 004's θ4 counts it).
* ``input_shaft``: the three meshes turn the sun against the locked input end by
  ``r_bs Σ f / K_in``; with equal mesh forces each mesh sees ``3 r_bs² / K_in``.  Exact when the three
  mesh forces are equal (error-free reducer, by symmetry).

**Crank as a star** (cycloid–crank bearings and crank–carrier contact).  A crank on its support
bearings, loaded at its two eccentrics, has a 2×2 flexibility ``F`` between them (beam on rigid
supports + support bearings).  The 20-DOF crank is one rigid point joined to the carrier (contact
C_CRANK) and to the two discs (the cams): a star.  It reproduces ``F`` exactly when the crank–carrier
contact carries the mutual term ``F_12`` on the crank's resultant and each cam the rest ``F_jj − F_12``
on its own force (``w_j = F_12 (P_1 + P_2) + (F_jj − F_12) P_j``).  So:

* ``crank_bending``: ``F^beam`` of :class:`~rvtol.elements.reducer_chain.CrankGeometry` (Timoshenko,
  rigid supports): ``F^beam_12`` in series with C_CRANK, ``F^beam_jj − F^beam_12`` with cam j.
* ``crank_support_bearings``: the preloaded tapered pair.  Its symmetric part — the crank's resultant
  at the eccentrics' mid-plane, both bearings loaded alike — is the pair's **nonlinear** load–deflection
  ``u(R)`` (:meth:`BearingPair.solve`, roller load distribution with preload), tabulated as a cubic
  Hermite law with the exact tangents of the pair (``TABLE_POINTS`` knots to ``TABLE_RANGE`` × the rated
  crank load, within 0.15 % of the pair; linear beyond).  The antisymmetric part (the two discs' opposite pin resultants tilt the crank) is the
  pair's tilt flexibility at the eccentrics, ``F^pair_jj − F^pair_12``, **linearised** at the rated
  symmetric load (tangent 5×5 matrix of the pair), in series with cam j; the table carries
  ``u(R) − (c_1 + c_2) R / 4`` so that the symmetric response stays exactly ``u(R)``.
* The planet-gear force (≈ 4 % of a crank's load at rated) is taken at the mid-plane: its overhang
  moment on beam and bearings is left out (``studies/compliance_chain.md`` measures the effect).
* **Each crank's own preload** (issue 39: the preload a unit is built with — shims, end-play reading, run-in
  — is a sampled input, ``crank_support_preload[i]`` of :mod:`.factors`): the pair's law and tilt terms are
  tabulated once per design at :data:`PRELOAD_GRID` preloads ``P_k = P_max (k/(n−1))²`` from 0 to
  ``P_max = max(PRELOAD_RANGE × the design preload, PRELOAD_FLOOR)`` and at the design preload itself; a crank's law at preload ``P`` is the
  linear interpolation in ``P`` of the two neighbouring laws (values, tangents and ``∫δ`` alike, so the
  Hermite law, its tangent and its energy stay consistent); above the grid's top (a shim the supply could not
  match) the pair is solved at ``P`` itself.  ``tests/models/reducer_20dof/test_compliance_chain.py`` holds the
  interpolated law to the pair re-solved at ``P``.

**Carrier and disc webs** (torque-path springs, in series with C_CRANK, isotropic)::

    c_carrier = 3 a'² ρ_A² / K_carrier,      c_web = 3 a'² i_b² / (2 K_web)

* ``carrier``: the end plate takes the share ``ρ_A = z_B / (z_B − z_A)`` (lever rule, = ½ for the
  symmetric crank) of the cranks' torque ``T`` and passes it to the output flange through the pillars,
  storing ``(ρ_A T)² / K_carrier`` (doc 004's ``θ5 = T_B²/(K_5 T)``); three equal cranks each carrying
  ``T/(3a')`` store the same with ``c_carrier`` in series.  Exact when the three crank resultants are
  equal and tangential at the mid-plane (the end plate then turns all three bearing seats alike).
* ``disc_web``: each disc carries ``T_c = T i_b/2`` (statics: pin forces through the pitch point) and its
  web stores ``T_c²/K_web``; the same equal-cranks argument gives ``c_web``.  Exact for equal disc
  torques and equal tangential crank resultants.

**Pins** (``pin_groove``): the groove contact carries the pin's force, so
``δ = δ_pin(f) + f (a − b ln f)`` — the log form is :func:`rvtol.elements.pin_groove.groove_approach`
exactly (its half-width is ``√(κ f)``).

Every term is multiplied by its family's ``compliance_scale.<family>`` (default 1).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy.interpolate import CubicHermiteSpline

from ...elements.reducer_chain import FAMILIES, ChainElements
from ...elements.rolling_bearings import edge_loaded_approach
from ...errors import SpecError
from . import layout as L
from .layout import T_C, T_D, T_F, T_M

#: knots of the tabulated crank-support-pair law (spaced as (k/(n−1))^1.5), its range (× the rated crank
#: resultant); the cubic Hermite through the pair's values and tangents stays within 0.15 % of the pair
#: (largest where rollers leave the loaded zone and the law's curvature jumps)
TABLE_POINTS = 128
TABLE_SPACING = 1.5
TABLE_RANGE = 4.0
#: preloads at which the pair's law is tabulated for per-crank preloads (module doc): their number, the range
#: as a multiple of the design preload and its least top (N)
PRELOAD_GRID = 17
PRELOAD_RANGE = 2.5
PRELOAD_FLOOR = 2500.0


def hermite_integrals(f, d, m) -> np.ndarray:
    """Cumulative ``∫_0^{f_k} δ`` of the cubic Hermite law through ``(f_k, δ_k, δ'_k)`` at the knots."""
    h = np.diff(f)
    seg = h * (0.5 * (d[:-1] + d[1:]) + h * (m[:-1] - m[1:]) / 12.0)
    return np.concatenate([[0.0], np.cumsum(seg)])


def groove_cap(a: float, b: float) -> float:
    """Force beyond which the log law ``f (a − b ln f)`` continues linearly: ``exp(a/b − 2)``, where its slope
    ``a − b − b ln f`` has fallen to ``b`` (the contact half-width has grown to the pin's size; the
    formula turns over at ``exp(a/b − 1)``)."""
    return math.exp(a / b - 2.0)


def log_law(params, f):
    """``(δ, dδ/df, ∫δ)`` of ``δ = f (a − b ln f)`` (linear with slope ``b`` beyond ``f_cap``), vectorised."""
    a, b, cap = params
    f = np.asarray(f, dtype=float)
    x = np.clip(f, 1e-300, cap)
    d = x * (a - b * np.log(x))
    dd = a - b - b * np.log(x)
    c = 0.5 * x * x * (a - b * np.log(x) + 0.5 * b)
    extra = np.maximum(f - cap, 0.0)
    pos = f > 0
    return (np.where(pos, d + b * extra, 0.0), np.where(extra > 0, b, dd),
            np.where(pos, c + d * extra + 0.5 * b * extra ** 2, 0.0))


def table_law(table: np.ndarray, f):
    """``(δ, dδ/df, ∫δ)`` of a tabulated law at forces ``f`` (cubic Hermite inside, linear beyond the last
    knot), by SciPy's :class:`~scipy.interpolate.CubicHermiteSpline` (the kernels evaluate it apart)."""
    x, y, m = table[T_F], table[T_D], table[T_M]
    sp = CubicHermiteSpline(x, y, m)
    f = np.asarray(f, dtype=float)
    inside = np.minimum(f, x[-1])
    beyond = np.maximum(f - x[-1], 0.0)
    d = sp(inside) + m[-1] * beyond
    dd = np.where(beyond > 0, m[-1], sp(inside, 1))
    c = sp.antiderivative()(inside) - sp.antiderivative()(x[0]) + y[-1] * beyond + 0.5 * m[-1] * beyond ** 2
    return d, dd, c


@dataclass(eq=False)
class ContactChain:
    """Series terms per contact group (compliances in mm/N, by family)."""

    elements: ChainElements
    mesh: dict = field(default_factory=dict)
    cam: tuple = field(default_factory=lambda: ({}, {}))
    crank: dict = field(default_factory=dict)
    pin: dict = field(default_factory=dict)     # linear terms with each pin (linearised variants)
    crank_table: np.ndarray | None = None       # (4, TABLE_POINTS): f, δ, dδ/df, ∫δ (replaces doc 000's law)
    groove: tuple | None = None                 # (a, b, f_cap): δ = f (a − b ln f), linear beyond f_cap
    pin_table: np.ndarray | None = None         # (4, TABLE_POINTS): the conforming groove law (in series)
    cam_table: np.ndarray | None = None         # (4, TABLE_POINTS): the needle row (replaces doc 000's law)
    notes: dict = field(default_factory=dict)   # family -> reduction as text (reports)
    design_preload: float = 0.0                 # N: the preload of ``crank_table`` and of the cam terms
    pair_law_args: tuple | None = None          # (rated crank resultant, family scale) of the pair's laws
    _grid: tuple | None = field(default=None, repr=False)   # (preloads, tables, tilts), made on first use

    def preload_grid(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(preloads (N), tables (n, 4, TABLE_POINTS), tilts (n, 2))``: the pair's law at each preload of the
        grid (module doc), made once on first use."""
        if self._grid is None:
            if self.pair_law_args is None:
                raise SpecError("this design's crank support has no preloaded pair: its preload cannot be set",
                                key="crank_support_preload")
            R_rated, sc = self.pair_law_args
            el = self.elements
            grid = max(PRELOAD_RANGE * el.pair_preload, PRELOAD_FLOOR) * (
                np.arange(PRELOAD_GRID) / (PRELOAD_GRID - 1)) ** 2
            P = np.unique(np.append(grid, el.pair_preload))     # the design preload is a node: exact there
            laws = [_scaled(*_pair_law(el.pair_at(p), el.crank, R_rated, TABLE_RANGE * R_rated), sc) for p in P]
            for t, _ in laws:
                _check_crank_law(t, sum(self.crank.values()), TABLE_RANGE * R_rated)
            self._grid = (P, np.stack([t for t, _ in laws]), np.array([tl for _, tl in laws]))
        return self._grid

    def crank_law(self, preload: float) -> tuple[np.ndarray, tuple[float, float]]:
        """``(table, (tilt_1, tilt_2))`` of the crank–carrier law and the cams' pair-tilt terms at ``preload`` (N):
        the linear interpolation of the tabulated laws (module doc); beyond the grid's top (a unit whose shim the
        supply could not match) the pair solved at that preload."""
        P, tables, tilts = self.preload_grid()
        if not (np.isfinite(preload) and preload >= 0.0):
            raise SpecError(f"a crank support preload must be a number >= 0 N, got {preload!r}",
                            key="crank_support_preload")
        if preload > P[-1]:
            R_rated, sc = self.pair_law_args
            el = self.elements
            table, tilt = _scaled(*_pair_law(el.pair_at(preload), el.crank, R_rated, TABLE_RANGE * R_rated), sc)
            _check_crank_law(table, sum(self.crank.values()), TABLE_RANGE * R_rated)
            return table, (float(tilt[0]), float(tilt[1]))
        k = int(min(np.searchsorted(P, preload, side="right") - 1, P.size - 2))
        w = (preload - P[k]) / (P[k + 1] - P[k])
        table = (1.0 - w) * tables[k] + w * tables[k + 1]
        tilt = (1.0 - w) * tilts[k] + w * tilts[k + 1]
        return table, (float(tilt[0]), float(tilt[1]))

    @property
    def families(self) -> tuple[str, ...]:
        """Families with a series term somewhere (the breakdown's extra rows)."""
        out = set(self.mesh) | set(self.cam[0]) | set(self.cam[1]) | set(self.crank) | set(self.pin)
        if self.crank_table is not None:
            out.add("crank_support_bearings")
        if self.groove is not None or self.pin_table is not None:
            out.add("pin_groove")
        return tuple(f for f in FAMILIES if f in out)

    def groove_delta(self, f):
        """The groove term ``δ(f)`` (mm) of the pin law."""
        if self.pin_table is not None:
            return table_law(self.pin_table, f)[0]
        return log_law(self.groove, f)[0]

    def series_work(self, group: str, forces, disc: int = 0) -> dict[str, float]:
        """Work ``Σ f·δ_i(f)`` of each series family over the contacts of ``group`` (``"mesh"``, ``"cam"``,
        ``"crank"``, ``"pin"``) carrying ``forces`` (N; cams of disc ``disc``): the element's share of the
        contacts' virtual work (the rest belongs to the contact's own law)."""
        f = np.maximum(np.asarray(forces, dtype=float), 0.0) if group != "mesh" else np.asarray(forces, float)
        out: dict[str, float] = {}
        linear = {"mesh": self.mesh, "cam": self.cam[disc], "crank": self.crank, "pin": self.pin}.get(group, {})
        for fam, c in linear.items():
            out[fam] = out.get(fam, 0.0) + float(c * (f * f).sum())
        if group == "crank" and self.crank_table is not None:
            fam = "crank_support_bearings"
            out[fam] = out.get(fam, 0.0) + float((f * table_law(self.crank_table, f)[0]).sum())
        if group == "pin" and (self.groove is not None or self.pin_table is not None):
            out["pin_groove"] = out.get("pin_groove", 0.0) + float((f * self.groove_delta(f)).sum())
        return out

    def to_frame(self) -> pd.DataFrame:
        """Each series term: family, contact it is reduced to, compliance and the reduction."""
        rows = []
        for fam, c in self.mesh.items():
            rows.append((fam, "each sun–planet mesh", c, self.notes.get(fam, "")))
        for j, terms in enumerate(self.cam):
            for fam, c in terms.items():
                rows.append((fam, f"each cycloid–crank bearing, disc {j + 1}", c, self.notes.get(fam, "")))
        for fam, c in self.crank.items():
            rows.append((fam, "each crank–carrier contact", c, self.notes.get(fam, "")))
        for fam, c in self.pin.items():
            rows.append((fam, "each cycloid–pin contact", c, self.notes.get(fam, "")))
        if self.crank_table is not None:
            f, d = self.crank_table[T_F], self.crank_table[T_D]
            rows.append(("crank_support_bearings", "each crank–carrier contact (nonlinear law)",
                         float(d[1] / f[1]), self.notes.get("crank_support_table", "")))
        if self.cam_table is not None:
            f, d = self.cam_table[T_F], self.cam_table[T_D]
            rows.append(("turning_arm_bearings", "each cycloid–crank bearing (nonlinear law, replaces doc 000's)",
                         float(d[-1] / f[-1]), self.notes.get("turning_arm_bearings", "")))
        if self.groove is not None or self.pin_table is not None:
            rows.append(("pin_groove", "each cycloid–pin contact (nonlinear law)",
                         float(self.groove_delta(1000.0) / 1000.0), self.notes.get("pin_groove", "")))
        return pd.DataFrame({"family": [r[0] for r in rows], "element": [FAMILIES[r[0]] for r in rows],
                             "in series with": [r[1] for r in rows],
                             "compliance (µm/kN)": [1e6 * r[2] for r in rows],
                             "reduction": [r[3] for r in rows]})


def reduce_chain(el: ChainElements, *, a_w: float, r_bs: float, r_bp: float, ratio: float, z_c: int, z_b: int,
                 ecc: float, rated_torque: float) -> ContactChain | None:
    """The elements ``el`` reduced to the 20-DOF contacts (module doc); None when there is nothing to add."""
    if not el.present and el.needle is None:
        return None
    s = el.scale
    out = ContactChain(el)
    notes = out.notes
    R_rated = rated_torque / (3.0 * a_w)          # crank resultant at rated torque (tangential)
    cr = el.crank
    if cr is not None:
        z = list(cr.eccentrics)
        Fb = cr.bending_flexibility(z)
        for j in range(2):
            out.cam[j]["crank_bending"] = s("crank_bending") * float(Fb[j, j] - Fb[0, 1])
        out.crank["crank_bending"] = s("crank_bending") * float(Fb[0, 1])
        notes["crank_bending"] = ("star: F12 = %.3g µm/kN on the crank resultant, F11 − F12 = %.3g µm/kN on each "
                                  "cam" % (1e6 * Fb[0, 1], 1e6 * (Fb[0, 0] - Fb[0, 1])))
        near = min(z, key=lambda v: abs(v - cr.gear))
        ctw = cr.twist(cr.gear, near)
        out.mesh["crank_torsion"] = s("crank_torsion") * r_bp ** 2 * ctw
        notes["crank_torsion"] = f"r_bp² ∫dz/GJ from the gear (z = {cr.gear:g}) to the eccentric at z = {near:g} mm"
    if el.input_shaft_stiffness is not None:
        out.mesh["input_shaft"] = s("input_shaft") * 3.0 * r_bs ** 2 / el.input_shaft_stiffness
        notes["input_shaft"] = "3 r_bs² / K_in (three equal mesh forces)"
    if el.pair is not None:
        sc = s("crank_support_bearings")
        table, tilt = _scaled(*_pair_law(el.pair, cr, R_rated, TABLE_RANGE * R_rated), sc)
        for j in range(2):
            out.cam[j]["crank_support_bearings"] = tilt[j]
        out.crank_table = table
        out.design_preload = el.pair_preload
        out.pair_law_args = (R_rated, sc)
        notes["crank_support_bearings"] = ("pair tilt at the eccentrics, F^pair_jj − F^pair_12, tangent at the rated "
                                           "symmetric crank load %.0f N" % R_rated)
        notes["crank_support_table"] = ("pair translation u(R) under the crank resultant at the mid-plane (roller "
                                        "load distribution, preload %g N) minus the tilt share" % el.pair_preload)
    if el.carrier_stiffness is not None:
        if cr is None:
            raise SpecError("the carrier element needs the crank layout (its bearing positions)", key="carrier")
        zA, zB = cr.support
        rho = zB / (zB - zA)
        out.crank["carrier"] = s("carrier") * 3.0 * a_w ** 2 * rho ** 2 / el.carrier_stiffness
        notes["carrier"] = f"3 a'² ρ_A² / K_carrier, ρ_A = {rho:g} (end-plate share of the crank resultant)"
    if el.web_stiffness is not None:
        ib = (1.0 - 1.0 / ratio) * z_c / z_b
        out.crank["disc_web"] = s("disc_web") * 3.0 * a_w ** 2 * ib ** 2 / (2.0 * el.web_stiffness)
        notes["disc_web"] = f"3 a'² i_b² / (2 K_web), i_b = {ib:.4f}"
    ib = (1.0 - 1.0 / ratio) * z_c / z_b
    disc = rated_torque * (1.0 - 1.0 / ratio) / (2.0 * z_b * ecc)   # one disc's pin resultant at rated
    if el.groove is not None:
        sc = s("pin_groove")
        f = _knots(disc)
        out.pin_table = _tabulate(lambda F: sc * el.groove.approach(F), f)
        notes["pin_groove"] = ("conforming pin-in-hole law (Hertz approach + exact conformity correction), tabulated "
                               f"to {f[-1]:.3g} N, pin centre to housing, same force as the pin")
    if el.roughness_compliance is not None:
        out.pin["contact_roughness"] = s("contact_roughness") * el.roughness_compliance
        notes["contact_roughness"] = "GW rough layer of the groove contact, energy-weighted over the rated pin loads"
    if el.carrier_joint_compliance is not None:
        rho = _input_end_share(cr, "carrier_joints", "the end plate's share")
        out.crank["carrier_joints"] = s("carrier_joints") * 3.0 * a_w ** 2 * rho ** 2 * el.carrier_joint_compliance
        notes["carrier_joints"] = "3 a'² ρ_A² (1/K_carrier with the joints − 1/K_carrier without)"
    if el.housing_ring_compliance is not None:
        out.pin["housing_ring"] = s("housing_ring") * el.housing_ring_compliance
        notes["housing_ring"] = "energy-equivalent per pin under the classical pin sharing at rated (FE ring)"
    if el.disc_seat_compliance is not None:
        for j in range(2):
            out.cam[j]["disc_seats"] = s("disc_seats") * el.disc_seat_compliance
        notes["disc_seats"] = "energy-equivalent per crank hole under doc 004's statics at rated (FE disc less the web)"
    if el.carrier_seat_compliance is not None:
        rho = _input_end_share(cr, "carrier_seats", "their bearing shares")
        cA, cB = el.carrier_seat_compliance
        out.crank["carrier_seats"] = s("carrier_seats") * (rho ** 2 * cA + (1.0 - rho) ** 2 * cB)
        notes["carrier_seats"] = (f"ρ_A² c_A + ρ_B² c_B on the crank resultant (c per cup, FE end plate / flange), "
                                  f"ρ_A = {rho:g}")
    if el.needle is not None:
        cam = rated_torque * ib / 2.0 / (3.0 * a_w)                     # tangential crank-hole load at rated
        F_cam = math.hypot(cam, disc / 3.0)
        sc = s("turning_arm_bearings")
        f = _knots(F_cam)
        sol = el.needle.solve(f)
        d = sc * np.hypot(sol.u[:, 0], sol.u[:, 1])
        m = np.full(f.size, np.nan)
        for k, K in enumerate(sol.stiffness):
            if np.linalg.cond(K) < 1e12:
                m[k] = sc * np.linalg.inv(K)[0, 0]
        m[0] = m[0] if np.isfinite(m[0]) else d[1] / f[1]
        out.cam_table = np.stack([f, d, m, hermite_integrals(f, d, m)])
        if cr is not None:
            gam = crank_tilt(el, cam, disc / 3.0)
            d_r = float(np.hypot(*el.needle.solve(F_cam).u[0]))
            extra = edge_loaded_approach(d_r, gam, el.needle.length) - d_r
            for j in range(2):
                out.cam[j]["edge_loading"] = s("edge_loading") * extra / F_cam
            notes["edge_loading"] = (f"crank tilt {gam * 1e6:.3g} µrad at the eccentrics at rated: the most loaded needle's "
                                     f"middle moves in {extra * 1e6:.3g} nm more (slice model), secant at {F_cam:.4g} N")
        notes["turning_arm_bearings"] = (f"needle row {el.needle.rollers} × {el.needle.length:g} mm, Palmgren with the "
                                         f"roller load distribution (zero clearance: the 20-DOF gap carries δ_b), "
                                         f"tabulated to {f[-1]:.3g} N")
    if out.crank_table is not None:
        _check_crank_law(out.crank_table, sum(out.crank.values()), TABLE_RANGE * R_rated)
    return out


def crank_tilt(el: ChainElements, tangential: float, radial: float) -> float:
    """Slope (rad) of the crank at its eccentrics relative to the disc under the rated crank loads: each disc's
    tangential crank-hole load ``tangential`` (N, the same at both eccentrics) and radial ``±radial`` (the two
    discs' pin resultants are opposite), on the stepped beam with rigid supports (its section rotation,
    :meth:`rvtol.elements.shafts.SteppedShaft.flexibility`) plus the support pair's tilt (tangent at the rated crank
    resultant); mean of the two eccentrics of the magnitude over both planes."""
    cr = el.crank
    z = list(cr.eccentrics)
    C = cr.shaft.flexibility(z + z, ["force", "force", "moment", "moment"], supports=cr.support)
    rot = C[2:, :2]                                   # section rotation at the eccentrics per force there
    planes = (np.array([tangential, tangential]), np.array([radial, -radial]))
    slope = np.zeros(2)
    for P in planes:
        s = rot @ P
        if el.pair is not None:
            f = np.array([P.sum(), 0.0, 0.0, 0.0, float(np.dot(z, P))])
            K = el.pair.solve(np.array([tangential * 2.0, 0.0, 0.0, 0.0, 0.0]), tol=1e-8).stiffness[0]
            s = s + np.linalg.solve(K, f)[4]
        slope = np.hypot(slope, s)
    return float(slope.mean())


def _knots(rated_force: float) -> np.ndarray:
    """Force knots of a tabulated law: ``TABLE_POINTS`` spaced as ``(k/(n−1))^TABLE_SPACING`` to
    ``TABLE_RANGE`` × the rated force."""
    return TABLE_RANGE * rated_force * (np.arange(TABLE_POINTS) / (TABLE_POINTS - 1)) ** TABLE_SPACING


def _tabulate(delta, f) -> np.ndarray:
    """``(4, n)`` table (f, δ, dδ/df, ∫δ) of a law ``delta(F)`` (vectorised) at the knots ``f``: slopes by
    central differences of relative step 1e-4 (one-sided at 0)."""
    d = np.asarray(delta(f), dtype=float)
    h = 1e-4 * np.maximum(f, f[1])
    up = np.asarray(delta(f + h), dtype=float)
    lo = np.asarray(delta(np.maximum(f - h, 0.0)), dtype=float)
    m = (up - lo) / (f + h - np.maximum(f - h, 0.0))
    m[0] = d[1] / f[1]
    return np.stack([f, d, m, hermite_integrals(f, d, m)])


def _scaled(table: np.ndarray, tilt, sc: float):
    """A pair law and its tilt terms times the family's compliance scale ``sc``."""
    table = table.copy()
    table[T_D] *= sc
    table[T_M] *= sc
    table[T_C] *= sc
    return table, (sc * tilt[0], sc * tilt[1])


def _pair_law(pair, cr, R_lin: float, R_max: float):
    """The pair's symmetric law (table) and the tilt terms of the two cams (module doc)."""
    z = cr.eccentrics
    Ks = pair.solve(np.array([R_lin, 0.0, 0.0, 0.0, 0.0]), tol=1e-8).stiffness[0]
    B = np.array([[1.0, 0.0, 0.0, 0.0, zj] for zj in z])          # u_x + θ_y z at the eccentrics
    Fp = B @ np.linalg.solve(Ks, B.T)
    tilt = (float(Fp[0, 0] - Fp[0, 1]), float(Fp[1, 1] - Fp[0, 1]))
    f = R_max * (np.arange(TABLE_POINTS) / (TABLE_POINTS - 1)) ** TABLE_SPACING
    sol = pair.solve(np.column_stack([f, np.zeros((f.size, 4))]), tol=1e-8)
    c = np.array([1.0, 0.0, 0.0, 0.0, 0.0])
    u = sol.q @ c - (sol.q[0] @ c)
    slope = np.empty(f.size)
    for k, K in enumerate(sol.stiffness):
        slope[k] = c @ np.linalg.solve(K, c) if np.linalg.cond(K) < 1e12 else np.nan
    if not np.isfinite(slope[0]):               # no preload: no roller loaded at zero load
        slope[0] = u[1] / f[1]
    share = 0.25 * (tilt[0] + tilt[1])
    d = u - share * f
    m = slope - share
    return np.stack([f, d, m, hermite_integrals(f, d, m)]), tilt


def _check_crank_law(table: np.ndarray, lin: float, R_max: float) -> None:
    """The crank–carrier law (pair table + linear terms ``lin``) must increase: the star's centre compliance
    ``F_12`` is the pair's mutual flexibility plus the beam's and the torque-path springs'; a pair whose
    tilt flexibility dwarfs its translation (no preload, X arrangement) can make the pair's own share
    decrease, which the others must make up."""
    fine = np.linspace(0.0, R_max, 20 * TABLE_POINTS)
    d, m, _ = table_law(table, fine)
    if not (np.all(m + lin > 0) and np.all(np.diff(d + lin * fine) > 0)):
        raise SpecError("the crank support law (pair translation less its tilt share, plus the crank's mutual "
                        "flexibility) is not increasing: the pair's tilt flexibility is larger than the star "
                        "reduction can carry", key="crank_support_bearing.preload")


#: the contact groups of the 20-DOF model and the family of each group's own law
GROUPS = {"sun": "sun_support", "mesh": "sun_planet_mesh", "cam": "turning_arm_bearings",
          "crank": "crank_support_bearings", "housing": "carrier_housing_bearing", "pin": "cycloid_pin"}


def group_slices(nc: int) -> dict[str, slice]:
    """Contact rows of each group (:mod:`.layout`)."""
    return {"sun": slice(L.C_SUN, L.C_MESH), "mesh": slice(L.C_MESH, L.C_CAM), "cam": slice(L.C_CAM, L.C_CRANK),
            "crank": slice(L.C_CRANK, L.C_HOUSING), "housing": slice(L.C_HOUSING, L.C_PIN), "pin": slice(L.C_PIN, nc)}


def family_work(chain: ContactChain | None, work, forces) -> dict[str, float]:
    """Per family, the work of the contacts (``work[c]``, N·mm) given their forces ``forces[c]`` (N):
    a group's series elements take ``f·δ_i(f)`` each, the group's own law the rest (module doc)."""
    work = np.asarray(work, dtype=float)
    forces = np.asarray(forces, dtype=float)
    present = set(GROUPS.values()) | (set(chain.families) if chain is not None else set())
    out = {f: 0.0 for f in FAMILIES if f in present}
    for group, sl in group_slices(work.size).items():
        total = float(work[sl].sum())
        series: dict[str, float] = {}
        if chain is not None:
            if group == "cam":
                for j in range(L.N_DISC):
                    rows = slice(L.C_CAM + L.N_CRANK * j, L.C_CAM + L.N_CRANK * (j + 1))
                    for fam, w in chain.series_work("cam", forces[rows], j).items():
                        series[fam] = series.get(fam, 0.0) + w
            elif group != "sun" and group != "housing":
                series = chain.series_work(group, forces[sl])
        for fam, w in series.items():
            out[fam] += w
        out[GROUPS[group]] += total - sum(series.values())
    return out


def _input_end_share(cr, key: str, what: str) -> float:
    """ρ_A = z_B/(z_B − z_A): the share of a crank's resultant its input-side support carries (statics of the crank
    on its two supports), for the element ``key`` that needs it (``what``: why, for the error)."""
    if cr is None:
        raise SpecError(f"the {key.replace('_', ' ')} need the crank layout ({what})", key=key)
    zA, zB = cr.support
    return zB / (zB - zA)
