"""Per-serial update: each reducer's end-of-line test updates its own prediction (Bayesian; issue 41).

**Prior.**  Reducer ``i``'s prior is its per-unit prediction (:mod:`.per_unit`): its measured parts at their
readings with their measurement error, every other factor from the spec.  Every factor is a function of one
independent coordinate of the unit's design (:func:`.per_unit.unit_values`), i.e. of a score
``z_j = Φ⁻¹(u_j) ~ N(0, 1)``: the unit's unknowns are the scores ``z ∈ Rᵏ`` with the prior ``N(0, I)``, whatever
the factors' laws and correlations.

**Evidence.**  The end-of-line test reads some of the study's outputs on the built unit — lost motion, backlash,
rigidity from its hysteresis curve, TE where measured — as ``y_obs`` with standard uncertainties ``u_obs``
(k = 1; :func:`read_end_of_line`).  Bayes' rule::

    p(z | y_obs) ∝ N(z; 0, I) · Π_j N(y_obs,j; f_j(z), u_obs,j²)

The model's cost is kept bounded in three steps:

1. **Coordinates** (:func:`informed_coordinates`).  The readings see the scores through the model; on the units'
   prior samples (their per-unit predictions, already evaluated; pooled over the batch, each unit centred on its
   own means) a score's first-order linear share of a reading's variance is ``b_j² / Var(y)`` with
   ``b_j = Cov(z_j, y)`` (the scores are independent with ``Var(z_j) = 1``: the multiple regression's coefficient,
   read without a regression on all k scores, which would need more samples than the RV-80E's 288 factors).  The
   sampler's coordinates are ``w = (z_H, Qᵀz)``: the ``hidden`` scores of the largest share summed over the
   readings (2 by default: what may act non-linearly), and the orthonormal directions ``Q`` spanned by the other
   scores' covariances with the readings — a likelihood-informed subspace (Cui et al. 2014, *Inverse Problems*
   30:114015): the combination of all the other factors each reading sees, however many they are.  ``w ~ N(0, I)``
   a priori, independent of the rest of ``z``; every direction of ``z`` outside them keeps its prior.
2. **Surrogate** (:class:`QuadraticSurrogate`).  Per unit and reading a full quadratic polynomial in ``w``, least
   squares on the unit's prior samples (scikit-learn's ``PolynomialFeatures`` and ``LinearRegression``).  Its error
   is measured by 5-fold cross-validation in which each fold re-estimates the coordinates and the quadratic on the
   other folds alone (:func:`cross_validated_error`: the directions' own estimation error is in it): the residual
   standard deviation ``s_j`` — what the quadratic misses — enters the likelihood as an independent error beside
   the test's own, ``y_obs,j ~ N(g_j(w), u_obs,j² + s_j²)``, so what the surrogate cannot explain widens the
   posterior instead of being believed.  The cross-validated ``R²`` and ``s_j`` are reported beside ``u_obs``.
3. **Sampler** (:func:`sample_posterior`).  emcee's affine-invariant ensemble sampler (Goodman & Weare 2010;
   Foreman-Mackey et al. 2013, PASP 125:306): no gradient and no proposal to tune — a posterior of a few
   correlated scores is sampled as readily as an uncorrelated one — with the log-density of the whole ensemble
   evaluated at once (vectorised).  ``chains`` independent ensembles start from the prior (over-dispersed
   against the posterior) and the first half of every chain is discarded.  Diagnostics per hidden factor: the
   split-R̂ (:func:`split_rhat`; Gelman et al., *Bayesian Data Analysis*, 3rd ed., §11.4 — every ensemble a chain,
   its draws in step order, each halved) and the effective sample size ``N/τ`` with ``τ`` the integrated autocorrelation time
   (``emcee.autocorr.integrated_time``: Sokal's automatic window on the walkers' mean autocorrelation).  A unit
   is **converged** when every R̂ ≤ 1.01 (Vehtari et al. 2021, *Bayesian Analysis* 16:667) and every ESS ≥ 400;
   a unit that is not keeps the verdict "undecided".

**Posterior predictive.**  ``n`` draws of ``w`` from the pooled chains set into the unit's prior design
(:meth:`Coordinates.replace`: common random numbers, the prior and posterior differ only by what the test pinned
down), mapped to
factor values and evaluated by the **study's model itself**, not the surrogate — every output, the ones
measured (as the model now reproduces them) and the ones not measured (TE at another load, the rigidity the
customer's test will read), with its median and interval, P(conforms) and the ISO 14253-1 decision per
requirement (:class:`.per_unit.UnitPredictions`).  A serial without an end-of-line record keeps its prior.

**The outputs' update** (``update = "outputs"``, :func:`ensemble_kalman`).  Where the readings depend on many
factors, or not smoothly — on the RV-80E the loop's mid-points and zero crossing are set by whichever of its many
contacts closes first — no surrogate in a few coordinates follows them (its cross-validated R² says so, and the
factor-level posterior then stays near the prior: calibrated, not sharp).  The alternative conditions in the
model's own outputs: the unit's prior samples of every output are moved by the stochastic ensemble Kalman analysis
on its readings.  No surrogate, no sampler, no model evaluation beyond the prior's; exact when the unit's outputs
are jointly normal, their linear-Gaussian approximation otherwise (the coverage script checks both methods).

Why the posterior predictive can be trusted (the coverage test in ``tests/production/test_production_per_serial.py``):
for units drawn from the prior with a known truth, the truth of each unmeasured output lies inside the 95 %
posterior interval about 95 % of the time; for a linear model with normal factors the posterior is the closed
form (Kalman) update, which the sampler reproduces.
"""
from __future__ import annotations

import hashlib
import logging
import time
from dataclasses import dataclass, replace
from functools import cached_property
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from .. import units
from ..errors import InputError, did_you_mean
from ..inputs.sheets import read_table
from ..mc import _progress
from ..model import STATUS_OK, Model
from ..sampling import substream, substream_seed
from ..spec import ToleranceSpec
from .measured_parts import REDUCER, UNCERTAINTY_ROW, MeasuredUnits, _text, uncertainty_row
from .per_unit import (COVERAGE_FACTOR, STATES, UnitPredictions, evaluate_units, unit_uniforms, unit_values)

