"""The study's run tables — ``[sampling]``, ``[execution]``, ``[report]`` — declared like every other table.

Each table is an options dataclass (:mod:`rvtol.options`: types, defaults, rules, cross-key checks; no file I/O), so
its defaults are written once (here), ``rvtol kinds sampling`` lists its keys, the common invalid-value test covers
them, and the command line reads ``[execution]`` with the same reader the study loader uses
(:func:`rvtol.study.execution_keys` merges the command line's flags over it).
"""
from __future__ import annotations

from dataclasses import dataclass, fields

from .executors import KINDS as EXECUTOR_KINDS
from .options import option
from .sampling import METHODS

#: table formats a report folder can hold beside samples.parquet
TABLE_FORMATS = ("csv", "xlsx")


@dataclass
class SamplingOptions:
    """``[sampling]``: how many samples of the factors, drawn how."""

    n: int = option(10000, "samples (rvtol run --n overrides); a sequential run's batch", min=2)
    method: str | None = option(None, "the sample design (default lhs; random when until_decided)", choices=METHODS)
    seed: int = option(12345, "the seed: the same seed gives the same result bit for bit, whatever the executor", min=0)
    until_decided: bool = option(False, "batches of n samples until every requirement is PASS or FAIL by the "
                                        "anytime-valid sequential rule (rvtol.sequential), or max_n is reached")
    max_n: int | None = option(None, "only with until_decided: the sample budget (default 20 n)", min=2)
    tails: bool = option(False, "a yield requirement the run leaves UNDECIDED is judged by importance sampling and "
                                "subset simulation (rvtol.tail_decision)")
    tail_samples: int = option(2000, "model runs of each tail estimator, per limit", min=100)


@dataclass
class ExecutionOptions:
    """``[execution]``: where the model runs (the command line's flags override)."""

    executor: str | None = option(None, "serial, process or dask (default process: every core; dask with a "
                                        "scheduler)", choices=EXECUTOR_KINDS)
    workers: int | None = option(None, "worker processes (default: every core)", min=1)
    scheduler: str | None = option(None, "a running Dask scheduler's address, e.g. tcp://host:8786 (implies dask)")
    chunk_size: int = option(0, "samples per chunk of a parallel run (0: automatic)", min=0)


@dataclass
class ReportOptions:
    """``[report]``: what the report folder holds."""

    pdf: bool = option(True, "report.pdf beside report.html")
    confidence: float = option(0.95, "the confidence of the intervals shown", min=0.5, max=0.999999)
    tables: list[str] | str = option([], 'samples and statistics also as "csv" and/or "xlsx" (a list, or one format)')

    def complete(self, study, error):
        v = [self.tables] if isinstance(self.tables, str) else self.tables
        bad = [x for x in v if x not in TABLE_FORMATS]
        if bad:
            raise error("tables", f"unknown table format {bad[0]!r} (expected one of: {', '.join(TABLE_FORMATS)})")

    def formats(self) -> tuple[str, ...]:
        """The table formats asked for, each once, in order."""
        return tuple(dict.fromkeys([self.tables] if isinstance(self.tables, str) else self.tables))



def default(cls, name: str):
    """The declared default of the key ``name`` of a run table (what the programmatic ``RunOptions`` also
    defaults to: one place)."""
    return next(f.default for f in fields(cls) if f.name == name)
