"""Executors: where chunks of model evaluations run.

``serial`` (in-process), ``process`` (a local process pool; the default,
using every core) and ``dask`` (``dask.distributed``: a LocalCluster, or a
running scheduler given by address).  Each maps a function over chunks and
hands results back *by chunk index*, so the assembled result never depends
on which worker finished first.

Stopping: :func:`stop_workers` kills the worker processes of every live
process pool at once (what the CLI does on SIGTERM/SIGINT, so a cancelled run
does not wait for chunks in flight).  Workers ignore SIGINT (the terminal
sends Ctrl-C to the whole process group: the parent decides, no worker
tracebacks) and exit by themselves when the parent process dies (``kill -9``
of the run): no orphan keeps computing.
"""
from __future__ import annotations

import contextlib
import hashlib
import logging
import multiprocessing
import os
import pickle
import signal
import threading
import time
import weakref
from concurrent.futures import ProcessPoolExecutor
from typing import Callable, Iterator, NamedTuple, Sequence

from .errors import InputError, RvtolError

KINDS = ("serial", "process", "dask")

#: what a pool's fork server imports once for every worker it forks (and our Dask LocalCluster's workers as they
#: start): besides the numerics, pyplot and the Agg backend — the report's figures render on the workers, and a
#: worker's first figure took 0.5–0.7 s against 0.1–0.2 s for the next (RV-80E sign-off): importing them and
#: reading the font cache
PRELOAD = ["numpy", "scipy.stats", "rvtol.model", "matplotlib.pyplot", "matplotlib.backends.backend_agg"]


def _single_thread_worker() -> None:
    """Worker initializer: one BLAS/OpenMP thread per process (no oversubscription)."""
    try:
        from threadpoolctl import threadpool_limits

        threadpool_limits(1)
    except Exception:  # threadpoolctl missing: nothing to limit
        pass


def _preload() -> None:
    import importlib

    for name in PRELOAD:
        importlib.import_module(name)


def _ignore_sigint() -> None:
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)


#: how often a pool worker checks that its parent is still alive (s)
ORPHAN_POLL = 0.5


def _started(pid: int) -> float | None:
    """When process ``pid`` started (None if it is gone or a zombie): tells a live owner from a reused pid."""
    try:
        import psutil

        proc = psutil.Process(pid)
        return None if proc.status() == psutil.STATUS_ZOMBIE else proc.create_time()
    except Exception:  # gone (or psutil missing: then only existence counts)
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return None
        except OSError:
            pass
        return 0.0


def _pool_worker(owner: int) -> None:
    """Process-pool worker initializer: one BLAS thread, Ctrl-C left to the owner, exit when orphaned.

    ``owner`` is the process that made the pool.  With the forkserver start method a worker's
    parent is the fork server, which lives as long as any worker does, so the watch is on the owner.
    """
    _single_thread_worker()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    born = _started(owner)

    def watch() -> None:  # the owner died (kill -9): stop computing
        while True:
            time.sleep(ORPHAN_POLL)
            if _started(owner) != born:
                os._exit(1)

    threading.Thread(target=watch, name="rvtol-orphan-watch", daemon=True).start()


_LIVE: "weakref.WeakSet[ProcessExecutor]" = weakref.WeakSet()


class Shared:
    """An argument that many executor calls pass unchanged — a model, the chunks of a fixed design —, pickled and
    digested once, here (:attr:`value` is the object itself, for a call that runs in this process).

    A process pool pickles every task's arguments, so an argument sent with each chunk of each call was pickled,
    piped and unpickled every time: a model unpickled once per chunk in the worker (0.1–0.3 s for the RV-80E
    sign-off's composite, the same wall time at any worker count), and the allocation's 3.6 MB chunks of its fixed
    design sent with each of its 64 GA and bisection batches (19–21 ms a batch of two chunks with a no-op task;
    0.5 ms with small arguments).  Instead a pool worker keeps what it received by digest (up to
    :data:`KEEP_BYTES`, least recently used dropped first) and the calls after the first send the digest alone; a
    worker that does not have it answers so and the chunk is sent again with the bytes.  A Dask cluster holds it
    scattered, found by the same digest.  Models are row-deterministic, so a kept copy answers as a fresh one;
    an array is copied once and read-only, here and on the workers (a task that wrote into it would change the next
    call's input).  Only a task's own arguments are unpacked, not a Shared inside a list or dict.
    Models need no wrapping: every call ships its models as Shared; a caller wraps the data it repeats.
    """

    __slots__ = ("value", "key", "blob")

    def __init__(self, value) -> None:
        if hasattr(value, "setflags"):          # an array: a read-only copy (the caller may change its own later)
            value = _read_only(value.copy())
        self.value = value
        self.blob, self.key = _pickled(value)

    def __reduce__(self):                   # travels as its digest and bytes (the task side: _Ref)
        return _Ref, (self.key, self.blob)

    def __copy__(self):                     # immutable: a copy is itself (not the _Ref it pickles to)
        return self

    def __deepcopy__(self, memo):
        return self


