"""The Monte Carlo engine: evaluate a Model over samples in chunks, then summarise.

:func:`evaluate` is the one place model evaluations are farmed out (Monte
Carlo, five-point and global sensitivity and allocation all call it), so
every analysis gets the executors, the progress bar and the failure
accounting for free.  :func:`run_monte_carlo` samples a spec, evaluates and
returns a :class:`MonteCarloResult` with statistics, yields, Cpk, verdicts,
convergence and failures.
"""
from __future__ import annotations

import contextlib
import math
import sys
import time
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np
import pandas as pd

from . import stats as st
from .executors import Executor, SerialExecutor, plain, recording_task_cpu
from .model import STATUS_NONFINITE, STATUS_OK, Model, Quantity
from .sampling import SampleSet, sample
from .spec import YIELD_INTERVALS, Requirement, ToleranceSpec
from .verdict import (bound_level, cpk_figures, judge, judge_statistic, other_cpk, percentile_cpk_confidence,
                      requirement_state, statistic_interval,
                      yield_bound)


def _eval_chunk(model: Model, X: np.ndarray):
    t0 = time.perf_counter()
    Y, status = model.evaluate_with_status(X)
    return np.asarray(Y, dtype=float), np.asarray(status, dtype=np.int16), time.perf_counter() - t0


#: wall time this process has spent inside :func:`evaluate` and :func:`map_chunks` (outermost calls only): the
#: study's phase profile subtracts two readings (:func:`parallel_seconds`) to get a phase's parallel share; and,
#: while a caller records them (:func:`recording_calls`), each of those calls
_PARALLEL = {"seconds": 0.0, "depth": 0, "calls": None}


class _ParallelClock:
    """Adds the wall time of the outermost ``with`` block to ``_PARALLEL`` (nested blocks count once)."""

    def __enter__(self):
        _PARALLEL["depth"] += 1
        if _PARALLEL["depth"] == 1:
            self.log = contextlib.ExitStack()
            self.cpu = None if _PARALLEL["calls"] is None else self.log.enter_context(recording_task_cpu())
            self.t0 = time.perf_counter()

    def __exit__(self, *exc):
        _PARALLEL["depth"] -= 1
        if _PARALLEL["depth"] == 0:
            wall = time.perf_counter() - self.t0
            _PARALLEL["seconds"] += wall
            self.log.close()
            if self.cpu is not None and _PARALLEL["calls"] is not None:
                _PARALLEL["calls"].append({"wall": wall, "tasks": self.cpu})


@contextlib.contextmanager
def recording_calls():
    """Each parallel call (outermost :func:`evaluate` or :func:`map_chunks`) made inside the block, in the list the
    block gets: ``{"wall": s, "tasks": [CPU s of each task the workers ran, in finishing order]}`` — tasks run in
    this process (a serial executor, one worker, a single inline task) are not listed: such a call is this process's
    own time (:mod:`rvtol.scaling`)."""
    outer, _PARALLEL["calls"] = _PARALLEL["calls"], []
    try:
        yield _PARALLEL["calls"]
    finally:
        _PARALLEL["calls"] = outer


def parallel_seconds() -> float:
    """Wall time (s) this process has spent so far in parallel evaluation (:func:`evaluate`, :func:`map_chunks`):
    the work the executor spreads over its workers (with one worker, the same work done in one process — the
    part of a phase that more workers can speed up)."""
    return _PARALLEL["seconds"]


def auto_chunk_size(n: int, workers: int, per_worker: int = 4) -> int:
    """Enough chunks to balance the workers and move the progress bar, not so many that overhead shows."""
    return int(max(1, min(8192, math.ceil(n / (per_worker * max(1, workers))))))


@dataclass
class Evaluation:
    """Outputs (base units) and per-sample status of one batch of evaluations."""

    Y: np.ndarray
    status: np.ndarray

    @property
    def ok(self) -> np.ndarray:
        return self.status == STATUS_OK


