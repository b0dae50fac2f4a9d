"""Global sensitivity of any Model through SALib: Sobol, Morris, eFAST, RBD-FAST and delta.

Every method uses each factor's **own distribution**: SALib designs live on
the unit hypercube (probabilities) and are mapped through the factors'
inverse CDFs (:meth:`rvtol.spec.Factor.ppf_base`), so a Rayleigh runout or a
triangular fit is sampled as such, not as a uniform box.  Factors not
analysed stay at their nominal value.  Model evaluations go through an
evaluator (the study's executor); outputs are analysed in display units.

=========  =============================================  ====================  ===============
method     indices (with confidence intervals)            design                inputs
=========  =============================================  ====================  ===============
sobol      S1, ST and S2 (Saltelli 2010 / Jansen)          Saltelli on a         independent
                                                          scrambled Sobol seq.
morris     μ, μ*, σ of elementary effects (μ* CI)         Morris trajectories   independent
fast       S1, ST (extended FAST)                         eFAST search curves   independent
rbd_fast   S1 (random balance designs FAST)               any sample (LHS)      independent
delta      δ (Borgonovo, moment-independent), S1          any sample            may be correlated
=========  =============================================  ====================  ===============

Morris elementary effects are ΔY/Δ with Δ the step in probability units:
each factor's range is its tolerance band in probability (P0.135…P99.865 for
±3σ), so μ* reads as "typical output change when a factor sweeps its
tolerance band", in the output's unit.

Seeds: each method draws from its own sub-stream of the study seed
(:data:`rvtol.sampling.STREAMS`), so results are reproducible and
the methods are independent of each other and of the Monte Carlo sample.
Delta and RBD-FAST can reuse the Monte Carlo samples (no extra evaluations).
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
import pandas as pd

from ..distributions import coverage
from ..errors import InputError
from ..executors import Executor, SerialExecutor
from ..model import Model
from ..records import frame_records
from ..sampling import SampleSet, sample, substream, substream_seed
from ..spec import ToleranceSpec
from ..mc import Evaluator, map_chunks
from .common import (FrameResult, correlation_note, factor_indices, output_indices, to_display)
from . import notes as N

_U_EPS = 2.0**-53

#: (index, confidence) column pairs of each method, in display order
INDEX_COLUMNS = {
    "sobol": [("S1", "S1_conf"), ("ST", "ST_conf")],
    "fast": [("S1", "S1_conf"), ("ST", "ST_conf")],
    "rbd_fast": [("S1", "S1_conf")],
    "delta": [("delta", "delta_conf"), ("S1", "S1_conf")],
    "morris": [("mu_star", "mu_star_conf")],
    "pce": [("S1", "S1_conf"), ("ST", "ST_conf")],       # rvtol.sensitivity.surrogate
    "given_data": [("S1", "S1_conf")],                   # rvtol.sensitivity.given_data
}
TITLES = {"sobol": "Sobol indices", "fast": "eFAST indices", "rbd_fast": "RBD-FAST indices",
          "delta": "Delta moment-independent indices", "morris": "Morris elementary effects",
          "pce": "Sobol indices from a polynomial chaos surrogate", "given_data": "First-order indices from given data"}


@dataclass
class GlobalSensitivityResult(FrameResult):
    """Indices of one method: ``frame`` has one row per (output, factor).

    Columns: ``output``, ``unit`` (output display unit), ``factor`` and the
    method's indices with their ``*_conf`` half-widths at ``confidence``
    (see :data:`INDEX_COLUMNS`; Morris also ``mu`` and ``sigma`` in the
    output unit).  ``second_order`` (Sobol only) has one row per factor pair.
    """

    method: str
    frame: pd.DataFrame
    n_evaluations: int
    confidence: float
    settings: dict = field(default_factory=dict)
    second_order: pd.DataFrame | None = None
    n_failed: int = 0
    notes: list[str] = field(default_factory=list)

    def summary(self) -> dict:
        out = {"method": self.method, "confidence": self.confidence, "n_evaluations": self.n_evaluations,
               "n_failed": self.n_failed, "settings": self.settings, "notes": self.notes,
               "indices": frame_records(self.frame)}
        if self.second_order is not None:
            out["second_order"] = frame_records(self.second_order)
        return out

    @property
    def index_columns(self) -> list[tuple[str, str]]:
        """(index, confidence) column pairs of this method, in display order."""
        return INDEX_COLUMNS[self.method]

    @property
    def title(self) -> str:
        return TITLES[self.method]

    def plot(self, output: str | None = None, ax=None):
        from ..plotting import sensitivity as ps

        name = output or self.outputs[0]
        return ps.morris_scatter(self, name, ax=ax) if self.method == "morris" else ps.index_bars(self, name, ax=ax)


# --------------------------------------------------------------------------- helpers
def _problem(spec: ToleranceSpec, idx: Sequence[int], bounds=None) -> dict:
    names = [spec.names[i] for i in idx]
    return {"num_vars": len(idx), "names": names, "bounds": bounds or [[0.0, 1.0]] * len(idx)}


def design_to_factors(spec: ToleranceSpec, idx: Sequence[int], U: np.ndarray,
                      x0: np.ndarray | None = None) -> np.ndarray:
    """Map a design of probabilities ``U[n, len(idx)]`` to factor values (base units).

    Columns ``idx`` go through each factor's inverse CDF; the other factors
    stay at ``x0`` (the nominal point by default).
    """
    x0 = spec.nominal_base() if x0 is None else np.asarray(x0, dtype=float)
    X = np.repeat(x0[None, :], len(U), axis=0)
    for c, i in enumerate(idx):
        X[:, i] = spec.factors[i].ppf_base(np.clip(U[:, c], _U_EPS, 1.0 - _U_EPS))
    return X


def _usable(y: np.ndarray) -> str | None:
    """Why an output column cannot be analysed (None if it can)."""
    if not np.all(np.isfinite(y)):
        return f"{int(np.sum(~np.isfinite(y)))} evaluation(s) failed"
    if np.ptp(y) == 0.0:
        return "constant"
    return None


def _columns(method: str) -> list[str]:
    cols = [c for pair in INDEX_COLUMNS[method] for c in pair]
    return (["mu", "sigma"] + cols) if method == "morris" else cols


def _analyse_each(method: str, model: Model, oidx: Sequence[int], names: Sequence[str], Yd: np.ndarray,
                  analyse, notes: list[str]) -> pd.DataFrame:
    """Run ``analyse(y) -> {column: array}`` per output column of ``Yd`` and assemble the long frame.

    An output that does not vary gets zero indices; one with failed
    evaluations gets NaN; both with a note.
    """
    cols = _columns(method)
    rows = []
    for c, j in enumerate(oidx):
        q = model.outputs[j]
        y = Yd[:, c]
        why = _usable(y)
        if why == "constant":
            notes.append(f"{q.name}: the output does not vary; its indices are 0.")
            res = {col: np.zeros(len(names)) for col in cols}
        elif why is not None:
            notes.append(f"{q.name}: {why}; {TITLES[method]} need every evaluation, so none are given.")
            res = {col: np.full(len(names), np.nan) for col in cols}
        else:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                res = analyse(y)
        for i, name in enumerate(names):
            row = {"output": q.name, "unit": q.shown_unit, "factor": name}
            row.update({col: float(np.asarray(res[col], dtype=float)[i]) for col in cols})
            rows.append(row)
    return pd.DataFrame(rows)


def _check_power_of_two(n: int, key: str = "n") -> None:
    if n < 2 or n & (n - 1):
        raise InputError(f"{key} must be a power of 2 (Sobol' sequence balance), got {n}", key=key)


def _prepare(model: Model, spec: ToleranceSpec, factors, outputs, evaluate):
    model.check_spec(spec)
    return (factor_indices(spec, factors), output_indices(model, outputs),
            evaluate or Evaluator())


def _evaluate_design(model, spec, idx, oidx, U, evaluate, desc) -> tuple[np.ndarray, int]:
    X = design_to_factors(spec, idx, U)
    ev = evaluate(model, X, desc)
    return to_display(model, ev.Y, oidx), int(np.sum(~ev.ok))


# --------------------------------------------------------------------------- Sobol
def sobol(model: Model, spec: ToleranceSpec, n: int = 1024, factors: Sequence[str] | None = None,
          outputs: Sequence[str] | None = None, second_order: bool = True, seed: int | None = None,
          num_resamples: int = 100, confidence: float = 0.95,
          evaluate: Evaluator | None = None, groups: Sequence[str] | None = None) -> GlobalSensitivityResult:
    """First-, total- (and second-) order Sobol indices with bootstrap confidence intervals.

    ``n`` base samples (a power of 2) of a scrambled Sobol' sequence in the
    Saltelli scheme: n·(2k+2) evaluations with second order, n·(k+2) without.
    ``groups`` (one name per selected factor): indices of groups of factors instead
    (k = the number of groups; rows named by group, in order of first appearance).
    """
    from SALib.analyze import sobol as sobol_analyze
    from SALib.sample import sobol as sobol_sample

    _check_power_of_two(n)
    idx, oidx, evaluate = _prepare(model, spec, factors, outputs, evaluate)
    problem = _problem(spec, idx)
    names = problem["names"]
    if groups is not None:
        groups = [str(g) for g in groups]
        if len(groups) != len(idx):
            raise InputError(f"one group name per factor: {len(groups)} for {len(idx)} factors", key="groups")
        problem["groups"] = groups
        names = list(dict.fromkeys(groups))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        U = sobol_sample.sample(problem, n, calc_second_order=second_order, scramble=True,
                                seed=substream(seed, "sobol"))
    Yd, n_failed = _evaluate_design(model, spec, idx, oidx, U, evaluate, "Sobol indices")
    notes = [m for m in [correlation_note(spec, "Sobol")] if m]
    pairs = []
    aseed = substream_seed(seed, "sobol")

    def analyse(y):
        si = sobol_analyze.analyze(problem, y, calc_second_order=second_order, num_resamples=num_resamples,
                                   conf_level=confidence, seed=aseed)
        if second_order:
            pairs.append((si["S2"], si["S2_conf"]))  # in the order of the analysable outputs
        return si

    frame = _analyse_each("sobol", model, oidx, names, Yd, analyse, notes)
    s2 = None
    if second_order:
        s2 = _second_order_frame(model, oidx, names, Yd, pairs)
    return GlobalSensitivityResult("sobol", frame, len(U), confidence,
                                   {"n_base": n, "second_order": second_order, "num_resamples": num_resamples,
                                    "design": "Saltelli scheme on a scrambled Sobol' sequence",
                                    "groups": groups is not None},
                                   s2, n_failed, notes)


def _second_order_frame(model, oidx, names, Yd, pairs) -> pd.DataFrame:
    """S2 per factor pair and output (pairs come in the order of the analysable outputs)."""
    rows, it = [], iter(pairs)
    for c, j in enumerate(oidx):
        why = _usable(Yd[:, c])
        S2, S2c = next(it) if why is None else (None, None)
        for a in range(len(names)):
            for b in range(a + 1, len(names)):
                if why is None:
                    v, conf = float(S2[a, b]), float(S2c[a, b])
                else:
                    v, conf = (0.0, 0.0) if why == "constant" else (np.nan, np.nan)
                rows.append({"output": model.outputs[j].name, "factor_i": names[a], "factor_j": names[b],
                             "S2": v, "S2_conf": conf})
    return pd.DataFrame(rows, columns=["output", "factor_i", "factor_j", "S2", "S2_conf"])


# --------------------------------------------------------------------------- Morris
def morris(model: Model, spec: ToleranceSpec, trajectories: int = 20, levels: int = 4,
           factors: Sequence[str] | None = None, outputs: Sequence[str] | None = None, seed: int | None = None,
           num_resamples: int = 1000, confidence: float = 0.95,
           evaluate: Evaluator | None = None) -> GlobalSensitivityResult:
    """Morris elementary effects: μ, μ* (with bootstrap CI) and σ, in the output's display unit.

    ``trajectories`` r of k+1 points each on a ``levels``-level grid; each
    factor's range is its tolerance band in probability (see module notes).
    """
    from SALib.analyze import morris as morris_analyze
    from SALib.sample import morris as morris_sample

    if trajectories < 2:
        raise InputError(f"trajectories must be >= 2, got {trajectories}", key="trajectories")
    if levels < 2 or levels % 2:
        raise InputError(f"levels must be an even number >= 2, got {levels}", key="levels")
    idx, oidx, evaluate = _prepare(model, spec, factors, outputs, evaluate)
    bounds = []
    for i in idx:
        q = 0.5 * (1.0 - coverage(spec.factors[i].dist.sigma_level))
        bounds.append([q, 1.0 - q])
    problem = _problem(spec, idx, bounds)
    U = morris_sample.sample(problem, trajectories, num_levels=levels, seed=substream(seed, "morris"))
    Yd, n_failed = _evaluate_design(model, spec, idx, oidx, U, evaluate, "Morris screening")
    notes = [m for m in [correlation_note(spec, "Morris screening")] if m]
    aseed = substream_seed(seed, "morris")

    def analyse(y):
        return morris_analyze.analyze(problem, U, y, num_resamples=num_resamples, conf_level=confidence,
                                      num_levels=levels, seed=aseed)

    frame = _analyse_each("morris", model, oidx, problem["names"], Yd, analyse, notes)
    return GlobalSensitivityResult("morris", frame, len(U), confidence,
                                   {"trajectories": trajectories, "levels": levels,
                                    "range": "each factor's tolerance band in probability"},
                                   None, n_failed, notes)


# --------------------------------------------------------------------------- FAST
def fast(model: Model, spec: ToleranceSpec, n: int = 1024, M: int = 4, factors: Sequence[str] | None = None,
         outputs: Sequence[str] | None = None, seed: int | None = None, num_resamples: int = 100,
         confidence: float = 0.95, evaluate: Evaluator | None = None) -> GlobalSensitivityResult:
    """Extended FAST (Saltelli et al. 1999): S1 and ST from n·k evaluations (n > 4M²)."""
    from SALib.analyze import fast as fast_analyze
    from SALib.sample import fast_sampler

    if n <= 4 * M * M:
        raise InputError(f"n must be > 4·M² = {4 * M * M}, got {n}", key="n")
    idx, oidx, evaluate = _prepare(model, spec, factors, outputs, evaluate)
    problem = _problem(spec, idx)
    U = fast_sampler.sample(problem, n, M=M, seed=substream(seed, "fast"))
    Yd, n_failed = _evaluate_design(model, spec, idx, oidx, U, evaluate, "eFAST indices")
    notes = [m for m in [correlation_note(spec, "eFAST")] if m]
    notes.append(N.FAST_INTERVALS)
    aseed = substream_seed(seed, "fast")

    def analyse(y):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # the bootstrap-CI caveat, repeated in the notes
            return fast_analyze.analyze(problem, y, M=M, num_resamples=num_resamples, conf_level=confidence,
                                        seed=aseed)

    frame = _analyse_each("fast", model, oidx, problem["names"], Yd, analyse, notes)
    return GlobalSensitivityResult("fast", frame, len(U), confidence, {"n_per_factor": n, "M": M},
                                   None, n_failed, notes)


# --------------------------------------------------------------------------- methods on given samples
def _given_or_fresh(model, spec, idx, oidx, evaluate, samples, Y, n, method, seed, stream, desc):
    """``(X, Yd, n_evaluations, notes)``: the given samples (failed rows dropped) or fresh ones."""
    notes = []
    if samples is None:
        s = sample(spec, n, method, substream_seed(seed, stream))
        ev = evaluate(model, s.values, desc)
        X, Yd, n_eval = s.values, to_display(model, ev.Y, oidx), n
    else:
        if Y is None:
            raise InputError("give the outputs Y (display units) with the samples", key="Y")
        if tuple(samples.names) != tuple(spec.names) or len(Y) != len(samples):
            raise InputError("samples and outputs do not match the spec", key="samples")
        X, Yd, n_eval = samples.values, np.asarray(Y, dtype=float)[:, list(oidx)], 0
    bad = ~np.all(np.isfinite(Yd), axis=1)
    if bad.any():
        notes.append(f"{int(bad.sum())} sample(s) whose evaluation failed were left out of the analysis.")
        X, Yd = X[~bad], Yd[~bad]
    return X[:, list(idx)], Yd, n_eval, notes, int(bad.sum())


def rbd_fast(model: Model, spec: ToleranceSpec, n: int = 2048, M: int = 10, factors: Sequence[str] | None = None,
             outputs: Sequence[str] | None = None, seed: int | None = None, samples: SampleSet | None = None,
             Y: np.ndarray | None = None, num_resamples: int = 100, confidence: float = 0.95,
             evaluate: Evaluator | None = None) -> GlobalSensitivityResult:
    """RBD-FAST first-order indices, on given ``samples`` + ``Y`` (display units) or on n fresh LHS samples."""
    from SALib.analyze import rbd_fast as rbd_analyze

    idx, oidx, evaluate = _prepare(model, spec, factors, outputs, evaluate)
    X, Yd, n_eval, notes, n_failed = _given_or_fresh(model, spec, idx, oidx, evaluate, samples, Y, n, "lhs",
                                                     seed, "rbd_fast", "RBD-FAST indices")
    notes = [m for m in [correlation_note(spec, "RBD-FAST")] if m] + notes
    problem = _problem(spec, idx)
    aseed = substream_seed(seed, "rbd_fast")

    def analyse(y):
        return rbd_analyze.analyze(problem, X, y, M=M, num_resamples=num_resamples, conf_level=confidence,
                                   seed=aseed)

    frame = _analyse_each("rbd_fast", model, oidx, problem["names"], Yd, analyse, notes)
    return GlobalSensitivityResult("rbd_fast", frame, n_eval, confidence,
                                   {"n": len(X), "M": M, "samples": "given" if samples is not None else "fresh LHS"},
                                   None, n_failed, notes)


def _delta_one(name: str, x: np.ndarray, y: np.ndarray, num_resamples: int, confidence: float,
               seed: int) -> dict:
    """δ "raw" (Plischke's bias-reduced estimator on the data as given: correlations kept) and S1 of one factor
    column, by ``SALib.analyze.delta.analyze`` with its own ``seed``; module level so an executor can run it.

    SALib's public call also bootstraps the "balanced" and "step" variants (rvtol reports "raw"): the price
    of its public interface, up to three times the kernel density estimates of "raw" alone.  SALib (≤ 1.6)
    seeds NumPy's global generator and replaces the global warning formatter: both are restored afterwards,
    so nothing else in the process sees it.  Where analyze cannot bin the factor (constant, one bin left) or
    a variant's density estimate fails, it leaves the factor's numbers NaN (δ kept when only the step
    variant or S1 fails).
    """
    from SALib.analyze import delta as sd

    problem = {"num_vars": 1, "names": ["x"], "bounds": [[0.0, 1.0]]}   # "x": analyze refuses some suffixes
    state, fmt = np.random.get_state(), warnings.formatwarning
    try:
        with warnings.catch_warnings(record=True):      # record: SALib resets the filters inside
            si = sd.analyze(problem, np.asarray(x, dtype=float)[:, None], np.asarray(y, dtype=float),
                            num_resamples=num_resamples, conf_level=confidence, seed=seed)
    finally:
        warnings.formatwarning = fmt
        np.random.set_state(state)
    return {"delta": float(si["delta_raw"][0]), "delta_conf": float(si["delta_raw_conf"][0]),
            "S1": float(si["S1"][0]), "S1_conf": float(si["S1_conf"][0])}


def delta(model: Model, spec: ToleranceSpec, n: int = 2048, factors: Sequence[str] | None = None,
          outputs: Sequence[str] | None = None, seed: int | None = None, samples: SampleSet | None = None,
          Y: np.ndarray | None = None, num_resamples: int = 100, confidence: float = 0.95,
          evaluate: Evaluator | None = None, executor: Executor | None = None) -> GlobalSensitivityResult:
    """Borgonovo's delta (moment-independent) and S1, valid with correlated inputs.

    On given ``samples`` + ``Y`` (display units; e.g. the study's Monte Carlo
    sample, correlation included) or on n fresh random samples of the spec.
    The per-factor analyses (kernel density estimates: the costly part) run
    on ``executor`` (serial by default), each with its own seed, so the
    result does not depend on where they ran.
    """
    if not 0.0 < confidence < 1.0:
        raise InputError(f"confidence must be in (0, 1), got {confidence}", key="confidence")
    idx, oidx, evaluate = _prepare(model, spec, factors, outputs, evaluate)
    X, Yd, n_eval, notes, n_failed = _given_or_fresh(model, spec, idx, oidx, evaluate, samples, Y, n, "random",
                                                     seed, "delta", "delta indices")
    problem = _problem(spec, idx)
    seeds = substream(seed, "delta").integers(1, 2**31 - 1, size=len(idx))
    executor = executor or SerialExecutor()

    def analyse(y):
        tasks = [(name, X[:, c], y, num_resamples, confidence, int(seeds[c]))
                 for c, name in enumerate(problem["names"])]
        res = dict(enumerate(map_chunks(_delta_one, tasks, executor)))
        return {col: np.array([res[c][col] for c in range(len(tasks))]) for col in res[0]}

    frame = _analyse_each("delta", model, oidx, problem["names"], Yd, analyse, notes)
    return GlobalSensitivityResult("delta", frame, n_eval, confidence,
                                   {"n": len(X), "samples": "given" if samples is not None else "fresh random"},
                                   None, n_failed, notes)
