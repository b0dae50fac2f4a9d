r"""Sobol indices from a polynomial chaos expansion (PCE) fitted on samples already computed.

The Monte Carlo of a study already holds n model runs ``(X, Y)``.  A PCE fitted on them gives
first-, total- and second-order Sobol indices *analytically from its coefficients*, with no
further model run (Sudret 2008).  The Saltelli route (:func:`rvtol.sensitivity.sobol`) stays
available; this one costs a least-squares fit instead of n·(k+2) runs.

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

Truncation and degree (Blatman & Sudret 2011)
    Multi-indices :math:`\alpha` with hyperbolic norm
    :math:`\|\alpha\|_q = (\sum_i \alpha_i^q)^{1/q} \le p` (``q = 1``: total degree; the
    default 0.75 favours main effects and low-rank interactions, the "sparsity of effects") and
    at most ``max_interaction`` active factors.  The degree p = 1, 2, … is chosen by the
    corrected leave-one-out error; the search stops when the error has risen for two degrees in
    a row, when the basis would exceed n/``oversampling`` terms (OLS) or ``max_terms``
    candidates (OMP), or at ``max_degree``.

Fit
    ``method="ols"``: ordinary least squares on the whole truncated basis, with the closed-form
    leave-one-out residuals :math:`(y_i - \hat y_i)/(1 - h_i)` (:math:`h_i` the leverages,
    Blatman & Sudret 2010) and the correction factor of Chapelle et al. (2002)
    :math:`T = \frac{n}{n-P}\,(1 + \mathrm{tr}((\Psi^T\Psi)^{-1}))`:
    :math:`\varepsilon^*_{LOO} = T\,\frac{1}{n}\sum_i \left(\frac{y_i-\hat y_i}{1-h_i}\right)^2 / \hat V[Y]`.

    ``method="omp"`` (default): a sparse expansion.  Orthogonal matching pursuit (Pati et al.
    1993) lets the candidate terms in one at a time, each time the one most correlated with the
    residual; every leading set is an OLS fit whose corrected LOO error is known in O(n) from the
    incremental QR factors, and the set with the smallest error is kept — the hybrid "greedy
    selection + OLS scored by LOO" of Blatman & Sudret (2011), with OMP in place of LAR as in
    Jakeman et al. (2015) and UQLab.  It keeps the tens to hundreds of terms that matter out of
    thousands of candidates, which OLS cannot fit with 35 factors.  (scikit-learn's
    ``lars_path`` took 36 s per path on a 3 200 × 6 196 design and its OMP does not expose the
    per-step LOO, hence the few lines here.)  The LOO error of a selected set is optimistic —
    the selection looked at the same data — which is why the hold-out check below exists.

Sobol indices (Sudret 2008)
    With :math:`Y \approx \sum_\alpha c_\alpha \Psi_\alpha`, :math:`D = \sum_{\alpha\ne0} c_\alpha^2`:

    .. math::
        S_i = \frac{1}{D}\sum_{\alpha \in \mathcal A_i} c_\alpha^2,\ \
        \mathcal A_i = \{\alpha: \alpha_i > 0, \alpha_{j\ne i} = 0\};\qquad
        S_{T,i} = \frac{1}{D}\sum_{\alpha_i > 0} c_\alpha^2;\qquad
        S_{ij} = \frac{1}{D}\sum_{\mathrm{supp}\,\alpha = \{i,j\}} c_\alpha^2 .

Validation
    * the LOO :math:`Q^2 = 1 - \varepsilon_{LOO}` of the final fit (on all samples);
    * a hold-out check: the degree and terms are chosen on a random (1 − ``holdout``) part,
      the fit predicts the rest: :math:`Q^2_{hold}` and the relative RMSE
      (RMSE / standard deviation of the held-out outputs).  The final coefficients are then
      refitted on all samples with the chosen terms.

    The fit is called **reliable** when :math:`\min(Q^2_{LOO}, Q^2_{hold}) \ge` ``min_q2``
    (0.95 by default).  Rationale: the variance the surrogate misses,
    :math:`(1-Q^2)\,V[Y]`, belongs to terms it lacks, which may be any factor's; so each index
    can be off by up to about :math:`1 - Q^2` beyond its interval (reported as
    ``bias_bound``).  At 0.95 that is 0.05, the size of the Saltelli intervals of the TE study
    (±0.02–0.08 at n = 256).  An unreliable fit's indices are withheld (NaN in ``frame``, the
    raw values in ``raw``) with a :class:`PoorSurrogateWarning`, or raise
    :class:`SurrogateError` (``on_poor_fit="raise"``), or are kept with the warning
    (``on_poor_fit="warn"``).

Confidence intervals
    ``ci="bootstrap"``: the rows are resampled with replacement ``num_resamples`` times and the
    **selected** terms refitted by OLS each time (Efron's pairs bootstrap); ``ci="asymptotic"``:
    coefficient vectors are drawn from the normal law with the heteroscedasticity-consistent
    (HC3) sandwich covariance :math:`R^{-1}Q^T\mathrm{diag}(e_i^2/(1-h_i)^2)QR^{-T}` — one
    factorisation instead of one per resample, for large bases.  Either way the interval covers
    the **sampling of the design** (which n points the Monte Carlo drew), conditional on the
    selected basis: it does **not** cover the surrogate's truncation bias (see ``bias_bound``)
    nor the variability of the term selection.  ``S1_conf`` etc. are half-widths
    :math:`z_{(1+c)/2}\,\mathrm{sd}_{boot}` as SALib reports them; ``S1_low``/``S1_high`` the
    percentile interval.  Measured: over 40 Ishigami designs of n = 600 the 95 % bootstrap
    intervals held the closed-form S1 and ST every time (conservative: with P up to n/2 terms a
    resample of ~63 % distinct rows overstates the spread; the HC3 intervals were ~12 % narrower
    and also held); over 20 designs each of Ishigami, Sobol' G and the linear test model the
    test rule (Bonferroni level + ``bias_bound``) never failed.

When it fails
    A peak-to-peak output with clearances is far from polynomial: on the TE study's 10 000
    Monte Carlo runs (te_pp, 35 factors) the best sparse expansion reaches Q² ≈ 0.65 (LOO) /
    0.60 (hold-out), ~0.8 even in the Cartesian components of the eccentricity vectors, so its
    indices are withheld; the given-data first-order indices
    (:mod:`rvtol.sensitivity.given_data`) are the ones to read there.

Independence
    PCE Sobol indices assume independent factors.  A correlated spec (or a sample whose rank
    correlations say so) gets a :class:`CorrelatedInputsWarning` and a note; the indices are
    then those of the surrogate with independent margins and the delta index is the valid
    measure.

References
    * B. Sudret (2008), Global sensitivity analysis using polynomial chaos expansions,
      Reliability Engineering & System Safety 93(7), 964–979.
    * G. Blatman, B. Sudret (2010), An adaptive algorithm to build up sparse polynomial chaos
      expansions for stochastic finite element analysis, Prob. Eng. Mech. 25(2), 183–197.
    * G. Blatman, B. Sudret (2011), Adaptive sparse polynomial chaos expansion based on least
      angle regression, J. Comput. Phys. 230(6), 2345–2367 (hyperbolic truncation, hybrid
      selection + OLS, corrected LOO).
    * O. Chapelle, V. Vapnik, Y. Bengio (2002), Model selection for small sample regression,
      Machine Learning 48, 9–23.
    * Y. C. Pati, R. Rezaiifar, P. S. Krishnaprasad (1993), Orthogonal matching pursuit,
      Proc. 27th Asilomar Conference on Signals, Systems and Computers, 40–44.
    * J. D. Jakeman, M. S. Eldred, K. Sargsyan (2015), Enhancing ℓ1-minimization estimates of
      polynomial chaos expansions using basis selection, J. Comput. Phys. 289, 18–34.
    * D. Xiu, G. E. Karniadakis (2002), The Wiener–Askey polynomial chaos for stochastic
      differential equations, SIAM J. Sci. Comput. 24(2), 619–644.
"""
from __future__ import annotations