#: convergence thresholds of the sampler's diagnostics (module docstring)
R_HAT_MAX, ESS_MIN = 1.01, 400
HIDDEN, WALKERS, STEPS, CHAINS, FOLDS = 2, 32, 1000, 4, 5
_U_EPS = 2.0 ** -53



# --------------------------------------------------------------------------- end-of-line records
@dataclass(frozen=True)
class EndOfLine:
    """The end-of-line readings of the units (each output in its display unit; NaN: not read on that unit)."""

    file: str
    sha256: str
    outputs: tuple[str, ...]
    units: tuple[str, ...]            # the display unit of each output (the values' unit)
    serials: tuple[str, ...]
    lines: tuple[str, ...]            # where each serial's readings are ("row 5", or its curve file's name)
    value: np.ndarray                 # [serials, outputs]
    uncertainty: np.ndarray           # [outputs], standard (k = 1), display unit
    per_serial_u: np.ndarray | None = None    # [serials, outputs]: each reducer's own (curves), else None

    def row(self, serial: str) -> int | None:
        return self.serials.index(serial) if serial in self.serials else None

    def u(self, row: int) -> np.ndarray:
        """The standard uncertainties of row ``row``'s readings ([outputs], display units)."""
        return self.uncertainty if self.per_serial_u is None else self.per_serial_u[row]


def read_end_of_line(path, model: Model) -> EndOfLine:
    """Read an end-of-line file: one row per reducer serial, one column per output the test reads (a study
    output's name, its unit in brackets), a row ``uncertainty`` with each reading's standard uncertainty
    (k = 1, > 0: a reading without error would make the posterior a point); an empty cell: not read on that unit::

        # end-of-line hysteresis test, rig R-2 (u: encoder 0.02 arcmin, torque cell 0.5 %)
        reducer, lost_motion [arcmin], torsional_rigidity [N*m/arcmin]
        uncertainty, 0.03, 4
        RV80E-0001, 0.62, 201
    """
    t = read_table(path, what=f"{REDUCER}, <output> [unit], ...")
    names = t.names
    if names.count(REDUCER) != 1 or names[0] != REDUCER:
        raise t.error(f"the first column must be {REDUCER!r} (once)", col=0)
    outs = [q.name for q in model.outputs]
    cols, shown = [], []
    for i, name in enumerate(names[1:], start=1):
        if name in names[:i]:
            raise t.error("column appears twice", col=i)
        if name not in outs:
            raise t.error(f"no output {name!r} in the study's model{did_you_mean(name, outs)}", col=i)
        q = model.output(name)
        unit = t.unit(i) or q.shown_unit
        if units.dimension(unit) != units.dimension(q.shown_unit):
            raise t.error(f"unit {unit!r} does not fit the output's unit {q.shown_unit!r}", col=i)
        cols.append((i, unit))
        shown.append(q.shown_unit)
    if not cols:
        raise t.error("no output columns (the outputs the test reads, e.g. 'lost_motion [arcmin]')")
    u_row, rows = uncertainty_row(t)
    if u_row is None:
        raise t.error(f"no {UNCERTAINTY_ROW!r} row: give each reading's standard uncertainty (k = 1)")
    u = np.empty(len(cols))
    for c, (i, unit) in enumerate(cols):
        if u_row[1][i] == "":
            raise t.error("no uncertainty for this reading", u_row[0], i)
        v = t.number(u_row[0], u_row[1], i)
        if not v > 0:
            raise t.error(f"an end-of-line reading's uncertainty must be > 0 (a reading without error pins the unit "
                          f"to a point), got {u_row[1][i]!r}", u_row[0], i)
        u[c] = units.convert(v, unit, shown[c])
    if not rows:
        raise t.error("no reducers (rows) in the file")
    serials, lines, seen = [], [], {}
    value = np.full((len(rows), len(cols)), np.nan)
    for r, (row, cells) in enumerate(rows):
        s = _text(cells[0])
        if not s:
            raise t.error("empty serial number", row, 0)
        if s in seen:
            raise t.error(f"reducer {s!r} appears twice (also on row {seen[s]})", row, 0)
        seen[s] = row
        serials.append(s)
        lines.append(f"row {row}")
        for c, (i, unit) in enumerate(cols):
            if cells[i] != "":
                value[r, c] = units.convert(t.number(row, cells, i), unit, shown[c])
        if np.isnan(value[r]).all():
            raise t.error("no reading on this row (leave the reducer out of the file instead)", row, 0)
    return EndOfLine(t.file, t.sha256, tuple(names[i] for i, _ in cols), tuple(shown), tuple(serials),
                     tuple(lines), value, u)


#: the maker's figures a hysteresis curve gives (:class:`rvtol.models.torsion_curve.model.CurveMetrics`) and their
#: dimension (base units rad, N·mm/rad)
CURVE_FIGURES = {"lost_motion": "angle", "backlash": "angle", "rigidity": "torsional stiffness",
                 "rigidity_50_100": "torsional stiffness"}
FIGURE_UNITS = {"angle": "rad", "torsional stiffness": "N*mm/rad"}     # the figures' base units