def _read_only(a):
    """A read-only view of array ``a`` (its pickle, and so its digest, is that of any read-only array of its
    content: pickle protocol 5 marks a writable buffer apart)."""
    v = a.view()
    v.setflags(write=False)
    return v


def _pickled(value) -> tuple[bytes, bytes]:
    """``value``'s pickle and the pickle's 128-bit digest (what identifies it on the workers)."""
    blob = pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL)
    return blob, hashlib.blake2b(blob, digest_size=16).digest()


class _NotKept(Exception):
    """A task carried a Shared argument's digest alone, and this worker does not keep it."""


class _Ref:
    """A :class:`Shared` argument as a pool task carries it: the digest, and the bytes unless workers have them (as
    a Dask task finds it scattered: always with the bytes).  ``keep``: the worker keeps the value by digest (a Dask
    call's own large array is used once: not kept)."""

    __slots__ = ("key", "blob", "keep")

    def __init__(self, key: bytes, blob: bytes | None, keep: bool = True) -> None:
        self.key, self.blob, self.keep = key, blob, keep

    def get(self):
        if not self.keep:       # a call's own array, writable as pickled, in memory of its own (aligned)
            return pickle.loads(self.blob)

        def unpickled():
            if self.blob is None:
                raise _NotKept
            value = pickle.loads(self.blob)
            return (_read_only(value) if hasattr(value, "setflags") else value), len(self.blob)

        with _KEPT_LOCK:                    # a Dask worker may run several tasks at once
            return _recently_used(_KEPT, self.key, unpickled)

    def __sizeof__(self) -> int:            # what Dask weighs a scattered one by (its placement, its memory)
        return object.__sizeof__(self) + len(self.blob or b"")


def _recently_used(store: dict, key, make: Callable, drop: Callable = lambda value: None):
    """``store[key]``'s value, made by ``make() -> (value, size)`` if missing, as the most recently used entry; the
    least recently used are dropped (``drop(value)``) while the sizes sum over :data:`KEEP_BYTES` and more than one
    is left.  What a worker keeps of the Shared arguments and what a Dask executor keeps scattered."""
    got = store.pop(key, None)
    if got is None:
        got = make()
    store[key] = got                                   # most recently used last
    while len(store) > 1 and sum(v[1] for v in store.values()) > KEEP_BYTES:
        drop(store.pop(next(iter(store)))[0])
    return got[0]


#: what a pool worker keeps of the Shared arguments it received (by digest: value and size), least recently used first
_KEPT: dict = {}
_KEPT_LOCK = threading.Lock()
#: a worker keeps Shared arguments up to this many pickled bytes, and a Dask executor its scattered ones
KEEP_BYTES = 256 << 20
#: a Dask executor scatters arrays from this size on
SCATTER_BYTES = 1 << 18


class _Missing:
    """A pool task's answer when it carried a digest its worker does not keep."""


def _once_per_call(convert: Callable) -> Callable:
    """``convert`` memoised by object for one executor call: the model (or array) every chunk of a call carries is
    pickled and digested once, not once per chunk."""
    seen: dict[int, tuple] = {}

    def get(a):
        if id(a) not in seen:
            seen[id(a)] = (a, convert(a))     # ``a`` kept with it, so its id is not reused during the call
        return seen[id(a)][1]

    return get


def plain(args: tuple) -> tuple:
    """A task's arguments as the function takes them in this process (each :class:`Shared` as its value)."""
    return tuple(a.value if isinstance(a, Shared) else a for a in args)


def _forget_kept() -> None:
    """A worker lets go of what it keeps (a Dask cluster the run does not own outlives it)."""
    with _KEPT_LOCK:
        _KEPT.clear()