import itertools
import math
import warnings
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
import pandas as pd
from scipy import linalg, stats

from ..errors import InputError, RvtolError
from ..model import Model
from ..records import frame_records
from ..sampling import SampleSet, substream
from ..spec import ToleranceSpec
from ._given import (CorrelatedInputsWarning, correlated_pairs, describe_pairs, given_samples,
                     u_from_samples)
from .common import factor_indices, output_indices
from .global_ import GlobalSensitivityResult
from . import notes as N

FAMILIES = ("legendre", "hermite")
METHODS = ("lars", "ols", "omp")
CI_METHODS = ("bootstrap", "asymptotic")
POOR_FIT = ("withhold", "warn", "raise")

#: default minimum Q² (LOO and hold-out) for the indices to be reported as reliable
MIN_Q2 = 0.95
#: default hyperbolic norm q and maximum degree of the degree search
Q_NORM = 0.75
MAX_DEGREE = 10
#: OMP candidate design size by default: n × candidates ≤ this many entries (200 MB of doubles)
OMP_MAX_ENTRIES = 25_000_000
#: OMP steps (terms entering) by default
OMP_MAX_STEPS = 500

_U_EPS = 2.0**-53


class SurrogateError(RvtolError, RuntimeError):
    """The surrogate is not accurate enough for its indices to be used (``on_poor_fit="raise"``)."""


class PoorSurrogateWarning(UserWarning):
    """The surrogate's validation Q² is below the threshold: its indices are not reliable."""


# --------------------------------------------------------------------------- polynomials
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


# --------------------------------------------------------------------------- least squares
@dataclass
class _OLS:
    coef: np.ndarray
    resid: np.ndarray
    h: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    loo: float            # ε_LOO relative to the output variance
    loo_corrected: float  # ε*_LOO (Chapelle correction)


def _ols(Psi: np.ndarray, y: np.ndarray, var_y: float) -> _OLS | None:
    """OLS by QR with the closed-form LOO error; None when the design is (numerically) rank deficient."""
    n, P = Psi.shape
    if P >= n:
        return None
    Q, R = np.linalg.qr(Psi)
    d = np.abs(np.diag(R))
    if d.min() <= 1e-10 * d.max():
        return None
    coef = linalg.solve_triangular(R, Q.T @ y)
    resid = y - Psi @ coef
    h = np.einsum("ij,ij->i", Q, Q)
    if h.max() >= 1.0 - 1e-10:
        return None
    loo = float(np.mean((resid / (1.0 - h)) ** 2) / var_y)
    Rinv = linalg.solve_triangular(R, np.eye(P))
    T = n / (n - P) * (1.0 + float(np.sum(Rinv**2)))
    return _OLS(coef, resid, h, Q, R, loo, loo * T)


