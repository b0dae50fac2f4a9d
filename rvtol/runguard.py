"""A run that survives CI: signals, the output folder's lock and work folder, checks before computing.

* :func:`stopping_on_signals` — SIGTERM (what CI sends on cancel) and SIGINT
  (Ctrl-C) kill the worker processes at once (:func:`rvtol.executors.stop_workers`)
  and raise :class:`Interrupted` in the main thread, so every ``finally``
  runs (no half-written folder) and the CLI prints one line and exits
  128 + signal (143, 130).  A second signal during that clean-up exits at once.
* :class:`RunFolder` — ``.NAME.rvtol-run/`` beside the output folder ``NAME``:
  an exclusive lock (two runs never write one folder; the lock dies with its
  process, ``kill -9`` included), the removal of temporary folders that killed
  runs left behind (a previous report folder a run killed between its final
  renames left aside is put back in place), and the checkpoint (:class:`rvtol.checkpoint.ChunkStore`)
  that ``--resume`` continues from.  A finished run removes it; an
  interrupted or killed one leaves the checkpoint for ``--resume``.
* :func:`check_writable`, :func:`estimate_run`, :func:`check_resources` —
  before anything is computed: the output can be written, and the Monte Carlo
  fits in memory and on disk (a clear error for an absurd n, exit 2); the
  estimate of memory, disk and time is printed.
"""
from __future__ import annotations

import contextlib
import fcntl
import glob
import json
import logging
import math
import os
import re
import shutil
import signal
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path


from .checkpoint import HELD, ChunkStore
from .errors import InputError, RvtolError


# --------------------------------------------------------------------------- signals
class Interrupted(BaseException):
    """The run was stopped by a signal (a BaseException, like KeyboardInterrupt: nothing swallows it)."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum
        self.kept_chunks = 0  # finished chunks left for --resume (set by RunFolder)

    @property
    def name(self) -> str:
        return signal.Signals(self.signum).name

    @property
    def exit_code(self) -> int:
        return 128 + self.signum


@contextlib.contextmanager
def stopping_on_signals(signals=(signal.SIGTERM, signal.SIGINT)):
    """Within the block, SIGTERM/SIGINT stop the workers and raise :class:`Interrupted` (main thread only)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    from .executors import stop_workers

    state = {"stopping": False}

    def handler(signum, frame):
        if HELD["depth"]:       # a chunk file is being written: the stop waits for it to be whole (signals_held)
            HELD["pending"] = signum
            return
        stop_workers()
        if state["stopping"]:  # asked twice: do not wait for the clean-up
            os._exit(128 + signum)
        state["stopping"] = True
        for name in ("distributed", "tornado", "asyncio"):  # a cluster torn down mid-task logs its closed comms
            logging.getLogger(name).setLevel(logging.CRITICAL + 1)
        raise Interrupted(signum)

    old = {s: signal.signal(s, handler) for s in signals}
    try:
        yield
    finally:
        for s, h in old.items():
            signal.signal(s, h)


