r"""The germs and the orthonormal polynomial basis of the expansion: one-dimensional polynomials, truncated
multi-index sets, the design matrix; the germ family of each factor.

Germ
    Each factor is mapped to a germ through its own CDF: the Monte Carlo drew
    ``x = F⁻¹(u)``, so ``u = F(x)`` recovers its uniform design
    (:func:`rvtol.sensitivity._given.u_from_samples`).  Two families (Wiener–Askey scheme,
    Xiu & Karniadakis 2002):

    * ``legendre`` — orthonormal Legendre polynomials :math:`\sqrt{2m+1}\,P_m(\xi)` of
      :math:`\xi = 2u-1 \sim \mathcal U(-1, 1)`.  Exact for uniform factors; the germ is bounded,
      so the least-squares design stays well conditioned at high degree;
    * ``hermite`` — orthonormal probabilists' Hermite polynomials :math:`He_m(z)/\sqrt{m!}` of
      :math:`z = \Phi^{-1}(u) \sim \mathcal N(0, 1)`.

    ``germs="auto"`` (the default with a spec) takes Hermite for factors whose support is
    unbounded (normal, lognormal, Rayleigh, Weibull) and Legendre for bounded ones (uniform,
    triangular, truncated normal).  Why not Legendre for all: a factor that is linear in a
    normal variable becomes :math:`\Phi^{-1}((\xi+1)/2)`, which has logarithmic singularities
    at :math:`\xi=\pm1`; its degree-1 Legendre term carries only :math:`3/\pi = 95.5\,\%` of its
    variance and the rest converges slowly, whereas in the Hermite germ it is exactly degree 1.
    Why not Hermite for all: a bounded factor (uniform phase, truncated normal) becomes a
    bounded, flat-tailed function of z that Hermite polynomials approximate slowly.
"""
from __future__ import annotations

import itertools
import math
from typing import Sequence

import numpy as np
from scipy import stats

from ...errors import InputError
from ...spec import ToleranceSpec

FAMILIES = ("legendre", "hermite")

_U_EPS = 2.0**-53


def germ(U: np.ndarray, families: Sequence[str]) -> np.ndarray:
    """The germ of each column of the uniform design ``U``: ``2u − 1`` (Legendre) or ``Φ⁻¹(u)`` (Hermite)."""
    U = np.clip(np.asarray(U, dtype=float), _U_EPS, 1.0 - _U_EPS)
    G = np.empty_like(U)
    for j, fam in enumerate(families):
        G[:, j] = 2.0 * U[:, j] - 1.0 if fam == "legendre" else stats.norm.ppf(U[:, j])
    return G


def orthonormal_1d(family: str, t: np.ndarray, degree: int) -> np.ndarray:
    """``[ψ_0(t), …, ψ_degree(t)]`` (n × degree+1), orthonormal under the germ's law.

    Legendre: three-term recurrence :math:`(m+1)P_{m+1} = (2m+1)tP_m - mP_{m-1}`, scaled by
    :math:`\\sqrt{2m+1}` (orthonormal for t ~ U(−1, 1)); Hermite:
    :math:`He_{m+1} = tHe_m - mHe_{m-1}`, scaled by :math:`1/\\sqrt{m!}` (t ~ N(0, 1)).
    """
    t = np.asarray(t, dtype=float)
    P = np.empty((t.size, degree + 1))
    P[:, 0] = 1.0
    if degree >= 1:
        P[:, 1] = t
    for m in range(1, degree):
        if family == "legendre":
            P[:, m + 1] = ((2 * m + 1) * t * P[:, m] - m * P[:, m - 1]) / (m + 1)
        else:
            P[:, m + 1] = t * P[:, m] - m * P[:, m - 1]
    m = np.arange(degree + 1)
    scale = np.sqrt(2 * m + 1.0) if family == "legendre" else 1.0 / np.sqrt([math.factorial(i) for i in m])
    return P * scale


def _patterns(j: int, degree: int, q: float) -> list[tuple[int, ...]]:
    """Tuples of ``j`` positive degrees with hyperbolic norm ≤ ``degree``."""
    budget = degree**q * (1 + 1e-12)
    out: list[tuple[int, ...]] = []

    def rec(prefix: tuple[int, ...], used: float):
        if len(prefix) == j:
            out.append(prefix)
            return
        left = j - len(prefix) - 1  # every later position needs at least degree 1 (cost 1)
        a = 1
        while used + a**q + left <= budget:
            rec(prefix + (a,), used + a**q)
            a += 1

    rec((), 0.0)
    return out


def multi_indices(k: int, degree: int, q: float = 1.0, max_interaction: int | None = None,
                  max_terms: int | None = None) -> np.ndarray | None:
    r"""The truncated set :math:`\{\alpha \in \mathbb N^k: \|\alpha\|_q \le p,\ |\mathrm{supp}\,\alpha| \le r\}`
    (p = ``degree``, r = ``max_interaction``).

    Rows ordered by interaction order, then support, then degrees; row 0 is the constant.
    Returns None when the set would have more than ``max_terms`` rows (checked before building).
    """
    if not 0 < q <= 1:
        raise InputError(f"q must be in (0, 1], got {q}", key="q")
    r = min(k, degree if max_interaction is None else max_interaction)
    blocks = [(j, _patterns(j, degree, q)) for j in range(1, r + 1)]
    blocks = [(j, p) for j, p in blocks if p]
    count = 1 + sum(math.comb(k, j) * len(p) for j, p in blocks)
    if max_terms is not None and count > max_terms:
        return None
    A = np.zeros((count, k), dtype=np.int16)
    row = 1
    for j, pats in blocks:
        pats = np.array(pats, dtype=np.int16)
        for support in itertools.combinations(range(k), j):
            A[row:row + len(pats), list(support)] = pats
            row += len(pats)
    return A


def design_matrix(G: np.ndarray, families: Sequence[str], alpha: np.ndarray) -> np.ndarray:
    """:math:`\\Psi_{i,a} = \\prod_j \\psi^{(j)}_{\\alpha_{a,j}}(g_{ij})` for germ values ``G`` (n × k); built
    term by term (a term's column is contiguous in memory: Fortran order), which OMP's scans also read fastest."""
    n = len(G)
    PsiT = np.ones((len(alpha), n))
    for j, fam in enumerate(families):
        cols = np.flatnonzero(alpha[:, j])
        if cols.size:
            deg = alpha[cols, j]
            table = orthonormal_1d(fam, G[:, j], int(deg.max()))
            PsiT[cols] *= table.T[deg]
    return PsiT.T



def germ_families(families, k: int) -> tuple[str, ...]:
    fams = (families,) * k if isinstance(families, str) else tuple(families)
    if len(fams) != k:
        raise InputError(f"{len(fams)} germ families for {k} factors", key="germs")
    for f in fams:
        if f not in FAMILIES:
            raise InputError(f"unknown germ family {f!r} (expected one of: {', '.join(FAMILIES)})", key="germs")
    return fams


def families_for_spec(spec: ToleranceSpec) -> tuple[str, ...]:
    """Hermite for factors with an unbounded support, Legendre for bounded ones (see module notes)."""
    out = []
    for f in spec.factors:
        lo, hi = (float(v) for v in f.dist.frozen.support())
        out.append("legendre" if np.isfinite(lo) and np.isfinite(hi) else "hermite")
    return tuple(out)

