"""Sampling: plain random, Latin hypercube and scrambled Sobol through inverse CDFs.

All randomness in a study starts here: :func:`rng` is the one entry point
that turns a seed into a ``numpy.random.Generator``; the uniform design is
drawn once, up front, so evaluating it in any number of chunks, workers or
executors gives bit-identical results.  Models are deterministic functions of
their inputs: where a physics needs chance (a part floating in a clearance,
measurement noise) that chance is a factor of the spec.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
from scipy import special
from scipy.stats import qmc

from . import units
from .errors import InputError
from .spec import ToleranceSpec

METHODS = ("random", "lhs", "sobol")

# keep u strictly inside (0, 1) so inverse CDFs stay finite
_U_EPS = 2.0**-53


def rng(seed: int | None, *keys: int) -> np.random.Generator:
    """The one way rvtol builds a Generator: from ``seed`` and optional sub-stream keys."""
    if seed is None:  # no seed: fresh entropy (never a silent fixed stream)
        return np.random.Generator(np.random.PCG64(np.random.SeedSequence()))
    ss = np.random.SeedSequence(seed) if not keys else np.random.SeedSequence([seed, *keys])
    return np.random.Generator(np.random.PCG64(ss))


#: Every named random sub-stream of a study seed: ``substream(seed, name, *keys)`` draws from
#: ``SeedSequence([seed, STREAMS[name], *keys])``.  The Monte Carlo design itself is drawn from the
#: seed alone (:func:`uniform_design`); every other random draw of a study has a name here, so two
#: methods never share a stream and a result is reproducible from the study seed.
STREAMS = {
    "sobol": 1, "morris": 2, "fast": 3, "rbd_fast": 4, "delta": 5,   # global sensitivity designs (SALib)
    "pce": 6, "given_data": 9, "delta_subsample": 8,                  # surrogate / given-data bootstraps, subsample
    "pce_subsample": 10,                                              # the Monte Carlo rows a surrogate is fitted on
    "ga_population": 7,                                               # GA initial population (from the GA seed)
    "stackup_domains": 11,                                            # domain sampling, one key per domain
    "clearance_fit_sizes": 12, "clearance_fit_positions": 13,         # hole/shaft sizes, position in the fit
    "screening_subsample": 14,                                        # reducers for the torsion curve beside doc 001
    "allocation_ga_design": 71, "allocation_ga": 72, "allocation_verify": 73,
    "allocation_levers": 74, "allocation_ga_confirm": 75,                                         # the shifted design of a design lever
    "calibration_noise": 81,                                          # noise of synthetic measured curves
    "measured_gof": 91,                                               # bootstrap of a measured factor's GoF test
    "fit_uncertainty": 95,                                            # a fitted measured law's parameter draws
    "stacking_tail": 92,                                              # the tail methods of rvtol.stacking.tail (key: method)
    "compare_bootstrap": 93,                                          # baseline comparison: percentile bootstrap
    "check_corners": 94,                                              # rvtol check: corners of many bands
    "per_unit": 101,                                                  # measurement noise + unmeasured factors per unit
    "selective_stock": 102, "selective_optimise": 103,                # graded batch; design of the class-limit search
    "synthetic_parts": 104,                                           # synthetic measured parts (studies/)
    "synthetic_eol": 105,                                             # synthetic end-of-line batch (studies/)
    "per_serial": 106,                                                # the per-serial update's sampler (key: unit)
    "epistemic_tolerance": 111, "epistemic_indices": 112,             # the epistemic band: units of each design; the
                                                                      # bootstrap of its indices (key: output)
}


def substream(seed: int | None, name: str, *keys: int) -> np.random.Generator:
    """The Generator of the named sub-stream ``name`` (:data:`STREAMS`) of ``seed`` (fresh entropy if None)."""
    return rng(seed, STREAMS[name], *keys)


def substream_seed(seed: int | None, name: str, *keys: int) -> int:
    """A positive int seed drawn from a named sub-stream (for libraries that take only int seeds)."""
    return int(substream(seed, name, *keys).integers(1, 2**31 - 1))


def uniform_design(n: int, k: int, method: str = "random", seed: int | None = None) -> np.ndarray:
    """An ``n×k`` design of uniforms in (0, 1)."""
    if method not in METHODS:
        raise InputError(f"unknown sampling method {method!r} (expected one of: {', '.join(METHODS)})",
                         key="sampling.method")
    if n < 1 or k < 1:
        raise InputError(f"need n >= 1 and k >= 1, got n={n}, k={k}", key="sampling.n")
    g = rng(seed)
    if method == "random":
        u = g.random((n, k))
    elif method == "lhs":
        u = latin_hypercube(n, k, g)
    else:
        eng = qmc.Sobol(d=k, scramble=True, rng=g)
        m = int(np.log2(n))
        if 2**m == n:
            u = eng.random_base2(m)
        else:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", UserWarning)  # balance warning: noted in SampleSet.note
                u = eng.random(n)
    return np.clip(u, _U_EPS, 1.0 - _U_EPS, out=u)


def latin_hypercube(n: int, k: int, g: np.random.Generator) -> np.ndarray:
    """``scipy.stats.qmc.LatinHypercube(d=k, rng=g).random(n)`` (scrambled, strength 1, no optimisation) in
    place: the same draws in the same order (scipy's engine draws from a child of ``g``'s seed sequence:
    n × k uniforms, then one shuffle of 1 … n per column) and the same arithmetic, a column at a time —
    memory n × k values instead of scipy's four (its permutation matrix and temporaries).
    ``tests/spec/test_sampling.py`` holds it to scipy's bit for bit."""
    g = g.spawn(1)[0]
    u = g.uniform(size=(n, k))
    perm = np.empty(n, dtype=np.int64)
    for i in range(k):
        perm[:] = np.arange(1, n + 1)
        g.shuffle(perm)
        u[:, i] = (perm - u[:, i]) / n
    return u