# --------------------------------------------------------------------------- the output folder's work folder
class RunFolder:
    """``.NAME.rvtol-run/`` beside output folder ``NAME``: lock, stale clean-up, checkpoint (module docstring)."""

    def __init__(self, out: str | Path):
        self.out = Path(out)
        self.path = self.out.parent / f".{self.out.name}.rvtol-run"
        self.store: ChunkStore | None = None
        self._fd: int | None = None

    # -- lock ----------------------------------------------------------------
    def __enter__(self) -> "RunFolder":
        self.acquire()
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        finished = exc_type is None
        if isinstance(exc, Interrupted) and self.store is not None:
            exc.kept_chunks = self.store.count()
        self.release(keep_checkpoint=not finished)

    def acquire(self) -> None:
        """Take the folder's lock (or raise InputError naming the run that holds it); clean stale temporaries."""
        lock = self.path / "lock"
        for _ in range(20):
            self.path.mkdir(parents=True, exist_ok=True)
            try:
                fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
            except FileNotFoundError:  # a finishing run removed the folder in between: again
                continue
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                holder = os.pread(fd, 64, 0).decode(errors="replace").strip() or "?"
                os.close(fd)
                raise InputError(f"another rvtol run (pid {holder}) is writing this folder; wait for it or choose "
                                 "another --out", file=str(self.out), key="--out") from None
            try:  # the file we locked must still be the one at the path (a finishing run unlinks it)
                same = os.fstat(fd).st_ino == os.stat(lock).st_ino
            except FileNotFoundError:
                same = False
            if same:
                os.ftruncate(fd, 0)
                os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
                self._fd = fd
                break
            os.close(fd)
        else:  # pragma: no cover - needs a pathological race
            raise RvtolError(f"could not lock {lock}")
        self._remove_stale()

    def _remove_stale(self) -> None:
        """Temporary and replaced report folders of runs that were killed (we hold the lock: none is live).  A run
        killed between its two final renames (:func:`rvtol.study.write_outputs`) left the output folder missing
        and the previous one under its temporary name: that one is put back in place, not deleted."""
        stem = glob.escape(f".{self.out.name}")
        replaced = sorted(self.out.parent.glob(f"{stem}.old-*"), key=lambda p: p.stat().st_ctime)
        if replaced and not self.out.exists() and not self.out.is_symlink():
            os.replace(replaced.pop(), self.out)    # the newest: renamed last
        for p in [*self.out.parent.glob(f"{stem}.tmp-*"), *replaced]:
            shutil.rmtree(p, ignore_errors=True)

    def release(self, keep_checkpoint: bool = False) -> None:
        if self._fd is None:
            return
        if not keep_checkpoint:
            shutil.rmtree(self.path / "chunks", ignore_errors=True)
            (self.path / "run.json").unlink(missing_ok=True)
            (self.path / "lock").unlink(missing_ok=True)  # while we hold it: a waiting run re-checks the inode
        fcntl.flock(self._fd, fcntl.LOCK_UN)
        os.close(self._fd)
        self._fd = None
        if not keep_checkpoint:
            with contextlib.suppress(OSError):
                self.path.rmdir()

    # -- checkpoint ----------------------------------------------------------
    def open_store(self, key: str, resume: bool) -> tuple[ChunkStore, str]:
        """The run's checkpoint: kept if ``resume`` and the interrupted run had the same ``key``; a note."""
        meta = self.path / "run.json"
        chunks = self.path / "chunks"
        try:
            old = json.loads(meta.read_text()).get("key")
        except (OSError, ValueError, AttributeError):
            old = None
        note = ""
        if resume and old == key and chunks.is_dir():
            store = ChunkStore(chunks)
            note = f"resuming: {store.count()} finished chunks of the interrupted run are reused"
        else:
            kept = ChunkStore(chunks).count() if chunks.is_dir() else 0
            if resume:
                note = ("nothing to resume: no interrupted run of this output folder" if old is None else
                        "nothing to resume: the inputs, n, seed or method changed since the interrupted run")
            elif kept:
                note = f"starting afresh: the {kept} finished chunks of an interrupted run are discarded " \
                       "(--resume continues a run)"
            shutil.rmtree(chunks, ignore_errors=True)
            store = ChunkStore(chunks)
        meta.write_text(json.dumps({"key": key, "pid": os.getpid(), "started": time.time()}))
        self.store = store
        return store, note


# --------------------------------------------------------------------------- before computing
def _existing_ancestor(path: Path) -> Path:
    p = path.absolute()
    while not p.exists() and p != p.parent:
        p = p.parent
    return p


def check_writable(target: str | Path, key: str) -> Path:
    """Raise InputError (``target``, ``key``) unless a file can be created where ``target`` goes.

    Probes the nearest existing folder on the way (creates and removes one empty file there).
    """
    target = Path(target)
    where = _existing_ancestor(target.parent)
    if not where.is_dir():
        raise InputError(f"{where} is not a folder", file=str(target), key=key)
    try:
        fd, probe = tempfile.mkstemp(prefix=".rvtol-probe-", dir=where)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise InputError(f"cannot write in {where} ({exc.strerror or exc})", file=str(target), key=key) from None
    return where


# --------------------------------------------------------------------------- what a run may replace
def _head(path: Path, size: int) -> bytes:
    try:
        with open(path, "rb") as fh:
            return fh.read(size)
    except OSError:
        return b""


def _is_junit(path: Path) -> bool:
    """JUnit XML rvtol wrote (:mod:`rvtol.ci.junit`): its root element is ``<testsuites name="rvtol">``."""
    import xml.etree.ElementTree as ET

    parser = ET.XMLPullParser(events=("start",))
    try:
        parser.feed(_head(path, 1 << 16))
        for _, element in parser.read_events():
            return element.tag == "testsuites" and element.get("name") == "rvtol"
    except ET.ParseError:
        return False
    return False


