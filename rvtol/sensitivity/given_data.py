r"""First-order indices straight from the Monte Carlo sample, and a subsample for delta.

No surrogate and no extra model run: the first-order index
:math:`S_i = V[E(Y|X_i)]/V[Y]` is the *correlation ratio* of Y on :math:`X_i`, which a given
sample estimates by partitioning :math:`X_i` into classes (Plischke, Borgonovo & Smith 2013,
"given data" estimators; the spectral EASI of Plischke 2010 is the same quantity with a
Fourier low-pass in place of the classes, and SALib's ``rbd_fast`` on given data implements it).

Estimator
    The n samples are sorted by :math:`X_i` and cut into M classes of equal count (equiprobable
    in :math:`X_i`'s own distribution, whatever it is; invariant to monotone transforms).  With
    class means :math:`\bar y_m`, counts :math:`n_m`,
    :math:`SS_B = \sum_m n_m(\bar y_m - \bar y)^2`, :math:`SS_W = SS_T - SS_B`:

    .. math::
        \hat S_i = \frac{SS_B - (M-1)\,SS_W/(n-M)}{SS_T}

    — the between-class share with Kelley's correction of its noise bias (within-class
    variance leaks :math:`(M-1)\sigma_W^2` into :math:`SS_B`).  What is left is the
    discretisation bias :math:`-E[V(E(Y|X_i)\,|\,\text{class})]/V \approx -\overline{g_i'^2}/(12M^2V)`
    (:math:`g_i` the main effect as a function of the probability :math:`u_i`); the default
    :math:`M = \lfloor\sqrt n\rfloor` (clipped to [8, 200]) makes it O(1/n) while the
    correction keeps the noise bias away: with n = 10 000, 100 classes of 100 samples.

Intervals
    Bootstrap: the rows are resampled ``num_resamples`` times with the classes kept; the
    estimator is recomputed with the actual class counts.  ``S1_conf`` is
    :math:`z_{(1+c)/2}\,\mathrm{sd}_{boot}` (as SALib), ``S1_low``/``S1_high`` the percentile
    interval shifted by (corrected − plug-in) estimate: the resamples are drawn from the sample
    itself, whose own ratio is the plug-in :math:`SS_B/SS_T`, so they scatter around it; the
    shift recentres them on the corrected estimate.  They cover the sampling of the n points,
    not the discretisation bias above.

Dependent inputs
    The correlation ratio stays well defined: it is then the share of variance explained by
    :math:`X_i` *including* what it carries of the factors correlated with it (not a term of a
    variance decomposition).  A note says so.

Delta on a subsample
    Borgonovo's δ (SALib ``delta``, kernel density estimates) costs roughly O(n²) per factor and
    resample: 212 s on 20 000 samples of a 3-factor model.  :func:`delta_subsample` draws a
    random subsample of :data:`DELTA_DEFAULT_N` = 2000 rows (without replacement, its own seed
    stream) and :func:`delta_given` runs delta on it and states n in the result.  At n = 2000
    the kernel estimator's sampling scatter is about ±0.015 on δ (measured on the correlated
    linear case of ``tests/sensitivity/test_sensitivity_global.py``: σ ≈ 0.011–0.018 at n = 4000), smaller
    than the differences that matter when ranking tolerances.

References
    * E. Plischke (2010), An effective algorithm for computing global sensitivity indices
      (EASI), Reliability Engineering & System Safety 95(4), 354–360.
    * E. Plischke, E. Borgonovo, C. L. Smith (2013), Global sensitivity measures from given data,
      European Journal of Operational Research 226(3), 536–550.
    * T. L. Kelley (1935), An unbiased correlation ratio measure, PNAS 21(9), 554–559.
    * E. Borgonovo (2007), A new uncertainty importance measure, RESS 92(6), 771–784.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np
import pandas as pd
from scipy import stats

from ..errors import InputError
from ..executors import Executor
from ..model import Model
from ..sampling import SampleSet, substream
from ..spec import ToleranceSpec
from . import global_ as gs
from ._given import correlated_pairs, describe_pairs, given_samples, spec_cdfs, u_column
from ..mc import Evaluator
from .common import factor_indices, output_indices
from . import notes as N

#: default size of the random subsample delta runs on (see module notes)
DELTA_DEFAULT_N = 2000

GIVEN_COLUMNS = ["S1", "S1_conf", "S1_low", "S1_high"]


def default_classes(n: int) -> int:
    """Number of equiprobable classes M = ⌊√n⌋ clipped to [8, 200] (see module notes)."""
    return int(np.clip(np.floor(np.sqrt(n)), 8, 200))


def _ordinal_rank(x: np.ndarray) -> np.ndarray:
    """The 0-based rank of every value of ``x`` (ties by order), as int32 when n allows (memory: 4 bytes a value)."""
    n = len(x)
    r = np.empty(n, dtype=np.int32 if n < 2**31 else np.int64)
    r[np.argsort(x, kind="stable")] = np.arange(n, dtype=r.dtype)
    return r


def _class_dtype(M: int):
    """The smallest unsigned integer type holding the classes 0 … M − 1 (1 byte a value for M ≤ 256)."""
    return np.uint8 if M <= 256 else (np.uint16 if M <= 65536 else np.int64)


def _classes_of(rank: np.ndarray, M: int, n: int) -> np.ndarray:
    return ((rank.astype(np.int64) * M) // n).astype(_class_dtype(M))


def class_index(x: np.ndarray, M: int) -> np.ndarray:
    """Class of each sample: the rank of ``x`` cut into ``M`` classes of equal count (ties by order);
    unsigned integers of the smallest width that holds M (uint8 for M ≤ 256)."""
    x = np.asarray(x, dtype=float)
    return _classes_of(_ordinal_rank(x), M, len(x))


def _corrected_ratio(counts: np.ndarray, sums: np.ndarray, sumsq: np.ndarray, kelley: bool = True) -> np.ndarray:
    """Kelley-corrected (or plain, ``kelley=False``) correlation ratio from per-class counts, sums, sums of squares."""
    n = counts.sum(axis=-1)
    total = sums.sum(axis=-1)
    ss_t = sumsq.sum(axis=-1) - total**2 / n
    with np.errstate(invalid="ignore", divide="ignore"):
        ss_b = np.where(counts > 0, sums**2 / np.where(counts > 0, counts, 1), 0.0).sum(axis=-1) - total**2 / n
        M = (counts > 0).sum(axis=-1)
        ss_w = ss_t - ss_b
        return (ss_b - (M - 1) * ss_w / (n - M) if kelley else ss_b) / ss_t


def correlation_ratio(x: np.ndarray, y: np.ndarray, classes: int | None = None) -> float:
    """The Kelley-corrected first-order index of ``y`` on ``x`` from ``classes`` equal-count classes."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    M = classes or default_classes(len(x))
    c = class_index(x, M)
    return float(_corrected_ratio(np.bincount(c, minlength=M), np.bincount(c, y, M), np.bincount(c, y * y, M)))