def apply_copula(u: np.ndarray, corr: np.ndarray | None) -> np.ndarray:
    """Gaussian copula: correlate uniforms through normal scores with ``corr``."""
    if corr is None:
        return u
    z = special.ndtri(u)
    L = np.linalg.cholesky(corr)
    return np.clip(special.ndtr(z @ L.T), _U_EPS, 1.0 - _U_EPS)


def to_factors(spec: ToleranceSpec, u: np.ndarray, out: np.ndarray | None = None, columns=None) -> np.ndarray:
    """Map a uniform design (already correlated) to factor values in base units (into ``out``, which may be
    ``u`` itself: each column is read before it is written); ``columns``: only those factors (the others of ``out``
    are left as they are)."""
    x = np.empty_like(u, dtype=float) if out is None else out
    for j in (range(len(spec.factors)) if columns is None else columns):
        f = spec.factors[j]
        x[:, j] = f.ppf_base(u[:, j])
        if not np.all(np.isfinite(x[:, j])):
            raise InputError("distribution produced non-finite values", file=spec.file,
                             key=f"factor {spec.names[j]!r}")
    return x


def from_normal_scores(spec: ToleranceSpec, Z: np.ndarray) -> np.ndarray:
    """Factor values (base units) of independent standard-normal scores ``Z`` (n×k) through the study's own
    transform: the Gaussian copula of the spec's correlation, then each factor's inverse CDF — for a normal factor
    its inverse CDF of Φ(z) directly, μ + σz (no round trip through Φ, exact in the far tails where Φ(z) rounds to
    1 beyond z ≈ 8.3)."""
    Z = np.atleast_2d(np.asarray(Z, dtype=float))
    if spec.correlation is not None:
        Z = Z @ np.linalg.cholesky(spec.correlation).T
    normal = [j for j, f in enumerate(spec.factors) if getattr(f.dist, "kind", None) == "normal" and f.dist.p["sigma"] > 0]
    other = sorted(set(range(Z.shape[1])) - set(normal))
    X = np.empty_like(Z)
    if other:
        to_factors(spec, np.clip(special.ndtr(Z), _U_EPS, 1.0 - _U_EPS), X, other)
    for j in normal:
        f = spec.factors[j]
        X[:, j] = units.to_base(Z[:, j] * f.dist.p["sigma"] + (f.dist.p["mean"] + f.dist.shift), f.unit)
    return X


@dataclass(frozen=True)
class SampleSet:
    """``n×k`` factor values (base units) with names, units, method and seed."""

    values: np.ndarray
    names: tuple[str, ...]
    units: tuple[str, ...]  # each factor's own (display) unit
    method: str
    seed: int | None
    note: str = ""

    def __len__(self) -> int:
        return self.values.shape[0]

    @property
    def base_units(self) -> tuple[str, ...]:
        return tuple(units.base_unit(u) for u in self.units)

    def display_values(self) -> np.ndarray:
        out = np.empty_like(self.values)
        for j, u in enumerate(self.units):
            out[:, j] = units.from_base(self.values[:, j], u)
        return out

    def to_frame(self, display: bool = True):
        import pandas as pd

        vals = self.display_values() if display else self.values
        us = self.units if display else self.base_units
        return pd.DataFrame(vals, columns=[f"{n} [{u}]" for n, u in zip(self.names, us)])


def sample(spec: ToleranceSpec, n: int, method: str = "random", seed: int | None = None) -> SampleSet:
    """Draw ``n`` samples of ``spec`` by ``method`` (random | lhs | sobol) from ``seed``."""
    u = uniform_design(n, len(spec), method, seed)
    u = apply_copula(u, spec.correlation)
    note = ""
    if method == "sobol" and n & (n - 1):
        note = f"n={n} is not a power of 2: the Sobol sequence is used without its balance property"
    if method == "lhs" and spec.correlation is not None:
        note = "Latin hypercube stratification holds for the uncorrelated normal scores, not the margins"
    return SampleSet(to_factors(spec, u, out=u), spec.names, spec.units, method, seed, note)   # in place