def evaluate(model: Model, X: np.ndarray, executor: Executor | None = None, chunk_size: int | None = None,
             progress: bool = True, desc: str = "evaluating", store=None, persist: str = "costly") -> Evaluation:
    """Evaluate ``model`` on ``X`` (base units) through ``executor`` in chunks.

    The result is bit-identical whatever the executor, worker count and chunk
    size (models are row-deterministic; chunks are reassembled by index).
    With a ``store`` (:class:`rvtol.checkpoint.ChunkStore`) finished chunks are
    persisted as they complete — ``persist="all"`` of them (the Monte Carlo),
    or only the ``"costly"`` ones, cheaper to keep than to recompute — and
    chunks the store already holds are not evaluated again (resume).
    """
    with _ParallelClock():
        return _evaluate(model, X, executor, chunk_size, progress, desc, store, persist)


def _evaluate(model, X, executor, chunk_size, progress, desc, store, persist) -> Evaluation:
    X = model.check_input(X)
    n = X.shape[0]
    executor = executor or SerialExecutor()
    cs = chunk_size or auto_chunk_size(n, executor.workers)
    bounds = [(i, min(i + cs, n)) for i in range(0, n, cs)]
    Y = np.empty((n, len(model.outputs)))
    status = np.empty(n, dtype=np.int16)
    call = store.begin(persist) if store is not None else None
    todo = []
    for i, (a, b) in enumerate(bounds):
        hit = call.get(a, b, X[a:b]) if call is not None else None
        if hit is None:
            todo.append(i)
        else:
            Y[a:b], status[a:b] = hit
    bar = _progress(n, desc) if progress else None
    try:
        if bar is not None and len(todo) < len(bounds):
            bar.update(n - sum(bounds[i][1] - bounds[i][0] for i in todo))
        tasks = [(model, X[bounds[i][0]:bounds[i][1]]) for i in todo]
        for t, (y, s, seconds) in executor.imap(_eval_chunk, tasks):
            a, b = bounds[todo[t]]
            if y.shape != (b - a, len(model.outputs)):
                raise ValueError(f"{type(model).__name__}.evaluate returned shape {y.shape}, "
                                 f"expected {(b - a, len(model.outputs))}")
            Y[a:b], status[a:b] = y, s
            if call is not None:
                call.put(a, b, X[a:b], y, s, seconds)
            if bar is not None:
                bar.update(b - a)
    finally:
        if bar is not None:
            bar.close()
    # a model that returns a non-finite value with status 0 has failed on that row, whatever it says
    status[(status == STATUS_OK) & ~np.all(np.isfinite(Y), axis=1)] = STATUS_NONFINITE
    Y[status != STATUS_OK] = np.nan
    return Evaluation(Y, status)


def map_chunks(fn, tasks, executor: Executor | None = None, single_inline: bool = True) -> list:
    """``[fn(*t) for t in tasks]`` on ``executor`` (results in task order; timed as parallel evaluation).

    For work that is not a model evaluation — a solver run per reducer, a fit per output —: each task
    should be large enough to amortise the scheduling (tens of ms at least).  A single task runs in this
    process unless ``single_inline`` is False: a task whose code the workers have already loaded (a compiled
    kernel, a model they keep) runs there without this process loading it first."""
    tasks = list(tasks)
    with _ParallelClock():
        if executor is None or executor.workers <= 1 or (len(tasks) <= 1 and single_inline):
            return [fn(*plain(t)) for t in tasks]
        out = [None] * len(tasks)
        for i, r in executor.imap(fn, tasks):
            out[i] = r
        return out


class EvaluationCache:
    """Rows a model has already been evaluated on in one study run, and their results.

    Models are row-deterministic, so a row seen before (bit for bit, the same model object) is not
    evaluated again: two analyses that linearise the same model at the same point (a sensitivity
    matrix and an allocation) share their five-point runs.  Keys are 128-bit BLAKE2 digests of the
    rows; at most ``max_rows`` results are kept (later rows are evaluated, not stored).
    """

    def __init__(self, max_rows: int = 100_000):
        self.max_rows = max_rows
        self._models: dict[int, tuple[Model, dict[bytes, tuple[np.ndarray, int]]]] = {}
        self.hits = 0

    def __call__(self, model: Model, X: np.ndarray, compute) -> Evaluation:
        """``compute(X_missing) -> Evaluation`` evaluates the rows not seen before (each distinct row once)."""
        import hashlib

        X = np.ascontiguousarray(model.check_input(X), dtype=float)
        # the model object is kept with its results, so its id cannot be reused by another model
        known = self._models.setdefault(id(model), (model, {}))[1]
        keys = [hashlib.blake2b(x.tobytes(), digest_size=16).digest() for x in X]
        todo = list(dict.fromkeys(k for k in keys if k not in known))
        self.hits += sum(k in known for k in keys)
        fresh = {}
        if todo:
            first = {k: i for i, k in reversed(list(enumerate(keys)))}
            ev = compute(X[[first[k] for k in todo]])
            fresh = {k: (ev.Y[i], int(ev.status[i])) for i, k in enumerate(todo)}
            room = self.max_rows - sum(len(v[1]) for v in self._models.values())
            for k in todo[:max(room, 0)]:
                known[k] = fresh[k]
        got = [known.get(k) or fresh[k] for k in keys]
        m = len(model.outputs)
        Y = np.array([g[0] for g in got], dtype=float).reshape(len(keys), m)
        return Evaluation(Y, np.array([g[1] for g in got], dtype=np.int16))


