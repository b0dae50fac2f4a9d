"""Running a loaded study (:func:`run_study`): the Monte Carlo, the analyses and what the report shows, each
phase timed."""
from __future__ import annotations

import time
from contextlib import nullcontext
from dataclasses import dataclass, field, replace
from functools import cached_property

from ..blocks import Section, deferred_figures, render_deferred
from ..executors import Executor, make_executor
from ..mc import (EvaluationCache, Evaluator, MonteCarloResult, parallel_seconds, recording_calls, run_monte_carlo,
                  run_until_decided)
from .load import Study


@dataclass
class StudyContext:
    """What an analysis sees when it runs."""

    study: Study
    executor: Executor
    mc: MonteCarloResult
    cache: EvaluationCache = field(default_factory=EvaluationCache)   # rows the analyses evaluated
    store: object = None  # rvtol.checkpoint.ChunkStore of the run (checkpoint / resume), or None
    results: dict = field(default_factory=dict)   # analysis key -> what its compute returned (Analysis.requires)

    @property
    def design(self):
        return self.study.design

    @property
    def spec(self):
        return self.study.spec

    @property
    def model(self):
        return self.study.model

    @property
    def options(self):
        return self.study.options

    @property
    def seed(self):
        return self.study.options.seed

    @property
    def evaluator(self) -> Evaluator:
        """Evaluate any model through the study's executor, chunking and progress bar (base units)."""
        o = self.study.options
        return Evaluator(self.executor, o.chunk_size, o.progress, self.cache, self.store)


@dataclass
class StudyResult:
    """Everything a run computed: the Monte Carlo, the analyses' sections and — computed in the run, so writing
    the report only writes — the sign-off digest, the report's standard sections and the summary."""

    study: Study
    mc: MonteCarloResult
    sections: list[Section]
    elapsed: float
    executor: str
    timings: dict = field(default_factory=dict)   # wall time (s) by phase: "monte_carlo", each analysis' key, ...
    signoff: list = field(default_factory=list)   # per requirement: verdict, drivers, what to change
    standard_sections: list[Section] = field(default_factory=list)   # the report's own sections (verdict, inputs...)
    comparison: object = None                     # rvtol.ci.compare.Comparison with the baseline, if one was given
    build_usage: object = None    # pandas.DataFrame: per build rule, what it did on the Monte Carlo's reducers
    parallel: dict = field(default_factory=dict)  # per phase of ``timings``: the wall time (s) spent in parallel evaluation
    measured_evidence: dict = field(default_factory=dict)   # measured factor -> rvtol.inputs.measured.report_tables.evidence
    calls: dict | None = None     # per phase of ``timings``, when recorded: its parallel calls (rvtol.mc.recording_calls)
    workers: int = 1              # the executor's workers

    @property
    def passed(self) -> bool:
        return self.mc.passed

    @property
    def verdict(self) -> str:
        """PASS, FAIL, NO REQUIREMENTS or EXPLORATORY (:func:`rvtol.verdict.study_verdict`)."""
        from ..verdict import study_verdict

        return study_verdict([v.passed for v in self.mc.verdicts()], self.study.exploratory)

    @cached_property
    def _summary(self) -> dict:
        from ..report.summary import build_summary

        return build_summary(self)

    def summary(self) -> dict:
        """summary.json's content (built once: every writer and the CLI read the same dict)."""
        return self._summary


def run_study(study: Study, executor: Executor | None = None, store=None, baseline=None,
              record_calls: bool = False) -> StudyResult:
    """Monte Carlo, the analyses, then what the report shows (timed phases: ``monte_carlo``, each analysis' key,
    ``build_usage`` — what the build rules did —, ``signoff`` — the per-requirement digest —,
    ``measured_factors`` — the measured factors' fits and their goodness-of-fit bootstrap, when a factor is
    measured —, ``comparison`` —
    with the ``baseline`` run (:class:`rvtol.ci.compare.RunData`) if one is given —, ``report`` — the report's
    own sections —, ``figures`` — every figure of the run rendered, on the workers); ``store``
    (:class:`rvtol.checkpoint.ChunkStore`) checkpoints every evaluation.
    Each phase's wall time goes to ``result.timings``, the part of it spent in parallel evaluation
    (:func:`rvtol.mc.parallel_seconds`) to ``result.parallel`` and, with ``record_calls``, its parallel calls and
    their tasks' CPU times (:func:`rvtol.mc.recording_calls`) to ``result.calls``."""
    o = study.options
    own = executor is None
    ex = executor or make_executor(o.executor, o.workers, o.scheduler)
    t0 = time.perf_counter()
    try:
        with recording_calls() if record_calls else nullcontext(None) as calls:
            clock = _PhaseClock(calls)
            result = _phases(study, ex, store, baseline, clock)
    finally:
        if own:
            ex.close()
    result.calls = clock.calls
    result.elapsed = time.perf_counter() - t0
    return result


