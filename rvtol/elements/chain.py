"""Compliance chain helpers: springs in series/parallel, radius and ratio transforms, virtual-work breakdown.

Conventions (rvtol base units): translational stiffness ``k`` in N/mm, torsional
stiffness ``K`` in N·mm/rad, torque ``T`` in N·mm, angles in rad (reported in
arcsec with :func:`arcsec`).

**Series and parallel.**  Springs that carry the same force add compliances,
springs that share the same deformation add stiffnesses::

    1/k_series = Σ 1/k_i            k_parallel = Σ k_i

**Radius and ratio.**  A translational spring ``k`` acting tangentially at
radius ``r`` of a member resists its rotation with ``K = k r²``; an element of
torsional stiffness ``K`` on a member that turns ``i`` times as fast as the
output (input shaft: ``i`` = reduction ratio) is seen at the output as
``K i²`` (its twist is ``T/(i K)`` under the torque ``T/i``, and that twist
turns the output by ``1/i`` of it).

**Virtual-work breakdown.**  Let a structure carry the output torque ``T`` and
let ``f_e`` be the (generalised) force and ``δ_e`` the (generalised)
deformation of element ``e``.  The forces ``f_e / T`` are in equilibrium with
a unit output torque and the deformations ``δ_e`` are compatible with the
output rotation ``θ``, so the principle of complementary virtual work (the
unit-load method; e.g. Timoshenko & Gere, *Mechanics of Materials*, or
Przemieniecki, *Theory of Matrix Structural Analysis*, ch. 3) gives exactly::

    θ = Σ_e (f_e / T) · δ_e = Σ_e θ_e,      θ_e = f_e · δ_e / T

for any small-displacement structure, statically determinate or not, linear
or not.  For a linear element ``δ_e = f_e / k_e`` and ``θ_e = f_e² / (k_e T)``;
the ``θ_e`` are then also twice the element's share of the strain energy
divided by ``T`` (Clapeyron).  For nonlinear elements the split depends on
using the *actual* forces as the virtual system; this is the split rvtol
reports (the same as :mod:`rvtol.models.stiffness.torsion_angle`).

**Nonlinear springs in series.**  Two springs carrying the same force ``F``
deform by ``δ(F) = Σ δ_i(F)``; the force at a given total deformation is
found by inverting that monotonic sum numerically (:func:`series_force`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Mapping, Sequence

import numpy as np
import pandas as pd
from scipy.optimize import brentq

from .. import units
from ..errors import SolverError, SpecError
from . import _checks

ARCSEC_PER_RAD = 648000.0 / np.pi


def series(*stiffness):
    """Stiffness of springs in series: ``k = 1 / Σ (1/k_i)`` (same unit as the ``k_i``).

    Each ``k_i > 0``; ``inf`` is a rigid element.  Arrays broadcast.
    """
    if not stiffness:
        raise SpecError("give at least one stiffness", key="stiffness")
    ks = [_checks.positive(f"stiffness[{i}]", k, allow_inf=True) for i, k in enumerate(stiffness)]
    with np.errstate(divide="ignore"):
        c = sum(1.0 / k for k in ks)
        return 1.0 / c


def parallel(*stiffness):
    """Stiffness of springs in parallel: ``k = Σ k_i`` (each ``k_i >= 0``, arrays broadcast)."""
    if not stiffness:
        raise SpecError("give at least one stiffness", key="stiffness")
    return sum(_checks.nonnegative(f"stiffness[{i}]", k, allow_inf=True) for i, k in enumerate(stiffness))


def torsional_from_translational(k, radius):
    """``K = k r²`` (N·mm/rad) of a tangential spring ``k`` (N/mm) at radius ``r`` (mm)."""
    return _checks.positive("k", k, allow_inf=True) * _checks.positive("radius", radius) ** 2


def translational_from_torsional(K, radius):
    """``k = K / r²`` (N/mm): the tangential stiffness at radius ``r`` (mm) of a torsional spring ``K``."""
    return _checks.positive("K", K, allow_inf=True) / _checks.positive("radius", radius) ** 2


def reflected_to_output(K, ratio):
    """Torsional stiffness seen at the output, ``K i²``, of an element on a member turning ``i`` × the output.

    ``ratio`` is the speed ratio member/output (> 0), e.g. the reduction ratio for the input shaft.
    """
    return _checks.positive("K", K, allow_inf=True) * _checks.positive("ratio", ratio) ** 2


def arcsec(angle_rad):
    """Angle in arcsec from rad."""
    return units.from_base(np.asarray(angle_rad, dtype=float), "arcsec")


def output_angle(torque, K):
    """Rotation ``T / K`` (rad) of a torsional spring ``K`` (N·mm/rad) under torque ``T`` (N·mm)."""
    return _checks.finite("torque", torque) / _checks.positive("K", K, allow_inf=True)


def linear_contribution(torque, force, stiffness):
    """``θ_e = f_e² / (k_e T)`` (rad): contribution of a linear element to the output rotation.

    ``force`` (N or N·mm) and ``stiffness`` (N/mm or N·mm/rad) of the element under the output
    torque ``torque`` (N·mm, non-zero).
    """
    T = _nonzero_torque(torque)
    k = _checks.positive("stiffness", stiffness, allow_inf=True)
    f = _checks.finite("force", force)
    return f * f / k / T


def virtual_work(torque, force, deformation):
    """``θ_e = Σ f·δ / T`` (rad), summed over every axis of ``force·deformation`` beyond ``torque``'s.

    ``torque`` has shape ``()`` or ``(n,)`` (load cases); ``force`` and ``deformation`` broadcast to
    ``torque.shape + (...)`` (vector components, several identical elements...).  Work-conjugate
    units: N with mm, or N·mm with rad.
    """
    T = _nonzero_torque(torque)
    p = _checks.finite("force", force) * _checks.finite("deformation", deformation)
    p = np.broadcast_to(p, np.broadcast_shapes(p.shape, T.shape)) if p.ndim < T.ndim else p
    if p.shape[:T.ndim] != T.shape and T.ndim:
        raise SpecError(f"leading axes of force*deformation {p.shape} must match the torque {T.shape}",
                        key="force")
    axes = tuple(range(T.ndim, p.ndim))
    return p.sum(axis=axes) / T if axes else p / T


def _nonzero_torque(torque):
    T = _checks.finite("torque", torque)
    if np.any(T == 0):
        raise SpecError("must be non-zero (the breakdown divides by the torque)", key="torque")
    return T


@dataclass
class Breakdown:
    """Per-element output rotation (rad) under one or more output torques (N·mm).

    ``theta[i, e]`` is element ``e``'s contribution in load case ``i``; :attr:`total` their sum.
    """

    torque: np.ndarray
    names: tuple
    theta: np.ndarray

    @classmethod
    def from_contributions(cls, torque, contributions: Mapping[str, np.ndarray]) -> "Breakdown":
        T = np.atleast_1d(_nonzero_torque(torque))
        names = tuple(contributions)
        if not names:
            raise SpecError("give at least one element", key="contributions")
        cols = [np.broadcast_to(np.asarray(contributions[n], dtype=float), T.shape) for n in names]
        return cls(T, names, np.stack(cols, axis=1))

    @classmethod
    def from_elements(cls, torque, elements: Mapping[str, tuple]) -> "Breakdown":
        """``elements[name] = (force, deformation)``, see :func:`virtual_work`."""
        T = np.atleast_1d(_nonzero_torque(torque))
        contrib = {}
        for name, fd in elements.items():
            f, d = fd
            f = np.asarray(f, float)
            d = np.asarray(d, float)
            if np.ndim(torque) == 0:       # one load case: add the case axis
                f, d = f[None, ...], d[None, ...]
            contrib[name] = virtual_work(T, f, d)
        return cls.from_contributions(T, contrib)

    @property
    def total(self) -> np.ndarray:
        return self.theta.sum(axis=1)

    @property
    def stiffness(self) -> np.ndarray:
        """Secant torsional stiffness ``T / θ_total`` (N·mm/rad)."""
        return self.torque / self.total

    def to_frame(self, row: int = 0) -> pd.DataFrame:
        a = arcsec(self.theta[row])
        tot = float(a.sum())
        df = pd.DataFrame({"element": list(self.names), "θ (arcsec)": a,
                           "share (%)": 100.0 * a / tot if tot else np.nan})
        return pd.concat([df, pd.DataFrame({"element": ["Total"], "θ (arcsec)": [tot], "share (%)": [100.0]})],
                         ignore_index=True)


# --------------------------------------------------------------------------------------------------
# nonlinear springs in series
# --------------------------------------------------------------------------------------------------

Law = Callable[[np.ndarray], np.ndarray]


def series_deflection(force, laws: Sequence[Law]):
    """``δ(F) = Σ δ_i(F)``: deformation of springs in series carrying the same force ``F``."""
    F = _checks.nonnegative("force", force)
    if not laws:
        raise SpecError("give at least one load-deflection law", key="laws")
    return sum(np.asarray(law(F), dtype=float) for law in laws)


def series_force(deflection, laws: Sequence[Law], *, force_scale: float = 1.0, rtol: float = 1e-12):
    """Force ``F`` with ``Σ δ_i(F) = δ`` for springs in series (each ``δ_i`` increasing, ``δ_i(0) = 0``).

    Solved per value by bracketing (doubling from ``force_scale``) and Brent's method to ``rtol``.
    """
    d = _checks.nonnegative("deflection", deflection)
    _checks.positive("force_scale", force_scale)
    out = np.zeros(d.shape)
    flat = out.reshape(-1)
    for j, dj in enumerate(d.reshape(-1)):
        if dj == 0.0:
            continue

        def g(F, dj=dj):
            return float(series_deflection(F, laws)) - dj

        hi = float(force_scale)
        for _ in range(200):
            if g(hi) > 0:
                break
            hi *= 2.0
        else:
            raise SolverError(f"series_force: no force up to {hi:g} N reaches the deflection {dj:g} mm")
        flat[j] = brentq(g, 0.0, hi, xtol=1e-300, rtol=max(rtol, 4 * np.finfo(float).eps), maxiter=500)
    return out


def tangent_compliance(force, law: Law, rel_step: float = 1e-6):
    """``dδ/dF`` of a load-deflection law at ``F > 0`` (central difference with step ``rel_step·F``)."""
    F = _checks.positive("force", force)
    h = rel_step * F
    return (np.asarray(law(F + h), float) - np.asarray(law(F - h), float)) / (2.0 * h)