#: the first line of the Markdown summary (:func:`rvtol.ci.markdown.render_markdown`)
_MARKDOWN_HEAD = re.compile(r"### \S* ?rvtol · .*: \*\*[A-Z ]+\*\*")


def _is_markdown(path: Path) -> bool:
    line = _head(path, 4096).split(b"\n", 1)[0].decode("utf-8", errors="replace")
    return bool(_MARKDOWN_HEAD.fullmatch(line.strip()))


def _json_object(path: Path) -> dict:
    try:
        if path.stat().st_size > 1 << 28:
            return {}
        data = json.loads(path.read_bytes())
    except (OSError, ValueError, RecursionError):
        return {}
    return data if isinstance(data, dict) else {}


def _is_task_log(path: Path) -> bool:
    """``--task-log``'s JSON (:func:`rvtol.scaling.task_log`; written before its format tag with these keys)."""
    d = _json_object(path)
    return str(d.get("format", "")).startswith("rvtol-task-log/") or \
        {"study", "executor", "workers", "run_s", "projected", "phases"} <= d.keys()


def _is_comparison(path: Path) -> bool:
    return str(_json_object(path).get("format", "")).startswith("rvtol-comparison/")


#: per kind of file a run or a comparison writes: what it is, and how an earlier one rvtol wrote is recognised
OWN_FILES = {"junit": ("a JUnit report", _is_junit), "markdown": ("a Markdown summary", _is_markdown),
             "task_log": ("a task log", _is_task_log), "comparison": ("a comparison (JSON)", _is_comparison)}


#: the longest file name most file systems take (ext4, XFS, Btrfs, APFS: 255 bytes; NTFS: 255 characters)
NAME_MAX_BYTES = 255
#: a file rvtol writes is written first as ``.STEM`` + this + 12 hex digits + its suffix beside it, then renamed
TMP_SUFFIX = ".rvtol-tmp-"


def _same_file(a: Path, b: Path) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def check_not_input(path: Path, inputs, key: str) -> None:
    """InputError unless ``path`` is none of ``inputs`` (the files the run read: the study, every file it names,
    a Python model's module, a baseline) nor a folder that holds one (a report folder is replaced whole)."""
    full = path.resolve()
    for f in sorted(inputs):
        if _same_file(path, f):
            raise InputError(f"is an input of this run ({f}); rvtol never replaces its own inputs: write elsewhere",
                             file=str(path), key=key)
        if full in Path(f).resolve().parents:
            raise InputError(f"holds an input of this run ({f}), and the run replaces the whole folder: choose "
                             "another --out", file=str(path), key=key)


def check_output_file(path: str | Path, kind: str, key: str, inputs=(), out: Path | None = None) -> Path:
    """Raise InputError (file ``path``, key ``key``) unless the run may write its ``kind`` of file
    (:data:`OWN_FILES`) at ``path``: not a folder, not the report folder ``out`` or in it (the run replaces that
    folder whole), none of the run's ``inputs`` (:func:`check_not_input`), not an existing file rvtol did not
    write — only an earlier file of the same kind is replaced —, and in a folder that can be written."""
    p = Path(path)
    what, ours = OWN_FILES[kind]
    if p.is_dir():
        raise InputError("is a folder, expected a file name", file=str(path), key=key)
    if out is not None and out.resolve() in (p.resolve(), *p.resolve().parents):
        raise InputError(f"is the report folder or inside it ({out}), which the run replaces whole; write it "
                         "elsewhere", file=str(path), key=key)
    check_not_input(p, inputs, key)
    longest = NAME_MAX_BYTES - len(".") - len(TMP_SUFFIX) - 12
    if len(p.name.encode()) > longest:
        raise InputError(f"the file's name is {len(p.name.encode())} bytes long: at most {longest} (a file name's "
                         f"{NAME_MAX_BYTES}, less the temporary name rvtol writes it under first)", file=str(path),
                         key=key)
    if p.exists() and not ours(p):
        raise InputError(f"exists and is not {what} rvtol wrote: rvtol replaces only its own files; choose another "
                         "name or move that file", file=str(path), key=key)
    check_writable(p, key)
    return p


