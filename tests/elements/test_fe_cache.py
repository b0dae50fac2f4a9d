"""The finite-element seats kept on disk by their inputs (rvtol.elements.fe_cache; issue 40 item 6): the key follows
every input number and nothing else, an entry reads back bit-identical to the seat computed afresh, a damaged entry
is computed again, an unwritable folder only loses the keeping, and two processes writing one entry at once leave
it whole (a reader never sees it half-written)."""
import inspect
import json
import math
import multiprocessing
import types
from pathlib import Path

import numpy as np
import pytest

from rvtol.elements import fe_cache, fe_seats

from conftest import ROOT

ring = fe_seats.housing_ring_work
#: a coarse housing ring of 12 pins at one crank angle (≈ 0.1 s): the seat these tests compute
KW = dict(r_inner=45.0, r_outer=50.0, thickness=24.0, z_p=12, z_c=11, R_p=40.0, ecc=1.5, E=210e3, nu=0.3, angles=1,
          n_r=2, per_pitch=2)
T = 3e5


@pytest.fixture
def folder(tmp_path, monkeypatch):
    """A fresh cache folder for the test; the per-process memo emptied before and after."""
    monkeypatch.setenv(fe_cache.ENV, str(tmp_path / "cache"))
    ring.cache_clear()
    yield tmp_path / "cache" / "fe-seats"
    ring.cache_clear()


@pytest.fixture
def solves(monkeypatch):
    """How many plates ``fe_seats`` builds (each computation of a seat builds one)."""
    count = {"n": 0}
    real = fe_seats.PlateModel

    def counted(*a, **k):
        count["n"] += 1
        return real(*a, **k)

    monkeypatch.setattr(fe_seats, "PlateModel", counted)
    return count


def _bits(result) -> list[str]:
    return [float(x).hex() for x in (*result.work, *result.force_sq)]


def test_the_key_follows_every_input_number_and_nothing_else():
    code = "digest"
    key = lambda *a, **k: fe_cache.entry_key(ring.fresh, a, k, code)   # noqa: E731
    base = key(T, **KW)
    # the same inputs spelt otherwise: all by keyword, NumPy scalars, a default written out or left out
    assert key(torque=T, **KW) == base
    numpy_scalars = {k: (np.int64(v) if isinstance(v, int) else np.float64(v)) for k, v in KW.items()}
    assert key(np.float64(T), **numpy_scalars) == base
    assert key(T, **{**KW, "per_pitch": 8}) == key(T, **{k: v for k, v in KW.items() if k != "per_pitch"})
    # every input moved by the least step (the next float up, an integer by one) gives a key of its own
    args = inspect.signature(ring.fresh).bind(T, **KW)
    args.apply_defaults()
    moved = {}
    for name, v in args.arguments.items():
        step = {**args.arguments, name: v + 1 if isinstance(v, int) else math.nextafter(float(v), math.inf)}
        moved[name] = key(**step)
    assert set(moved) == set(inspect.signature(ring.fresh).parameters)
    assert len(set(moved.values()) | {base}) == len(moved) + 1
    # another code digest (an edited module, another library version), another function: other keys
    assert key(T, **KW) != fe_cache.entry_key(ring.fresh, (T,), KW, "other")
    assert fe_cache.entry_key(fe_seats.carrier_plate_work.fresh, (T,), dict(r_outer=1.0, bore=1.0, crank_radius=1.0,
                              cup_diameter=1.0, pillar_radius=1.0, pillar_root_radius=1.0, thickness=1.0, share=1.0,
                              E=1.0, nu=0.3), code) != base
    with pytest.raises(TypeError, match="numbers only"):
        key(T, **{**KW, "E": "210e3"})


def test_the_code_digest_follows_the_source_bytes(tmp_path):
    a, b, c = (tmp_path / n for n in ("a.py", "b.py", "c.py"))
    a.write_text("x = 1.0\n")
    b.write_text("x = 1.0\n")
    c.write_text("x = 1.5\n")
    mod = lambda p: types.SimpleNamespace(__file__=str(p))   # noqa: E731
    assert fe_cache.code_digest([mod(a)]) == fe_cache.code_digest([mod(b)])
    assert fe_cache.code_digest([mod(a)]) != fe_cache.code_digest([mod(c)])


