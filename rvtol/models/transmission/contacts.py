"""The static part of the contact table: which DOFs each contact touches and its force law.

The time-dependent coefficients and the error offsets are written by
:func:`._kernels.update_table` at every position.  With a compliance chain (:mod:`.compliance`) a
contact's law becomes a series law (``ser``, ``tab``; layout in :mod:`.layout`): linear terms of the
meshes are folded into their stiffness, the others are evaluated by :func:`._kernels.series_law`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import layout as L
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


def static_table(g: RVGeometry, err: np.ndarray) -> ContactTable:
    """Contact kinds, DOF maps, stiffness laws and bearing clearances (from ``err``)."""
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
    t_crank = t_cam = t_pin = -1
    if ch is not None:
        k_mesh = 1.0 / (1.0 / g.k_sp + sum(ch.mesh.values()))
        tables = []
        for name in ("crank_table", "cam_table", "pin_table"):
            if getattr(ch, name) is not None:
                tables.append(getattr(ch, name))
                if name == "crank_table":
                    t_crank, k0_oc = len(tables) - 1, 0.0     # the pair's table replaces doc 000's law
                elif name == "cam_table":
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
            series(L.C_CRANK + i, sum(ch.crank.values()), table=t_crank)
        for j in range(L.N_DISC):
            d = L.disc(j)
            put(L.C_CAM + 3 * j + i, L.RADIAL, [[b, b + 2, d, d + 1, d + 2], [b + 1, b + 2, d, d + 1, d + 2]],
                k0_dc, p, err[L.DELTA_B + 3 * j + i])
            if ch is not None and (ch.cam[j] or ch.cam_table is not None):
                series(L.C_CAM + 3 * j + i, sum(ch.cam[j].values()), table=t_cam)
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