def read_end_of_line_curves(folder, outputs: dict[str, str], model: Model, percent: float = 3.0, seed: int = 0, *,
                            figures) -> EndOfLine:
    """The end-of-line records from one hysteresis curve per reducer: ``folder/<reducer>.csv`` (any table format
    :func:`rvtol.inputs.sheets.read_table` reads), each read by ``figures(path, percent, seed=...) -> (values, u)``
    (the torsion-curve model's :func:`rvtol.models.torsion_curve.measured.hysteresis_figures`, reached through
    :func:`rvtol.registry.curve_reader`: this package knows no model); ``outputs``: figure ->
    the study output it is (``{lost_motion = "reducer.lost_motion", rigidity = "torsion.torsional_rigidity"}``).
    Each reading's uncertainty is that curve's own (:meth:`EndOfLine.u`)."""
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError("not a folder of end-of-line curves (<reducer>.csv, one per reducer)", file=str(folder),
                         key="curves")
    bad = [f for f in outputs if f not in CURVE_FIGURES]
    if bad:
        raise InputError(f"no figure {bad[0]!r} of a hysteresis curve{did_you_mean(bad[0], list(CURVE_FIGURES))} "
                         f"(known: {', '.join(CURVE_FIGURES)})", key="curve_outputs")
    outs = [q.name for q in model.outputs]
    for f, o in outputs.items():
        if o not in outs:
            raise InputError(f"no output {o!r} in the study's model{did_you_mean(o, outs)}", key=f"curve_outputs.{f}")
        if units.dimension(model.output(o).unit) != units.dimension(FIGURE_UNITS[CURVE_FIGURES[f]]):
            raise InputError(f"output {o!r} ({model.output(o).shown_unit}) does not have the dimension of the figure's "
                             f"{CURVE_FIGURES[f]}", key=f"curve_outputs.{f}")
    files = sorted(p for p in folder.iterdir() if p.suffix.lower() in (".csv", ".tsv", ".txt", ".xlsx")
                   and not p.name.startswith("."))
    if not files:
        raise InputError("no curve files (<reducer>.csv) in the folder", file=str(folder), key="curves")
    stems = [p.stem for p in files]
    twice = next((p for p in files if stems.count(p.stem) > 1), None)
    if twice is not None:
        both = [p.name for p in files if p.stem == twice.stem]
        raise InputError(f"two curves of reducer {twice.stem!r}: {' and '.join(both)} (keep one)", file=str(folder),
                         key="curves")
    shown = [model.output(o).shown_unit for o in outputs.values()]
    value = np.empty((len(files), len(outputs)))
    u = np.empty_like(value)
    for r, path in enumerate(files):
        v, s = figures(path, percent, seed=seed + r)
        for c, (f, o) in enumerate(outputs.items()):
            value[r, c] = units.convert(v[f], FIGURE_UNITS[CURVE_FIGURES[f]], shown[c])
            u[r, c] = units.convert(s[f], FIGURE_UNITS[CURVE_FIGURES[f]], shown[c])
    digest = hashlib.sha256(b"".join(hashlib.sha256(p.read_bytes()).digest() for p in files)).hexdigest()
    return EndOfLine(str(folder), digest, tuple(outputs.values()), tuple(shown), tuple(p.stem for p in files),
                     tuple(p.name for p in files), value, u.max(axis=0), per_serial_u=u)


# --------------------------------------------------------------------------- the update of one unit
def hidden_scores(Z: np.ndarray, Y: np.ndarray, h: int) -> tuple[np.ndarray, np.ndarray]:
    """``(columns, share)``: the ``h`` scores of ``Z[n, k]`` with the largest share of the variance of the outputs
    ``Y[n, m]``, summed over the outputs (module docstring, step 1), largest first, and their shares.

    The scores are independent standard normals by construction, so a score's first-order linear share of an
    output's variance is its squared correlation with the output, ``b_j² / Var(y)`` with ``b_j = Cov(z_j, y)`` —
    the multiple regression's coefficient without a regression on all k columns (which would need n > k samples:
    the RV-80E has 288 factors)."""
    Zc, Yc = Z - Z.mean(axis=0), Y - Y.mean(axis=0)
    b = Zc.T @ Yc / (len(Z) - 1)                              # [k, m]
    var = Y.var(axis=0, ddof=1)
    share = (b ** 2 / np.where(var > 0, var, np.inf)).sum(axis=1)
    order = np.argsort(-share, kind="stable")[:h]
    return order, share[order]


@dataclass(frozen=True)
class Coordinates:
    """The sampler's coordinates ``w = (z_H, Qᵀz)`` of the scores ``z`` (module docstring, step 1): the ``h`` hidden
    scores ``cols`` and the projections on the orthonormal directions ``Q[k, M]`` (zero on ``cols``) along which
    the other scores move the readings.  ``w ~ N(0, I)`` a priori, independent of the rest of ``z``."""

    cols: np.ndarray                  # [h]
    Q: np.ndarray                     # [k, M]
    labels: tuple[str, ...]           # [h + M]
    share: np.ndarray                 # [h] the hidden scores' share of the readings' variance

    @property
    def d(self) -> int:
        return len(self.cols) + self.Q.shape[1]

    def __call__(self, Z: np.ndarray) -> np.ndarray:
        return np.column_stack([Z[:, self.cols], Z @ self.Q])

    def replace(self, Z: np.ndarray, W: np.ndarray) -> np.ndarray:
        """``Z`` with its coordinates set to ``W`` and the rest of each row kept: ``z + Q(w_Q − Qᵀz)``, then the
        hidden scores."""
        h = len(self.cols)
        out = Z + (W[:, h:] - Z @ self.Q) @ self.Q.T
        out[:, self.cols] = W[:, :h]
        return out


def informed_coordinates(Zs, Ys, masks, h: int, factor_names, outputs) -> Coordinates:
    """The :class:`Coordinates` from the units' prior samples pooled (``Zs``/``Ys``/``masks``: per unit its scores,
    readings' outputs and the rows to use; each unit centred on its own means, so a unit's offset is no
    sensitivity): the ``h`` scores of the largest share (:func:`hidden_scores`), then the directions spanned by the
    other scores' covariances with the readings (each reading scaled to unit variance; the SVD's left vectors of
    non-zero singular value)."""
    Zc = np.concatenate([Z[m] - Z[m].mean(axis=0) for Z, m in zip(Zs, masks)])
    Yc = np.concatenate([Y[m] - Y[m].mean(axis=0) for Y, m in zip(Ys, masks)])
    cols, share = hidden_scores(Zc, Yc, min(h, Zc.shape[1]))
    sd = Yc.std(axis=0, ddof=1)
    b = Zc.T @ (Yc / np.where(sd > 0, sd, np.inf)) / (len(Zc) - 1)    # [k, m] correlations
    b[cols] = 0.0
    U, S, _ = np.linalg.svd(b, full_matrices=False)
    Q = U[:, S > 1e-9 * max(S.max(initial=0.0), 1e-300)]
    return Coordinates(cols, Q, tuple(factor_names[c] for c in cols)
                       + tuple(f"direction {j + 1} of the other factors" for j in range(Q.shape[1])), share)


