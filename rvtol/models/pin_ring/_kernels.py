"""The no-load sweep's contacts, position by position (numba; :mod:`.preload`).

:func:`noload_contacts` reads, at every equilibrium of a sweep, what the pin-ring preload needs from the 20-DOF
kernel's contact table (:func:`rvtol.models.reducer_20dof._kernels.update_table_fast`) and force laws
(:func:`~rvtol.models.reducer_20dof._kernels.contact_forces`): each pin's force, its approach ``G q + offset`` and
its normal's ``cos α``, ``sin α`` (eccentric frame), and the needle rows' and crank supports' resultants.  The
arithmetic on them is NumPy's (:meth:`.preload.PinRingPreloadModel.drag`); :func:`noload_contacts_py` is the same
loop in Python over the kernel's public functions, for the test that holds one to the other.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..reducer_20dof import _kernels as K
from ..reducer_20dof.layout import C_CAM, C_CRANK, C_PIN, N_CRANK, N_DISC

_JIT = dict(cache=True, nogil=True, error_model="numpy")


@njit(**_JIT)
def noload_contacts(theta_c, q_path, prm, err, pin_err, disc_h, pin_cs, kind, idx, k0, pw, gap, ser, tab, ecc,
                    force, approach, cos_a, sin_a, cams, cranks):
    """Fill, per position p of ``theta_c`` (equilibria ``q_path[p]``): ``force``, ``approach``, ``cos_a``,
    ``sin_a`` ``[p, N_DISC·z_b]`` of the pins, ``cams[p, 6]`` and ``cranks[p, 3]`` the bearing resultants."""
    nd = q_path.shape[1]
    nc = kind.size
    coef, off, aux, w, ws = K.sweep_arrays(prm, err, pin_cs, idx, nd, nc)
    F = np.zeros(nd)
    fc = np.zeros(nc)
    kt = np.zeros((nc, 3))
    npin = force.shape[1]
    for p in range(theta_c.size):
        K.update_table_fast(theta_c[p], 0.0, prm, err, aux, pin_err, disc_h, pin_cs, coef, off, w)
        q = q_path[p]
        K.contact_forces(q, kind, idx, coef, off, k0, pw, gap, ser, tab, F, fc, kt)
        for m in range(npin):
            c = C_PIN + m
            a = off[c, 0]
            for z in range(idx.shape[2]):
                i = idx[c, 0, z]
                if i >= 0:
                    a += coef[c, 0, z] * q[i]
            force[p, m] = fc[c]
            approach[p, m] = a
            cos_a[p, m] = coef[c, 0, 0]
            sin_a[p, m] = coef[c, 0, 1] / ecc
        for m in range(N_DISC * N_CRANK):
            cams[p, m] = fc[C_CAM + m]
        for m in range(N_CRANK):
            cranks[p, m] = fc[C_CRANK + m]


def noload_contacts_py(theta_c, q_path, prm, err, pin_err, disc_h, pin_cs, kind, idx, k0, pw, gap, ser, tab, ecc,
                       force, approach, cos_a, sin_a, cams, cranks):
    """:func:`noload_contacts` in Python, on :func:`~rvtol.models.reducer_20dof._kernels.update_table` (the
    reference implementation of the table, not the fast one)."""
    nc = kind.size
    npin = force.shape[1]
    for p in range(theta_c.size):
        coef, off = np.zeros((nc, 2, idx.shape[2])), np.zeros((nc, 2))
        K.update_table(float(theta_c[p]), 0.0, prm, err, pin_err, disc_h, pin_cs, coef, off)
        F, fc, kt = np.zeros(q_path.shape[1]), np.zeros(nc), np.zeros((nc, 3))
        q = np.ascontiguousarray(q_path[p])
        K.contact_forces(q, kind, idx, coef, off, k0, pw, gap, ser, tab, F, fc, kt)
        rows = slice(C_PIN, C_PIN + npin)
        ix = idx[rows, 0, :]
        approach[p] = np.where(ix >= 0, coef[rows, 0, :] * q[np.where(ix >= 0, ix, 0)], 0.0).sum(axis=1) + off[rows, 0]
        force[p] = fc[rows]
        cos_a[p], sin_a[p] = coef[rows, 0, 0], coef[rows, 0, 1] / ecc
        cams[p] = fc[C_CAM:C_CAM + N_DISC * N_CRANK]
        cranks[p] = fc[C_CRANK:C_CRANK + N_CRANK]