class Evaluator:
    """The one evaluator signature of rvtol: ``evaluator(model, X, desc) -> Evaluation``.

    Monte Carlo, five-point and global sensitivity, allocation and the
    analyses all evaluate models through an Evaluator, so every evaluation
    runs on the same executor with the same chunking, progress bar and
    failure accounting.  ``Evaluator()`` is serial without a progress bar; a
    study's is ``ctx.evaluator`` (its executor and options, and the run's
    :class:`EvaluationCache`).  ``X`` and the returned ``Y`` are in base units;
    failed rows are NaN with a non-zero status.
    """

    def __init__(self, executor: Executor | None = None, chunk_size: int | None = None, progress: bool = False,
                 cache: EvaluationCache | None = None, store=None):
        self.executor = executor
        self.chunk_size = chunk_size
        self.progress = progress
        self.cache = cache
        self.store = store  # rvtol.checkpoint.ChunkStore: persist chunks, reuse them on resume

    def map(self, fn, tasks, single_inline: bool = True) -> list:
        """``[fn(*t) for t in tasks]`` on the evaluator's executor (:func:`map_chunks`)."""
        return map_chunks(fn, tasks, self.executor, single_inline)

    @property
    def workers(self) -> int:
        return self.executor.workers if self.executor is not None else 1

    def __call__(self, model: Model, X: np.ndarray, desc: str = "evaluating") -> Evaluation:
        run = lambda Xm: evaluate(model, Xm, self.executor, self.chunk_size, self.progress, desc, self.store)  # noqa: E731
        return run(X) if self.cache is None else self.cache(model, X, run)


def _progress(total: int, desc: str):
    """A progress bar on stderr, shown only after ~1.5 s and only on a terminal."""
    from tqdm.auto import tqdm

    return tqdm(total=total, desc=desc, unit="sample", delay=1.5, leave=False, file=sys.stderr,
                disable=None, dynamic_ncols=True)


