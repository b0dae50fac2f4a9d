"""The run's options: the study's ``[sampling]``, ``[execution]`` and ``[report]`` tables (declared in
:mod:`rvtol.run_options`) with the command line's values over them, and the checks of a sequential run's options."""
from __future__ import annotations

from dataclasses import dataclass

from ..errors import InputError
from ..options import read_options
from ..params import Params
from ..registry import table_options
from ..run_options import ExecutionOptions, SamplingOptions, default
from ..sampling import METHODS


@dataclass
class RunOptions:
    """What a run does: the study's run tables (:mod:`rvtol.run_options`, whose declared defaults these are) with
    the command line's values over them."""

    n: int = default(SamplingOptions, "n")
    method: str = "lhs"
    seed: int | None = default(SamplingOptions, "seed")
    executor: str = "process"
    workers: int | None = None
    scheduler: str | None = None
    chunk_size: int | None = None
    pdf: bool = True
    confidence: float = 0.95
    progress: bool = True
    tables: tuple[str, ...] = ()       # also write samples/statistics as these table formats (csv, xlsx)
    until_decided: bool = False        # sequential run: batches of n until every requirement is decided (or max_n)
    max_n: int | None = None           # a sequential run's sample budget (default: MAX_N_PER_BATCH × n)
    tails: bool = False                # undecided yield requirements decided by tail estimators (rvtol.tail_decision)
    tail_samples: int = 2000           # model runs per tail estimator and limit


#: the most rows and columns an XLSX sheet holds (Excel's limits, header included)
XLSX_MAX_ROWS, XLSX_MAX_COLUMNS = 1_048_576, 16_384


#: a sequential run's default budget, in batches (``max_n = MAX_N_PER_BATCH × n``)
MAX_N_PER_BATCH = 20


def run_options(root: Params, ov: dict) -> RunOptions:
    """The run's options: the study's ``[sampling]``, ``[execution]`` and ``[report]`` (:mod:`rvtol.run_options`)
    with the command line's values ``ov`` over them."""
    s, e, r = (read_table_options(root, name) for name in ("sampling", "execution", "report"))
    until = bool(ov.get("until_decided")) or s.until_decided
    o = RunOptions(
        n=s.n,
        method=s.method or ("random" if until else "lhs"),
        until_decided=until,
        max_n=s.max_n,
        tails=s.tails or bool(ov.get("tails")),
        tail_samples=s.tail_samples,
        seed=s.seed,
        **execution_keys(e, ov, lambda key, why: root.error(f"execution.{key}", why)),
        chunk_size=e.chunk_size or None,
        pdf=r.pdf,
        confidence=r.confidence,
        tables=r.formats(),
    )
    for k, v in ov.items():
        if v is None or k in _EXECUTION:
            continue
        if not hasattr(o, k):
            raise InputError(f"unknown option {k!r}", key=k)
        setattr(o, k, v)
    if o.n < 2:
        raise InputError(f"n must be >= 2, got {o.n}", file=root.file, key="sampling.n")
    if o.method not in METHODS:
        raise InputError(f"unknown sampling method {o.method!r}", file=root.file, key="sampling.method")
    _sequential_options(o, root.file, ov)
    if "xlsx" in o.tables and o.n + 1 > XLSX_MAX_ROWS:
        raise InputError(f"{o.n} samples do not fit an XLSX sheet ({XLSX_MAX_ROWS - 1} rows): write them as csv",
                         file=root.file, key="report.tables")
    return o


def read_table_options(root: Params, name: str):
    """A run table of the study (``sampling``, ``execution``, ``report``) read by its declared options: every key
    checked, an unknown one refused."""
    p = root.sub(name, {})
    o = read_options(table_options(name), p)
    p.finish()
    return o


def _sequential_options(o: RunOptions, file: str, ov: dict) -> None:
    """A sequential run's options checked (and its budget defaulted); ``max_n`` alone asks for nothing."""
    cli = {k: ov.get(k) is not None for k in ("method", "max_n", "n")}
    def where(k: str) -> dict:
        return ({"file": "<command line>", "key": f"--{k.replace('_', '-')}"} if cli.get(k) else
                {"file": file, "key": f"sampling.{k}"})

    if o.tails and o.until_decided:
        raise InputError("tails = true decides what a fixed-n run leaves undecided; a sequential run decides by its "
                         "own rule: choose one", **({"file": "<command line>", "key": "--tails"} if ov.get("tails")
                                                    else {"file": file, "key": "sampling.tails"}))
    if not o.until_decided:
        if o.max_n is not None:
            raise InputError("max_n is the budget of a sequential run: set until_decided = true (or --until-decided), "
                             "or drop it", **where("max_n"))
        return
    if o.method != "random":
        fix = "--method random" if cli["method"] else 'method = "random" (or --method random), or leave it out'
        raise InputError(f"a sequential run draws independent random samples, batch after batch (the anytime-valid "
                         f"rule assumes independent draws; a {o.method} design is neither independent nor extendable): "
                         f"{fix}", **where("method"))
    if o.max_n is None:
        o.max_n = MAX_N_PER_BATCH * o.n
    if o.max_n < o.n:
        raise InputError(f"the budget max_n = {o.max_n} is smaller than one batch (n = {o.n})", **where("max_n"))


#: the keys that choose where the model runs ([execution] and the command line's flags)
_EXECUTION = ("executor", "workers", "scheduler")


def _contradiction(v: dict) -> tuple[str, str, str] | None:
    """Two execution keys that cannot both hold: ``(key, other key, why)`` — ``why`` names the other as ``{other}``
    —, or None."""
    if v["executor"] == "serial" and v["workers"] is not None and v["workers"] > 1:
        return "workers", "executor", (f"{v['workers']} workers with {{other}}, which evaluates everything in this "
                                       "process: ask for the process or dask executor")
    if v["scheduler"] is not None and v["executor"] in ("serial", "process"):
        return "scheduler", "executor", "a Dask scheduler with {other}, which does not use one"
    if v["scheduler"] is not None and v["workers"] is not None:
        return "workers", "scheduler", "workers with {other}: a running Dask cluster has its own (workers start a " \
                                       "local one)"
    return None


def execution_keys(e: ExecutionOptions, ov: dict, error) -> dict:
    """``executor``, ``workers``, ``scheduler``: the command line's values over ``[execution]``'s (``e``; ``error``:
    its table's located error).  Two that contradict each other (:func:`_contradiction`) are refused when one source
    gives both; when the command line gives one and the study file the other, the command line's wins and the file's
    is dropped (``--workers 4`` runs a study written serial on a process pool; ``--scheduler`` one written for a
    process pool on Dask, as ``--executor`` would)."""
    given = {"file": {"executor": e.executor, "workers": e.workers, "scheduler": e.scheduler},
             "cli": {k: ov.get(k) for k in _EXECUTION}}
    src = {k: "cli" if given["cli"][k] is not None else "file" for k in _EXECUTION}
    v = {k: given[src[k]][k] for k in _EXECUTION}
    while (c := _contradiction(v)) is not None:
        key, other, why = c
        if src[key] != src[other]:            # the file's yields to the command line's
            v[key if src[key] == "file" else other] = None
            continue
        if src[key] == "cli":
            raise InputError(why.format(other=f"--{other} {v[other]}"), file="<command line>", key=f"--{key}")
        raise error(key, why.format(other=f"{other} = {v[other]!r}"))
    v["executor"] = v["executor"] or ("dask" if v["scheduler"] else "process")
    return v