def _omp(Psi: np.ndarray, y: np.ndarray, var_y: float, max_steps: int, patience: int = 30):
    r"""Orthogonal matching pursuit with the corrected LOO error of every step; ``(columns, _OLS)`` of the best.

    Column 0 (the constant) is always in.  Each step adds the candidate most correlated with
    the residual (correlation / column norm) and orthogonalises it against the active set
    (Gram–Schmidt, twice), so the OMP residual *is* the OLS residual of the active set, the
    leverages grow by :math:`q^2` and :math:`\mathrm{tr}((\Psi^T\Psi)^{-1}) = \|R^{-1}\|_F^2`
    grows by :math:`(\|R^{-1}a\|^2 + 1)/\rho^2`: the corrected LOO error of each step costs
    O(n) on top of the O(nP) correlation search.  The scan stops ``patience`` steps after the
    best error so far.
    """
    n, P = Psi.shape
    norms = np.sqrt(np.einsum("ij,ij->j", Psi, Psi))
    norms[norms == 0] = np.inf
    Q = np.empty((n, min(max_steps, P) + 1))
    Rinv = np.zeros((Q.shape[1], Q.shape[1]))
    Q[:, 0] = Psi[:, 0] / norms[0]
    Rinv[0, 0] = 1.0 / norms[0]
    r = y - Q[:, 0] * (Q[:, 0] @ y)
    h = Q[:, 0] ** 2
    tr = Rinv[0, 0] ** 2
    cols, avail = [0], np.ones(P, dtype=bool)
    avail[0] = False
    best, best_err = 1, np.inf
    Psi32 = Psi.astype(np.float32)
    while len(cols) <= max_steps and avail.any():
        s = len(cols)
        j = _most_correlated(Psi, Psi32, r, norms, avail)
        avail[j] = False
        v = Psi[:, j].copy()
        a = Q[:, :s].T @ v
        v -= Q[:, :s] @ a
        a2 = Q[:, :s].T @ v  # second Gram–Schmidt pass
        v -= Q[:, :s] @ a2
        a += a2
        rho = float(np.linalg.norm(v))
        if rho <= 1e-8 * norms[j]:
            continue  # numerically in the span of the active set
        q = v / rho
        Q[:, s] = q
        ra = Rinv[:s, :s] @ a
        Rinv[:s, s] = -ra / rho
        Rinv[s, s] = 1.0 / rho
        tr += (ra @ ra + 1.0) / rho**2
        r -= q * (q @ r)
        h += q**2
        cols.append(j)
        m = s + 1
        if h.max() >= 1.0 - 1e-10 or m >= n:
            break
        err = float(np.mean((r / (1.0 - h)) ** 2) / var_y) * n / (n - m) * (1.0 + tr)
        if err < best_err:
            best, best_err = m, err
        elif m - best >= patience:
            break
    sel = np.array(cols[:best])
    return sel, _ols(Psi[:, sel], y, var_y)


def _most_correlated(Psi: np.ndarray, Psi32: np.ndarray, r: np.ndarray, norms: np.ndarray, avail: np.ndarray) -> int:
    r"""The available column of largest :math:`|\Psi_j \cdot r| / \|\Psi_j\|` — the float64 scan's choice, found by
    a float32 scan and a float64 look at the columns that scan cannot tell apart (the look is a product of its own:
    where two columns tie to float64's last bit, it may pick the other one).

    OMP reads all of Ψ once per step and that read is its cost: float32 halves it (RV-80E TE study, 1600 × 9696
    candidates: 2.7 against 8.5 ms a scan).  The float32 product's error is at most
    :math:`\gamma_{n+2} \|\Psi_j\| \|r\|` with :math:`\gamma_m = m u / (1 - m u)`, ``u`` float32's unit
    round-off (the dot product's forward error bound, Higham, *Accuracy and Stability of Numerical Algorithms*,
    2nd ed., §3.1, with the rounding of Ψ and r to float32 as two more factors ``1 + δ``; Cauchy–Schwarz for the
    sum of the terms' magnitudes).  The float64 scan's own error, :math:`\gamma_n` in float64's round-off, is
    added to it.  So every column within twice that of the float32 maximum, and only those, can be the float64
    maximum; they are compared in float64."""
    n = Psi.shape[0]

    def gamma(m: int, dtype) -> float:
        mu = m * float(np.finfo(dtype).eps) / 2.0
        return mu / (1.0 - mu)

    width = 2.0 * (gamma(n + 2, np.float32) + gamma(n, np.float64)) * float(np.linalg.norm(r))
    c = np.abs(Psi32.T @ r.astype(np.float32)) / norms
    c[~avail] = -np.inf
    near = np.flatnonzero(c >= c.max() - width)
    if near.size == 1:
        return int(near[0])
    return int(near[np.argmax(np.abs(Psi[:, near].T @ r) / norms[near])])