# --------------------------------------------------------------------------- results
@dataclass
class Verdict:
    """One requirement judged: the two-sided intervals shown, the bounds judged (:mod:`rvtol.verdict`)."""

    requirement: Requirement
    yield_: st.YieldResult
    capability: dict
    cpk_percentile_ci: tuple[float | None, float | None]
    passed: bool
    reasons: list[str]
    yield_bound: float | None = None
    cpk_bound: float | None = None
    n_to_demonstrate: int | None = None
    notes: list[str] = field(default_factory=list)
    parts_to_demonstrate: dict[str, int] | None = None
    undecided: bool = False
    shape: st.Shape | None = None          # the output's departure from normality (a requirement with a min_cpk)
    fit: dict | None = None                # the measured factors' fit uncertainty (rvtol.fit_uncertainty)
    #: a statistic requirement's (estimate, lower bound, upper bound) (:func:`rvtol.verdict.statistic_interval`)
    statistic: tuple[float, float | None, float | None] | None = None

    @property
    def state(self) -> str:
        """PASS, UNDECIDED or FAIL (:func:`rvtol.verdict.requirement_state`): the word every output gives it."""
        return requirement_state(self.passed, self.undecided)

    @property
    def judged_cpk(self) -> tuple[float | None, float | None]:
        """The Cpk and lower bound the requirement is judged on (its ``cpk_method``)."""
        method = "cpk_percentile" if self.requirement.cpk_method == "percentile" else "cpk"
        return self.capability.get(method), self.cpk_bound

    def to_dict(self) -> dict:
        r = self.requirement
        cap = self.capability
        return {
            "requirement": r.label, "output": r.output, "unit": r.unit, "lower": r.lower, "upper": r.upper,
            "min_yield": r.min_yield, "min_yield_default": r.yield_defaulted, "min_cpk": r.min_cpk,
            "basis": r.basis, "confidence": r.confidence, "bound": r.bound, "bound_level": bound_level(r),
            "cpk_method": r.cpk_method,
            "yield_interval": r.interval,
            "yield": self.yield_.estimate, "yield_ci": [self.yield_.lo, self.yield_.hi],
            "yield_bound": self.yield_bound,
            "ppm": self.yield_.ppm, "ppm_ci": list(self.yield_.ppm_ci),
            "cp": cap["cp"], "cpk": cap["cpk"], "cpk_ci": [cap["cpk_lo"], cap["cpk_hi"]], "cpk_bound": self.cpk_bound,
            "cpk_percentile": cap["cpk_percentile"], "cpk_percentile_ci": list(self.cpk_percentile_ci),
            "passed": self.passed, "state": self.state, "reasons": self.reasons,
            "n_to_demonstrate": self.n_to_demonstrate,
            "undecided": self.undecided, "notes": self.notes, "parts_to_demonstrate": self.parts_to_demonstrate,
            "shape": None if self.shape is None else {
                "skewness": self.shape.skewness, "excess_kurtosis": self.shape.excess_kurtosis,
                "anderson_darling": self.shape.ad_statistic, "anderson_darling_p": self.shape.ad_pvalue,
                "non_normal": self.shape.non_normal},
            "fit_uncertainty": self.fit,
            "statistic": r.statistic,
            **({"statistic_estimate": self.statistic[0], "statistic_interval": list(self.statistic[1:])}
               if self.statistic is not None else {}),
            "reading": r.reading, "source": r.source, "status": r.status,
        }