def cross_validated_error(Zs, Ys, masks, h: int, factor_names, outputs, folds: int = FOLDS,
                          seed: int = 0) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Per unit and reading, the surrogate's ``folds``-fold cross-validated residual standard deviation ``s`` and
    ``R²``: every fold's coordinates (:func:`informed_coordinates`) and quadratic fitted on the other folds' rows
    alone, so the directions' own estimation error is in ``s`` (module docstring, step 2)."""
    n = len(Zs[0])
    fold = np.random.default_rng(seed).permutation(n) % folds
    pred = [np.full_like(Y, np.nan) for Y in Ys]
    for f in range(folds):
        train = [m & (fold != f) for m in masks]
        coords = informed_coordinates(Zs, Ys, train, h, factor_names, outputs)
        for i, (Z, Y, m) in enumerate(zip(Zs, Ys, masks)):
            test = m & (fold == f)
            if test.any():
                pred[i][test] = QuadraticSurrogate(coords(Z[train[i]]), Y[train[i]], s=0.0)(coords(Z[test]))
    s = [np.sqrt(np.mean((Y[m] - p[m]) ** 2, axis=0)) for Y, p, m in zip(Ys, pred, masks)]
    var = [Y[m].var(axis=0) for Y, m in zip(Ys, masks)]
    return s, [1.0 - si ** 2 / np.where(v > 0, v, np.inf) for si, v in zip(s, var)]


class QuadraticSurrogate:
    """A full quadratic polynomial per output in the scores ``Z[n, h]``, least squares (scikit-learn), with its
    ``folds``-fold cross-validated residual standard deviation ``s`` and ``r2`` (module docstring, step 2).

    ``__call__`` evaluates it as ``c + Z a + Σ_{i≤j} B_ij z_i z_j`` from the fitted coefficients: the same
    numbers as the scikit-learn pipeline, without its per-call overhead inside the sampler."""

    def __init__(self, Z: np.ndarray, Y: np.ndarray, folds: int = FOLDS, seed: int = 0, s=None):
        from sklearn.linear_model import LinearRegression
        from sklearn.model_selection import KFold, cross_val_predict
        from sklearn.pipeline import make_pipeline
        from sklearn.preprocessing import PolynomialFeatures

        self.h = Z.shape[1]
        self.pipeline = make_pipeline(PolynomialFeatures(2, include_bias=False), LinearRegression())
        var = Y.reshape(len(Y), -1).var(axis=0)
        if s is None:               # its own cross-validation (``s`` given: cross-validated by the caller)
            cv = cross_val_predict(self.pipeline, Z, Y, cv=KFold(folds, shuffle=True, random_state=seed))
            s = np.sqrt(np.mean((Y - cv).reshape(len(Y), -1) ** 2, axis=0))
        self.s = np.broadcast_to(np.asarray(s, float), var.shape)
        self.r2 = 1.0 - self.s ** 2 / np.where(var > 0, var, np.inf)
        self.pipeline.fit(Z, Y)
        poly, lin = self.pipeline.steps[0][1], self.pipeline.steps[1][1]
        coef = np.atleast_2d(lin.coef_)                         # [m, terms]
        self.c = np.atleast_1d(lin.intercept_)
        self.a = np.zeros((self.h, coef.shape[0]))
        self.B = np.zeros((self.h, self.h, coef.shape[0]))
        for t, p in enumerate(poly.powers_):
            idx = np.flatnonzero(p)
            if p.sum() == 1:
                self.a[idx[0]] = coef[:, t]
            elif idx.size == 1:
                self.B[idx[0], idx[0]] = coef[:, t]
            else:
                self.B[idx[0], idx[1]] = coef[:, t]

    def __call__(self, Z: np.ndarray) -> np.ndarray:
        return self.c + Z @ self.a + np.einsum("wi,ijm,wj->wm", Z, self.B, Z)


def split_rhat(x: np.ndarray) -> float:
    """The split-R̂ of ``x[chains, draws]`` (BDA3 §11.4): every chain halved, ``R̂ = √(var⁺/W)`` with
    ``var⁺ = (n − 1)/n · W + B/n``, W the mean within-chain variance and B/n the variance of the chain means
    (n draws per half-chain)."""
    n = x.shape[1] // 2
    halves = np.concatenate([x[:, :n], x[:, n:2 * n]])
    W = halves.var(axis=1, ddof=1).mean()
    B_n = halves.mean(axis=1).var(ddof=1)
    return float(np.sqrt(((n - 1) / n * W + B_n) / W)) if W > 0 else float("inf")


@dataclass(frozen=True)
class Posterior:
    """The pooled posterior draws of the hidden scores and the sampler's diagnostics."""

    z: np.ndarray                     # [draws, h] (after burn-in, every chain pooled)
    r_hat: np.ndarray                 # [h]
    ess: np.ndarray                   # [h]
    acceptance: float                 # mean acceptance fraction of the walkers

    @property
    def converged(self) -> bool:
        return bool(np.all(self.r_hat <= R_HAT_MAX) and np.all(self.ess >= ESS_MIN))


