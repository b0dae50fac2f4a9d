"""Helpers shared by the analyses that work on *given* samples (the Monte Carlo sample, no new runs).

* :func:`given_samples` checks a :class:`~rvtol.sampling.SampleSet` and its outputs against the
  spec and the model and drops the rows whose evaluation failed (with a note);
* :func:`u_from_values` maps factor values back to the uniform design ``u = F(x)`` through each
  factor's own CDF (the Monte Carlo drew ``x = F⁻¹(u)``, so this recovers its ``u``-design);
* :func:`correlated_pairs` / :func:`correlation_notes` detect dependent inputs, from the spec's
  copula and from the data (Spearman rank correlation of the sample).
"""
from __future__ import annotations

import warnings
from typing import Callable, Sequence

import numpy as np

from .. import units
from ..errors import InputError
from ..model import Model
from ..sampling import SampleSet
from ..spec import ToleranceSpec

_U_EPS = 2.0**-53


class CorrelatedInputsWarning(UserWarning):
    """The inputs are dependent: variance-based indices that assume independence are not valid."""


def given_samples(model: Model, spec: ToleranceSpec, samples: SampleSet, Y, oidx: Sequence[int]):
    """``(X_base[n, k], Y_display[n, len(oidx)], n_dropped, notes)`` from a Monte Carlo sample.

    ``Y`` holds every model output in display units (as :class:`rvtol.mc.MonteCarloResult` keeps
    them); rows with a non-finite selected output (failed evaluations) are dropped with a note.
    """
    if samples is None or Y is None:
        raise InputError("give the samples and their outputs Y (display units)", key="samples")
    if tuple(samples.names) != tuple(spec.names):
        raise InputError("the samples' factors do not match the spec", key="samples")
    Y = np.asarray(Y, dtype=float)
    if Y.ndim == 1:
        Y = Y[:, None]
    if len(Y) != len(samples) or Y.shape[1] != len(model.outputs):
        raise InputError(f"Y has shape {Y.shape}, expected ({len(samples)}, {len(model.outputs)})", key="Y")
    X, Yd = np.asarray(samples.values, dtype=float), Y[:, list(oidx)]
    notes = []
    bad = ~np.all(np.isfinite(Yd), axis=1)
    if bad.any():
        notes.append(f"{int(bad.sum())} sample(s) whose evaluation failed were left out of the analysis "
                     "(the indices describe the samples that ran).")
        X, Yd = X[~bad], Yd[~bad]
    return X, Yd, int(bad.sum()), notes


def u_column(x: np.ndarray, cdf: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    """``cdf(x)`` kept strictly inside (0, 1); a non-finite value is an input error."""
    u = np.asarray(cdf(x), dtype=float)
    if not np.all(np.isfinite(u)):
        raise InputError("a CDF returned non-finite values", key="X")
    return np.clip(u, _U_EPS, 1.0 - _U_EPS)


def u_from_values(X: np.ndarray, cdfs: Sequence[Callable[[np.ndarray], np.ndarray]]) -> np.ndarray:
    """The uniform design ``u[:, j] = cdfs[j](X[:, j])``, kept strictly inside (0, 1)."""
    X = np.asarray(X, dtype=float)
    if X.ndim != 2 or X.shape[1] != len(cdfs):
        raise InputError(f"X has shape {X.shape}, expected (n, {len(cdfs)})", key="X")
    return np.column_stack([u_column(X[:, j], f) for j, f in enumerate(cdfs)])


def spec_cdfs(spec: ToleranceSpec) -> list[Callable[[np.ndarray], np.ndarray]]:
    """Each factor's CDF as a function of its value in **base** units."""
    return [lambda x, f=f: f.dist.cdf(units.from_base(x, f.unit)) for f in spec.factors]


def u_from_samples(spec: ToleranceSpec, X_base: np.ndarray) -> np.ndarray:
    """The uniform design of Monte Carlo values (base units) of ``spec``: ``u = F_j(x_j)`` per factor."""
    return u_from_values(X_base, spec_cdfs(spec))


def spearman_threshold(n: int) -> float:
    """|ρ_s| above which a rank correlation of ``n`` independent samples is called real.

    Under independence ρ_s ≈ N(0, 1/(n−1)); 5 standard deviations keep the family-wise false
    alarm rate below 1e-4 for up to ~600 factor pairs (35 factors); the floor 0.05 ignores
    correlations too weak to move an index.
    """
    return max(0.05, 5.0 / np.sqrt(max(n - 1, 1)))


def correlated_pairs(names: Sequence[str], U: np.ndarray | None = None,
                     correlation: np.ndarray | None = None, rho: np.ndarray | None = None,
                     n: int | None = None) -> list[tuple[str, str, float, str]]:
    """Pairs of dependent factors ``(a, b, rho, source)``: from the spec's copula and/or the sample.

    ``correlation`` is the spec's normal-score correlation matrix (columns in the order of
    ``names``); ``U`` the uniform design, whose Spearman matrix flags dependence the spec does not
    state (e.g. samples from another source).  Source is ``"spec"`` or ``"sample"``.  ``rho`` (with the
    sample size ``n``): that Spearman matrix when already computed
    (:func:`rvtol.sensitivity.given_data.classes_and_spearman`), in place of ``U``.
    """
    if rho is not None and n is None:
        raise ValueError("correlated_pairs: a Spearman matrix rho needs its sample size n (the threshold depends "
                         "on it)")
    k = len(names)
    out: dict[tuple[int, int], tuple[float, str]] = {}
    if correlation is not None:
        C = np.asarray(correlation, dtype=float)
        for a in range(k):
            for b in range(a + 1, k):
                if C[a, b] != 0.0:
                    out[(a, b)] = (float(C[a, b]), "spec")
    if rho is None and U is not None and len(U) > 3 and k > 1:
        from scipy import stats

        n = len(U)
        with warnings.catch_warnings(), np.errstate(invalid="ignore", divide="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)  # constant columns: NaN, skipped
            rho = np.corrcoef(stats.rankdata(U, axis=0), rowvar=False)    # Spearman = Pearson of the ranks
    if rho is not None and n is not None and n > 3 and k > 1:
        thr = spearman_threshold(n)
        for a in range(k):
            for b in range(a + 1, k):
                if (a, b) not in out and np.isfinite(rho[a, b]) and abs(rho[a, b]) > thr:
                    out[(a, b)] = (float(rho[a, b]), "sample")
    return [(names[a], names[b], r, s) for (a, b), (r, s) in sorted(out.items())]


def describe_pairs(pairs, limit: int = 6) -> str:
    txt = ", ".join(f"{a}–{b} (ρ = {r:+.2f}, {s})" for a, b, r, s in pairs[:limit])
    return txt + (f" and {len(pairs) - limit} more" if len(pairs) > limit else "")