class _Done(NamedTuple):
    """A task's result and the CPU seconds its worker thread spent on it."""

    value: object
    cpu: float


#: while a caller records them (:func:`recording_task_cpu`): the CPU seconds of each task a pool or Dask finished
_TASK_CPU: list | None = None


@contextlib.contextmanager
def recording_task_cpu():
    """The CPU seconds (worker thread) of every task the process pool or Dask finishes inside the block, in the
    order they finish: the list the block gets."""
    global _TASK_CPU
    outer, _TASK_CPU = _TASK_CPU, []
    try:
        yield _TASK_CPU
    finally:
        _TASK_CPU = outer


def _finished(res: _Done):
    if _TASK_CPU is not None:
        _TASK_CPU.append(res.cpu)
    return res.value


def _call_shipped(fn: Callable, *args):
    """Worker side of the process pool's and Dask's ``imap``: ``fn`` on the arguments with shared ones unpacked,
    timed by its thread's CPU clock, the unpacking included (a worker's first task unpickles the model it then
    keeps: 0.26 s for the RV-80E sign-off's; a worker's task is its thread's: one BLAS thread, no other work)."""
    t0 = time.thread_time()
    try:
        args = tuple(a.get() if isinstance(a, _Ref) else a for a in args)
    except _NotKept:
        return _Missing()
    value = fn(*args)
    return _Done(value, time.thread_time() - t0)


def stop_workers() -> None:
    """Kill the worker processes of every live process pool now (safe to call from a signal handler)."""
    for ex in list(_LIVE):
        ex.kill_workers()


class _Background:
    """``fn()`` on a daemon thread; :meth:`wait` joins it and raises what it raised."""

    def __init__(self, fn: Callable, name: str):
        self._error: BaseException | None = None

        def run():
            try:
                fn()
            except BaseException as exc:     # handed to the thread that waits
                self._error = exc

        self._thread = threading.Thread(target=run, name=name, daemon=True)
        self._thread.start()

    def wait(self, raise_error: bool = True) -> None:
        self._thread.join()
        if raise_error and self._error is not None:
            raise self._error


class Executor:
    """Maps ``fn(*args)`` over task argument tuples; yields ``(index, result)`` as tasks finish."""

    kind = "base"
    workers = 1
    _starting: _Background | None = None

    def imap(self, fn: Callable, tasks: Sequence[tuple]) -> Iterator[tuple[int, object]]:
        raise NotImplementedError  # pragma: no cover - abstract

    def start(self) -> None:
        """Start the workers now, in the background (:meth:`_start`); their first use waits for them."""
        if self._starting is None:
            self._starting = _Background(self._start, f"rvtol-{self.kind}-start")

    def _start(self) -> None:
        """What :meth:`start` does on its thread (nothing to start by default)."""

    def _started(self, raise_error: bool = True) -> None:
        """Wait for :meth:`start` (if it ran), raising what it raised unless ``raise_error`` is false."""
        starting = self._starting
        if starting is not None:
            # let go only once joined and its error raised: a wait interrupted (Ctrl-C) leaves it for close() to
            # wait on, and every later use raises the same error
            starting.wait(raise_error)
            self._starting = None

    def close(self, wait: bool = True) -> None:
        """Release the workers (``wait=False``: do not wait for them to exit)."""

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def describe(self) -> str:
        return f"{self.kind} ({self.workers} worker{'s' if self.workers != 1 else ''})"


class SerialExecutor(Executor):
    kind = "serial"

    def imap(self, fn, tasks):
        for i, t in enumerate(tasks):
            yield i, fn(*plain(t))


