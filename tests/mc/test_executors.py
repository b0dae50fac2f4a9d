"""Process pools: a model travels to each worker once, not with every chunk; a pool started early (while a study
loads) is the one the run then uses; the crank circle is one value for every model (one finite-element solve)."""
import numpy as np
import pytest

from rvtol import executors
from rvtol.executors import ProcessExecutor, make_executor, start_early
from rvtol.mc import evaluate
from rvtol.testing import UnpickleCountingModel


def test_a_worker_unpickles_a_model_once_for_all_its_chunks():
    m = UnpickleCountingModel()
    with ProcessExecutor(1) as ex:
        first = evaluate(m, np.zeros((6, 1)), ex, chunk_size=1, progress=False).Y
        again = evaluate(m, np.zeros((3, 1)), ex, chunk_size=1, progress=False).Y   # a second call: kept
        same = evaluate(UnpickleCountingModel(), np.zeros((2, 1)), ex, chunk_size=1, progress=False).Y
        other = evaluate(UnpickleCountingModel(tag=1), np.zeros((2, 1)), ex, chunk_size=1, progress=False).Y
    assert first.ravel().tolist() == [1.0] * 6          # one unpickling for six chunks (was 1, 2, …, 6)
    assert again.ravel().tolist() == [1.0] * 3
    assert same.ravel().tolist() == [1.0] * 2           # an equal model (the same pickle) is the kept one
    assert other.ravel().tolist() == [2.0] * 2          # a different model is unpacked once in its turn


@pytest.fixture
def no_early_executor():
    """Whatever a test starts early is closed after it."""
    yield
    executors.discard_early()


def _taken_early(kind, workers, scheduler=None):
    """An executor started early, then asked for: the same object, taken from the early slot."""
    start_early(kind, workers, scheduler)
    early = executors._EARLY[0]
    got = make_executor(kind, workers, scheduler)
    assert got is early and not executors._EARLY
    return got


def test_a_pool_started_early_is_the_one_the_run_gets(no_early_executor):
    got = _taken_early("process", 2)
    assert got.workers == 2
    got.close()
    start_early("process", 1)
    other = make_executor("process", 2)        # another worker count: the early pool is closed, a new one made
    assert not executors._EARLY and isinstance(other, ProcessExecutor) and other.workers == 2
    other.close()
    start_early("process", 1)
    assert make_executor("serial").kind == "serial" and not executors._EARLY
    start_early("serial")
    assert not executors._EARLY


def test_a_pool_starts_in_the_background_and_its_first_use_waits_for_it(monkeypatch):
    """Starting the fork server waits for its imports (about 1 s of a run's serial part): the caller goes on while
    it starts, the pool's first use waits for it, and an error while starting reaches that first use."""
    import threading

    go, made = threading.Event(), []
    real = ProcessExecutor._make_pool

    def slow(self):
        go.wait(30)
        made.append(threading.current_thread().name)
        return real(self)

    monkeypatch.setattr(ProcessExecutor, "_make_pool", slow)
    ex = ProcessExecutor(1)
    ex.start()                                       # returns while the pool is still to be made
    assert made == [] and ex._pool is None
    go.set()
    with ex:
        assert ex.pool is not None and made == ["rvtol-process-start"]      # made by the start, once
        assert [r for _, r in ex.imap(abs, [(-2,), (3,)])] in ([2, 3], [3, 2])

    tried = []

    def broken(self):
        tried.append(threading.current_thread().name)
        raise OSError("no fork server")

    monkeypatch.setattr(ProcessExecutor, "_make_pool", broken)
    ex = ProcessExecutor(1)
    ex.start()
    for _ in range(2):                               # the start's own error, every time: not a new attempt
        with pytest.raises(OSError, match="no fork server"):
            ex.pool
    ex.close()
    assert tried == ["rvtol-process-start"]


