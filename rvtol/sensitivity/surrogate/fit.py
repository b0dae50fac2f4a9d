r"""The expansion fitted on given samples: least squares with the leave-one-out error, the selection of its
terms (OMP, LARS) and of its degree, and the Sobol indices of its coefficients.

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
    the selection looked at the same data — which is why the hold-out check
    (:mod:`rvtol.sensitivity.surrogate.indices`) exists.

Sobol indices (Sudret 2008)
    With :math:`Y \approx \sum_\alpha c_\alpha \Psi_\alpha`, :math:`D = \sum_{\alpha\ne0} c_\alpha^2`:

    .. math::
        S_i = \frac{1}{D}\sum_{\alpha \in \mathcal A_i} c_\alpha^2,\ \
        \mathcal A_i = \{\alpha: \alpha_i > 0, \alpha_{j\ne i} = 0\};\qquad
        S_{T,i} = \frac{1}{D}\sum_{\alpha_i > 0} c_\alpha^2;\qquad
        S_{ij} = \frac{1}{D}\sum_{\mathrm{supp}\,\alpha = \{i,j\}} c_\alpha^2 .
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
import pandas as pd
from scipy import linalg

from ...errors import InputError
from .basis import design_matrix, germ, germ_families, multi_indices

METHODS = ("lars", "ols", "omp")

#: default hyperbolic norm q and maximum degree of the degree search
Q_NORM = 0.75
MAX_DEGREE = 10
#: OMP candidate design size by default: n × candidates ≤ this many entries (200 MB of doubles)
OMP_MAX_ENTRIES = 25_000_000
#: OMP steps (terms entering) by default
OMP_MAX_STEPS = 500


# --------------------------------------------------------------------------- least squares
@dataclass
class OLSFit:
    coef: np.ndarray
    resid: np.ndarray
    h: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    loo: float            # ε_LOO relative to the output variance
    loo_corrected: float  # ε*_LOO (Chapelle correction)


def ols_fit(Psi: np.ndarray, y: np.ndarray, var_y: float) -> OLSFit | None:
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
    return OLSFit(coef, resid, h, Q, R, loo, loo * T)


def _omp(Psi: np.ndarray, y: np.ndarray, var_y: float, max_steps: int, patience: int = 30):
    r"""Orthogonal matching pursuit with the corrected LOO error of every step; ``(columns, OLSFit)`` of the best.

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
    return sel, ols_fit(Psi[:, sel], y, var_y)


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
    fit: OLSFit
    n_candidates: int


def _degree(G, y, families, p, *, q, max_interaction, method, oversampling, cap, max_terms, max_steps, var_y):
    """The candidate expansion of total degree ``p`` (or None) and, when there is none, why: one step of
    :func:`_select` (module level: an executor can run it)."""
    A = multi_indices(G.shape[1], p, q, max_interaction, max_terms=cap if method == "ols" else max_terms)
    if A is None:
        return None, None, (f"degree {p} would need more than n/{oversampling:g} = {cap} terms" if method == "ols"
                            else f"degree {p} would need more than max_terms = {max_terms} candidates")
    if method == "ols":
        fit = ols_fit(design_matrix(G, families, A), y, var_y)
        cand = None if fit is None else _Candidate(p, A, fit, len(A))
    elif method == "lars":
        sel = _lars(G, y, families, p, q, len(A))
        fit = ols_fit(design_matrix(G, families, sel), y, var_y)
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

    ``families``: one family for all factors or one per factor (:mod:`.basis`).  The degree
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
    fams = germ_families(families, U.shape[1])
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