def check_distinct_targets(targets: dict[str, str]) -> None:
    """InputError when two flags name one file (the second would replace the first): ``targets`` flag -> path."""
    seen: dict[Path, str] = {}
    for key, path in targets.items():
        full = Path(path).absolute().resolve()
        if full in seen:
            raise InputError(f"names the same file as {seen[full]}: give each output its own file", file=str(path),
                             key=key)
        seen[full] = key


@dataclass
class RunEstimate:
    """What the study's Monte Carlo and its report will need (analyses not included)."""

    n: int
    factors: int
    outputs: int
    memory: int          # bytes, peak increase of the run
    disk: int            # bytes: samples.parquet, checkpoint, report
    workers: int
    per_sample: float | None = None   # s, from a pilot at the nominal point
    seconds: float | None = None      # Monte Carlo wall time
    report_seconds: float | None = None   # writing the report folder
    budget: bool = False      # n is a sequential run's budget (max_n): the most it may draw

    def describe(self) -> str:
        s = f"estimate: {'up to ' if self.budget else ''}{self.n:,} samples × {self.factors} factors → " \
            f"{self.outputs} outputs; " \
            f"memory ≈ {human_bytes(self.memory)}, disk ≈ {human_bytes(self.disk)}"
        if self.seconds is not None:
            s += (f", Monte Carlo ≈ {human_seconds(self.seconds)} on {self.workers} worker"
                  f"{'s' if self.workers != 1 else ''} ({1e3 * self.per_sample:.3g} ms/sample in a pilot)")
        if self.report_seconds is not None:
            s += f", report ≈ {human_seconds(self.report_seconds)}"
        return s + " — analyses come on top"


#: bytes per sample per factor / per output / fixed, of the Monte Carlo's peak memory (design, values,
#: outputs in base and display units, sorted copies for the statistics, the table written to parquet):
#: an upper envelope of the measured peak (linear model, n = 10⁶: 158 B per sample for 3 factors, 1 output)
MEMORY_PER_SAMPLE = (40, 32, 32)
#: disk bytes per sample: samples.parquet (8 B per value: random floats do not compress; measured 7.9 B for
#: 20 000 samples of linear_stackup) and the checkpoint of the outputs during the run
DISK_PER_SAMPLE = (8, 16, 10)
#: ``--tables xlsx``: openpyxl holds every cell of a sheet until it saves — bytes per cell of samples.xlsx (measured:
#: 400 B, 200 000 samples × 5 columns) and seconds per cell (57 µs on a loaded 2-core machine)
XLSX_BYTES_PER_CELL, XLSX_SECONDS_PER_CELL = 400, 57e-6
#: the report besides the samples: HTML (figures inlined) per part — the base, each output, each analysis —
#: an envelope of the measured 146 kB (1 output, no analysis), 232 kB (1 output, 2 analyses), 448 kB (2, 2);
#: a PDF about as much again
REPORT_BYTES_PER_PART = 150_000
#: seconds to start a process pool's workers (each imports numpy, scipy and rvtol; measured 3–4 s on 2 idle
#: cores, 8 s at a load average of 17)
POOL_START_SECONDS = 4.0
#: the engine's own cost per sample (design, inverse CDFs, statistics) per factor and fixed: measured
#: 2–4 µs per sample for 3–11 factors (linear_stackup, stack_handbook_motor)
ENGINE_SECONDS_PER_SAMPLE = (0.3e-6, 1.0e-6)
#: the report's seconds: fixed and per output (HTML; measured 3–5 s for 1 output, 6 s for 5), ×3 with the PDF
REPORT_SECONDS = (2.5, 0.6)
REPORT_PDF_FACTOR = 3.0


def estimate_run(study) -> RunEstimate:
    """Memory and disk of the study's Monte Carlo and report (no computation; :func:`time_pilot` adds the time)."""
    o = study.options
    n, k, m = o.max_n if o.until_decided else o.n, len(study.spec), len(study.model.outputs)
    mem = n * (MEMORY_PER_SAMPLE[0] * k + MEMORY_PER_SAMPLE[1] * m + MEMORY_PER_SAMPLE[2])
    if "xlsx" in o.tables:       # the samples sheet, written after the Monte Carlo it holds
        mem += n * (k + m + 1) * XLSX_BYTES_PER_CELL
    parts = 1 + m + len(study.analyses)
    report = REPORT_BYTES_PER_PART * parts * (2 if o.pdf else 1)
    disk = n * (DISK_PER_SAMPLE[0] * k + DISK_PER_SAMPLE[1] * m + DISK_PER_SAMPLE[2]) + report
    workers = 1 if o.executor == "serial" else (o.workers or os.cpu_count() or 1)
    return RunEstimate(n, k, m, mem, disk, workers, budget=o.until_decided)


