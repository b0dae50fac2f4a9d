"""The static part of the contact table: which DOFs each contact touches and its force law.

The time-dependent coefficients and the error offsets are written by
:func:`._kernels.update_table` at every position (:func:`pin_contacts` reads the cycloid–pin rows of that
table at one position: the geometry a fit check of the discs in the pin ring needs).  With a compliance chain (:mod:`.compliance`) a
contact's law becomes a series law (``ser``, ``tab``; layout in :mod:`.layout`): linear terms of the
meshes are folded into their stiffness, the others are evaluated by :func:`._kernels.series_law`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _kernels as K
from . import layout as L
from .factors import ErrorState
from .geometry import RVGeometry


@dataclass(frozen=True)
class ContactTable:
    kind: np.ndarray   # [nc] int64
    idx: np.ndarray    # [nc, 2, NZ] int64, −1 = unused
    k0: np.ndarray     # [nc] linear stiffness (LINEAR) or Hertz base coefficient
    pw: np.ndarray     # [nc] force exponent (1 for LINEAR)
    gap: np.ndarray    # [nc] radial clearance of bearings (mm), 0 otherwise
    ser: np.ndarray    # [nc, NSER] series-law parameters (all 0: the kind's power law alone)
    tab: np.ndarray    # [ntab, 4, npts] tabulated laws (one dummy row when there is none)

    @property
    def n(self) -> int:
        return self.kind.size


def static_table(g: RVGeometry, err: np.ndarray, preload: np.ndarray | None = None) -> ContactTable:
    """Contact kinds, DOF maps, stiffness laws and bearing clearances (from ``err``); ``preload``: each crank's
    support preload (N, NaN or None: the design's), which gives each crank its own pair law and cam tilt terms
    (:meth:`.compliance.ContactChain.crank_law`)."""
    nc = L.n_contacts(g.z_b)
    kind = np.zeros(nc, np.int64)
    idx = np.full((nc, 2, L.NZ), -1, np.int64)
    k0 = np.zeros(nc)
    pw = np.ones(nc)
    gap = np.zeros(nc)
    p = g.force_exponent

    def put(c, kd, rows, stiff, expo=1.0, clearance=0.0):
        kind[c] = kd
        for r, dofs in enumerate(rows):
            idx[c, r, :len(dofs)] = dofs
        k0[c], pw[c], gap[c] = stiff, expo, clearance

    ch = g.chain
    ser = np.zeros((nc, L.NSER))
    tab = np.zeros((1, 4, 2))
    k_mesh, k0_oc, k0_dc = g.k_sp, g.k0_oc, g.k0_dc
    t_crank = [-1] * L.N_CRANK
    t_cam = t_pin = -1
    # the cams' linear series terms per crank (the pair's tilt share depends on that crank's preload)
    cam_lin = [[sum(ch.cam[j].values()) if ch is not None else 0.0 for _ in range(L.N_CRANK)] for j in range(L.N_DISC)]
    if ch is not None:
        k_mesh = 1.0 / (1.0 / g.k_sp + sum(ch.mesh.values()))
        tables = []
        own = preload is not None and np.any(np.isfinite(preload)) and ch.crank_table is not None
        if ch.crank_table is not None:                 # the pair's table replaces doc 000's law
            k0_oc = 0.0
            tables.append(ch.crank_table)
            t_crank = [0] * L.N_CRANK
            if own:
                for i in range(L.N_CRANK):
                    if np.isfinite(preload[i]):
                        law, tilt = ch.crank_law(float(preload[i]))
                        tables.append(law)
                        t_crank[i] = len(tables) - 1
                        for j in range(L.N_DISC):
                            cam_lin[j][i] += tilt[j] - ch.cam[j].get("crank_support_bearings", 0.0)
        for name in ("cam_table", "pin_table"):
            if getattr(ch, name) is not None:
                tables.append(getattr(ch, name))
                if name == "cam_table":
                    t_cam, k0_dc = len(tables) - 1, 0.0       # the needle row replaces doc 000's law
                else:
                    t_pin = len(tables) - 1
        if tables:
            tab = np.ascontiguousarray(np.stack(tables))

    def series(c, linear=0.0, log=None, table=-1):
        ser[c, L.S_ON] = 1.0
        ser[c, L.S_LIN] = linear
        if log is not None:
            ser[c, L.S_LOGA], ser[c, L.S_LOGB], ser[c, L.S_LOGCAP] = log
        ser[c, L.S_TAB] = table

    put(L.C_SUN, L.LINEAR, [[L.XS]], g.k_s)
    put(L.C_SUN + 1, L.LINEAR, [[L.YS]], g.k_s)
    for i in range(L.N_CRANK):
        b = L.planet(i)
        put(L.C_MESH + i, L.LINEAR, [[L.XS, L.YS, b, b + 1, b + 2]], k_mesh)
        put(L.C_CRANK + i, L.RADIAL, [[b, L.XCA, L.THCA], [b + 1, L.YCA, L.THCA]], k0_oc, p,
            err[L.DELTA_OC + i])
        if ch is not None and (ch.crank or ch.crank_table is not None):
            series(L.C_CRANK + i, sum(ch.crank.values()), table=t_crank[i])
        for j in range(L.N_DISC):
            d = L.disc(j)
            put(L.C_CAM + 3 * j + i, L.RADIAL, [[b, b + 2, d, d + 1, d + 2], [b + 1, b + 2, d, d + 1, d + 2]],
                k0_dc, p, err[L.DELTA_B + 3 * j + i])
            if ch is not None and (ch.cam[j] or ch.cam_table is not None):
                series(L.C_CAM + 3 * j + i, cam_lin[j][i], table=t_cam)
    put(L.C_HOUSING, L.RADIAL, [[L.XCA], [L.YCA]], g.k0_ca, p, err[L.DELTA_CA])
    for j in range(L.N_DISC):
        d = L.disc(j)
        for k in range(g.z_b):
            put(L.C_PIN + j * g.z_b + k, L.UNILATERAL, [[d, d + 1, d + 2]], g.k0_pin, p)
            if ch is not None and (ch.groove is not None or ch.pin or ch.pin_table is not None):
                series(L.C_PIN + j * g.z_b + k, sum(ch.pin.values()), log=ch.groove, table=t_pin)
    return ContactTable(kind, idx, k0, pw, gap, ser, tab)


def pin_angles(g: RVGeometry) -> np.ndarray:
    """θ_k = 2π k / z_b, k = 0 … z_b − 1 (pin k + 1 of the document)."""
    return 2.0 * np.pi * np.arange(g.z_b) / g.z_b


def pin_cos_sin(g: RVGeometry) -> np.ndarray:
    th = pin_angles(g)
    return np.ascontiguousarray(np.stack([np.cos(th), np.sin(th)]))


@dataclass(frozen=True)
class PinContacts:
    """The cycloid–pin contacts of both discs at one position, as the kernel's contact table writes them.

    Disc j's frame is its eccentric frame (x along the eccentric u_e, at the absolute angle ``eccentric[j]``).
    A disc displaced by ``d`` (its centre, in that frame) and turned by ``ψ`` about its centre approaches pin
    k by ``normal[j, k]·d + arm[j, k]·ψ`` (doc 000 §1.3, contact 4: η cos α + e Δθ_do sin α + R_d Δθ_d sin α,
    with d = (η, e Δθ_do)); the pin touches when the approach reaches ``clearance[j, k]``.
    """

    normal: np.ndarray      # [N_DISC, z_b, 2] contact normal (cos α, sin α): from the pitch point P to pin k
    arm: np.ndarray         # [N_DISC, z_b] moment arm about the disc centre, R_d sin α = z_c e sin α (mm)
    clearance: np.ndarray   # [N_DISC, z_b] normal clearance (mm): −(the table's offset), every error included
    eccentric: np.ndarray   # [N_DISC] absolute angle of disc j's eccentric direction u_e (rad)


def pin_contacts(g: RVGeometry, errors: ErrorState, theta_c: float = 0.0) -> PinContacts:
    """The pin rows of :func:`._kernels.update_table` at the nominal carrier angle ``theta_c``.

    The normal clearance is the kernel's: n_j(φ) of the profile modification, the pin's own clearance δ_jk,
    the pin's radial and tangential position errors projected on the normal and the disc's profile fields at
    the contact point — so a fit check reads exactly the clearances the 20-DOF model loads.
    """
    nc = L.n_contacts(g.z_b)
    coef = np.zeros((nc, 2, L.NZ))
    off = np.zeros((nc, 2))
    K.update_table(float(theta_c), 0.0, g.prm(), errors.err, errors.pin_err, errors.disc_h, pin_cos_sin(g),
                   coef, off)
    rows = slice(L.C_PIN, L.C_PIN + L.N_DISC * g.z_b)
    c = coef[rows, 0, :3].reshape(L.N_DISC, g.z_b, 3)
    normal = np.stack([c[..., 0], c[..., 1] / g.ecc], axis=-1)      # coef: (cos α, e sin α, R_d sin α)
    eccentric = (1.0 - g.z_b) * float(theta_c) + np.pi * np.arange(L.N_DISC)
    return PinContacts(normal, c[..., 2].copy(), -off[rows, 0].reshape(L.N_DISC, g.z_b), eccentric)
