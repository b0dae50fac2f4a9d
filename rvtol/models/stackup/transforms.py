"""Homogeneous transforms of 6-DOF deviation vectors, batched over samples.

A deviation vector is ``E = (Δu, Δv, Δw, Δα, Δβ, Δγ)`` (doc 003): translations
along x, y, z (mm) and rotations about x, y, z (rad), in the frame of the
feature it belongs to.  Arrays of them have shape ``(..., 6)``; every function
here works on any leading shape without Python loops over samples.

Two transforms, both ``T = Trans × Rot`` (rotate first, then translate, so
``t`` is the last column of ``T``):

* :func:`small_angle` — the document's matrix, ``Rot = I + [ω]×`` with
  ``ω = (Δα, Δβ, Δγ)``; not orthogonal (error O(angle²)).
* :func:`exact` — the rotation ``R = Rz(Δγ)·Ry(Δβ)·Rx(Δα)``: rotations about
  the *fixed* x, then y, then z axes (equivalently intrinsic z-y'-x''; the
  "roll-pitch-yaw" convention).  Its first-order expansion is exactly the
  document's ``I + [ω]×``, so the two agree to first order.

:func:`extract` inverts either transform exactly for a single matrix: the
small-angle one by the skew part of ``R`` (``Δα = (R₂₁ − R₁₂)/2`` …), the
exact one by the Euler angles of the convention above.  Applied to a product
of transforms it returns the resulting (total) deviation.

The 3×3 part of products of small-angle matrices is a general matrix, so
:func:`inverse` inverts it by the adjugate; exact transforms by the transpose.
The fused numba kernel in :mod:`._kernels` implements the same equations.
"""
from __future__ import annotations

import numpy as np

from ...errors import ModelError

DOF = ("u", "v", "w", "alpha", "beta", "gamma")
MODES = ("small", "exact")


def _check(E) -> np.ndarray:
    E = np.asarray(E, dtype=float)
    if E.shape[-1:] != (6,):
        raise ModelError(f"deviation vectors need a last axis of length 6, got shape {E.shape}")
    return E


def skew(w) -> np.ndarray:
    """``[ω]×`` for ``w[..., 3]``: the matrix with ``[ω]× p = ω × p``."""
    w = np.asarray(w, dtype=float)
    S = np.zeros(w.shape[:-1] + (3, 3))
    S[..., 0, 1], S[..., 0, 2] = -w[..., 2], w[..., 1]
    S[..., 1, 0], S[..., 1, 2] = w[..., 2], -w[..., 0]
    S[..., 2, 0], S[..., 2, 1] = -w[..., 1], w[..., 0]
    return S


def rotation_small(w) -> np.ndarray:
    """The document's small-angle rotation ``I + [ω]×`` (3×3)."""
    return np.eye(3) + skew(w)


def rotation_exact(w) -> np.ndarray:
    """``Rz(γ)·Ry(β)·Rx(α)`` for ``w = (α, β, γ)`` (3×3, orthonormal)."""
    w = np.asarray(w, dtype=float)
    ca, sa = np.cos(w[..., 0]), np.sin(w[..., 0])
    cb, sb = np.cos(w[..., 1]), np.sin(w[..., 1])
    cg, sg = np.cos(w[..., 2]), np.sin(w[..., 2])
    R = np.empty(w.shape[:-1] + (3, 3))
    R[..., 0, 0] = cg * cb
    R[..., 0, 1] = cg * sb * sa - sg * ca
    R[..., 0, 2] = cg * sb * ca + sg * sa
    R[..., 1, 0] = sg * cb
    R[..., 1, 1] = sg * sb * sa + cg * ca
    R[..., 1, 2] = sg * sb * ca - cg * sa
    R[..., 2, 0] = -sb
    R[..., 2, 1] = cb * sa
    R[..., 2, 2] = cb * ca
    return R


def homogeneous(R, t) -> np.ndarray:
    """``[[R, t], [0, 0, 0, 1]]`` from ``R[..., 3, 3]`` and ``t[..., 3]``."""
    R = np.asarray(R, dtype=float)
    T = np.zeros(R.shape[:-2] + (4, 4))
    T[..., :3, :3] = R
    T[..., :3, 3] = t
    T[..., 3, 3] = 1.0
    return T


def small_angle(E) -> np.ndarray:
    """The document's ``T = Trans × Rot`` with ``Rot ≈ I + [ω]×`` (shape ``(..., 4, 4)``)."""
    E = _check(E)
    return homogeneous(rotation_small(E[..., 3:]), E[..., :3])