def time_pilot(est: RunEstimate, study, rows: int = 64) -> RunEstimate:
    """Add the Monte Carlo's and the report's time to ``est``: the model timed at the nominal point on 1 and on
    ``rows`` rows (after a warm-up), which separates the cost of a call from the cost of a row; a process
    pool's start; the report's parts."""
    from .mc import Evaluator
    from .sampling import sample

    x0 = study.spec.nominal_base()[None, :]
    ev = Evaluator()
    ev(study.model, x0, "pilot")  # first call: compiled kernels, caches

    def timed(X, repeat):          # the fastest of a few: a shared machine's stalls are not the model's cost
        best = math.inf
        for _ in range(repeat):
            t0 = time.perf_counter()
            ev(study.model, X, "pilot")
            best = min(best, time.perf_counter() - t0)
        return best

    t1 = timed(x0, 3)
    rows = max(2, min(est.n, rows if t1 < 0.02 else 8))
    # sampled reducers, not the nominal one: a solver may work harder away from the nominal point
    X = sample(study.spec, rows, "random", seed=study.options.seed).values
    tm = timed(X, 3 if t1 < 0.02 else 1)
    per_row = max((tm - t1) / (rows - 1), tm / rows / 50.0)
    if per_row * rows > 0.5:        # a costly model: the many-row timing is the better per-sample figure
        per_row = tm / rows
    o = study.options
    from .mc import auto_chunk_size

    chunk = o.chunk_size or auto_chunk_size(est.n, est.workers)
    calls = math.ceil(est.n / max(chunk, 1))
    est.per_sample = per_row
    engine = est.n * (ENGINE_SECONDS_PER_SAMPLE[0] * est.factors + ENGINE_SECONDS_PER_SAMPLE[1])
    est.seconds = (per_row * est.n + max(t1 - per_row, 0.0) * calls) / est.workers + engine \
        + (POOL_START_SECONDS if o.executor != "serial" and est.workers > 1 else 0.0)
    est.report_seconds = (REPORT_SECONDS[0] + REPORT_SECONDS[1] * est.outputs) * (REPORT_PDF_FACTOR if o.pdf else 1.0)
    if "xlsx" in o.tables:
        est.report_seconds += est.n * (est.factors + est.outputs + 1) * XLSX_SECONDS_PER_CELL
    return est


#: where the kernel describes this process's control groups, and where their files are
PROC_CGROUP, CGROUP_ROOT = Path("/proc/self/cgroup"), Path("/sys/fs/cgroup")
#: a cgroup v1 limit at or above this is "no limit" (the kernel writes 2⁶³ rounded down to a page)
_NO_LIMIT = 1 << 60


def _read_int(path: Path) -> int | None:
    try:
        text = path.read_text().strip()
    except OSError:
        return None
    return int(text) if text.isdigit() else None       # v2 writes "max" for no limit


def cgroup_memory_left(proc_cgroup: Path | None = None, root: Path | None = None) -> int | None:
    """Bytes the memory limits of this process's control groups still allow (a container's limit, which the
    machine's free memory does not show): the least of limit − usage over its group and the groups above it —
    cgroup v2 ``memory.max`` − ``memory.current``, v1 ``memory.limit_in_bytes`` − ``memory.usage_in_bytes``
    (Linux's Documentation/admin-guide/cgroup-v2.rst and cgroup-v1/memory.rst); None without a limit."""
    proc_cgroup, root = proc_cgroup or PROC_CGROUP, root or CGROUP_ROOT
    try:
        lines = proc_cgroup.read_text().splitlines()
    except OSError:
        return None
    left = []
    for line in lines:
        _, controllers, path = line.split(":", 2)
        if controllers == "":                                           # v2: "0::/path"
            base, files = root / "unified" if (root / "unified").is_dir() else root, ("memory.max", "memory.current")
        elif "memory" in controllers.split(","):                        # v1: "4:memory:/path"
            base, files = root / "memory", ("memory.limit_in_bytes", "memory.usage_in_bytes")
        else:
            continue
        d = base / path.lstrip("/")
        for g in (d, *d.parents):
            limit, used = _read_int(g / files[0]), _read_int(g / files[1])
            if limit is not None and limit < _NO_LIMIT:
                left.append(max(0, limit - (used or 0)))
            if g == base:
                break
    return min(left) if left else None