class ProcessExecutor(Executor):
    """A local process pool (forkserver start: safe beside threads such as Dask's)."""

    kind = "process"

    def __init__(self, workers: int | None = None):
        self.workers = workers or os.cpu_count() or 1
        self._pool: ProcessPoolExecutor | None = None

    @property
    def pool(self) -> ProcessPoolExecutor:
        self._started()
        return self._pool or self._make_pool()

    def _start(self) -> None:
        """The pool and its workers: starting the fork server waits for its imports (about 1 s)."""
        pool = self._make_pool()
        for _ in range(self.workers):
            pool.submit(_warm)

    def _make_pool(self) -> ProcessPoolExecutor:
        if self._pool is None:
            method = "forkserver" if "forkserver" in multiprocessing.get_all_start_methods() else "spawn"
            ctx = multiprocessing.get_context(method)
            if method == "forkserver":
                ctx.set_forkserver_preload(PRELOAD)
            self._pool = ProcessPoolExecutor(max_workers=self.workers, mp_context=ctx, initializer=_pool_worker,
                                             initargs=(os.getpid(),))
            self._killed = False
            self._sent: set[bytes] = set()      # digests of the Shared arguments whose bytes tasks have carried
            _LIVE.add(self)
        return self._pool

    def kill_workers(self) -> None:
        """SIGKILL the pool's worker processes (their chunks are lost; :meth:`close` then does not wait)."""
        pool = self._pool
        if pool is None:
            return
        self._killed = True
        for proc in list((getattr(pool, "_processes", None) or {}).values()):
            try:
                os.kill(proc.pid, signal.SIGKILL)
            except (ProcessLookupError, OSError, AttributeError, TypeError):
                pass
        # A worker killed while sending its result leaves half a message in the result pipe, and the pool's
        # manager thread would wait for the rest forever (and the interpreter for it at exit).  Closing our
        # copy of the pipe's write end lets it see end-of-file once the workers are gone: the pool then
        # reports itself broken and cleans up as designed.
        writer = getattr(getattr(pool, "_result_queue", None), "_writer", None)
        try:
            if writer is not None:
                writer.close()
        except OSError:
            pass

    def imap(self, fn, tasks):
        from concurrent.futures import FIRST_COMPLETED, wait
        from concurrent.futures.process import BrokenProcessPool

        share = _once_per_call(lambda a: Shared(a) if _is_model(a) else a)
        tasks = [tuple(map(share, t)) for t in tasks]
        pool = self.pool
        sent = self._sent           # carried by an earlier call's tasks: this call's carry the digest alone
        futs: dict = {}

        def submit(i: int, digest_only: bool):
            args = (_Ref(a.key, None if digest_only and a.key in sent else a.blob) if isinstance(a, Shared) else a
                    for a in tasks[i])
            futs[pool.submit(_call_shipped, fn, *args)] = i

        try:
            try:
                for i in range(len(tasks)):
                    submit(i, True)
                self._sent = sent | {a.key for t in tasks for a in t if isinstance(a, Shared)}
                while futs:
                    done, _ = wait(futs, return_when=FIRST_COMPLETED)
                    for f in done:
                        i = futs.pop(f)
                        res = f.result()
                        if isinstance(res, _Missing):           # that worker does not keep it: send the bytes too
                            submit(i, False)
                            continue
                        yield i, _finished(res)
            except BrokenProcessPool:
                raise RvtolError(
                    "the worker processes stopped before finishing. If you call rvtol from a script, "
                    "put the calls under `if __name__ == \"__main__\":` (worker processes import the "
                    "script), or use make_executor(\"serial\"); otherwise a worker ran out of memory "
                    "or crashed") from None
        finally:
            if not getattr(self, "_killed", False):  # killed: the broken pool fails its futures itself
                for f in futs:
                    f.cancel()

    def close(self, wait: bool = True):
        self._started(raise_error=False)
        if self._pool is not None:
            pool, self._pool = self._pool, None
            _LIVE.discard(self)
            # after kill_workers the pool finds itself broken at once; waiting lets it clean up in order
            killed = getattr(self, "_killed", False)
            pool.shutdown(wait=wait or killed, cancel_futures=not killed)