@dataclass
class MonteCarloResult:
    """Samples, outputs (display units), status and everything derived from them.

    Derived tables are computed once and cached: treat the arrays as read-only.
    """

    outputs: tuple[Quantity, ...]
    samples: SampleSet
    Y: np.ndarray  # display units, NaN where the model failed
    status: np.ndarray
    status_reasons: dict[int, str]
    requirements: list[Requirement] = field(default_factory=list)  # limits in display units
    confidence: float = 0.95
    executor: str = "serial"
    #: the spec's measured factors (rvtol.fit_uncertainty.MeasuredFactors): their fits' uncertainty is judged
    measured: object = None
    #: a sequential run's record (rvtol.sequential.Stopping): its rule, not the fixed-n bounds, gives the verdicts
    stopping: object = None
    #: requirement label -> rvtol.tail_decision.TailDecision: what the tail estimators decided of those left undecided
    tails: dict | None = None

    @property
    def n(self) -> int:
        return len(self.status)

    @property
    def ok(self) -> np.ndarray:
        return self.status == STATUS_OK

    def column(self, name: str) -> np.ndarray:
        return self.Y[:, [q.name for q in self.outputs].index(name)]

    def unit_of(self, name: str) -> str:
        return next(q.shown_unit for q in self.outputs if q.name == name)

    # -- tables ----------------------------------------------------------------
    def to_frame(self, rows: slice = slice(None)) -> pd.DataFrame:
        """One row per sample (``rows``: a range of them): factor values and outputs in display units, and status."""
        from . import units

        s = self.samples
        cols = {f"{nm} [{u}]": units.from_base(s.values[rows, j], u) for j, (nm, u) in enumerate(zip(s.names, s.units))}
        for j, q in enumerate(self.outputs):
            cols[f"{q.name} [{q.shown_unit}]"] = self.Y[rows, j]
        cols["status"] = self.status[rows]
        return pd.DataFrame(cols)

    def write_parquet(self, path, rows: int = 1 << 17) -> None:
        """:meth:`to_frame` written to a Parquet file ``rows`` samples at a time (one row group each): the memory
        it takes is that of a chunk, not of n."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        writer = None
        try:
            for a in range(0, max(self.n, 1), rows):
                table = pa.Table.from_pandas(self.to_frame(slice(a, a + rows)), preserve_index=False)
                if writer is None:
                    writer = pq.ParquetWriter(path, table.schema)
                writer.write_table(table)
        finally:
            if writer is not None:
                writer.close()

    def statistics(self) -> pd.DataFrame:
        return self._statistics.copy()

    @cached_property
    def _statistics(self) -> pd.DataFrame:
        rows = [self._describe(j, q) for j, q in enumerate(self.outputs)]
        return pd.DataFrame(rows).set_index("output")

    def _describe(self, j: int, q: Quantity) -> dict:
        y = self.Y[self.ok, j]
        ys = np.sort(y)
        c = self.confidence
        row = {"output": q.name, "unit": q.shown_unit, "n": len(y), "failed": int(self.n - len(y))}
        if len(y) == 0:
            return row
        m, mlo, mhi = st.mean_ci(y, c)
        s, slo, shi = st.std_ci(y, c)
        row.update(mean=m, mean_lo=mlo, mean_hi=mhi, std=s, std_lo=slo, std_hi=shi,
                   min=float(ys[0]), max=float(ys[-1]))
        for p in st.PERCENTILES:
            est, lo, hi = st.percentile_ci(ys, p / 100, c)
            row[f"P{p:g}"] = est
            row[f"P{p:g}_lo"] = lo
            row[f"P{p:g}_hi"] = hi
        return row

    def verdicts(self) -> list[Verdict]:
        return list(self._verdicts)

    @cached_property
    def _verdicts(self) -> list[Verdict]:
        out = []
        fits = self._fit_effects
        for r in self.requirements:
            j = [q.name for q in self.outputs].index(r.output)
            y = self.Y[:, j]
            yr = st.yield_of(y, self.ok, r.lower, r.upper, r.confidence, YIELD_INTERVALS[r.interval])
            good = y[self.ok]
            if not r.per_unit:
                out.append(self._statistic_verdict(r, yr, good))
                continue
            cap = st.capability(good, r.lower, r.upper, r.confidence)
            pci = (st.percentile_cpk_ci(np.sort(good), r.lower, r.upper, r.confidence)
                   if len(good) >= 100 else (None, None))
            yb = yield_bound(r, yr.conforming, yr.n)
            pj = (st.bootstrap_ci(good, lambda s: st.percentile_cpk(s, r.lower, r.upper), percentile_cpk_confidence(r))
                  if r.cpk_method == "percentile" and len(good) >= 100 else (None, None))
            cpk, cb = cpk_figures(r, cap, len(good), pj)
            constant = float(good[0]) if len(good) >= 2 and not np.ptp(good) > 0 else None
            shape, other = other_cpk(r, good, cap) if r.min_cpk is not None and constant is None else (None, None)
            fit, record = fits.get(r.label), None
            if fit is not None:
                from .fit_uncertainty import to_record

                yb_mc, cb_mc = yb, cb
                yb = st.combined_lower_bound(yr.estimate, yb, fit.yield_dev)
                cb = st.combined_lower_bound(cpk, cb, fit.cpk_dev)
                fit.describe(self.confidence, yb, yb_mc)
                record = to_record(fit, self.confidence, yb_mc, cb_mc)
            jd = judge(r, yield_=yr.estimate, yield_lo=yb, cpk=cpk, cpk_lo=cb, n_failed=int(self.n - self.ok.sum()),
                       n=self.n, constant=constant, other_cpk=other, shape=shape, fit=fit)
            out.append(Verdict(r, yr, cap, pci, jd.passed, jd.reasons, yb, cb, jd.n_to_demonstrate, jd.notes,
                               jd.parts_to_demonstrate, jd.undecided, shape, record))
        if self.tails:
            out = [self._tail_verdict(v, self.tails[v.requirement.label]) if v.requirement.label in self.tails else v
                   for v in out]
        return out if self.stopping is None else [self._sequential_verdict(v) for v in out]

    @staticmethod
    def _tail_verdict(v: Verdict, d) -> Verdict:
        """``v`` as its tail decision ``d`` (rvtol.tail_decision.TailDecision: ``state``, ``yield_bound``, ``why``)
        judges it: PASS or FAIL with the tails' bound, else UNDECIDED with their figures among the reasons."""
        if d.state in ("PASS", "FAIL"):
            return _decided(v, d.state == "PASS", d.why, yield_bound=d.yield_bound)
        return replace(v, reasons=[*v.reasons, d.why])

    def _sequential_verdict(self, v: Verdict) -> Verdict:
        """A sequential run's verdict of ``v``'s requirement (:mod:`rvtol.sequential`): PASS or FAIL as its first
        decision made it, else UNDECIDED (the budget ended first) — the fixed-n bounds stay in the tables, and their
        reasons beside it, but they hold for one look, not for the run's many."""
        from .sequential import PASS as SEQ_PASS

        stop = self.stopping
        label = v.requirement.label
        why = stop.why(label)
        if label in stop.decided:
            return _decided(v, stop.decided[label][1].state == SEQ_PASS, why)
        fixed = (f"the fixed-n bound would pass at n = {self.n:,}, but it holds for one look, not for "
                 f"{len(stop.looks)}" if v.passed else None)
        return replace(v, passed=False, undecided=True, n_to_demonstrate=None, parts_to_demonstrate=None,
                       reasons=[why, fixed] if fixed else [why] + [r for r in v.reasons if "would demonstrate" not in r])

    def _statistic_verdict(self, r: Requirement, yr: st.YieldResult, good: np.ndarray) -> Verdict:
        """A population statistic's band (:func:`rvtol.verdict.judge_statistic`); ``yr``, the share of the units
        inside the band, is kept for the tables that list every requirement's yield (not judged); no Cpk."""
        failed = int(self.n - self.ok.sum())
        est, lo, hi = statistic_interval(r, good, failed)
        j = judge_statistic(r, est, lo, hi, self.n, failed)
        cap = dict.fromkeys(("cp", "cpk", "cpk_lo", "cpk_hi", "cpk_percentile"))
        return Verdict(r, yr, cap, (None, None), j.passed, j.reasons, None, None, j.n_to_demonstrate,
                       undecided=j.undecided, statistic=(est, lo, hi))

    @cached_property
    def _fit_effects(self) -> dict:
        """Requirement label -> its measured factors' fit uncertainty (:func:`rvtol.fit_uncertainty.effects`); per-unit
        requirements only (a statistic's band judges no unit's yield)."""
        reqs = [r for r in self.requirements if r.per_unit]
        if self.measured is None or not reqs:
            return {}
        from .fit_uncertainty import effects

        out = effects(self.measured, self.samples.values, self.Y, self.ok, [q.name for q in self.outputs],
                      reqs, [bound_level(r) for r in reqs], self.samples.seed)
        return {k: v for k, v in out.items() if v is not None}

    @property
    def passed(self) -> bool:
        return all(v.passed for v in self.verdicts())

    def convergence(self) -> pd.DataFrame:
        return self._convergence.copy()

    @cached_property
    def _convergence(self) -> pd.DataFrame:
        frames = []
        for j, q in enumerate(self.outputs):
            lims = [(r.lower, r.upper) for r in self.requirements if r.output == q.name and r.per_unit]
            tr = st.convergence_trace(self.Y[:, j], self.ok, lims, confidence=self.confidence)
            df = pd.DataFrame(tr)
            df.insert(0, "output", q.name)
            frames.append(df)
        return pd.concat(frames, ignore_index=True)

    def failures(self) -> pd.DataFrame:
        """One row per failure reason: code, reason, count and the first sample indices."""
        bad = np.flatnonzero(~self.ok)
        rows = []
        for code in np.unique(self.status[bad]):
            idx = bad[self.status[bad] == code]
            rows.append({"status": int(code), "reason": self.status_reasons.get(int(code), "unknown"),
                         "count": len(idx), "samples": ", ".join(map(str, idx[:20])) + (" …" if len(idx) > 20 else "")})
        return pd.DataFrame(rows, columns=["status", "reason", "count", "samples"])

    def plot(self, output: str | None = None, ax=None):
        from .plotting.mc import histogram

        name = output or self.outputs[0].name
        return histogram(self, name, ax=ax)