def _lars(G: np.ndarray, y: np.ndarray, families, degree: int, q: float, size: int) -> np.ndarray:
    """The terms OpenTURNS' functional chaos keeps out of the hyperbolic set of ``degree`` (its first ``size``
    terms): least-angle regression (``ot.LARS``) along the path, the step chosen by the corrected leave-one-out
    error (``ot.CorrectedLeaveOneOut``) — Blatman & Sudret (2011) as OpenTURNS implements it.  Returns the
    multi-indices (row 0 the constant) in rvtol's orthonormal basis (the same Legendre and Hermite polynomials)."""
    import openturns as ot

    ot.Log.Show(ot.Log.NONE)
    k = G.shape[1]
    margins = [ot.Uniform(-1.0, 1.0) if f == "legendre" else ot.Normal(0.0, 1.0) for f in families]
    factories = [ot.LegendreFactory() if f == "legendre" else ot.HermiteFactory() for f in families]
    enum = ot.HyperbolicAnisotropicEnumerateFunction(k, q)
    basis = ot.OrthogonalProductPolynomialFactory(factories, enum)
    selection = ot.LeastSquaresMetaModelSelectionFactory(ot.LARS(), ot.CorrectedLeaveOneOut())
    algo = ot.FunctionalChaosAlgorithm(ot.Sample(G), ot.Sample(y[:, None]), ot.JointDistribution(margins),
                                       ot.FixedStrategy(basis, size), ot.LeastSquaresStrategy(selection))
    algo.run()
    idx = list(algo.getResult().getIndices())
    alpha = np.array([list(enum(int(i))) for i in idx], dtype=np.int16)
    order = np.lexsort(alpha.T[::-1])   # the constant first, then as OpenTURNS enumerates
    alpha = alpha[order]
    if np.any(alpha[0]):
        alpha = np.vstack([np.zeros((1, k), dtype=np.int16), alpha])
    return alpha


@dataclass
class _Candidate:
    degree: int
    alpha: np.ndarray
    fit: _OLS
    n_candidates: int


def _degree(G, y, families, p, *, q, max_interaction, method, oversampling, cap, max_terms, max_steps, var_y):
    """The candidate expansion of total degree ``p`` (or None) and, when there is none, why: one step of
    :func:`_select` (module level: an executor can run it)."""
    A = multi_indices(G.shape[1], p, q, max_interaction, max_terms=cap if method == "ols" else max_terms)
    if A is None:
        return None, None, (f"degree {p} would need more than n/{oversampling:g} = {cap} terms" if method == "ols"
                            else f"degree {p} would need more than max_terms = {max_terms} candidates")
    if method == "ols":
        fit = _ols(design_matrix(G, families, A), y, var_y)
        cand = None if fit is None else _Candidate(p, A, fit, len(A))
    elif method == "lars":
        sel = _lars(G, y, families, p, q, len(A))
        fit = _ols(design_matrix(G, families, sel), y, var_y)
        cand = None if fit is None else _Candidate(p, sel, fit, len(A))
    else:
        sel, fit = _omp(design_matrix(G, families, A), y, var_y, min(len(A) - 1, cap - 1, max_steps))
        cand = None if fit is None else _Candidate(p, A[sel], fit, len(A))
    return len(A), cand, None if cand is not None else f"degree {p}: the least-squares design is rank deficient"


def _degree_task(G, y, families, p, kw):
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        return _degree(G, y, families, p, **kw)


def _blas_threads() -> int:
    """The BLAS threads this process's least squares use (threadpoolctl: a dependency of scikit-learn)."""
    from threadpoolctl import threadpool_info

    return max([int(i.get("num_threads", 1)) for i in threadpool_info() if i.get("user_api") == "blas"] or [1])