def available_memory() -> int | None:
    """Memory the run may still take: the machine's available memory, or less under a control group's limit."""
    try:
        import psutil

        avail = int(psutil.virtual_memory().available)
    except Exception:  # pragma: no cover - psutil missing or unsupported platform
        return None
    left = cgroup_memory_left()
    return avail if left is None else min(avail, left)


#: private memory of one local worker at its peak (measured on linear_stackup, figures rendered on the workers: a
#: process-pool worker, forked from the preloaded fork server, 26–36 MB; a Dask LocalCluster worker, an interpreter
#: of its own, 152–159 MB)
WORKER_MEMORY = {"process": 36_000_000, "dask": 160_000_000}
#: open files the run holds per local worker (its pipe and its process sentinel: measured 2 each) and besides them
FILES_PER_WORKER, FILES_BESIDE = 2, 64


def local_workers(executor: str, workers: int | None, scheduler: str | None) -> int:
    """The worker processes a run starts on this machine: none for the serial executor or a running Dask cluster."""
    if executor == "serial" or scheduler:
        return 0
    return workers or os.cpu_count() or 1


def open_files_limit() -> int | None:
    import resource

    soft = resource.getrlimit(resource.RLIMIT_NOFILE)[0]
    return None if soft == resource.RLIM_INFINITY else soft


def workers_problem(executor: str, workers: int | None, scheduler: str | None, beside: int = 0) -> str | None:
    """Why this machine cannot hold the run's local workers — more open files than ``ulimit -n`` allows, or more
    memory than is available beside ``beside`` bytes (the Monte Carlo's) —, or None."""
    w = local_workers(executor, workers, scheduler)
    if not w:
        return None
    soft = open_files_limit()
    if soft is not None and FILES_BESIDE + FILES_PER_WORKER * w > soft:
        return (f"{w} workers need about {FILES_BESIDE + FILES_PER_WORKER * w} open files and this process may open "
                f"{soft} (ulimit -n): at most {max(0, (soft - FILES_BESIDE) // FILES_PER_WORKER)} workers")
    avail, each = available_memory(), WORKER_MEMORY[executor]
    if avail is not None and beside + w * each > avail:
        with_mc = f", beside the Monte Carlo's {human_bytes(beside)}" if beside else ""
        return (f"{w} workers need about {human_bytes(w * each)} of memory ({human_bytes(each)} each{with_mc}) and "
                f"{human_bytes(avail)} are available: at most {max(0, (avail - beside) // each)} workers fit")
    return None


def check_resources(est: RunEstimate, out: Path, n_file: str, n_key: str, options=None,
                    workers_at: tuple[str, str] = ("<command line>", "--workers")) -> None:
    """InputError when the Monte Carlo cannot fit in memory (key ``n_key``) or on disk (``--out``), or this machine
    cannot hold the local workers of ``options`` (:func:`workers_problem`, at ``workers_at``: file and key)."""
    avail = available_memory()
    if avail is not None and est.memory > avail:
        raise InputError(f"n = {est.n:,} needs about {human_bytes(est.memory)} of memory for the Monte Carlo "
                         f"({est.factors} factors, {est.outputs} outputs) and {human_bytes(avail)} are available; "
                         f"lower n (about {max(2, int(est.n * avail / est.memory)):,} fit)", file=n_file, key=n_key)
    if options is not None:
        why = workers_problem(options.executor, options.workers, options.scheduler, est.memory)
        if why:
            raise InputError(why, file=workers_at[0], key=workers_at[1])
    where = _existing_ancestor(out.parent)
    free = shutil.disk_usage(where).free
    if est.disk > free:
        raise InputError(f"the run needs about {human_bytes(est.disk)} on disk and {where} has "
                         f"{human_bytes(free)} free", file=str(out), key="--out")


def human_bytes(b: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB", "PB"):
        if abs(b) < 1000 or unit == "PB":
            return f"{b:.3g} {unit}"
        b /= 1000
    return f"{b:.3g} EB"  # pragma: no cover


def human_seconds(s: float) -> str:
    if not math.isfinite(s):
        return "∞"
    if s < 90:
        return f"{s:.2g} s"
    if s < 5400:
        return f"{s / 60:.2g} min"
    if s < 2 * 86400:
        return f"{s / 3600:.2g} h"
    return f"{s / 86400:.3g} days"
