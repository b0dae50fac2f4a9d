"""A deviation chain as a small register program, run by numba or by NumPy.

The assembly graph (:mod:`.graph`) compiles into a :class:`Program`: affine
constants (nominal frames), a list of operations on a few registers and a
number of outputs.  Per sample the program multiplies nominal frames and
deviation transforms ``T(E[slot])`` (or their inverses) into registers,
forms relative poses and extracts deviation vectors.

* :func:`run_numba` — the fused kernel (:mod:`._kernels`), 3×4 affine products;
* :func:`run_numpy` — the same operations as batched 4×4 NumPy matmuls.

Both return ``(out[n, n_out, 6], status[n])``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import ModelError
from . import _kernels as K
from .transforms import MODES, extract, homogeneous, inverse, transform

OP_NAMES = {K.OP_SET: "set", K.OP_MULC: "mul_const", K.OP_MULD: "mul_dev", K.OP_MULDI: "mul_dev_inv",
            K.OP_COPY: "copy", K.OP_LINV: "left_inv", K.OP_OUT: "out"}


@dataclass
class Program:
    """Operations ``(code, dst, src, arg)`` on ``n_reg`` affine registers."""

    n_slots: int
    consts: list[np.ndarray] = field(default_factory=list)  # 4×4 each
    ops: list[tuple[int, int, int, int]] = field(default_factory=list)
    n_reg: int = 0
    n_out: int = 0

    # -- building -------------------------------------------------------------
    def const(self, T) -> int:
        T = np.asarray(T, dtype=float)
        for i, C in enumerate(self.consts):
            if np.array_equal(C, T):
                return i
        self.consts.append(T.copy())
        return len(self.consts) - 1

    def register(self) -> int:
        self.n_reg += 1
        return self.n_reg - 1

    def set(self, dst: int, T=None) -> None:
        self.ops.append((K.OP_SET, dst, -1, -1 if T is None else self.const(T)))

    def mul_const(self, dst: int, T) -> None:
        if not np.array_equal(np.asarray(T, float), np.eye(4)):
            self.ops.append((K.OP_MULC, dst, -1, self.const(T)))

    def mul_dev(self, dst: int, slot: int, inverse: bool = False) -> None:
        if not 0 <= slot < self.n_slots:
            raise ModelError(f"slot {slot} out of range")
        self.ops.append((K.OP_MULDI if inverse else K.OP_MULD, dst, -1, slot))

    def copy(self, dst: int, src: int) -> None:
        self.ops.append((K.OP_COPY, dst, src, -1))

    def left_inv(self, dst: int, src: int) -> None:
        self.ops.append((K.OP_LINV, dst, src, -1))

    def out(self, src: int) -> int:
        self.ops.append((K.OP_OUT, -1, src, self.n_out))
        self.n_out += 1
        return self.n_out - 1

    # -- arrays for the kernel -------------------------------------------------
    def arrays(self) -> tuple[np.ndarray, np.ndarray]:
        C = np.array([c[:3, :].ravel() for c in self.consts]) if self.consts else np.zeros((1, 12))
        ops = np.array(self.ops, dtype=np.int64).reshape(-1, 4)
        return np.ascontiguousarray(C), ops

    def describe(self) -> list[str]:
        return [f"{OP_NAMES[c]}(dst={d}, src={s}, arg={a})" for c, d, s, a in self.ops]

    def run(self, E, mode: str = "exact", backend: str = "numba"):
        if backend == "numba":
            return run_numba(self, E, mode)
        if backend == "numpy":
            return run_numpy(self, E, mode)
        raise ModelError(f"unknown backend {backend!r} (expected numba or numpy)")


def _check(program: Program, E, mode: str) -> np.ndarray:
    if mode not in MODES:
        raise ModelError(f"unknown transform mode {mode!r} (expected one of {MODES})")
    E = np.ascontiguousarray(E, dtype=float)
    if E.ndim != 3 or E.shape[1:] != (program.n_slots, 6):
        raise ModelError(f"E must have shape (n, {program.n_slots}, 6), got {E.shape}")
    return E


def run_numba(program: Program, E, mode: str = "exact"):
    E = _check(program, E, mode)
    C, ops = program.arrays()
    out = np.empty((E.shape[0], program.n_out, 6))
    status = np.zeros(E.shape[0], dtype=np.int16)
    K.run_program(E, C, ops, program.n_reg, program.n_out,
                  K.MODE_SMALL if mode == "small" else K.MODE_EXACT, out, status)
    return out, status


def run_numpy(program: Program, E, mode: str = "exact"):
    """The same program as batched NumPy 4×4 matmuls (reference for the kernel)."""
    E = _check(program, E, mode)
    n = E.shape[0]
    status = np.zeros(n, dtype=np.int16)
    bad = ~np.all(np.isfinite(E), axis=(1, 2))
    status[bad] = K.STATUS_NONFINITE_INPUT
    E = np.where(bad[:, None, None], 0.0, E)
    reg = np.broadcast_to(np.eye(4), (program.n_reg, n, 4, 4)).copy()
    out = np.full((n, program.n_out, 6), np.nan)
    with np.errstate(divide="ignore", invalid="ignore"):
        for code, dst, src, arg in program.ops:
            if code == K.OP_SET:
                reg[dst] = np.eye(4) if arg < 0 else program.consts[arg]
            elif code == K.OP_MULC:
                reg[dst] = reg[dst] @ program.consts[arg]
            elif code == K.OP_MULD:
                reg[dst] = reg[dst] @ transform(E[:, arg], mode)
            elif code == K.OP_MULDI:
                reg[dst] = reg[dst] @ inverse(transform(E[:, arg], mode), mode)
            elif code == K.OP_COPY:
                reg[dst] = reg[src]
            elif code == K.OP_LINV:
                reg[dst] = inverse(reg[src], mode) @ reg[dst]
            elif code == K.OP_OUT:
                out[:, arg] = extract(reg[src], mode)
    sing = ~bad & ~np.all(np.isfinite(out), axis=(1, 2))
    status[sing] = K.STATUS_SINGULAR
    out[status != 0] = np.nan
    return out, status


def chain_program(m: int) -> Program:
    """The plain chain ``Π_{i<m} T(E_i)`` followed by extraction (tests and benchmarks)."""
    p = Program(n_slots=m)
    r = p.register()
    p.set(r)
    for i in range(m):
        p.mul_dev(r, i)
    p.out(r)
    return p


__all__ = ["Program", "run_numba", "run_numpy", "chain_program", "homogeneous"]
