"""Fused numba kernel for deviation chains: build, compose, invert and extract in one pass.

The assembly graph compiles into a small *program* (see :mod:`.program`):
a list of operations on a few 3×4 affine registers per sample.  The kernel
runs the program for every sample without building any ``(n, m, 4, 4)``
array: deviation transforms are built on the fly from ``E[i, slot, :]`` as
12-number tuples (registers are rows of 12) and multiplied in as 3×4
affine products (36 multiply-adds instead of the 64 of a 4×4 product).  :func:`.program.run_numpy` implements the same
equations with batched NumPy matmuls; tests hold the two together.

Pure array function, ``@njit(cache=True, nogil=True)``, status per sample:
0 ok, 1 non-finite input, 2 singular matrix in a small-angle inversion.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

# operation codes: (code, dst, src, arg)
OP_SET = 0      # reg[dst] = C[arg]            (arg < 0: identity)
OP_MULC = 1     # reg[dst] = reg[dst] @ C[arg]
OP_MULD = 2     # reg[dst] = reg[dst] @ T(E[slot=arg])
OP_MULDI = 3    # reg[dst] = reg[dst] @ T(E[slot=arg])^-1
OP_COPY = 4     # reg[dst] = reg[src]
OP_LINV = 5     # reg[dst] = reg[src]^-1 @ reg[dst]
OP_OUT = 6      # out[i, arg, :] = extract(reg[src])

MODE_SMALL = 0
MODE_EXACT = 1

STATUS_NONFINITE_INPUT = 1
STATUS_SINGULAR = 2


@njit(cache=True, nogil=True, inline="always")
def _sincos(x):
    """(sin x, cos x) to double precision: Taylor polynomials for the small angles of deviations
    (|x| < 2e-3: to x⁵/x⁶, next term < 2e-20 relative; |x| < 0.1: to x¹¹/x¹², < 2e-22), ``math`` beyond."""
    x2 = x * x
    if x2 < 4e-6:
        return x * (1.0 - x2 / 6.0 * (1.0 - x2 / 20.0)), 1.0 - x2 / 2.0 * (1.0 - x2 / 12.0 * (1.0 - x2 / 30.0))
    if x2 < 1e-2:
        s = x * (1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0 * (1.0 - x2 / 72.0 * (1.0 - x2 / 110.0)))))
        c = 1.0 - x2 / 2.0 * (1.0 - x2 / 12.0 * (1.0 - x2 / 30.0 * (1.0 - x2 / 56.0 * (1.0 - x2 / 90.0
                                                                                     * (1.0 - x2 / 132.0)))))
        return s, c
    return math.sin(x), math.cos(x)


@njit(cache=True, nogil=True, inline="always")
def _deviation(u, v, w, a, b, g, mode):
    """Trans × Rot of one deviation vector, as 12 numbers (row-major 3×4)."""
    if mode == MODE_SMALL:
        return (1.0, -g, b, u, g, 1.0, -a, v, -b, a, 1.0, w)
    sa, ca = _sincos(a)
    sb, cb = _sincos(b)
    sg, cg = _sincos(g)
    return (cg * cb, cg * sb * sa - sg * ca, cg * sb * ca + sg * sa, u,
            sg * cb, sg * sb * sa + cg * ca, sg * sb * ca - cg * sa, v,
            -sb, cb * sa, cb * ca, w)


@njit(cache=True, nogil=True, inline="always")
def _inverse(m, mode):
    """Inverse of an affine 3×4 (12-tuple) and whether it exists."""
    if mode == MODE_EXACT:  # orthonormal: transpose
        r00, r01, r02 = m[0], m[4], m[8]
        r10, r11, r12 = m[1], m[5], m[9]
        r20, r21, r22 = m[2], m[6], m[10]
        ok = True
    else:  # adjugate / determinant
        c00 = m[5] * m[10] - m[6] * m[9]
        c01 = m[2] * m[9] - m[1] * m[10]
        c02 = m[1] * m[6] - m[2] * m[5]
        c10 = m[6] * m[8] - m[4] * m[10]
        c11 = m[0] * m[10] - m[2] * m[8]
        c12 = m[2] * m[4] - m[0] * m[6]
        c20 = m[4] * m[9] - m[5] * m[8]
        c21 = m[1] * m[8] - m[0] * m[9]
        c22 = m[0] * m[5] - m[1] * m[4]
        det = m[0] * c00 + m[1] * c10 + m[2] * c20
        ok = abs(det) > 1e-300
        f = 1.0 / det if ok else 0.0
        r00, r01, r02 = c00 * f, c01 * f, c02 * f
        r10, r11, r12 = c10 * f, c11 * f, c12 * f
        r20, r21, r22 = c20 * f, c21 * f, c22 * f
    t0, t1, t2 = m[3], m[7], m[11]
    return (r00, r01, r02, -(r00 * t0 + r01 * t1 + r02 * t2),
            r10, r11, r12, -(r10 * t0 + r11 * t1 + r12 * t2),
            r20, r21, r22, -(r20 * t0 + r21 * t1 + r22 * t2)), ok


@njit(cache=True, nogil=True, inline="always")
def _row(R, d):
    return (R[d, 0], R[d, 1], R[d, 2], R[d, 3], R[d, 4], R[d, 5], R[d, 6], R[d, 7],
            R[d, 8], R[d, 9], R[d, 10], R[d, 11])


@njit(cache=True, nogil=True, inline="always")
def _store(R, d, a, m):
    """R[d] = a @ m for affine 12-tuples ``a`` and ``m``."""
    for r in range(3):
        x0, x1, x2, x3 = a[4 * r], a[4 * r + 1], a[4 * r + 2], a[4 * r + 3]
        R[d, 4 * r + 0] = x0 * m[0] + x1 * m[4] + x2 * m[8]
        R[d, 4 * r + 1] = x0 * m[1] + x1 * m[5] + x2 * m[9]
        R[d, 4 * r + 2] = x0 * m[2] + x1 * m[6] + x2 * m[10]
        R[d, 4 * r + 3] = x0 * m[3] + x1 * m[7] + x2 * m[11] + x3


@njit(cache=True, nogil=True)
def run_program(E, consts, ops, n_reg, n_out, mode, out, status):
    """Run ``ops`` for each sample: ``E[n, s, 6]``, ``consts[q, 12]`` -> ``out[n, n_out, 6]``."""
    n = E.shape[0]
    R = np.empty((n_reg, 12))
    for i in range(n):
        ok = True
        for s in range(E.shape[1]):
            for d in range(6):
                if not math.isfinite(E[i, s, d]):
                    ok = False
        st = 0 if ok else STATUS_NONFINITE_INPUT
        if ok:
            for k in range(ops.shape[0]):
                code, dst, src, arg = ops[k, 0], ops[k, 1], ops[k, 2], ops[k, 3]
                if code == OP_SET:
                    for c in range(12):
                        R[dst, c] = consts[arg, c] if arg >= 0 else (1.0 if c == 0 or c == 5 or c == 10 else 0.0)
                elif code == OP_MULC:
                    _store(R, dst, _row(R, dst), _row(consts, arg))
                elif code == OP_MULD:
                    m = _deviation(E[i, arg, 0], E[i, arg, 1], E[i, arg, 2], E[i, arg, 3], E[i, arg, 4],
                                   E[i, arg, 5], mode)
                    _store(R, dst, _row(R, dst), m)
                elif code == OP_MULDI:
                    m = _deviation(E[i, arg, 0], E[i, arg, 1], E[i, arg, 2], E[i, arg, 3], E[i, arg, 4],
                                   E[i, arg, 5], mode)
                    mi, good = _inverse(m, mode)
                    if not good:
                        st = STATUS_SINGULAR
                        break
                    _store(R, dst, _row(R, dst), mi)
                elif code == OP_COPY:
                    for c in range(12):
                        R[dst, c] = R[src, c]
                elif code == OP_LINV:
                    mi, good = _inverse(_row(R, src), mode)
                    if not good:
                        st = STATUS_SINGULAR
                        break
                    _store(R, dst, mi, _row(R, dst))
                elif code == OP_OUT:
                    out[i, arg, 0] = R[src, 3]
                    out[i, arg, 1] = R[src, 7]
                    out[i, arg, 2] = R[src, 11]
                    if mode == MODE_SMALL:
                        out[i, arg, 3] = 0.5 * (R[src, 9] - R[src, 6])
                        out[i, arg, 4] = 0.5 * (R[src, 2] - R[src, 8])
                        out[i, arg, 5] = 0.5 * (R[src, 4] - R[src, 1])
                    else:
                        out[i, arg, 3] = math.atan2(R[src, 9], R[src, 10])
                        out[i, arg, 4] = math.asin(min(1.0, max(-1.0, -R[src, 8])))
                        out[i, arg, 5] = math.atan2(R[src, 4], R[src, 0])
        status[i] = st
        if st != 0:
            for k in range(n_out):
                for d in range(6):
                    out[i, k, d] = np.nan