class SampleStream:
    """Independent random draws of ``spec``, batch after batch, from one seeded stream (a sequential run,
    :func:`rvtol.mc.run_until_decided`): each batch continues the stream where the last one ended, so a row's values
    do not depend on how the rows were cut into batches — nor, then, on the executor or a resume.

    The uniforms are those of ``uniform_design(N, k, "random", seed)`` row for row; without a correlation the factor
    values are ``sample(spec, N, "random", seed)``'s bit for bit.  A Gaussian copula's matrix product is taken in
    blocks of :attr:`COPULA_BLOCK` rows aligned on the row's index in the run (BLAS rounds a row differently in the
    last bit by the shape of the product it is in: one row, or a long matrix split over threads), so a row gets the
    same bits in any batching; they may differ in the last bit from the fixed-n design's single product."""

    COPULA_BLOCK = 64

    def __init__(self, spec: ToleranceSpec, seed: int | None):
        self.spec = spec
        self.seed = seed
        self._g = rng(seed)
        self.drawn = 0
        self._cholesky_t = None if spec.correlation is None else np.linalg.cholesky(spec.correlation).T

    def next(self, m: int) -> np.ndarray:
        """The next ``m`` rows of factor values (base units)."""
        u = np.clip(self._g.random((m, len(self.spec))), _U_EPS, 1.0 - _U_EPS)
        if self._cholesky_t is not None:
            u = self._copula(u)
        self.drawn += m
        return to_factors(self.spec, u, out=u)

    def _copula(self, u: np.ndarray) -> np.ndarray:
        """:func:`apply_copula`, its product taken block by block (class docstring)."""
        b = self.COPULA_BLOCK
        z = special.ndtri(u)
        block = np.zeros((b, u.shape[1]))
        i = 0
        while i < len(u):
            at = (self.drawn + i) % b                  # the row's place in its block of the whole run
            take = min(b - at, len(u) - i)
            block[at:at + take] = z[i:i + take]
            z[i:i + take] = (block @ self._cholesky_t)[at:at + take]
            i += take
        return np.clip(special.ndtr(z), _U_EPS, 1.0 - _U_EPS)


#: Gauss–Hermite nodes per dimension of the copula's Pearson correlation (the closed forms of two uniforms and of
#: two lognormals to 1e-10, ``tests/stacking/test_stacking_correlation.py``); the quadrature clips the copula's uniforms
#: as the sampling does (``_U_EPS``)
HERMITE_NODES = 64
def factor_correlation(spec: ToleranceSpec) -> np.ndarray | None:
    """The Pearson correlation of the factors under the spec's Gaussian copula (None: independent factors).

    For a pair of normal-score correlation ρ, x_i = F_i⁻¹(Φ(u)) and x_j = F_j⁻¹(Φ(ρu + √(1 − ρ²) v)) with u, v
    independent standard normals, and corr(x_i, x_j) = E[(x_i − μ_i)(x_j − μ_j)] / (σ_i σ_j) by a tensor
    Gauss–Hermite rule of ``HERMITE_NODES`` per dimension (its own μ and σ of each margin, so a perfectly
    correlated pair gives exactly 1).  Two normal factors keep ρ (their copula is the bivariate normal); for
    others |corr| < |ρ| — two uniforms (6/π) asin(ρ/2) [K. Pearson 1904; W. Kruskal, "Ordinal measures of
    association", JASA 53 (1958) 814–861], two lognormals of log-σ s_i, s_j (e^{ρ s_i s_j} − 1) /
    √((e^{s_i²} − 1)(e^{s_j²} − 1)).
    """
    R = spec.correlation
    if R is None:
        return None
    R = np.asarray(R, dtype=float)
    P = R.copy()
    z, w = np.polynomial.hermite_e.hermegauss(HERMITE_NODES)
    w = w / math.sqrt(2.0 * math.pi)

    def margin(i, u):
        x = spec.factors[i].ppf_base(np.clip(special.ndtr(u), _U_EPS, 1.0 - _U_EPS))
        m = float(w @ spec.factors[i].ppf_base(np.clip(special.ndtr(z), _U_EPS, 1.0 - _U_EPS)))
        return x - m

    for i, j in zip(*np.nonzero(np.triu(R, 1))):
        if spec.factors[i].dist.kind == "normal" and spec.factors[j].dist.kind == "normal":
            continue
        rho = R[i, j]
        gi = margin(i, z)
        gj = margin(j, rho * z[:, None] + math.sqrt(max(0.0, 1.0 - rho * rho)) * z[None, :])
        si, sj = math.sqrt(float(w @ gi ** 2)), math.sqrt(float(w @ margin(j, z) ** 2))
        P[i, j] = P[j, i] = float(w @ (gi[:, None] * gj) @ w) / (si * sj)
    return P