def _select(G, y, families, *, max_degree, q, max_interaction, method, oversampling, max_terms, max_steps,
            map=None, workers: int = 1):
    """Degree-adaptive selection; returns (best candidate, selection table rows, stop reason).

    ``map`` (``map(fn, tasks) -> results in order``, e.g. :meth:`rvtol.mc.Evaluator.map`) with ``workers`` > 1:
    the next ``workers`` degrees are fitted side by side (each is independent of the others), then judged in
    order as the serial search does — the same selection; a degree beyond the stop is fitted for nothing.  Only
    with more workers than this process's BLAS threads: the serial search's least squares already spread over those
    (measured on 2 cores, TE study: the degrees in pairs on 2 single-threaded workers 8.0 s, one by one on 2 BLAS
    threads 7.1 s — a pair waits for its costlier degree)."""
    n, k = G.shape
    var_y = float(np.var(y, ddof=1))
    if method == "lars" and max_interaction is not None:
        raise InputError("max_interaction needs method 'omp' or 'ols': OpenTURNS' enumeration (LARS) caps the "
                         "hyperbolic norm, not the interaction order", key="max_interaction")
    best: _Candidate | None = None
    rows, rises, last, why = [], 0, np.inf, f"max_degree = {max_degree} reached"
    cap = int(n / oversampling)
    if max_terms is None:
        max_terms = max(cap, OMP_MAX_ENTRIES // n)
    kw = dict(q=q, max_interaction=max_interaction, method=method, oversampling=oversampling, cap=cap, max_terms=max_terms,
              max_steps=max_steps, var_y=var_y)
    batch = max(1, int(workers)) if map is not None and int(workers) > _blas_threads() else 1
    p, stop = 1, False
    while p <= max_degree and not stop:
        degrees = range(p, min(p + batch, max_degree + 1))
        if len(degrees) > 1:
            results = map(_degree_task, [(G, y, families, d, kw) for d in degrees])
        else:
            results = [_degree(G, y, families, p, **kw)]
        for d, (n_cand, cand, failed) in zip(degrees, results):
            if cand is None:
                why, stop = failed, True
                break
            err = cand.fit.loo_corrected
            rows.append({"degree": d, "candidates": n_cand, "terms": len(cand.alpha), "loo_error": cand.fit.loo,
                         "loo_error_corrected": err})
            if best is None or err < best.fit.loo_corrected:
                best = cand
            rises = rises + 1 if err >= last else 0
            last = err
            if rises >= 2:
                why, stop = f"the corrected LOO error rose at degrees {d - 1} and {d}", True
                break
            if err < 1e-12:
                why, stop = "the expansion interpolates the data (LOO error < 1e-12)", True
                break
        p += len(degrees)
    if best is None:
        raise InputError(f"no polynomial chaos expansion can be fitted on {n} samples of {k} factors "
                         f"({why}); give more samples", key="samples")
    return best, rows, why


# --------------------------------------------------------------------------- the expansion
@dataclass
class PolynomialChaos:
    """A fitted PCE :math:`\\hat Y(u) = \\sum_a c_a \\Psi_a(g(u))` on the uniform design ``u``.

    ``alpha`` (P × k) are the multi-indices of the kept terms (row 0 the constant), ``coef``
    their coefficients in the output's unit.  ``selection`` tabulates the degree search.
    """

    families: tuple[str, ...]
    alpha: np.ndarray
    coef: np.ndarray
    degree: int
    q: float
    method: str
    n_samples: int
    loo_error: float
    loo_error_corrected: float
    selection: pd.DataFrame
    stop_reason: str = ""

    @property
    def n_terms(self) -> int:
        return len(self.coef)

    @property
    def mean(self) -> float:
        return float(self.coef[0])

    @property
    def variance(self) -> float:
        return float(np.sum(self.coef[1:] ** 2))

    @property
    def q2_loo(self) -> float:
        return 1.0 - self.loo_error

    def predict(self, U: np.ndarray) -> np.ndarray:
        """The surrogate at uniform-design points ``U`` (n × k)."""
        return design_matrix(germ(U, self.families), self.families, self.alpha) @ self.coef

    def sobol(self) -> dict[str, np.ndarray]:
        """``S1`` (k), ``ST`` (k) and ``S2`` (k × k, upper triangle) from the coefficients (Sudret 2008)."""
        S1, ST, S2 = sobol_from_coefficients(self.alpha, self.coef[None, :])
        return {"S1": S1[0], "ST": ST[0], "S2": S2[0]}


def _index_maps(alpha: np.ndarray):
    """0/1 matrices mapping squared coefficients to partial variances: first order, total, pairs."""
    nz = alpha > 0
    order = nz.sum(axis=1)
    M1 = (nz & (order == 1)[:, None]).astype(float)
    MT = nz.astype(float)
    pair_rows = np.flatnonzero(order == 2)
    return M1, MT, pair_rows, nz


def sobol_from_coefficients(alpha: np.ndarray, coefs: np.ndarray):
    """Sobol indices of each coefficient vector (rows of ``coefs``, B × P) of the basis ``alpha``.

    Returns ``S1`` (B × k), ``ST`` (B × k), ``S2`` (B × k × k, upper triangle), all relative to
    the expansion's variance :math:`D = \\sum_{\\alpha \\ne 0} c_\\alpha^2`.
    """
    alpha = np.asarray(alpha)
    if np.any(alpha[0]):
        raise ValueError("row 0 of alpha must be the constant term")
    c2 = np.asarray(coefs, dtype=float) ** 2
    c2[:, 0] = 0.0
    D = c2.sum(axis=1, keepdims=True)
    D[D == 0] = np.inf   # an expansion of the constant alone attributes no variance to any factor: indices 0
    M1, MT, pair_rows, nz = _index_maps(alpha)
    S1, ST = (c2 @ M1) / D, (c2 @ MT) / D
    k = alpha.shape[1]
    S2 = np.zeros((len(c2), k, k))
    for r in pair_rows:
        i, j = np.flatnonzero(nz[r])
        S2[:, i, j] += c2[:, r] / D[:, 0]
    return S1, ST, S2


def fit_pce(U: np.ndarray, y: np.ndarray, families: str | Sequence[str] = "legendre", *,
            max_degree: int = MAX_DEGREE, q: float = Q_NORM, max_interaction: int | None = None,
            method: str = "omp", oversampling: float = 2.0, max_terms: int | None = None,
            max_steps: int = OMP_MAX_STEPS, map=None, workers: int = 1) -> PolynomialChaos:
    """Fit a PCE on the uniform design ``U`` (n × k, in (0, 1)) and outputs ``y`` (n).

    ``families``: one family for all factors or one per factor (see module notes).  The degree
    p ≤ ``max_degree`` of the hyperbolic set (``q``, ``max_interaction``) is chosen by the
    corrected LOO error.  ``method`` "ols" fits the whole set (at most n/``oversampling``
    terms); "omp" keeps the best leading set of an orthogonal matching pursuit over at most
    ``max_terms`` candidates (default: n × candidates ≤ :data:`OMP_MAX_ENTRIES`) and
    ``max_steps`` terms (and n/``oversampling``).
    """
    U = np.asarray(U, dtype=float)
    y = np.asarray(y, dtype=float).ravel()
    if U.ndim != 2 or len(U) != len(y):
        raise InputError(f"U has shape {U.shape} and y {y.shape}: expected (n, k) and (n,)", key="U")
    if not (np.all(np.isfinite(U)) and np.all(np.isfinite(y))):
        raise InputError("U and y must be finite (drop failed samples first)", key="U")
    if np.any((U <= 0) | (U >= 1)):
        raise InputError("U must lie strictly inside (0, 1): map factor values through their CDFs", key="U")
    fams = _families(families, U.shape[1])
    if method not in METHODS:
        raise InputError(f"unknown method {method!r} (expected one of: {', '.join(METHODS)})", key="method")
    if max_degree < 1:
        raise InputError(f"max_degree must be >= 1, got {max_degree}", key="max_degree")
    if oversampling < 1:
        raise InputError(f"oversampling must be >= 1, got {oversampling}", key="oversampling")
    sd = float(np.std(y, ddof=1)) if len(y) > 1 else 0.0
    if not sd > 0:
        raise InputError("the output does not vary: nothing to expand", key="y")
    mu = float(np.mean(y))
    z = (y - mu) / sd  # fit on the standardised output (conditioning); coefficients rescaled below
    best, rows, why = _select(germ(U, fams), z, fams, max_degree=max_degree, q=q, max_interaction=max_interaction,
                              method=method, oversampling=oversampling, max_terms=max_terms,
                              max_steps=max_steps, map=map, workers=workers)
    coef = best.fit.coef * sd
    coef[0] += mu
    return PolynomialChaos(fams, best.alpha, coef, best.degree, q, method, len(y), best.fit.loo,
                           best.fit.loo_corrected, pd.DataFrame(rows), why)


def _families(families, k: int) -> tuple[str, ...]:
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


# --------------------------------------------------------------------------- intervals
def _refit_fixed(Psi: np.ndarray, y: np.ndarray, w: np.ndarray) -> np.ndarray | None:
    """Weighted OLS ``(Ψᵀ W Ψ)⁻¹ Ψᵀ W y`` (bootstrap multiplicities ``w``) by Cholesky; None if singular."""
    rows = np.flatnonzero(w)  # ~37 % of the rows are not drawn: skip them
    sw = np.sqrt(w[rows])
    A = Psi[rows] * sw[:, None]
    try:
        cf = linalg.cho_factor(A.T @ A, check_finite=False)  # A.T @ A: NumPy uses the symmetric product
    except linalg.LinAlgError:
        return None
    return linalg.cho_solve(cf, A.T @ (sw * y[rows]), check_finite=False)


def _coef_draws(Psi: np.ndarray, y: np.ndarray, fit: _OLS, ci: str, B: int, rng: np.random.Generator):
    """``B`` coefficient vectors of the fixed basis: pairs bootstrap or HC3 sandwich normal draws."""
    n, P = Psi.shape
    if ci == "bootstrap":
        out = []
        while len(out) < B:
            w = np.bincount(rng.integers(0, n, n), minlength=n).astype(float)
            c = _refit_fixed(Psi, y, w)
            if c is not None:
                out.append(c)
        return np.array(out)
    e = fit.resid / (1.0 - fit.h)
    M = fit.Q.T @ (fit.Q * (e**2)[:, None])
    Rinv = linalg.solve_triangular(fit.R, np.eye(P))
    C = Rinv @ M @ Rinv.T
    L = np.linalg.cholesky(C + 1e-15 * np.trace(C) / P * np.eye(P))
    return fit.coef[None, :] + rng.standard_normal((B, P)) @ L.T


# --------------------------------------------------------------------------- array-level analysis
@dataclass
class PCEIndices:
    """Indices of one output from a PCE fitted on given samples, with intervals and validation.

    Arrays over factors: ``S1``, ``ST`` (estimates from the fit on all samples), ``S1_conf``,
    ``ST_conf`` (half-widths z·sd of the bootstrap), ``S1_low``… ``ST_high`` (percentile
    interval); ``S2``, ``S2_conf`` are k × k (upper triangle).  ``validation``: Q² (LOO and
    hold-out), relative RMSE, terms, degree; ``reliable`` is min(Q²) ≥ ``min_q2``.
    """

    S1: np.ndarray
    S1_conf: np.ndarray
    S1_low: np.ndarray
    S1_high: np.ndarray
    ST: np.ndarray
    ST_conf: np.ndarray
    ST_low: np.ndarray
    ST_high: np.ndarray
    S2: np.ndarray
    S2_conf: np.ndarray
    fit: PolynomialChaos
    validation: dict
    reliable: bool
    confidence: float


def pce_indices(U: np.ndarray, y: np.ndarray, families: str | Sequence[str] = "legendre", *, holdout: float = 0.2,
                ci: str = "bootstrap", num_resamples: int = 100, confidence: float = 0.95, min_q2: float = MIN_Q2,
                seed: int | np.random.Generator | None = None, **fit_options) -> PCEIndices:
    """Fit, validate and bootstrap a PCE on ``(U, y)``; Sobol indices with intervals (see module notes).

    ``holdout`` (0 ≤ h < 0.5): the share of samples held out to check the selected expansion
    (0: LOO only).  ``ci``: "bootstrap" or "asymptotic".  ``seed``: the hold-out split and the
    resamples.  ``fit_options``: :func:`fit_pce`'s keywords (``max_degree``, ``q``,
    ``max_interaction``, ``method``, ``oversampling``, ``max_terms``, ``max_steps``).
    """
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):   # small factorisations: threads cost more than they give
        return _pce_indices(U, y, families, holdout=holdout, ci=ci, num_resamples=num_resamples,
                            confidence=confidence, min_q2=min_q2, seed=seed, **fit_options)