class DaskExecutor(Executor):
    """``dask.distributed``: a LocalCluster of ``workers`` processes, or ``scheduler`` address."""

    kind = "dask"

    #: seconds to wait for a scheduler given by address
    CONNECT_TIMEOUT = 10.0

    def __init__(self, workers: int | None = None, scheduler: str | None = None, connect_timeout: float | None = None):
        self.scheduler = scheduler
        self.connect_timeout = connect_timeout or self.CONNECT_TIMEOUT
        self._want = workers or os.cpu_count() or 1
        self._client = None
        self._cluster = None
        # (digest, kept on the workers) of a scattered model or array -> (its future on the cluster, its size)
        self._scattered: dict = {}

    @property
    def client(self):
        self._started()
        if self._client is None:
            self._connect()
        return self._client

    def _start(self) -> None:
        self._connect()

    def _connect(self) -> None:
        if self._client is None:
            from dask.distributed import Client, LocalCluster

            if self.scheduler:
                try:
                    self._client = Client(self.scheduler, timeout=f"{self.connect_timeout}s")
                except (OSError, TimeoutError) as exc:
                    raise InputError(f"cannot reach Dask scheduler {self.scheduler!r} ({exc})",
                                     key="--scheduler") from None
            else:
                import dask

                with dask.config.set(LOCAL_CLUSTER):
                    self._cluster = LocalCluster(n_workers=self._want, threads_per_worker=1, processes=True,
                                                 dashboard_address=None, silence_logs=logging.ERROR)
                self._client = Client(self._cluster)
                # our own cluster's processes leave Ctrl-C (sent to the whole process group) to us:
                # closing the cluster stops them, without a traceback from each
                self._client.run(_ignore_sigint, nanny=True)
                self._client.run(_ignore_sigint)
                self._client.run(_preload)          # as a pool's fork server does
            self._client.run(_single_thread_worker)

    @property
    def workers(self) -> int:  # type: ignore[override]
        if self._client is None:
            return self._want
        return max(1, len(self._client.scheduler_info().get("workers", {})))

    def imap(self, fn, tasks):
        from dask.distributed import as_completed as dask_as_completed

        c = self.client
        # models and Shared arrays (broadcast to every worker) and a call's own large arrays (to one worker) travel
        # once, outside the task graph, and stay there while calls reuse them: the sensitivity stencils and the
        # allocation's generations call with the same model, and the allocation with the same chunks of its fixed
        # design, hundreds of times.  Results come back with their futures (no round trip per result) and finished
        # futures are simply dropped (a cancel is one more): a call of 8 small chunks 34 → 24 ms on a 2-worker
        # LocalCluster (a process pool: 2–3 ms)
        share = _once_per_call(self._shared)
        args = [[fn] + [share(a) for a in t] for t in tasks]
        futs = c.map(_call_shipped, *zip(*args), pure=False) if args else []
        index = {f.key: i for i, f in enumerate(futs)}
        done = False
        try:
            for f, res in dask_as_completed(futs, with_results=True):
                yield index[f.key], _finished(res)
            done = True
        finally:
            if not done:             # stopped early (an error, a cancelled run): the rest need not run
                c.cancel(futs)

    def _shared(self, a):
        """``a`` as the task will get it: a model, a :class:`Shared` or a large array as the future of its
        :class:`_Ref` (digest and pickle) scattered on the cluster, else itself.  Scattered as its pickle, not
        as itself: an array Dask scatters itself reaches the task as a view into the received message at any byte
        offset — unaligned, and an allocation task (its GA's candidates built from a chunk of the design) took
        8–15 % more CPU on it; unpickled, it is in memory of its own."""
        import numpy as np

        if _is_model(a):
            a = Shared(a)
        if isinstance(a, Shared):           # used by many calls, so by every worker (as a pool's workers keep it)
            ref, broadcast = _Ref(a.key, a.blob), True
        elif isinstance(a, np.ndarray) and a.nbytes >= SCATTER_BYTES:
            # pickled at once, so no later change of the caller's reaches it (not copied as a Shared is)
            blob, key = _pickled(a)
            ref, broadcast = _Ref(key, blob, keep=False), False
        else:
            return a
        # the same content as a Shared (kept, read-only) and as a call's own array (writable): two scatters
        return _recently_used(self._scattered, (ref.key, ref.keep),
                              lambda: (self.client.scatter(ref, broadcast=broadcast, hash=False), len(ref.blob)),
                              lambda future: future.release())

    def close(self, wait: bool = True):
        self._started(raise_error=False)
        self._scattered.clear()
        if self._client is not None and self._cluster is None:      # a scheduler's workers live on
            with contextlib.suppress(Exception):    # workers gone or unreachable: nothing kept to let go
                self._client.run(_forget_kept)
        if self._client is not None:
            self._client.close()
            self._client = None
        if self._cluster is not None:
            self._cluster.close()
            self._cluster = None