def _check_classes(n: int, classes: int | None) -> int:
    M = classes or default_classes(n)
    if not 2 <= M <= n // 2:
        raise InputError(f"classes must be in [2, n/2 = {n // 2}], got {M}", key="classes")
    return M


def class_indices(X: np.ndarray, classes: int | None = None) -> np.ndarray:
    """:func:`class_index` of every column of ``X`` (``n × k``; M = ``classes`` or :func:`default_classes`):
    computed once and shared by every output of one sample (1 byte a value for M ≤ 256)."""
    X = np.atleast_2d(np.asarray(X, dtype=float))
    n, k = X.shape
    M = _check_classes(n, classes)
    C = np.empty((n, k), dtype=_class_dtype(M))
    for i in range(k):
        C[:, i] = _classes_of(_ordinal_rank(X[:, i]), M, n)
    return C


#: rows per block of the rank Gram matrix (:func:`classes_and_spearman`): the transient is block × k values
GRAM_BLOCK = 1 << 13


def classes_and_spearman(X: np.ndarray, cdfs, columns: Sequence[int], classes: int | None = None):
    """One ranking of the factors, a column at a time, for the classes and the dependence check.

    Returns ``(C, rho)``: :func:`class_indices` of ``X[:, columns]`` and the Spearman matrix of the uniform
    design ``U = F(X)`` (``cdfs[j]`` maps column j; ``k × k``, NaN for a constant column).  A CDF keeps the
    order, so where ``U``'s column has no ties its ranks are ``X``'s ordinal ranks; a column with ties (a flat
    stretch of F, a constant factor) takes :func:`scipy.stats.rankdata`'s average ranks, as a fresh ranking
    would.  Spearman's ρ is the Pearson correlation of the ranks, its Gram matrix summed over blocks of
    :data:`GRAM_BLOCK` rows.  Memory: the int32 ranks (4 bytes a value) and the classes (1 byte) besides ``X``
    — not the several float copies of ``n × k`` a whole-matrix ranking would hold.
    """
    X = np.asarray(X, dtype=float)
    n, k = X.shape
    M = _check_classes(n, classes)
    R = np.empty((n, k), dtype=np.int32 if n < 2**31 else np.int64)
    tied: dict[int, np.ndarray] = {}
    where = {j: c for c, j in enumerate(columns)}
    C = np.empty((n, len(columns)), dtype=_class_dtype(M))
    for j in range(k):
        R[:, j] = _ordinal_rank(X[:, j])
        if j in where:
            C[:, where[j]] = _classes_of(R[:, j], M, n)
        u = u_column(X[:, j], cdfs[j])
        in_order = np.empty(n)
        in_order[R[:, j]] = u
        if not np.all(np.diff(in_order) > 0):
            tied[j] = stats.rankdata(u) - 1.0          # average ranks, from 0 as the ordinal ones
    mean = np.array([tied[j].mean() if j in tied else (n - 1) / 2.0 for j in range(k)])
    G = np.zeros((k, k))
    for a in range(0, n, GRAM_BLOCK):
        Z = R[a:a + GRAM_BLOCK].astype(float)
        for j, t in tied.items():
            Z[:, j] = t[a:a + GRAM_BLOCK]
        Z -= mean
        G += Z.T @ Z
    with np.errstate(invalid="ignore", divide="ignore"):
        d = np.sqrt(np.diag(G))
        rho = G / np.outer(d, d)
    return C, rho