def _pce_indices(U, y, families, *, holdout, ci, num_resamples, confidence, min_q2, seed, **fit_options):
    if ci not in CI_METHODS:
        raise InputError(f"unknown ci {ci!r} (expected one of: {', '.join(CI_METHODS)})", key="ci")
    if not 0 <= holdout < 0.5:
        raise InputError(f"holdout must be in [0, 0.5), got {holdout}", key="holdout")
    if num_resamples < 10:
        raise InputError(f"num_resamples must be >= 10, got {num_resamples}", key="num_resamples")
    if not 0 < confidence < 1:
        raise InputError(f"confidence must be in (0, 1), got {confidence}", key="confidence")
    U = np.asarray(U, dtype=float)
    y = np.asarray(y, dtype=float).ravel()
    n, k = U.shape
    fams = _families(families, k)
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    opts = fit_options
    # 1. selection on the training part, checked on the held-out part
    q2_hold = rmse_hold = np.nan
    n_hold = int(round(holdout * n))
    if n_hold >= 10:
        perm = rng.permutation(n)
        test, train = perm[:n_hold], perm[n_hold:]
        sel = fit_pce(U[train], y[train], fams, **opts)
        err = y[test] - sel.predict(U[test])
        v = float(np.var(y[test], ddof=1))
        q2_hold = 1.0 - float(np.mean(err**2)) / v if v > 0 else np.nan
        rmse_hold = float(np.sqrt(np.mean(err**2)) / np.sqrt(v)) if v > 0 else np.nan
        alpha = sel.alpha
    else:
        n_hold = 0
        sel = fit_pce(U, y, fams, **opts)
        alpha = sel.alpha
    # 2. final coefficients: the selected terms refitted on every sample
    sd, mu = float(np.std(y, ddof=1)), float(np.mean(y))
    z = (y - mu) / sd
    Psi = design_matrix(germ(U, fams), fams, alpha)
    fit = _ols(Psi, z, 1.0)
    if fit is None:
        raise InputError("the selected expansion is rank deficient on the full sample", key="samples")
    coef = fit.coef * sd
    coef[0] += mu
    pce_fit = PolynomialChaos(fams, alpha, coef, sel.degree, sel.q, sel.method, n, fit.loo, fit.loo_corrected,
                              sel.selection, sel.stop_reason)
    S1, ST, S2 = (a[0] for a in sobol_from_coefficients(alpha, coef[None, :]))
    # 3. intervals: resampled coefficient vectors of the fixed basis
    draws = _coef_draws(Psi, z, fit, ci, num_resamples, rng)
    b1, bT, b2 = sobol_from_coefficients(alpha, draws)
    zc = stats.norm.ppf(0.5 + confidence / 2.0)
    lo_q, hi_q = 100 * (1 - confidence) / 2, 100 * (1 + confidence) / 2
    q2_loo = 1.0 - fit.loo
    q2_min = q2_loo if not np.isfinite(q2_hold) else min(q2_loo, q2_hold)
    n_cand = int(sel.selection.set_index("degree").loc[sel.degree, "candidates"])
    validation = {"n_samples": n, "n_holdout": n_hold, "degree": sel.degree, "q": sel.q, "method": sel.method,
                  "n_terms": len(alpha), "n_candidates": n_cand,
                  "Q2_loo": q2_loo, "Q2_loo_corrected": 1.0 - fit.loo_corrected, "Q2_holdout": q2_hold,
                  "rel_rmse_holdout": rmse_hold, "bias_bound": max(0.0, 1.0 - q2_min),
                  "min_q2": min_q2, "reliable": bool(q2_min >= min_q2), "stop": sel.stop_reason}
    return PCEIndices(S1, zc * b1.std(axis=0, ddof=1), np.percentile(b1, lo_q, axis=0),
                      np.percentile(b1, hi_q, axis=0), ST, zc * bT.std(axis=0, ddof=1),
                      np.percentile(bT, lo_q, axis=0), np.percentile(bT, hi_q, axis=0), S2,
                      zc * b2.std(axis=0, ddof=1), pce_fit, validation, validation["reliable"], confidence)