def _decided(v: Verdict, passed: bool, why: str, **judged) -> Verdict:
    """``v`` decided by another rule than the fixed-n bounds (a sequential run's, the tails'): PASS with ``why`` among
    its notes, or FAIL with ``why`` first among its reasons; no sample size left to demonstrate it; ``judged``: the
    figures that rule judged (its yield bound)."""
    return replace(v, passed=passed, undecided=False, n_to_demonstrate=None, parts_to_demonstrate=None,
                   reasons=[] if passed else [why, *v.reasons], notes=[why, *v.notes] if passed else v.notes, **judged)


def run_monte_carlo(model: Model, spec: ToleranceSpec, n: int, method: str = "lhs", seed: int | None = None,
                    requirements=(), executor: Executor | None = None, chunk_size: int | None = None,
                    progress: bool = True, confidence: float = 0.95,
                    samples: SampleSet | None = None, store=None) -> MonteCarloResult:
    """Sample ``spec`` (or use ``samples``), evaluate ``model``, and wrap the result (``store``: :func:`evaluate`)."""
    model.check_spec(spec)
    s = samples if samples is not None else sample(spec, n, method, seed)
    ev = evaluate(model, s.values, executor, chunk_size, progress, desc="Monte Carlo", store=store, persist="all")
    return result_of(model, s, ev, requirements, confidence, executor.describe() if executor else "serial", spec)