def first_order_given_data(X: np.ndarray, y: np.ndarray, classes: int | None = None, num_resamples: int = 200,
                           confidence: float = 0.95, seed: int | np.random.Generator | None = None,
                           C: np.ndarray | None = None) -> dict:
    """First-order indices of ``y`` on each column of ``X`` (any scale: only ranks matter), with bootstrap CIs.

    Returns arrays ``S1``, ``S1_conf`` (z·sd half-width), ``S1_low``, ``S1_high`` (percentiles)
    and the number of classes ``M``.  ``C``: the :func:`class_indices` of ``X`` when already computed.
    ``num_resamples = 0``: the indices alone (the interval columns NaN) — no bootstrap.
    """
    X, y = np.atleast_2d(np.asarray(X, dtype=float)), np.asarray(y, dtype=float).ravel()
    n, k = X.shape
    if len(y) != n:
        raise InputError(f"X has {n} rows and y {len(y)}", key="Y")
    M = classes or default_classes(n)
    if num_resamples != 0 and num_resamples < 10:
        raise InputError(f"num_resamples must be 0 (no intervals) or >= 10, got {num_resamples}", key="num_resamples")
    C = class_indices(X, M) if C is None else C
    S1, plug_in = np.empty(k), np.empty(k)
    for i in range(k):
        sums = (np.bincount(C[:, i], minlength=M), np.bincount(C[:, i], y, M), np.bincount(C[:, i], y * y, M))
        S1[i] = _corrected_ratio(*sums)
        plug_in[i] = _corrected_ratio(*sums, kelley=False)
    if num_resamples == 0:
        nan = np.full(k, np.nan)
        return {"S1": S1, "S1_conf": nan, "S1_low": nan, "S1_high": nan, "M": M}
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    # bootstrap in blocks of resamples (memory ~ 3 × block × n values); classes kept
    boot = np.empty((num_resamples, k))
    block = max(1, min(num_resamples, 4_000_000 // max(n, 1)))
    for b0 in range(0, num_resamples, block):
        nb = min(block, num_resamples - b0)
        rows = rng.integers(0, n, (nb, n))
        yi = y[rows]
        offs = (np.arange(nb) * M)[:, None]
        for i in range(k):
            flat = (C[:, i][rows] + offs).ravel()
            cnt = np.bincount(flat, minlength=nb * M).reshape(nb, M)
            s = np.bincount(flat, yi.ravel(), nb * M).reshape(nb, M)
            s2 = np.bincount(flat, (yi * yi).ravel(), nb * M).reshape(nb, M)
            boot[b0:b0 + nb, i] = _corrected_ratio(cnt, s, s2)
    z = stats.norm.ppf(0.5 + confidence / 2.0)
    lo_q, hi_q = 100 * (1 - confidence) / 2, 100 * (1 + confidence) / 2
    # the resamples scatter around the sample's own (plug-in) ratio SS_B/SS_T, not around the corrected
    # estimate: the percentile interval is shifted by their difference (the spread is what they tell)
    shift = S1 - plug_in
    return {"S1": S1, "S1_conf": z * boot.std(axis=0, ddof=1), "S1_low": np.percentile(boot, lo_q, axis=0) + shift,
            "S1_high": np.percentile(boot, hi_q, axis=0) + shift, "M": M}


def given_data(model: Model, spec: ToleranceSpec, samples: SampleSet, Y: np.ndarray,
               factors: Sequence[str] | None = None, outputs: Sequence[str] | None = None, seed: int | None = None,
               classes: int | None = None, num_resamples: int = 200,
               confidence: float = 0.95) -> gs.GlobalSensitivityResult:
    """First-order indices S1 (with bootstrap CIs) of each output from the Monte Carlo ``samples`` and ``Y``.

    ``Y``: every model output in display units (``MonteCarloResult.Y``); no model run is made
    (``n_evaluations`` = 0).  ``classes``: M (default ⌊√n⌋ in [8, 200]).  Method ``"given_data"``,
    columns ``S1, S1_conf, S1_low, S1_high`` (see the module notes).
    """
    model.check_spec(spec)
    idx, oidx = factor_indices(spec, factors), output_indices(model, outputs)
    X, Yd, n_failed, notes = given_samples(model, spec, samples, Y, oidx)
    C, rho = classes_and_spearman(X, spec_cdfs(spec), idx, classes)   # one ranking: classes and dependence
    pairs = correlated_pairs(spec.names, correlation=spec.correlation, rho=rho, n=len(X))
    if pairs:
        notes.append(N.GIVEN_DEPENDENT.format(pairs=describe_pairs(pairs)))
    rng = substream(seed, "given_data")
    names = [spec.names[i] for i in idx]
    rows, M = [], None
    for c, j in enumerate(oidx):
        q = model.outputs[j]
        y = Yd[:, c]
        if np.ptp(y) == 0.0:
            notes.append(N.CONSTANT_OUTPUT.format(output=q.name))
            res = {col: np.zeros(len(idx)) for col in GIVEN_COLUMNS}
        else:
            res = first_order_given_data(X[:, idx], y, classes, num_resamples, confidence, rng, C)
            M = res["M"]
        for i, nm in enumerate(names):
            rows.append({"output": q.name, "unit": q.shown_unit, "factor": nm,
                         **{col: float(res[col][i]) for col in GIVEN_COLUMNS}})
    frame = pd.DataFrame(rows, columns=["output", "unit", "factor", *GIVEN_COLUMNS])
    if num_resamples:
        notes.append(N.GIVEN_INTERVALS.format(resamples=num_resamples, n=len(X)))
    settings = {"n": len(X), "samples": "given", "classes": M or classes or default_classes(len(X)),
                "num_resamples": num_resamples, "estimator": "Kelley-corrected correlation ratio, equal-count classes"}
    return gs.GlobalSensitivityResult("given_data", frame, 0, confidence, settings, None, n_failed, notes)


# --------------------------------------------------------------------------- delta on a subsample
def delta_subsample(samples: SampleSet, Y: np.ndarray, n: int | None = DELTA_DEFAULT_N,
                    seed: int | None = None, stream: str = "delta_subsample",
                    what: str = "delta") -> tuple[SampleSet, np.ndarray, str]:
    """A random subsample of ``min(n, len(samples))`` rows (without replacement) and a note saying so.

    ``n=None`` keeps every sample.  The rows are drawn from the sub-stream ``stream`` of ``seed``
    (:data:`rvtol.sampling.STREAMS`; delta's by default) and kept in their original order; ``what`` names
    the method in the note.
    """
    from dataclasses import replace

    N = len(samples)
    Y = np.asarray(Y)
    if len(Y) != N:
        raise InputError(f"Y has {len(Y)} rows for {N} samples", key="Y")
    if n is None or n >= N:
        return samples, Y, f"{what} on all {N} samples"
    if n < 100:
        raise InputError(f"the {what} subsample needs n >= 100, got {n}", key="n")
    rows = np.sort(substream(seed, stream).choice(N, size=n, replace=False))
    sub = replace(samples, values=samples.values[rows])
    cost = " (its kernel density estimates cost ~n² per factor)" if what == "delta" else ""
    return sub, Y[rows], f"{what} on a random subsample of {n} of the {N} samples{cost}"


def delta_given(model: Model, spec: ToleranceSpec, samples: SampleSet, Y: np.ndarray, n: int | None = DELTA_DEFAULT_N,
                factors: Sequence[str] | None = None, outputs: Sequence[str] | None = None,
                seed: int | None = None, num_resamples: int = 50, confidence: float = 0.95,
                evaluate: Evaluator | None = None, executor: Executor | None = None) -> gs.GlobalSensitivityResult:
    """Borgonovo's δ (and S1) on a subsample of ``n`` (default :data:`DELTA_DEFAULT_N`) of the given samples.

    Correlation in the sample is kept (δ is valid with dependent inputs).  The subsample size
    is in ``settings["n"]`` and ``settings["n_given"]`` and stated in the notes.
    """
    sub, Ysub, note = delta_subsample(samples, Y, n, seed)
    res = gs.delta(model, spec, factors=factors, outputs=outputs, seed=seed, samples=sub, Y=Ysub,
                   num_resamples=num_resamples, confidence=confidence, evaluate=evaluate, executor=executor)
    res.settings.update({"n_given": len(samples), "subsample": n})
    res.notes.insert(0, note + ".")
    return res