def sample_posterior(surrogate: QuadraticSurrogate, y_obs: np.ndarray, sigma: np.ndarray, *, walkers: int = WALKERS,
                     steps: int = STEPS, chains: int = CHAINS, seed: int = 0) -> Posterior:
    """Sample ``p(z_H | y_obs) ∝ N(z_H; 0, I) Π_j N(y_obs,j; g_j(z_H), σ_j²)`` with emcee (module docstring,
    step 3); ``sigma``: the likelihood's standard deviations √(u_obs² + s²)."""
    import emcee

    h = surrogate.h
    walkers = max(walkers, 2 * h + 2)
    rng = np.random.default_rng(seed)

    def log_p(z):
        r = (y_obs - surrogate(z)) / sigma
        return -0.5 * (np.sum(z * z, axis=1) + np.sum(r * r, axis=1))

    kept, accept = [], []
    for _ in range(chains):
        s = emcee.EnsembleSampler(walkers, h, log_p, vectorize=True)
        s.random_state = np.random.RandomState(int(rng.integers(2 ** 31))).get_state()
        s.run_mcmc(rng.standard_normal((walkers, h)), steps)
        kept.append(s.get_chain()[steps // 2:])                 # [steps/2, walkers, h]
        accept.append(s.acceptance_fraction.mean())
    chain = np.stack(kept)                                      # [chains, steps/2, walkers, h]
    seq = chain.reshape(chains, -1, h)                          # each ensemble's draws in step order
    r_hat = np.array([split_rhat(seq[:, :, j]) for j in range(h)])
    quiet = logging.getLogger("emcee.autocorr")
    level, quiet.level = quiet.level, logging.ERROR             # its "chain shorter than 50 τ" warning: ESS says it
    try:
        tau = np.stack([emcee.autocorr.integrated_time(c, quiet=True) for c in kept])    # [chains, h]
    finally:
        quiet.setLevel(level)
    ess = (chain.shape[1] * walkers / tau).sum(axis=0)
    return Posterior(chain.reshape(-1, h), r_hat, ess, float(np.mean(accept)))


@dataclass(frozen=True)
class SerialUpdate:
    """What one unit's end-of-line record did: the readings, the coordinates, the surrogate, the sampler."""

    reducer: str
    observed: tuple[str, ...]
    y_obs: np.ndarray
    u_obs: np.ndarray
    hidden: tuple[str, ...]           # the sampler's coordinates: hidden factors, then directions of the others
    share: np.ndarray                 # the hidden factors' share of the readings' variance (summed over readings)
    surrogate_s: np.ndarray           # [observed] cross-validated residual standard deviation (display units)
    surrogate_r2: np.ndarray          # [observed]
    posterior: Posterior | None       # the sampler's draws and diagnostics (None: the outputs' closed-form update)
    seconds: float
    method: str = "factors"
    conflict: tuple[str, ...] = ()    # readings the unit's prior cannot produce (:func:`prior_conflict`)

    @property
    def converged(self) -> bool:
        """The sampler's diagnostics met (:attr:`Posterior.converged`); the closed-form update has none to meet."""
        return self.posterior is None or self.posterior.converged


def posterior_draws(walkers: int, steps: int, chains: int) -> int:
    """The draws the sampler keeps: ``chains · walkers · steps//2`` (walkers as given: at least that many run)."""
    return chains * walkers * (steps // 2)


def min_samples(d: int) -> int:
    """The fewest prior samples the surrogate in ``d`` coordinates is fitted on: five per coefficient of the full
    quadratic, (d + 1)(d + 2)/2 (its cross-validated error, not this count, is what guards against overfitting)."""
    return 5 * (d + 1) * (d + 2) // 2


def _sample_unit(reducer, coords: Coordinates, W, Y, y_obs, u_obs, s, r2, observed, *, walkers, steps, chains,
                 seed, t0) -> SerialUpdate:
    sur = QuadraticSurrogate(W, Y, s=s)
    post = sample_posterior(sur, y_obs, np.sqrt(u_obs ** 2 + sur.s ** 2), walkers=walkers, steps=steps,
                            chains=chains, seed=seed)
    return SerialUpdate(reducer, tuple(observed), y_obs, u_obs, coords.labels, coords.share, np.asarray(s, float),
                        np.asarray(r2, float), post, time.perf_counter() - t0)


def update_unit(reducer: str, Z: np.ndarray, Y: np.ndarray, y_obs: np.ndarray, u_obs: np.ndarray,
                factor_names, observed, *, hidden: int = HIDDEN, walkers: int = WALKERS, steps: int = STEPS,
                chains: int = CHAINS, seed: int = 0) -> tuple[SerialUpdate, Coordinates]:
    """One unit alone from its prior scores ``Z[n, k]`` and its readings' outputs on them ``Y[n, m]`` (rows the
    model evaluated): ``(update, coordinates)``; :func:`update_serials` pools the units' samples instead."""
    t0 = time.perf_counter()
    d = min(hidden, Z.shape[1]) + Y.shape[1]
    if len(Z) < min_samples(d):
        raise ValueError(f"{reducer}: {len(Z)} prior samples the model evaluated; the surrogate in {d} coordinates "
                         f"needs at least {min_samples(d)} (give a larger n)")
    ok = np.ones(len(Z), bool)
    s, r2 = cross_validated_error([Z], [Y], [ok], hidden, factor_names, observed, seed=seed)
    coords = informed_coordinates([Z], [Y], [ok], hidden, factor_names, observed)
    return _sample_unit(reducer, coords, coords(Z), Y, y_obs, u_obs, s[0], r2[0], observed, walkers=walkers,
                        steps=steps, chains=chains, seed=seed, t0=t0), coords


CONFLICT_Z = 4.0                      # a reading this many prior-predictive standard deviations away conflicts


def prior_conflict(Y: np.ndarray, y_obs: np.ndarray, u_obs: np.ndarray, names) -> tuple[str, ...]:
    """The readings the unit's prior cannot produce: a prior-predictive check (Box 1980, *J. R. Statist. Soc. A*
    143:383) — the reading's distance from the mean of the unit's prior samples ``Y[n, m]`` in standard deviations of
    its prior prediction, ``|y_obs − mean(Y)| / √(var(Y) + u_obs²)``, above :data:`CONFLICT_Z` (a normal prior
    prediction gives such a reading with probability 6e-5; the estimates, not the sample's range, so the rule does
    not depend on n).  Such a unit is not what its measured parts and the spec say (a part mis-measured, a serial
    mixed up, a fault the model does not have): the update would move it to the edge of its prior and certify that
    (a posterior beyond about 8 standard deviations of a score is out of reach), so its verdicts are withheld —
    undecided — and the conflict is named."""
    mean, var = np.nanmean(Y, axis=0), np.nanvar(Y, axis=0, ddof=1)
    z = np.abs(y_obs - mean) / np.sqrt(var + u_obs ** 2)
    return tuple(n for n, zz in zip(names, z) if zz > CONFLICT_Z)


def _withheld(up: SerialUpdate) -> str:
    """Why an update's verdicts are withheld: a reading conflicts with the prior (:func:`prior_conflict`) or the
    sampler did not converge; '' when they stand (the posterior prediction's
    :attr:`~.per_unit.UnitPredictions.withheld`)."""
    if up.conflict:
        return f"prior conflict: {', '.join(up.conflict)}"
    return "" if up.converged else "the sampler did not converge"


def _diagnostics(up: SerialUpdate) -> dict:
    """The sampler's diagnostics of one update as table cells (NaN for the closed-form update, which has none)."""
    p = up.posterior
    if p is None:
        return {"R-hat max": np.nan, "ESS min": np.nan, "acceptance": np.nan, "converged": "closed form"}
    return {"R-hat max": float(p.r_hat.max()), "ESS min": float(p.ess.min()), "acceptance": p.acceptance,
            "converged": "yes" if p.converged else "no"}


# --------------------------------------------------------------------------- every unit of a study
@dataclass
class SerialUpdates:
    """Every unit's prior and posterior prediction, the end-of-line readings and what each update did."""

    prior: UnitPredictions
    posterior: UnitPredictions
    eol: EndOfLine
    updates: dict[str, SerialUpdate]  # reducer -> its update (units with an end-of-line record)
    factors: pd.DataFrame             # per updated unit the factors its test narrowed most (:func:`_pinned_down`)

    @property
    def units(self) -> tuple[str, ...]:
        return self.prior.units

    def withheld(self, u: str) -> str:
        """Why unit ``u``'s verdicts are withheld (undecided; :func:`_withheld`), '' when they stand."""
        return self.posterior.withheld.get(u, "")

    def verdicts(self) -> dict[str, str]:
        """Reducer -> its verdict after the update (the posterior's, whose withheld units are undecided; the prior's
        where the unit has no end-of-line record)."""
        return self.posterior.verdicts()

    def counts(self) -> dict[str, int]:
        v = list(self.verdicts().values())
        return {s: v.count(s) for s in STATES}

    @cached_property
    def _outputs(self) -> pd.DataFrame:
        a, b = self.prior.output_frame(), self.posterior.output_frame()
        keep = ["reducer", "output", "unit", "median", "lo", "hi"]
        out = a[keep].merge(b[keep + ["failed"]], on=["reducer", "output", "unit"], suffixes=(" prior", " posterior"))
        obs = []
        for _, r in out.iterrows():
            i = self.eol.row(r["reducer"])
            j = self.eol.outputs.index(r["output"]) if r["output"] in self.eol.outputs else None
            v = self.eol.value[i, j] if i is not None and j is not None else np.nan
            obs.append(v)
        out.insert(3, "measured", obs)
        width = (out["hi posterior"] - out["lo posterior"]) / (out["hi prior"] - out["lo prior"])
        out["width ratio"] = width.where(np.isfinite(width))
        return out

    def output_frame(self) -> pd.DataFrame:
        """One row per unit and output: the end-of-line reading (if any), the prior's and the posterior's median
        and interval, the ratio of the interval widths."""
        return self._outputs.copy()

    def update_frame(self) -> pd.DataFrame:
        """One row per updated unit: readings, surrogate error against the reading's uncertainty, the sampler's
        diagnostics and time."""
        rows = []
        for u, up in self.updates.items():
            sur = {} if up.method != "factors" else {
                "surrogate s / u_obs": ", ".join(f"{s:.3g}/{uo:.3g}" for s, uo in zip(up.surrogate_s, up.u_obs)),
                "surrogate R²(CV)": ", ".join(f"{r:.3f}" for r in up.surrogate_r2), "coordinates": len(up.hidden)}
            rows.append({"reducer": u, "read": ", ".join(up.observed), "update": up.method, **sur, **_diagnostics(up),
                         "prior conflict": ", ".join(up.conflict), "seconds": up.seconds})
        return pd.DataFrame(rows)

    def factor_frame(self) -> pd.DataFrame:
        """Per updated unit the factors its test narrowed most: prior and posterior median and interval, the ratio of
        the interval widths."""
        return self.factors.copy()

    def to_frame(self) -> pd.DataFrame:
        return self.unit_frame()

    def unit_frame(self) -> pd.DataFrame:
        """One row per reducer (``per_unit.csv``): verdict after and before the update, the diagnostics, per
        requirement P and ISO 14253-1 decision after the update, per output the reading and the prior and
        posterior median and interval, the factors the test pinned down."""
        post = self.posterior.unit_frame().set_index("reducer")
        prior_v = self.prior.verdicts()
        verdicts = self.verdicts()
        outs = self._outputs
        rows = []
        for u in self.units:
            up = self.updates.get(u)
            row = {"reducer": u, "verdict": verdicts[u], "verdict before the test": prior_v[u],
                   "end-of-line record": "yes" if up else "no",
                   "prior conflict": ", ".join(up.conflict) if up else "",
                   **(_diagnostics(up) if up else {"R-hat max": np.nan, "ESS min": np.nan, "acceptance": np.nan,
                                                   "converged": ""}),
                   "measured_factors": int(post.loc[u, "measured_factors"]), "n": int(post.loc[u, "n"])}
            row.update({c: post.loc[u, c] for c in post.columns if c.endswith((": P", ": P_lo", ": verdict"))
                        or "ISO 14253-1" in c})
            row["withheld"] = self.withheld(u)
            for _, o in outs[outs["reducer"] == u].iterrows():
                unit = o["unit"]
                if np.isfinite(o["measured"]):
                    row[f"{o['output']} measured [{unit}]"] = o["measured"]
                for w in ("prior", "posterior"):
                    row[f"{o['output']} {w} median [{unit}]"] = o[f"median {w}"]
                    row[f"{o['output']} {w} lo [{unit}]"] = o[f"lo {w}"]
                    row[f"{o['output']} {w} hi [{unit}]"] = o[f"hi {w}"]
            f = self.factors[self.factors["reducer"] == u]
            row["pinned down"] = "; ".join(f"{r['factor']} (interval ×{r['width ratio']:.2f})"
                                           for _, r in f.iterrows() if r["width ratio"] < 0.8)
            rows.append(row)
        return pd.DataFrame(rows)

    def plot(self, output: str, ax=None):
        """Per unit the prior and the posterior interval of ``output`` and the end-of-line reading."""
        from ..plotting.production import plot_prior_posterior

        o = self._outputs[self._outputs["output"] == output].set_index("reducer").reindex(self.units)
        rs = [r for r in self.posterior.requirements if r.output == output]
        return plot_prior_posterior(list(self.units), o, output=output, unit=o["unit"].iloc[0],
                                    lower=next((r.lower for r in rs if r.lower is not None), None),
                                    upper=next((r.upper for r in rs if r.upper is not None), None),
                                    interval=self.prior.interval, ax=ax)

    def summary(self) -> dict:
        post = self.posterior.summary()
        verdicts = self.verdicts()
        prior_v = self.prior.verdicts()
        for entry in post["units"]:
            u = entry["reducer"]
            entry["verdict"], entry["verdict_before_test"] = verdicts[u], prior_v[u]
            if self.withheld(u):
                entry["withheld"] = self.withheld(u)
            up = self.updates.get(u)
            if up is not None:
                entry["end_of_line"] = {
                    "read": {o: {"value": float(y), "u": float(s)} for o, y, s in zip(up.observed, up.y_obs, up.u_obs)},
                    "hidden_factors": list(up.hidden),
                    "surrogate": {o: {"s": float(s), "r2_cv": float(r)} for o, s, r in
                                  zip(up.observed, up.surrogate_s, up.surrogate_r2)},
                    "update": up.method, "converged": up.converged, "prior_conflict": list(up.conflict),
                    **({} if up.posterior is None else {
                        "r_hat": dict(zip(up.hidden, map(float, up.posterior.r_hat))),
                        "ess": dict(zip(up.hidden, map(float, up.posterior.ess))),
                        "acceptance": up.posterior.acceptance}),
                    "seconds": up.seconds}
        post["counts"] = self.counts()
        post["end_of_line_file"] = self.eol.file
        return post


PINNED = 5                            # the factors listed per unit: those whose interval the test narrowed most


def _pinned_down(spec: ToleranceSpec, reducer: str, X0: np.ndarray, X1: np.ndarray, a: float) -> list[dict]:
    """The :data:`PINNED` factors whose central interval (``a`` in each tail) the update narrowed most: prior and
    posterior median and interval (the factor's unit) and the ratio of the widths."""
    lo0, med0, hi0 = np.quantile(X0, [a, 0.5, 1 - a], axis=0)
    lo1, med1, hi1 = np.quantile(X1, [a, 0.5, 1 - a], axis=0)
    w0 = hi0 - lo0
    ratio = np.where(w0 > 0, (hi1 - lo1) / np.where(w0 > 0, w0, 1.0), np.inf)
    rows = []
    for c in np.argsort(ratio, kind="stable")[:PINNED]:
        f = spec.factors[c]
        v = units.from_base(np.array([med0[c], lo0[c], hi0[c], med1[c], lo1[c], hi1[c]]), f.unit)
        rows.append({"reducer": reducer, "factor": f.name, "unit": f.unit, "median prior": v[0], "lo prior": v[1],
                     "hi prior": v[2], "median posterior": v[3], "lo posterior": v[4], "hi posterior": v[5],
                     "width ratio": float(ratio[c])})
    return rows


def check_serials(eol: EndOfLine, measured: MeasuredUnits) -> None:
    """Every reducer of the end-of-line file is one of the kit list's (else an :class:`InputError` at its row)."""
    unknown = [s for s in eol.serials if s not in measured.units]
    if unknown:
        raise InputError(f"reducer {unknown[0]!r} is not in the kit list {Path(measured.kit_file).name!r}",
                         file=eol.file, key=eol.lines[eol.serials.index(unknown[0])])


UPDATES = ("factors", "outputs")      # how the test updates a unit (module docstring)


def ensemble_kalman(Y: np.ndarray, X: np.ndarray, read, y_obs: np.ndarray, u_obs: np.ndarray,
                    rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """The outputs' update (``update = "outputs"``): the stochastic ensemble Kalman analysis (Evensen 1994; Burgers,
    van Leeuwen & Evensen 1998, *Mon. Wea. Rev.* 126:1719) of a unit's prior samples ``Y[n, m]`` (and its factor values
    ``X[n, k]``) on the readings of the columns ``read``::

        y_i' = y_i + K (y_obs + ε_i − d_i),   K = C_yd (C_dd + R)⁻¹,   ε_i ~ N(0, R),  R = diag(u_obs²)

    with ``d_i`` the read columns and the covariances of the samples.  For jointly normal outputs the updated
    samples are draws of the posterior given the readings (the Kalman filter's, in the model's own outputs: no
    factor-level surrogate); otherwise its linear-Gaussian approximation.  Rows the model could not evaluate stay
    as they are (NaN)."""
    ok = np.all(np.isfinite(Y), axis=1)
    D = Y[ok][:, read]
    Dc = D - D.mean(axis=0)
    C = Dc.T @ Dc / (len(D) - 1) + np.diag(u_obs ** 2)
    innovation = y_obs + rng.standard_normal(D.shape) * u_obs - D
    gain = np.linalg.solve(C, innovation.T).T                       # (C_dd + R)⁻¹ (y_obs + ε − d), per sample
    Y1, X1 = Y.copy(), X.copy()
    for A, A1 in ((Y, Y1), (X, X1)):
        Ac = A[ok] - A[ok].mean(axis=0)
        A1[ok] = A[ok] + gain @ (Dc.T @ Ac / (len(D) - 1))
    return Y1, X1


def update_serials(model: Model, spec: ToleranceSpec, measured: MeasuredUnits, eol: EndOfLine, n: int, *,
                   evaluator, requirements=(), method: str = "lhs", seed: int | None = None,
                   interval: float = 0.95, probability: float | None = None,
                   coverage_factor: float = COVERAGE_FACTOR, update: str = "factors", hidden: int = HIDDEN,
                   walkers: int = WALKERS, steps: int = STEPS, chains: int = CHAINS,
                   progress: bool = False) -> SerialUpdates:
    """Every unit's prior (:func:`.per_unit.predict_units`) and, for the units with an end-of-line record, its
    posterior (module docstring): ``update = "factors"`` infers the unit's factors (surrogate and sampler, the
    posterior prediction the model itself), ``"outputs"`` updates its prior samples by :func:`ensemble_kalman`;
    ``progress``: a bar over the units (on a terminal)."""
    if update not in UPDATES:
        raise ValueError(f"update must be one of {UPDATES}, got {update!r}")
    if update == "factors" and posterior_draws(walkers, steps, chains) < n:
        raise ValueError(f"{n} posterior draws wanted, the sampler keeps {posterior_draws(walkers, steps, chains)} "
                         "(chains · walkers · steps/2): give more steps or walkers, or a smaller n")
    check_serials(eol, measured)
    kw = dict(evaluator=evaluator, requirements=requirements, method=method, seed=seed, interval=interval,
              probability=probability, coverage_factor=coverage_factor)
    u = unit_uniforms(spec, measured, n, method, seed)
    cache: dict = {}
    X = [unit_values(spec, measured, i, u, cache) for i in range(len(measured))]
    prior = evaluate_units(model, spec, measured, np.concatenate(X), what="per-serial update: prior", **kw)
    todo = [i for i, s in enumerate(measured.units) if eol.row(s) is not None]
    bar = _progress(len(todo), "per-serial update") if progress and todo else None
    if update == "outputs":
        posterior, updates, rows = _update_outputs(spec, measured, eol, prior, X, todo, seed, interval, bar)
    else:
        X_post, updates, rows = _update_factors(spec, measured, eol, prior, X, u, cache, todo, n, seed, interval,
                                                hidden, walkers, steps, chains, bar)
        posterior = evaluate_units(model, spec, measured, np.concatenate(X_post),
                                   what="per-serial update: posterior", **kw)
    if bar is not None:
        bar.close()
    factors = pd.DataFrame(rows, columns=["reducer", "factor", "unit", "median prior", "lo prior", "hi prior",
                                          "median posterior", "lo posterior", "hi posterior", "width ratio"])
    withheld = {u: why for u, up in updates.items() if (why := _withheld(up))}
    return SerialUpdates(prior, replace(posterior, withheld=withheld), eol, updates, factors)


def _update_outputs(spec, measured, eol, prior, X, todo, seed, interval, bar):
    names = [q.name for q in prior.outputs]
    Y = prior.Y.copy()
    updates, rows = {}, []
    for i in todo:
        t0 = time.perf_counter()
        reducer = measured.units[i]
        r = eol.row(reducer)
        read = np.flatnonzero(np.isfinite(eol.value[r]))
        cols = [names.index(eol.outputs[j]) for j in read]
        Y[i], X1 = ensemble_kalman(prior.Y[i], X[i], cols, eol.value[r, read], eol.u(r)[read],
                                   substream(seed, "per_serial", i, 2))
        rows += _pinned_down(spec, reducer, X[i], X1, (1.0 - interval) / 2.0)
        updates[reducer] = SerialUpdate(reducer, tuple(eol.outputs[j] for j in read), eol.value[r, read],
                                        eol.u(r)[read], (), np.zeros(0), np.zeros(0), np.zeros(0), None,
                                        time.perf_counter() - t0, "outputs",
                                        prior_conflict(prior.Y[i][:, cols], eol.value[r, read], eol.u(r)[read],
                                                       [eol.outputs[j] for j in read]))
        if bar is not None:
            bar.update(1)
    return replace(prior, Y=Y), updates, rows


def _update_factors(spec, measured, eol, prior, X, u, cache, todo, n, seed, interval, hidden, walkers, steps, chains,
                    bar):
    Z = stats.norm.ppf(u)
    names = [q.name for q in prior.outputs]
    # every unit's prior samples of the readings' outputs, pooled for the coordinates and their cross-validation
    Ys = [prior.Y[i][:, [names.index(o) for o in eol.outputs]] for i in range(len(measured))]
    masks = [(prior.status[i] == STATUS_OK) & np.all(np.isfinite(Y), axis=1) for i, Y in enumerate(Ys)]
    cv_s, cv_r2 = cross_validated_error([Z] * len(Ys), Ys, masks, hidden, spec.names, eol.outputs,
                                        seed=substream_seed(seed, "per_serial", len(measured)))
    coords = informed_coordinates([Z] * len(Ys), Ys, masks, hidden, spec.names, eol.outputs)
    X_post = list(X)
    updates, rows = {}, []
    a = (1.0 - interval) / 2.0
    for i in todo:
        t0 = time.perf_counter()
        reducer = measured.units[i]
        r = eol.row(reducer)
        read = np.flatnonzero(np.isfinite(eol.value[r]))
        m = masks[i]
        if m.sum() < min_samples(coords.d):
            raise ValueError(f"{reducer}: {int(m.sum())} prior samples the model evaluated; the surrogate in "
                             f"{coords.d} coordinates needs at least {min_samples(coords.d)} (give a larger n)")
        up = _sample_unit(reducer, coords, coords(Z[m]), Ys[i][m][:, read], eol.value[r, read], eol.u(r)[read],
                          cv_s[i][read], cv_r2[i][read], [eol.outputs[j] for j in read], walkers=walkers, steps=steps,
                          chains=chains, seed=substream_seed(seed, "per_serial", i), t0=t0)
        up = replace(up, conflict=prior_conflict(Ys[i][m][:, read], eol.value[r, read], eol.u(r)[read],
                                                 [eol.outputs[j] for j in read]))
        pick = substream(seed, "per_serial", i, 1).choice(len(up.posterior.z), n, replace=False)
        u_post = np.clip(stats.norm.cdf(coords.replace(Z, up.posterior.z[pick])), _U_EPS, 1.0 - _U_EPS)
        X_post[i] = unit_values(spec, measured, i, u_post, cache)
        updates[reducer] = up
        rows += _pinned_down(spec, reducer, X[i], X_post[i], a)
        if bar is not None:
            bar.update(1)
    return X_post, updates, rows