def run_until_decided(model: Model, spec: ToleranceSpec, batch: int, max_n: int, seed: int | None = None,
                      requirements=(), executor: Executor | None = None, chunk_size: int | None = None,
                      progress: bool = True, confidence: float = 0.95, store=None) -> MonteCarloResult:
    """A sequential Monte Carlo: independent random samples of ``spec`` in batches of ``batch``
    (:class:`rvtol.sampling.SampleStream`, one seeded stream), every requirement looked at after each batch by the
    anytime-valid rule (:func:`rvtol.sequential.look_at`, tuned to ``batch``) until each is decided or ``max_n``
    samples are drawn.  The result is that of all the samples drawn, its verdicts the sequential ones
    (``result.stopping``: :class:`rvtol.sequential.Stopping`).  Each batch is one :func:`evaluate` call (``store``:
    checkpointed like a fixed run's, so a resumed run redraws the same batches and reuses their chunks); the rows and
    verdicts are bit-identical whatever the executor, workers or chunk size."""
    from .sampling import SampleStream
    from .sequential import Stopping, look_at

    model.check_spec(spec)
    stream = SampleStream(spec, seed)
    stop = Stopping(batch, max_n, float(batch))
    xs, ys, statuses = [], [], []
    described = executor.describe() if executor else "serial"
    while True:
        x = stream.next(min(batch, max_n - stream.drawn))
        ev = evaluate(model, x, executor, chunk_size, progress, desc=f"Monte Carlo, look {len(stop.looks) + 1}",
                      store=store, persist="all")
        xs.append(x)
        ys.append(ev.Y)
        statuses.append(ev.status)
        s = SampleSet(np.concatenate(xs), spec.names, spec.units, "random", seed)
        res = result_of(model, s, Evaluation(np.concatenate(ys), np.concatenate(statuses)), requirements, confidence,
                        described, spec)
        stop.look(stream.drawn, {r.label: look_at(r, res.column(r.output), res.ok, stop.tune_n)
                                 for r in res.requirements})
        if stop.finished:
            res.stopping = stop
            return res


def result_of(model: Model, samples: SampleSet, ev: Evaluation, requirements=(), confidence: float = 0.95,
              executor: str = "serial", spec: ToleranceSpec | None = None) -> MonteCarloResult:
    """The :class:`MonteCarloResult` of an evaluation ``ev`` of ``samples`` (outputs to display units;
    a value that overflows there fails its sample); with the ``spec`` the samples were drawn from, its measured
    factors' fit uncertainty enters the verdicts (:mod:`rvtol.fit_uncertainty`)."""
    Yd = np.empty_like(ev.Y)
    with np.errstate(over="ignore", invalid="ignore"):
        for j, q in enumerate(model.outputs):
            Yd[:, j] = q.to_display(ev.Y[:, j])
    overflow = (ev.status == STATUS_OK) & ~np.all(np.isfinite(Yd), axis=1)
    if overflow.any():
        ev.status[overflow] = STATUS_NONFINITE
        Yd[overflow] = np.nan
    reqs = [r.in_unit(model.output(r.output).shown_unit) for r in requirements]
    measured = None
    if spec is not None and reqs:
        from .fit_uncertainty import MeasuredFactors

        measured = MeasuredFactors.of(spec, model)
    return MonteCarloResult(tuple(model.outputs), samples, Yd, ev.status, dict(model.status_reasons), reqs,
                            confidence, executor, measured)
