"""Checkpoints of model evaluations: finished chunks persisted as they complete, reused on resume.

The Monte Carlo design is drawn whole, up front, from the seed, and
:func:`rvtol.mc.evaluate` evaluates it in chunks reassembled by index; models
are row-deterministic.  So a chunk's outputs are a function of the run's
inputs, the evaluation it belongs to and its rows — persisting each chunk as
it completes and loading it back on resume gives a result bit-identical to an
uninterrupted run, whatever was killed when.

A :class:`ChunkStore` lives in one folder.  Every evaluation of a run
(the Monte Carlo first, then each analysis' evaluations, in their
deterministic order) takes the next *call number*; a chunk's key is the call
number, its row range and the SHA-256 of its input rows, so a chunk is
reused only for the very rows it was computed from.  Every chunk of the
Monte Carlo is persisted; of the other evaluations only chunks that took at
least :data:`COSTLY_SECONDS` to compute (an allocation evaluates thousands of
cheap candidate designs: storing them would cost more disk and time than
recomputing them).  The caller (the study
runner) keys the folder itself by the run's inputs (:func:`run_key`): input
file hashes, n, seed, method, rvtol version.

Writes are atomic (a temporary file renamed into place): ``kill -9`` loses at
most the chunks in flight, never leaves a torn one.
"""
from __future__ import annotations

import contextlib
import hashlib
import json
import os
import signal
from pathlib import Path

import numpy as np

#: the version of the checkpoint layout (part of the run key)
FORMAT = "rvtol-checkpoint/1"
#: compute time above which a chunk of an analysis' evaluation is persisted (s)
COSTLY_SECONDS = 1.0


#: a stop signal that arrived while a checkpoint file was being written (:func:`signals_held`): ``depth`` of the
#: held sections, the ``pending`` signal.  :func:`rvtol.runguard.stopping_on_signals`' handler reads it.
HELD = {"depth": 0, "pending": None}


@contextlib.contextmanager
def signals_held():
    """Within the block, a SIGTERM/SIGINT that stops the run waits for the block's end, then stops it: a chunk file is
    written whole.  (Raised inside :func:`numpy.savez`, the stop left a ZIP member half written, and closing the
    archive then failed with its own error: the run ended as an internal error instead of stopped, exit 3 for 143.)"""
    HELD["depth"] += 1
    try:
        yield
    finally:
        HELD["depth"] -= 1
        if HELD["depth"] == 0 and HELD["pending"] is not None:
            signum, HELD["pending"] = HELD["pending"], None
            signal.raise_signal(signum)       # the handler runs now, outside the block, and stops the run


def run_key(material: dict) -> str:
    """A short stable hash of the run's identity (JSON of ``material`` with sorted keys)."""
    blob = json.dumps({"format": FORMAT, **material}, sort_keys=True, default=str).encode()
    return hashlib.sha256(blob).hexdigest()[:24]


class ChunkStore:
    """Persisted chunk results of one run in ``folder`` (see the module docstring)."""

    def __init__(self, folder: str | Path):
        self.folder = Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        self._calls = 0
        self._present = {int(p.name[1:6]) for p in self.folder.glob("c*.npz")}  # calls with persisted chunks
        self.reused = 0      # chunks loaded instead of evaluated
        self.reused_rows = 0
        self.saved = 0

    def begin(self, persist: str = "costly") -> "ChunkCall":
        """The store of the next evaluation of this run: ``persist`` "all" chunks or the "costly" ones."""
        if persist not in ("all", "costly"):
            raise ValueError(f"persist must be 'all' or 'costly', got {persist!r}")
        self._calls += 1
        return ChunkCall(self, self._calls, persist == "all")

    def count(self) -> int:
        """How many finished chunks the folder holds."""
        return sum(1 for _ in self.folder.glob("c*.npz"))

    def clear(self) -> None:
        for p in self.folder.glob("c*.npz*"):
            p.unlink(missing_ok=True)


class ChunkCall:
    """The chunks of one evaluation (one ``evaluate`` call) of a run."""

    def __init__(self, store: ChunkStore, number: int, persist_all: bool = True):
        self.store = store
        self.number = number
        self.persist_all = persist_all

    def _path(self, a: int, b: int, X: np.ndarray) -> Path:
        x = np.ascontiguousarray(X, dtype=float)
        digest = hashlib.sha256(x.tobytes() + repr(x.shape).encode()).hexdigest()[:20]
        return self.store.folder / f"c{self.number:05d}-{a}-{b}-{digest}.npz"

    def get(self, a: int, b: int, X: np.ndarray):
        """``(Y, status)`` of rows ``a:b`` (inputs ``X``) if persisted, else None."""
        if self.number not in self.store._present:  # nothing of this evaluation was kept: no need to hash
            return None
        p = self._path(a, b, X)
        if not p.exists():
            return None
        try:
            with np.load(p) as z:
                Y, status = z["Y"], z["status"]
        except (OSError, ValueError, KeyError, EOFError):  # unreadable: evaluate again
            return None
        if Y.shape[0] != b - a or status.shape != (b - a,):
            return None
        self.store.reused += 1
        self.store.reused_rows += b - a
        return Y, status

    def put(self, a: int, b: int, X: np.ndarray, Y: np.ndarray, status: np.ndarray,
            seconds: float | None = None) -> None:
        """Persist rows ``a:b`` (unless the call keeps only costly chunks and this one took < COSTLY_SECONDS)."""
        if not self.persist_all and (seconds is None or seconds < COSTLY_SECONDS):
            return
        p = self._path(a, b, X)
        tmp = p.with_name(p.name + f".{os.getpid()}.tmp")
        with signals_held():
            with open(tmp, "wb") as f:
                np.savez(f, Y=np.asarray(Y, dtype=float), status=np.asarray(status, dtype=np.int16))
            os.replace(tmp, p)
            self.store.saved += 1