def test_a_seat_read_back_is_bit_identical_to_the_seat_computed_afresh(folder, solves):
    fresh = ring.fresh(T, **KW)
    assert solves["n"] == 1
    first = ring(T, **KW)                                   # computed (nothing kept yet) and written
    assert solves["n"] == 2 and len(list(folder.glob("*.json"))) == 1
    ring.cache_clear()                                      # as in a new process
    again = ring(T, **KW)
    assert solves["n"] == 2                                 # read from disk, not solved
    assert _bits(again) == _bits(first) == _bits(fresh)
    assert again == fresh
    for p in folder.glob("*.json"):                         # the memo answers within the process, disk or not
        p.unlink()
    assert ring(T, **KW) is again and solves["n"] == 2


def _torn(p: Path) -> None:
    p.write_bytes(p.read_bytes()[: p.stat().st_size // 2])


def _garbage(p: Path) -> None:
    p.write_bytes(b"\x00\xff not json")


def _wrong_number(p: Path) -> None:                        # valid JSON, its value no longer the one digested
    entry = json.loads(p.read_text())
    entry["value"]["work"][0] *= 2.0
    p.write_text(json.dumps(entry))


def _other_key(p: Path) -> None:                            # another seat's whole entry under this name
    entry = json.loads(p.read_text())
    entry["key"] = "0" * 64
    p.write_text(json.dumps(entry))


@pytest.mark.parametrize("damage", [_torn, _garbage, _wrong_number, _other_key])
def test_a_damaged_entry_is_computed_again_and_rewritten(folder, solves, damage):
    good = ring(T, **KW)
    (path,) = folder.glob("*.json")
    damage(path)
    ring.cache_clear()
    assert ring(T, **KW) == good and solves["n"] == 2      # solved again, the same numbers
    key = ring.key(T, **KW)
    assert path.name == f"{key}.json"
    assert fe_seats.SeatResult.from_value(fe_cache.load(key)) == good


def test_a_folder_that_cannot_be_written_only_loses_the_keeping(tmp_path, monkeypatch, solves):
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    monkeypatch.setenv(fe_cache.ENV, str(blocker))            # its fe-seats folder cannot be made
    ring.cache_clear()
    try:
        assert ring(T, **KW) == ring.fresh(T, **KW)
    finally:
        ring.cache_clear()
    assert fe_cache.store("k" * 64, {"x": 1.0}) is False


def test_the_folder_is_the_variables_else_the_users_cache_outside_the_repository(tmp_path, monkeypatch):
    monkeypatch.setenv(fe_cache.ENV, str(tmp_path))
    assert fe_cache.cache_dir() == tmp_path / "fe-seats"
    monkeypatch.delenv(fe_cache.ENV)
    default = fe_cache.cache_dir().resolve()
    assert ROOT.resolve() not in default.parents and "rvtol" in [part.lower() for part in default.parts]


#: a value of about 40 kB: a write of it is many system calls, so a reader can meet a write half-done
BIG = {"work": [1.0 / 3.0 + k for k in range(2000)]}


def _writer(key: str, rounds: int, start) -> None:
    start.wait()
    for _ in range(rounds):
        fe_cache.store(key, BIG)


@pytest.mark.skipif("fork" not in multiprocessing.get_all_start_methods(), reason="needs the fork start method")
def test_two_processes_writing_one_entry_leave_it_whole_and_a_reader_never_sees_it_torn(folder):
    key = "ab" * 32
    path = folder / f"{key}.json"
    ctx = multiprocessing.get_context("fork")
    start = ctx.Barrier(3)
    procs = [ctx.Process(target=_writer, args=(key, 8, start)) for _ in range(2)]
    for p in procs:
        p.start()
    start.wait()
    reads = 0
    while any(p.is_alive() for p in procs):
        try:
            text = path.read_text()
        except FileNotFoundError:
            continue
        assert json.loads(text)["value"] == BIG                # never torn: one writer's whole entry
        reads += 1
    for p in procs:
        p.join()
        assert p.exitcode == 0
    assert reads > 0
    assert fe_cache.load(key) == BIG
    assert [p.name for p in folder.iterdir()] == [path.name]  # no temporary file left behind