def _phases(study: Study, ex: Executor, store, baseline, clock: "_PhaseClock") -> StudyResult:
    """:func:`run_study`'s phases, each timed by ``clock``."""
    from ..report.standard import standard_sections
    from ..signoff import digest

    o = study.options
    # with several workers, figures are pickled as they are made and rendered together on the workers
    with deferred_figures() if ex.workers > 1 else nullcontext():
        if o.until_decided:
            mc = clock.timed("monte_carlo", lambda: run_until_decided(
                study.model, study.spec, o.n, o.max_n, o.seed, study.requirements, ex, o.chunk_size, o.progress,
                o.confidence, store=store))
        else:
            mc = clock.timed("monte_carlo", lambda: run_monte_carlo(study.model, study.spec, o.n, o.method, o.seed,
                                                                    study.requirements, ex, o.chunk_size, o.progress,
                                                                    o.confidence, store=store))
        if o.tails:
            from ..tail_decision import decide

            evaluator = StudyContext(study, ex, mc, store=store).evaluator
            mc = clock.timed("tails", lambda: replace(mc, tails=decide(mc, study.model, study.spec, evaluator,
                                                                       seed=o.seed, samples=o.tail_samples)))
        ctx = StudyContext(study, ex, mc, store=store)
        sections: list[Section] = []
        for i, a in enumerate(study.analyses):
            mark = clock.mark()
            res = a.run(ctx)
            res = res if isinstance(res, list) else [res]
            sections.extend(res)
            clock.add(getattr(a, "key", None) or (res[0].key if res else f"analysis[{i}]"), mark)
        result = StudyResult(study, mc, sections, 0.0, ex.describe(), clock.timings, parallel=clock.parallel,
                             workers=ex.workers)
        if study.build is not None:    # what the build rules did on the Monte Carlo's reducers (report, summary)
            from ..production.build import usage

            def build_usage():
                env, _ = study.model.without_build().environment(mc.samples.values, set())
                return usage(study.build, env, mc.n)

            result.build_usage = clock.timed("build_usage", build_usage)
        result.signoff = clock.timed("signoff", lambda: digest(mc, study.model, study.spec, o.seed))
        if any(f.measured is not None for f in study.spec.factors):   # the fits' goodness-of-fit bootstrap
            from ..inputs.measured import evidence
            from ..sampling import substream_seed

            result.measured_evidence = clock.timed("measured_factors", lambda: {
                f.name: evidence(f.measured, f.dist, seed=substream_seed(o.seed, "measured_gof", i))
                for i, f in enumerate(study.spec.factors) if f.measured is not None})
        if baseline is not None:
            from ..ci.compare import RunData, compare

            def comparison():
                result.comparison = compare(baseline, RunData.from_result(result), seed=o.seed)
                result.__dict__.pop("_summary", None)   # built for the comparison; rebuilt with every phase's time

            clock.timed("comparison", comparison)
        result.standard_sections = clock.timed("report", lambda: standard_sections(result))
    clock.timed("figures", lambda: render_deferred([*result.sections, *result.standard_sections], ctx.evaluator.map))
    return result


class _PhaseClock:
    """Each phase's wall time (``timings``), the part of it in parallel evaluation (``parallel``) and — with the
    run's parallel calls recorded (``calls``: the list :func:`rvtol.mc.recording_calls` fills) — its calls."""

    def __init__(self, calls: list | None):
        self.timings: dict = {}
        self.parallel: dict = {}
        self._all = calls
        self.calls: dict | None = None if calls is None else {}

    def mark(self) -> tuple:
        return time.perf_counter(), parallel_seconds(), len(self._all or ())

    def add(self, name: str, mark: tuple) -> None:
        t, p, n = mark
        self.timings[name] = self.timings.get(name, 0.0) + time.perf_counter() - t
        self.parallel[name] = self.parallel.get(name, 0.0) + parallel_seconds() - p
        if self.calls is not None:
            self.calls.setdefault(name, []).extend(self._all[n:])

    def timed(self, name: str, f):
        mark = self.mark()
        try:
            return f()
        finally:
            self.add(name, mark)