def test_a_dask_cluster_started_early_is_the_one_the_run_gets_and_evaluates_the_same(no_early_executor):
    from rvtol.executors import SerialExecutor

    with _taken_early("dask", 1) as got:
        m = UnpickleCountingModel(tag=3)
        y = evaluate(m, np.zeros((3, 1)), got, chunk_size=1, progress=False).Y
    assert y.ravel().tolist() == [1.0] * 3
    assert evaluate(m, np.zeros((3, 1)), SerialExecutor(), progress=False).Y.shape == (3, 1)


def test_an_unreachable_scheduler_found_in_the_background_is_still_an_input_error(monkeypatch, no_early_executor):
    from rvtol.errors import InputError

    monkeypatch.setattr(executors.DaskExecutor, "CONNECT_TIMEOUT", 1.0)
    ex = _taken_early("dask", 1, "tcp://127.0.0.1:9")
    with pytest.raises(InputError, match="cannot reach Dask scheduler"):
        ex.client


def test_every_model_of_the_product_puts_the_crank_on_one_circle():
    """The 20-DOF geometry and the torsion-angle model read the crank circle as the design writes it, so their
    finite-element seats are one solve (they differed by the design's rounding of a', 0.4 µm, and solved twice)."""
    from rvtol.design import load_design
    from rvtol.elements import fe_seats
    from rvtol.models.stiffness.torsion_angle import ReducerStiffness
    from rvtol.models.reducer_20dof.geometry import geometry_from_design

    d = load_design("data/products/rv80e/design.toml")
    fe_seats.disc_work.cache_clear()
    g = geometry_from_design(d)
    ReducerStiffness.from_design(d)
    assert fe_seats.disc_work.cache_info().misses == 1
    assert abs(g.a_w - float(d["crank_bearing.centre_radius"])) < 5e-4     # the design's value is a' rounded


def _unpickled(m) -> float:
    from rvtol.testing import UNPICKLED

    return float(UNPICKLED["count"])


def _forget_kept() -> None:
    executors._KEPT.clear()


def test_a_shared_argument_travels_once_and_again_only_to_a_worker_that_lost_it(monkeypatch):
    """After a call has sent a Shared argument's bytes, the next calls send its digest alone; a worker that no
    longer keeps it answers so and gets the bytes again — the results are the same throughout."""
    from rvtol.executors import Shared

    m = Shared(UnpickleCountingModel(tag=5))
    with ProcessExecutor(1) as ex:
        carried = []
        submit = ex.pool.submit

        def recording(fn, f, *args):
            carried.append(["bytes" if a.blob is not None else "digest" for a in args if isinstance(a, executors._Ref)])
            return submit(fn, f, *args)

        monkeypatch.setattr(ex.pool, "submit", recording)
        run = lambda fn, tasks: [r for _, r in sorted(ex.imap(fn, tasks), key=lambda ir: ir[0])]  # noqa: E731
        first = run(_unpickled, [(m,)] * 3)
        again = run(_unpickled, [(m,)] * 2)
        run(_forget_kept, [()])
        lost = run(_unpickled, [(m,), (m,)])
    assert first == [1.0] * 3 and again == [1.0] * 2 and lost == [2.0] * 2   # unpickled once, then once more
    assert carried[:5] == [["bytes"]] * 3 + [["digest"]] * 2
    assert carried[6:8] == [["digest"]] * 2 and ["bytes"] in carried[8:]      # lost: sent again with the bytes


def _write_into(a):
    a[0] = 1.0


def test_a_shared_array_is_read_only_on_the_workers_and_in_this_process():
    from rvtol.executors import SerialExecutor, Shared
    from rvtol.errors import RvtolError
    from rvtol.mc import map_chunks

    mine = np.arange(4.0)
    a = Shared(mine)
    mine[0] = 9.0                                   # the caller's own array: not what was shared
    assert a.value[0] == 0.0 and executors.plain((a,))[0] is a.value
    import copy

    assert copy.deepcopy([a])[0] is a
    assert map_chunks(np.sum, [(a,)], SerialExecutor()) == [6.0] and map_chunks(np.sum, [(a,)]) == [6.0]
    with pytest.raises(ValueError, match="read-only"):
        map_chunks(_write_into, [(a,)])
    with ProcessExecutor(2) as ex:
        assert map_chunks(np.sum, [(a,), (a,)], ex) == [6.0, 6.0]
        with pytest.raises((ValueError, RvtolError), match="read-only"):
            map_chunks(_write_into, [(a,), (a,)], ex)
    assert a.value[0] == 0.0


