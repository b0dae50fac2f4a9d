"""The finite-element seats (:mod:`.fe_seats`) kept on disk by the content of their inputs, across processes and runs.

A seat's result is a pure function of its arguments (geometry, loads, material, mesh settings) and of the code
that computes it, so it is stored under a **key** that hashes exactly those: the SHA-256 of the function's name,
its arguments bound to its signature with the defaults filled in (every number in ``repr``, which reads back the
same float: ``thickness=10.0`` given or left to its default is one key, ``10.0`` and its neighbour
``10.000000000000002`` are two), the source bytes of the modules the result depends on (:func:`code_digest`: any
edit to them changes every key) and the installed versions of NumPy, SciPy and scikit-fem, which mesh and solve.

Entries live in ``$RVTOL_CACHE_DIR/fe-seats/`` when that variable is set, else in the platform's per-user cache
folder (``platformdirs.user_cache_dir("rvtol")``: ``~/.cache/rvtol`` on Linux), never beside the repository or a
report.  Each is one JSON file: the key, the value (floats as ``repr``, read back bit-identical) and the SHA-256 of
the value's text.  It is written to a temporary file in the same folder and renamed into place (``os.replace``, an
atomic rename), so a process reading it — a pool or Dask worker, a pytest-xdist worker — sees the whole entry of one
writer or none.  An entry that cannot be read, does not parse, belongs to another key or fails its digest is
computed again and rewritten; a folder that cannot be written only means the result is not kept.  Entries are a few
hundred bytes; deleting the folder is always safe.

:func:`content_cached` adds the per-process memo (``functools.lru_cache``) in front, so one process computes or
reads each seat at most once.
"""
from __future__ import annotations

import functools
import hashlib
import inspect
import json
import numbers
import os
import tempfile
from importlib import metadata
from pathlib import Path

#: the entries' layout; part of every key
FORMAT = "rvtol-fe-cache/1"
#: the environment variable naming the cache folder
ENV = "RVTOL_CACHE_DIR"
#: the libraries whose versions enter every key (they mesh, assemble and factorise)
LIBRARIES = ("numpy", "scipy", "scikit-fem")


def cache_dir() -> Path:
    """The folder of the entries: ``$RVTOL_CACHE_DIR/fe-seats``, else the per-user cache folder's ``fe-seats``."""
    root = os.environ.get(ENV)
    if not root:
        import platformdirs

        root = platformdirs.user_cache_dir("rvtol", appauthor=False)
    return Path(root) / "fe-seats"


def code_digest(modules) -> str:
    """SHA-256 of the source files of ``modules`` (in the order given) and of :data:`LIBRARIES`' versions."""
    h = hashlib.sha256(FORMAT.encode())
    for m in modules:
        h.update(Path(m.__file__).read_bytes())
    for name in LIBRARIES:
        try:
            v = metadata.version(name)
        except metadata.PackageNotFoundError:
            v = "?"
        h.update(f"{name}={v}".encode())
    return h.hexdigest()


def _plain(name: str, value):
    """An argument as JSON: an integer as int, another real number as float; anything else is refused."""
    if isinstance(value, numbers.Integral) and not isinstance(value, bool):
        return int(value)
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        return float(value)
    raise TypeError(f"a cached finite-element seat takes numbers only; {name} = {value!r}")


def entry_key(fn, args: tuple, kwargs: dict, code: str) -> str:
    """The key of ``fn(*args, **kwargs)`` under code digest ``code`` (module doc)."""
    bound = inspect.signature(fn).bind(*args, **kwargs)
    bound.apply_defaults()
    arguments = {k: _plain(k, v) for k, v in bound.arguments.items()}
    blob = json.dumps({"format": FORMAT, "function": f"{fn.__module__}.{fn.__qualname__}", "arguments": arguments,
                       "code": code}, sort_keys=True, allow_nan=True)
    return hashlib.sha256(blob.encode()).hexdigest()


def _value_digest(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()


def load(key: str):
    """The value stored under ``key``, or None when there is none or it is unreadable, torn or not this key's."""
    try:
        entry = json.loads((cache_dir() / f"{key}.json").read_text(encoding="utf-8"))
        text = json.dumps(entry["value"], sort_keys=True)
        if entry["key"] != key or entry["digest"] != _value_digest(text):
            return None
        return entry["value"]
    except (OSError, ValueError, KeyError, TypeError):
        return None


def store(key: str, value) -> bool:
    """Write ``value`` (JSON: dicts, lists, floats) under ``key`` atomically; False if the folder cannot be written."""
    text = json.dumps(value, sort_keys=True)
    entry = json.dumps({"key": key, "digest": _value_digest(text), "value": value}, sort_keys=True)
    folder = cache_dir()
    tmp = None
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=f".{key[:16]}.", suffix=".tmp")
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(entry)
        os.replace(tmp, folder / f"{key}.json")
        return True
    except OSError:
        if tmp is not None:
            Path(tmp).unlink(missing_ok=True)
        return False


def content_cached(*, to_value, from_value, modules, maxsize: int = 16):
    """Decorator: ``fn``'s results kept on disk by :func:`entry_key` (``to_value`` / ``from_value`` convert a result
    to JSON and back exactly; ``modules``: those whose source the result depends on, :func:`code_digest`) behind a
    per-process ``functools.lru_cache`` (``cache_info``, ``cache_clear``; ``fresh``: the computation itself; ``key``:
    the entry's key of a call)."""

    def decorate(fn):
        code = functools.lru_cache(maxsize=1)(lambda: code_digest(modules))

        @functools.lru_cache(maxsize=maxsize)
        @functools.wraps(fn)
        def cached(*args, **kwargs):
            key = entry_key(fn, args, kwargs, code())
            value = load(key)
            if value is not None:
                try:
                    return from_value(value)
                except (KeyError, TypeError, ValueError):
                    pass                    # an entry of another shape: computed again below
            result = fn(*args, **kwargs)
            store(key, to_value(result))
            return result

        cached.fresh = fn
        cached.key = lambda *args, **kwargs: entry_key(fn, args, kwargs, code())
        return cached

    return decorate


__all__ = ["FORMAT", "ENV", "cache_dir", "code_digest", "entry_key", "load", "store", "content_cached"]
