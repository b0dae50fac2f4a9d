"""Statistics of 6-DOF deviation vectors (doc 003): multivariate normal model and magnitudes.

* :class:`DeviationNormal` — ``E ~ N(μ, P)`` with the document's density
  ``f(E) = (2π)^-3 |P|^-1/2 exp(-½ (E-μ)ᵀ P⁻¹ (E-μ))``; sampling through
  :func:`rvtol.sampling.rng`.  A singular ``P`` (a feature that does not
  deviate in some DOF, e.g. a planar zone) has no density in 6-D: the
  density is then taken on the DOFs that vary (``restricted``).
* :func:`linear_magnitude` ``‖e(E)‖ = √(Δu²+Δv²+Δw²+(Δα r_α)²+(Δβ r_β)²+(Δγ r_γ)²)``
  and :func:`rotational_magnitude` ``‖ε(E)‖ = √(Δu²/r_α²+Δv²/r_β²+Δw²/r_γ²+Δα²+Δβ²+Δγ²)``
  exactly as printed (note the document pairs Δu with r_α, Δv with r_β and
  Δw with r_γ in ‖ε‖); ``r`` are effective radii (mm) turning angles into
  lengths at the critical point.  ‖e‖ is a length (mm), ‖ε‖ an angle (rad).
* :func:`mean_square_magnitude` — ``E‖e‖² = Σ w_i (μ_i² + P_ii)``, the closed
  form the sampled magnitudes are checked against.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import InputError, ModelError
from ...sampling import rng
from .transforms import DOF

UNITS = ("mm", "mm", "mm", "rad", "rad", "rad")


def _radii(radii) -> np.ndarray:
    r = np.broadcast_to(np.asarray(radii, dtype=float), (3,))
    if not np.all(np.isfinite(r)) or np.any(r <= 0):
        raise InputError(f"effective radii must be finite and > 0, got {list(r)}", key="radii")
    return r


def magnitude_weights(radii, kind: str = "linear") -> np.ndarray:
    """Weights ``w`` with ``‖·‖² = Σ w_i E_i²`` for ``kind`` "linear" (‖e‖) or "rotational" (‖ε‖)."""
    r = _radii(radii)
    if kind == "linear":
        return np.concatenate([np.ones(3), r**2])
    if kind == "rotational":
        return np.concatenate([1.0 / r**2, np.ones(3)])
    raise ModelError(f"unknown magnitude kind {kind!r}")


def linear_magnitude(E, radii) -> np.ndarray:
    """‖e(E)‖ (mm) of ``E[..., 6]`` with effective radii ``(r_α, r_β, r_γ)`` in mm."""
    E = np.asarray(E, dtype=float)
    return np.sqrt(np.einsum("...i,i->...", E**2, magnitude_weights(radii, "linear")))


def rotational_magnitude(E, radii) -> np.ndarray:
    """‖ε(E)‖ (rad) of ``E[..., 6]`` with effective radii ``(r_α, r_β, r_γ)`` in mm."""
    E = np.asarray(E, dtype=float)
    return np.sqrt(np.einsum("...i,i->...", E**2, magnitude_weights(radii, "rotational")))


def mean_square_magnitude(mean, cov, radii, kind: str = "linear") -> float:
    """``E[‖·‖²] = Σ w_i (μ_i² + P_ii)`` for any distribution with that mean and covariance."""
    w = magnitude_weights(radii, kind)
    return float(np.sum(w * (np.asarray(mean, float) ** 2 + np.diag(np.asarray(cov, float)))))


@dataclass(frozen=True)
class DeviationNormal:
    """``E ~ N(mean, cov)`` over the six DOFs (u, v, w in mm; α, β, γ in rad)."""

    mean: np.ndarray
    cov: np.ndarray

    def __post_init__(self):
        m = np.asarray(self.mean, dtype=float).reshape(6)
        P = np.asarray(self.cov, dtype=float)
        if P.shape != (6, 6):
            raise InputError(f"covariance must be 6×6, got {P.shape}", key="cov")
        if not (np.all(np.isfinite(m)) and np.all(np.isfinite(P))):
            raise InputError("mean and covariance must be finite", key="cov")
        if not np.allclose(P, P.T, rtol=1e-10, atol=1e-300):
            raise InputError("covariance is not symmetric", key="cov")
        if np.linalg.eigvalsh(P).min() < -1e-12 * max(1.0, np.abs(P).max()):
            raise InputError("covariance is not positive semi-definite", key="cov")
        object.__setattr__(self, "mean", m)
        object.__setattr__(self, "cov", 0.5 * (P + P.T))

    @classmethod
    def independent(cls, mean, std) -> "DeviationNormal":
        """The document's per-DOF model ``Δx_i ~ N(μ_i, σ_i²)``, independent."""
        s = np.asarray(std, dtype=float).reshape(6)
        return cls(mean, np.diag(s**2))

    @classmethod
    def fit(cls, samples) -> "DeviationNormal":
        """Mean and covariance estimated from samples ``E[n, 6]``."""
        E = np.asarray(samples, dtype=float)
        return cls(E.mean(axis=0), np.cov(E, rowvar=False))

    @property
    def std(self) -> np.ndarray:
        return np.sqrt(np.diag(self.cov))

    @property
    def active(self) -> np.ndarray:
        """Indices of the DOFs with non-zero variance."""
        return np.flatnonzero(np.diag(self.cov) > 0)

    def restricted(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(dofs, mean, cov)`` on the varying DOFs only."""
        a = self.active
        return a, self.mean[a], self.cov[np.ix_(a, a)]

    def logpdf(self, E) -> np.ndarray:
        """Log of the document's density; on the varying DOFs when ``P`` is singular."""
        E = np.asarray(E, dtype=float)
        a, m, P = self.restricted()
        if len(a) < 6:
            fixed = np.setdiff1d(np.arange(6), a)
            off = np.any(E[..., fixed] != self.mean[fixed], axis=-1)
        else:
            off = np.zeros(E.shape[:-1], dtype=bool)
        sign, logdet = np.linalg.slogdet(P)
        if sign <= 0:
            raise ModelError("covariance is singular on its varying DOFs (perfectly correlated DOFs)")
        d = E[..., a] - m
        q = np.einsum("...i,ij,...j->...", d, np.linalg.inv(P), d)
        lp = -0.5 * len(a) * np.log(2.0 * np.pi) - 0.5 * logdet - 0.5 * q
        return np.where(off, -np.inf, lp)

    def pdf(self, E) -> np.ndarray:
        """``f(E) = (2π)^-3 |P|^-1/2 exp(-½ (E-μ)ᵀ P⁻¹ (E-μ))`` (the document's formula, 6 DOFs)."""
        return np.exp(self.logpdf(E))

    def sample(self, n: int, seed: int | None = None) -> np.ndarray:
        """``n`` deviation vectors ``E[n, 6]`` (eigen-decomposition, so a singular ``P`` works)."""
        w, V = np.linalg.eigh(self.cov)
        L = V * np.sqrt(np.clip(w, 0.0, None))
        z = rng(seed).standard_normal((n, 6))
        return self.mean + z @ L.T

    def to_frame(self):
        import pandas as pd

        return pd.DataFrame({"dof": DOF, "unit": UNITS, "mean": self.mean, "std": self.std})