# --------------------------------------------------------------------------- model-level analysis
PCE_COLUMNS = ["S1", "S1_conf", "ST", "ST_conf", "S1_low", "S1_high", "ST_low", "ST_high"]


@dataclass
class SurrogateSensitivityResult(GlobalSensitivityResult):
    """PCE Sobol indices: ``frame`` as for Sobol (``S1, S1_conf, ST, ST_conf`` + percentile bounds).

    Outputs whose surrogate failed validation have NaN indices in ``frame`` (with
    ``on_poor_fit="withhold"``); ``raw`` always holds the surrogate's values.  ``validation``
    has one row per output (Q², relative RMSE, degree, terms, ``reliable``, ``bias_bound``);
    ``fits`` the fitted expansions by output name; ``independent`` is False when the inputs are
    dependent (see notes).
    """

    validation: pd.DataFrame | None = None
    raw: pd.DataFrame | None = None
    fits: dict = field(default_factory=dict)
    independent: bool = True

    def summary(self) -> dict:
        out = super().summary()
        out["validation"] = frame_records(self.validation) if self.validation is not None else []
        out["independent"] = self.independent
        return out


def pce(model: Model, spec: ToleranceSpec, samples: SampleSet, Y: np.ndarray, factors: Sequence[str] | None = None,
        outputs: Sequence[str] | None = None, seed: int | None = None, *, germs: str | Sequence[str] = "auto",
        holdout: float = 0.2, ci: str = "bootstrap", num_resamples: int = 100, confidence: float = 0.95,
        min_q2: float = MIN_Q2, on_poor_fit: str = "withhold", second_order: bool = True,
        **fit_options) -> SurrogateSensitivityResult:
    """Sobol S1, ST (and S2) from a PCE fitted on the Monte Carlo ``samples`` and outputs ``Y``.

    ``Y``: every model output in display units (``MonteCarloResult.Y``); no model run is made.
    The expansion uses **all** factors of the spec (they all vary in the sample); ``factors``
    selects the rows reported.  ``germs``: "auto" (Hermite for unbounded factors, Legendre for
    bounded), "legendre", "hermite" or one per factor.  ``on_poor_fit``: "withhold" (default),
    "warn" or "raise" when min(Q²_LOO, Q²_hold-out) < ``min_q2``.  Other keywords: see
    :func:`pce_indices` and :func:`fit_pce` (``fit_options``) and the module notes.
    """
    if on_poor_fit not in POOR_FIT:
        raise InputError(f"unknown on_poor_fit {on_poor_fit!r} (expected one of: {', '.join(POOR_FIT)})",
                         key="on_poor_fit")
    model.check_spec(spec)
    idx, oidx = factor_indices(spec, factors), output_indices(model, outputs)
    X, Yd, n_failed, notes = given_samples(model, spec, samples, Y, oidx)
    U = u_from_samples(spec, X)
    fams = families_for_spec(spec) if germs == "auto" else _families(germs, len(spec))
    pairs = correlated_pairs(spec.names, U, spec.correlation)
    independent = not pairs
    if pairs:
        msg = N.PCE_DEPENDENT.format(pairs=describe_pairs(pairs))
        warnings.warn(msg, CorrelatedInputsWarning, stacklevel=2)
        notes.append(msg)
    rng = substream(seed, "pce")
    names = [spec.names[i] for i in idx]
    rows, s2rows, vrows, fits = [], [], [], {}
    for c, j in enumerate(oidx):
        q_ = model.outputs[j]
        y = Yd[:, c]
        base = {"output": q_.name, "unit": q_.shown_unit}
        if len(y) < 2 or np.ptp(y) == 0.0:
            notes.append(N.CONSTANT_OUTPUT.format(output=q_.name))
            rows += [{**base, "factor": nm, **{col: 0.0 for col in PCE_COLUMNS}} for nm in names]
            s2rows += [{"output": q_.name, "factor_i": a, "factor_j": b, "S2": 0.0, "S2_conf": 0.0}
                       for a, b in itertools.combinations(names, 2)]
            vrows.append({"output": q_.name, "reliable": True})
            continue
        res = pce_indices(U, y, fams, holdout=holdout, ci=ci, num_resamples=num_resamples, confidence=confidence,
                          min_q2=min_q2, seed=rng, **fit_options)
        fits[q_.name] = res.fit
        v = res.validation
        vrows.append({"output": q_.name, **v})
        for i, nm in zip(idx, names):
            rows.append({**base, "factor": nm, **{col: float(getattr(res, col)[i]) for col in PCE_COLUMNS}})
        for (a, ia), (b, ib) in itertools.combinations(list(zip(names, idx)), 2):
            lo, hi = min(ia, ib), max(ia, ib)
            s2rows.append({"output": q_.name, "factor_i": a, "factor_j": b, "S2": float(res.S2[lo, hi]),
                           "S2_conf": float(res.S2_conf[lo, hi])})
        if not res.reliable:
            msg = N.PCE_POOR_FIT.format(output=q_.name, q2_loo=v["Q2_loo"], q2_holdout=v["Q2_holdout"], min_q2=min_q2,
                                        bias=v["bias_bound"]) + N.PCE_POOR_FIT_THEN[on_poor_fit]
            if on_poor_fit == "raise":
                raise SurrogateError(msg)
            warnings.warn(msg, PoorSurrogateWarning, stacklevel=2)
            notes.append(msg)
    raw = pd.DataFrame(rows, columns=["output", "unit", "factor", *PCE_COLUMNS])
    validation = pd.DataFrame(vrows)
    frame = raw.copy()
    if on_poor_fit == "withhold":
        bad = set(validation.loc[~validation["reliable"].astype(bool), "output"])
        frame.loc[frame["output"].isin(bad), PCE_COLUMNS] = np.nan
    s2 = None
    if second_order:
        s2 = pd.DataFrame(s2rows, columns=["output", "factor_i", "factor_j", "S2", "S2_conf"])
        if on_poor_fit == "withhold":
            s2.loc[s2["output"].isin(bad), ["S2", "S2_conf"]] = np.nan
    notes.append(N.PCE_INTERVALS.format(ci=ci, resamples=num_resamples, n=len(X)))
    shown = {k: v for k, v in fit_options.items() if k not in ("map", "workers")}     # where it ran: not a setting
    settings = {"n": len(X), "samples": "given", "germs": dict(zip(spec.names, fams)), **shown,
                "holdout": holdout, "ci": ci, "num_resamples": num_resamples, "min_q2": min_q2,
                "on_poor_fit": on_poor_fit}
    return SurrogateSensitivityResult("pce", frame, 0, confidence, settings, s2, n_failed, notes,
                                      validation=validation, raw=raw, fits=fits, independent=independent)


def pce_given(model: Model, spec: ToleranceSpec, samples: SampleSet, Y: np.ndarray, n: int | None = None,
              factors: Sequence[str] | None = None, outputs: Sequence[str] | None = None, seed: int | None = None,
              **options) -> SurrogateSensitivityResult:
    """:func:`pce` fitted on a random subsample of ``n`` rows of the given samples (None: all of them), the
    subsample stated first in the notes; a poor fit and correlated inputs are said in the notes, not warned."""
    from .given_data import delta_subsample

    samples, Y, note = delta_subsample(samples, Y, n, seed, "pce_subsample", "the surrogate fit")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PoorSurrogateWarning)   # said in the notes
        warnings.simplefilter("ignore", CorrelatedInputsWarning)
        res = pce(model, spec, samples, Y, factors, outputs, seed, **options)
    res.notes.insert(0, note[0].upper() + note[1:] + ".")
    return res