def test_a_dask_cluster_receives_a_model_once_for_all_calls():
    from rvtol.executors import DaskExecutor

    m = UnpickleCountingModel(tag=2)
    with DaskExecutor(1) as ex:
        first = evaluate(m, np.zeros((4, 1)), ex, chunk_size=1, progress=False).Y
        again = evaluate(m, np.zeros((3, 1)), ex, chunk_size=1, progress=False).Y   # not scattered again
        assert len(ex._scattered) == 1
    assert first.ravel().tolist() == [1.0] * 4 and again.ravel().tolist() == [1.0] * 3


def test_a_dask_cluster_receives_a_large_array_once_and_results_are_the_serial_ones():
    from rvtol.executors import SCATTER_BYTES, DaskExecutor, SerialExecutor
    from rvtol.mc import map_chunks

    rng = np.random.default_rng(1)
    big = [rng.normal(size=(SCATTER_BYTES // 8 + 10,)) for _ in range(3)]     # each over the scatter size
    tasks = [(b, k) for k in (1.0, 2.0) for b in big]                          # each array in two tasks
    want = map_chunks(np.multiply, tasks, SerialExecutor())
    shared = [executors.Shared(b) for b in big]                                 # the same arrays, digested once
    with DaskExecutor(2) as ex:
        got = map_chunks(np.multiply, tasks, ex)
        got_again = map_chunks(np.multiply, tasks, ex)
        got_shared = map_chunks(np.multiply, [(b, k) for k in (1.0, 2.0) for b in shared], ex)
        # three arrays, each sent once as a call's own and once as Shared (kept on the workers, read-only)
        assert len(ex._scattered) == 6
    for w, g, g2, g3 in zip(want, got, got_again, got_shared):
        np.testing.assert_array_equal(g, w)
        np.testing.assert_array_equal(g2, w)
        np.testing.assert_array_equal(g3, w)


def test_every_dask_worker_keeps_its_copy_of_a_model_between_calls():
    """Dask's active memory manager (every 2 s by default) would drop the broadcast copies no waiting task needs; a
    later call then found its model on one worker, and the scheduler ran all its chunks there."""
    import time

    from rvtol.executors import DaskExecutor

    m = UnpickleCountingModel(tag=3)
    with DaskExecutor(2) as ex:
        evaluate(m, np.zeros((2, 1)), ex, chunk_size=1, progress=False)
        (future, _), = ex._scattered.values()
        time.sleep(2.5)                     # longer than the manager's interval
        assert len(ex.client.who_has([future])[future.key]) == 2


def _layout(a, _):
    return bool(a.flags.aligned), bool(a.flags.writeable), a.ctypes.data % 8


def test_a_dask_task_gets_a_large_array_aligned_and_read_only_as_a_pool_task_does():
    """Dask hands an array it scattered itself to the task as a view into the received message, at any byte
    offset: float64s off their 8-byte alignment, which numpy reads through buffered copies (an allocation task of
    the RV-80E sign-off took 8–15 % more CPU).  Scattered as its pickle, the task gets an array of its own:
    writable if the call's own, read-only if :class:`Shared`, as on a pool."""
    from rvtol.executors import SCATTER_BYTES, DaskExecutor
    from rvtol.mc import map_chunks

    big = np.random.default_rng(2).normal(size=(SCATTER_BYTES // 8 + 10,))
    tasks = [(big, 0), (executors.Shared(big), 1)]
    with ProcessExecutor(2) as ex:
        pool = map_chunks(_layout, tasks, ex)
    with DaskExecutor(2) as ex:
        dask = map_chunks(_layout, tasks, ex)
    assert dask == pool == [(True, True, 0), (True, False, 0)]     # a call's own array writable, a Shared not


def _kept_count():
    return len(executors._KEPT)


def test_dask_weighs_a_scattered_reference_by_its_bytes():
    """A Dask cluster places tasks near their data and counts memory by ``sizeof``: a reference that weighed its
    60 bytes of object would let a 3.6 MB chunk of the design move for free."""
    from dask.sizeof import sizeof

    ref = executors._Ref(b"k" * 16, b"x" * 1_000_000)
    assert 1_000_000 <= sizeof(ref) < 1_001_000


def test_the_workers_of_a_scheduler_let_go_of_what_they_kept_when_the_run_closes():
    """A cluster given by address outlives the run: its workers drop the Shared values they kept for it."""
    from dask.distributed import Client, LocalCluster

    from rvtol.executors import DaskExecutor
    from rvtol.mc import map_chunks

    a = executors.Shared(np.arange(40_000.0))
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as lc, \
            Client(lc) as c:
        ex = DaskExecutor(scheduler=lc.scheduler_address)
        assert map_chunks(np.sum, [(a,), (a,)], ex) == [float(np.arange(40_000.0).sum())] * 2
        assert sum(c.run(_kept_count).values()) >= 1
        ex.close()
        assert sum(c.run(_kept_count).values()) == 0


def _worker_settings():
    import dask

    return {k: dask.config.get(k) for k in executors.LOCAL_CLUSTER}


def test_our_dask_workers_keep_their_housekeeping_rare_and_a_users_config_is_left_alone():
    import dask

    from rvtol.executors import LOCAL_CLUSTER, DaskExecutor

    with DaskExecutor(1) as ex:
        seen = list(ex.client.run(_worker_settings).values())
    assert seen == [LOCAL_CLUSTER]
    assert dask.config.get("distributed.admin.tick.interval") != LOCAL_CLUSTER["distributed.admin.tick.interval"]


def _malloc_trim():
    import os

    return os.environ.get("MALLOC_TRIM_THRESHOLD_")


def test_our_dask_workers_keep_glibcs_memory_policy_as_pool_workers_do():
    """Dask's nanny would start each worker with MALLOC_TRIM_THRESHOLD_=65536 (every large temporary array a fresh
    mmap): our cluster's workers get the environment of the process that starts them, as pool workers do."""
    import os

    import dask

    from rvtol.executors import DaskExecutor

    here = os.environ.get("MALLOC_TRIM_THRESHOLD_")
    with DaskExecutor(1) as ex:
        seen = list(ex.client.run(_malloc_trim).values())
        assert os.environ.get("MALLOC_TRIM_THRESHOLD_") == here          # nor set here by the nanny
    assert seen == [here]
    assert dask.config.get("distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_") == 65536   # Dask's own


def test_a_single_task_runs_here_unless_asked_to_go_to_the_workers():
    import os

    from rvtol.mc import map_chunks

    with ProcessExecutor(2) as ex:
        here = map_chunks(os.getpid, [()], ex)
        there = map_chunks(os.getpid, [()], ex, single_inline=False)
    assert here == [os.getpid()] and there != [os.getpid()]


def _has_agg() -> bool:
    import sys

    return {"matplotlib.pyplot", "matplotlib.backends.backend_agg"} <= set(sys.modules)


def test_pool_and_dask_workers_have_the_plotting_backend_before_their_first_figure():
    from rvtol.executors import DaskExecutor
    from rvtol.mc import map_chunks

    with ProcessExecutor(2) as ex:
        assert map_chunks(_has_agg, [(), ()], ex) == [True, True]
    with DaskExecutor(1) as ex:
        assert list(ex.client.run(_has_agg).values()) == [True]


def test_a_dask_call_pickles_its_model_once_for_all_its_chunks(monkeypatch):
    from rvtol.executors import DaskExecutor

    made = []
    real = executors.Shared.__init__

    def counting(self, obj):
        made.append(type(obj).__name__)
        real(self, obj)

    monkeypatch.setattr(executors.Shared, "__init__", counting)
    m = UnpickleCountingModel(tag=3)
    with DaskExecutor(1) as ex:
        y = evaluate(m, np.zeros((5, 1)), ex, chunk_size=1, progress=False).Y
    assert made == ["UnpickleCountingModel"] and y.ravel().tolist() == [1.0] * 5