#: our own LocalCluster's settings.  The workers' housekeeping made rarer: by default each worker process wakes its
#: event loop every 20 ms (the tick that watches for a blocked loop), reads its memory every 100 ms (and its nanny too),
#: samples system figures every 500 ms and its own stack every 10 ms (the statistical profiler, for a dashboard nobody
#: opens).  On a machine whose cores all compute, each wake takes the GIL and a core from the task: a chunk of the
#: RV-80E sign-off's composite took 6–7 % longer on a 2-worker LocalCluster than on a 2-process pool (timed inside the
#: tasks); with these settings the same.  A tick of 1 s still reports a loop blocked for the warning's 3 s; memory is
#: still checked every second against the kill limit.
#:
#: And glibc's own memory policy, as in a process pool: Dask's nanny starts each worker with
#: ``MALLOC_TRIM_THRESHOLD_=65536``, which (any explicit threshold does) switches off glibc's dynamic mmap threshold, so
#: every temporary array above 128 kB is a fresh ``mmap`` whose pages fault in again.  An allocation task of the RV-80E
#: sign-off (its GA's candidates on a chunk of the design) took 10–12 % more CPU in its own thread on a Dask worker than
#: on a pool worker (31.4 against 25.3 ms, 523 against 468 ms); without the variable 25.1 and 469 ms.  A run's cluster
#: lives for the run, so the memory it keeps is returned when it ends.
#:
#: And every worker keeps its copy of a model or a Shared array.  Dask's active memory manager drops, every 2 s, the
#: copies of a key that no task waiting on that worker needs — the broadcast copies of a model and of a Shared array
#: among them — so a later call found its model on one worker only, and the scheduler put all of that call's tasks
#: there; work stealing then moved them over one a second.  The RV-80E sign-off's independent check of its allocation (8
#: chunks of 2 s on 2 workers) took 8.2–10.1 s in five runs (in one, its first 5 chunks ran on one worker; Dask's task
#: stream and the key's story), 8.2 s without the manager; the allocation phase on 2 Dask workers 25.8 → 23.9 s.
#: Without the manager the copies stay until the run lets go of them (:meth:`DaskExecutor.close`).  A scheduler given by
#: address keeps its own settings: there the tasks of such a call still finish, later.
LOCAL_CLUSTER = {
    "distributed.worker.profile.enabled": False,
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "5s",
    "distributed.worker.memory.monitor-interval": "1s",
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
    "distributed.scheduler.active-memory-manager.start": False,
}


def _is_model(a) -> bool:
    from .model import Model

    return isinstance(a, Model)


def _warm() -> None:
    """A first task for a pool started early: its worker starts (the fork server's imports, the initializer)."""


#: an executor started ahead of need (:func:`start_early`), until :func:`make_executor` takes it
_EARLY: list[Executor] = []


def start_early(kind: str = "process", workers: int | None = None, scheduler: str | None = None) -> None:
    """Start the executor a run will ask for now, in the background — e.g. while a study loads on the main process:
    a process pool's fork server imports and its workers start, a Dask LocalCluster starts (or the scheduler is
    reached), and that overlaps the loading instead of following it (1–3 s of a run's serial part).  The next
    :func:`make_executor` with the same kind, workers and scheduler takes it; one asking for something else closes it
    (:func:`discard_early`)."""
    discard_early()
    if kind == "process":
        ex = ProcessExecutor(workers)
    elif kind == "dask":
        ex = DaskExecutor(workers, scheduler)
    else:
        return
    ex.start()
    _EARLY.append(ex)


def _take_early(kind: str, workers: int | None, scheduler: str | None) -> Executor | None:
    """The executor :func:`start_early` made, if it is the one asked for; else it is closed."""
    if _EARLY:
        ex = _EARLY[0]
        same = (ex.kind == kind and getattr(ex, "_want", ex.workers) == (workers or os.cpu_count() or 1)
                and getattr(ex, "scheduler", None) == scheduler)
        if same:
            return _EARLY.pop()
    discard_early()
    return None


def discard_early() -> None:
    """Close an executor :func:`start_early` made and nobody took (a pool's workers exit by themselves; only a start
    still under way is waited for, ≈ 1 s for a pool's fork server)."""
    while _EARLY:
        _EARLY.pop().close(wait=False)


def make_executor(kind: str = "process", workers: int | None = None, scheduler: str | None = None) -> Executor:
    if kind not in KINDS:
        raise InputError(f"unknown executor {kind!r} (expected one of: {', '.join(KINDS)})", key="executor")
    if workers is not None and workers < 1:
        raise InputError(f"workers must be >= 1, got {workers}", key="workers")
    early = _take_early(kind, workers, scheduler if kind == "dask" else None)
    if early is not None:
        return early
    if kind == "serial":
        return SerialExecutor()
    if kind == "process":
        return ProcessExecutor(workers)
    return DaskExecutor(workers, scheduler)
