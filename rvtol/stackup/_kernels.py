"""Fused numba kernel for deviation chains: build, compose, invert and extract in one pass.

The assembly graph compiles into a small *program* (see :mod:`.program`):
a list of operations on a few 3×4 affine registers per sample.  The kernel
runs the program for every sample without building any ``(n, m, 4, 4)``
array: deviation transforms are built on the fly from ``E[i, slot, :]``
and multiplied in as 3×4 affine products (36 multiply-adds instead of the
64 of a 4×4 product).  :func:`.program.run_numpy` implements the same
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


@njit(cache=True, nogil=True)
def _deviation_matrix(e, mode, M):
    """M (3×4) = Trans × Rot of deviation e[6]."""
    a, b, g = e[3], e[4], e[5]
    if mode == MODE_SMALL:
        M[0, 0] = 1.0
        M[0, 1] = -g
        M[0, 2] = b
        M[1, 0] = g
        M[1, 1] = 1.0
        M[1, 2] = -a
        M[2, 0] = -b
        M[2, 1] = a
        M[2, 2] = 1.0
    else:
        ca, sa = math.cos(a), math.sin(a)
        cb, sb = math.cos(b), math.sin(b)
        cg, sg = math.cos(g), math.sin(g)
        M[0, 0] = cg * cb
        M[0, 1] = cg * sb * sa - sg * ca
        M[0, 2] = cg * sb * ca + sg * sa
        M[1, 0] = sg * cb
        M[1, 1] = sg * sb * sa + cg * ca
        M[1, 2] = sg * sb * ca - cg * sa
        M[2, 0] = -sb
        M[2, 1] = cb * sa
        M[2, 2] = cb * ca
    M[0, 3] = e[0]
    M[1, 3] = e[1]
    M[2, 3] = e[2]


@njit(cache=True, nogil=True)
def _invert(A, mode, out):
    """out = A^-1 for an affine 3×4 A; returns False if the 3×3 part is singular."""
    if mode == MODE_EXACT:
        for r in range(3):
            for c in range(3):
                out[r, c] = A[c, r]
    else:
        for r in range(3):
            for c in range(3):
                r1, r2 = (r + 1) % 3, (r + 2) % 3
                c1, c2 = (c + 1) % 3, (c + 2) % 3
                out[r, c] = A[c1, r1] * A[c2, r2] - A[c1, r2] * A[c2, r1]
        det = A[0, 0] * out[0, 0] + A[0, 1] * out[1, 0] + A[0, 2] * out[2, 0]
        if not (abs(det) > 1e-300):
            return False
        for r in range(3):
            for c in range(3):
                out[r, c] = out[r, c] / det
    for r in range(3):
        out[r, 3] = -(out[r, 0] * A[0, 3] + out[r, 1] * A[1, 3] + out[r, 2] * A[2, 3])
    return True


@njit(cache=True, nogil=True)
def _mul(A, B, out):
    """out = A @ B for affine 3×4 matrices (out may not alias A or B)."""
    for r in range(3):
        a0, a1, a2 = A[r, 0], A[r, 1], A[r, 2]
        for c in range(4):
            out[r, c] = a0 * B[0, c] + a1 * B[1, c] + a2 * B[2, c]
        out[r, 3] += A[r, 3]


@njit(cache=True, nogil=True)
def _extract(A, mode, out):
    out[0] = A[0, 3]
    out[1] = A[1, 3]
    out[2] = A[2, 3]
    if mode == MODE_SMALL:
        out[3] = 0.5 * (A[2, 1] - A[1, 2])
        out[4] = 0.5 * (A[0, 2] - A[2, 0])
        out[5] = 0.5 * (A[1, 0] - A[0, 1])
    else:
        out[3] = math.atan2(A[2, 1], A[2, 2])
        s = -A[2, 0]
        out[4] = math.asin(min(1.0, max(-1.0, s)))
        out[5] = math.atan2(A[1, 0], A[0, 0])


@njit(cache=True, nogil=True)
def run_program(E, consts, ops, n_reg, n_out, mode, out, status):
    """Run ``ops`` for each sample: ``E[n, s, 6]``, ``consts[q, 3, 4]`` -> ``out[n, n_out, 6]``."""
    n = E.shape[0]
    reg = np.empty((n_reg, 3, 4))
    M = np.empty((3, 4))
    tmp = np.empty((3, 4))
    e = np.empty(6)
    for i in range(n):
        ok = True
        for s in range(E.shape[1]):
            for d in range(6):
                if not math.isfinite(E[i, s, d]):
                    ok = False
        if not ok:
            status[i] = STATUS_NONFINITE_INPUT
            for k in range(n_out):
                for d in range(6):
                    out[i, k, d] = np.nan
            continue
        st = 0
        for k in range(ops.shape[0]):
            code, dst, src, arg = ops[k, 0], ops[k, 1], ops[k, 2], ops[k, 3]
            if code == OP_SET:
                if arg < 0:
                    for r in range(3):
                        for c in range(4):
                            reg[dst, r, c] = 1.0 if r == c else 0.0
                else:
                    reg[dst] = consts[arg]
            elif code == OP_MULC:
                _mul(reg[dst], consts[arg], tmp)
                reg[dst] = tmp
            elif code == OP_MULD or code == OP_MULDI:
                for d in range(6):
                    e[d] = E[i, arg, d]
                _deviation_matrix(e, mode, M)
                if code == OP_MULDI:
                    if not _invert(M, mode, tmp):
                        st = STATUS_SINGULAR
                        break
                    M[:, :] = tmp
                _mul(reg[dst], M, tmp)
                reg[dst] = tmp
            elif code == OP_COPY:
                reg[dst] = reg[src]
            elif code == OP_LINV:
                if not _invert(reg[src], mode, M):
                    st = STATUS_SINGULAR
                    break
                _mul(M, reg[dst], tmp)
                reg[dst] = tmp
            elif code == OP_OUT:
                _extract(reg[src], mode, e)
                for d in range(6):
                    out[i, arg, d] = e[d]
        status[i] = st
        if st != 0:
            for k in range(n_out):
                for d in range(6):
                    out[i, k, d] = np.nan