def exact(E) -> np.ndarray:
    """``T = Trans × Rot`` with the exact rotation ``Rz(Δγ)·Ry(Δβ)·Rx(Δα)``."""
    E = _check(E)
    return homogeneous(rotation_exact(E[..., 3:]), E[..., :3])


def transform(E, mode: str = "exact") -> np.ndarray:
    """:func:`small_angle` or :func:`exact` by ``mode``."""
    if mode == "small":
        return small_angle(E)
    if mode == "exact":
        return exact(E)
    raise ModelError(f"unknown transform mode {mode!r} (expected one of {MODES})")


def extract(T, mode: str = "exact") -> np.ndarray:
    """The deviation vector of ``T[..., 4, 4]`` (inverse of :func:`transform` for one matrix)."""
    T = np.asarray(T, dtype=float)
    R = T[..., :3, :3]
    E = np.empty(T.shape[:-2] + (6,))
    E[..., :3] = T[..., :3, 3]
    if mode == "small":
        E[..., 3] = 0.5 * (R[..., 2, 1] - R[..., 1, 2])
        E[..., 4] = 0.5 * (R[..., 0, 2] - R[..., 2, 0])
        E[..., 5] = 0.5 * (R[..., 1, 0] - R[..., 0, 1])
    elif mode == "exact":
        E[..., 3] = np.arctan2(R[..., 2, 1], R[..., 2, 2])
        E[..., 4] = np.arcsin(np.clip(-R[..., 2, 0], -1.0, 1.0))
        E[..., 5] = np.arctan2(R[..., 1, 0], R[..., 0, 0])
    else:
        raise ModelError(f"unknown transform mode {mode!r} (expected one of {MODES})")
    return E


def inverse(T, mode: str = "exact") -> np.ndarray:
    """Inverse of homogeneous transforms: transpose (exact) or adjugate (small-angle products)."""
    T = np.asarray(T, dtype=float)
    R, t = T[..., :3, :3], T[..., :3, 3]
    if mode == "exact":
        Ri = np.swapaxes(R, -1, -2)
    elif mode == "small":
        Ri = inverse3(R)
    else:
        raise ModelError(f"unknown transform mode {mode!r} (expected one of {MODES})")
    return homogeneous(Ri, -np.einsum("...ij,...j->...i", Ri, t))


def inverse3(A) -> np.ndarray:
    """Inverse of ``A[..., 3, 3]`` by the adjugate (the formula the numba kernel uses)."""
    A = np.asarray(A, dtype=float)
    C = np.empty_like(A)
    for i in range(3):
        for j in range(3):
            i1, i2 = (i + 1) % 3, (i + 2) % 3
            j1, j2 = (j + 1) % 3, (j + 2) % 3
            # cofactor of element (j, i): the adjugate is the transposed cofactor matrix
            C[..., i, j] = A[..., j1, i1] * A[..., j2, i2] - A[..., j1, i2] * A[..., j2, i1]
    det = np.einsum("...i,...i->...", A[..., 0, :], C[..., :, 0])
    return C / det[..., None, None]


def compose(Ts) -> np.ndarray:
    """``Π T_i`` along axis -3 of ``Ts[..., m, 4, 4]`` (assembly order, left to right)."""
    Ts = np.asarray(Ts, dtype=float)
    out = Ts[..., 0, :, :]
    for i in range(1, Ts.shape[-3]):  # loop over chain links, never over samples
        out = out @ Ts[..., i, :, :]
    return out


def chain_deviation(E, mode: str = "exact") -> np.ndarray:
    """Total deviation of a chain ``E[..., m, 6]``: ``extract(Π transform(E_i))``."""
    return extract(compose(transform(E, mode)), mode)


def adjoint(T) -> np.ndarray:
    """6×6 map of a small deviation in the frame *before* nominal transform ``T`` to the frame after.

    If ``D = I + ξ^`` is a small deviation followed by the nominal ``T =
    [[R, p]]``, then ``D·T = T·(I + (Ad ξ)^)`` with ``Ad = [[Rᵀ, −Rᵀ[p]×],
    [0, Rᵀ]]`` acting on ``ξ = (t, ω)`` — the small-displacement-torsor
    transport used by the linearised chain.
    """
    T = np.asarray(T, dtype=float)
    Rt = np.swapaxes(T[..., :3, :3], -1, -2)
    A = np.zeros(T.shape[:-2] + (6, 6))
    A[..., :3, :3] = Rt
    A[..., :3, 3:] = -Rt @ skew(T[..., :3, 3])
    A[..., 3:, 3:] = Rt
    return A
