"""Typed access to a TOML table with errors that name the file and the key.

Every loader in rvtol reads its table through :class:`Params`, so a typo, a
wrong type, a NaN or an out-of-range number always ends as one line
``FILE: KEY: reason``, and keys nobody read are reported by :meth:`finish`
(typos do not pass silently).  A misspelt key is blamed itself, with the key
it resembles: when a loader finds a key missing (``tolerance`` of a normal
factor) while the table holds an unread key close to one the loader read or
looked for (``tolerence``), the error names ``tolerence`` and suggests
``tolerance`` — not the missing ``sigma`` a loader might ask for next.
"""
from __future__ import annotations

import contextlib
import hashlib
import math
import os
import stat
import tomllib
from pathlib import Path
from typing import Any, Iterable

from . import units
from .errors import InputError, SpecError, did_you_mean
from .safetext import control_character

_MISSING = object()

#: how close (difflib ratio) an unknown key must be to a known one to be called its misspelling
KEY_CUTOFF = 0.75


#: the largest input file rvtol reads (bytes); ``RVTOL_MAX_INPUT_MB`` raises or lowers it
MAX_INPUT_BYTES = 256 * 2**20


def max_input_bytes() -> int:
    v = os.environ.get("RVTOL_MAX_INPUT_MB")
    try:
        return int(float(v) * 2**20) if v else MAX_INPUT_BYTES
    except ValueError:
        return MAX_INPUT_BYTES


def check_input_file(path: str | Path, expected: str = "a file") -> int:
    """The size of an input file that may be read: a regular file (not a folder, FIFO or device such as
    /dev/zero — a FIFO would hang, a device never ends) no larger than :func:`max_input_bytes`."""
    p = Path(path)
    try:
        st = p.stat()
    except FileNotFoundError:
        raise SpecError("file not found", file=str(path), key="-") from None
    except OSError as exc:
        raise SpecError(f"cannot read file ({exc.strerror})", file=str(path), key="-") from None
    if stat.S_ISDIR(st.st_mode):
        raise SpecError(f"is a directory, expected {expected}", file=str(path), key="-")
    if not stat.S_ISREG(st.st_mode):
        kind = ("a FIFO (named pipe)" if stat.S_ISFIFO(st.st_mode) else "a device" if
                stat.S_ISCHR(st.st_mode) or stat.S_ISBLK(st.st_mode) else "a socket" if stat.S_ISSOCK(st.st_mode)
                else "not a regular file")
        raise SpecError(f"is {kind}, expected {expected} (rvtol reads only regular files)", file=str(path), key="-")
    cap = max_input_bytes()
    if st.st_size > cap:
        raise SpecError(f"is {st.st_size / 2**20:.0f} MB, more than rvtol reads ({cap / 2**20:.0f} MB; set "
                        "RVTOL_MAX_INPUT_MB to allow more)", file=str(path), key="-")
    return st.st_size


#: the sets :func:`recording_reads` fills (nested recordings each see every read)
_RECORDINGS: list[set[Path]] = []


@contextlib.contextmanager
def recording_reads():
    """Within the block, every input file rvtol reads (:func:`read_bytes`, :func:`note_read`) is added, as an
    absolute path, to the set the block receives: the inputs of a run, which nothing the run writes may replace."""
    seen: set[Path] = set()
    _RECORDINGS.append(seen)
    try:
        yield seen
    finally:
        _RECORDINGS.remove(seen)


def note_read(path: str | Path) -> None:
    """Record ``path`` as an input read (:func:`recording_reads`): for files read other than by :func:`read_bytes`
    (a Python model's module, imported)."""
    for seen in _RECORDINGS:
        seen.add(Path(path).absolute())


def read_bytes(path: str | Path, expected: str = "a file") -> bytes:
    """The bytes of an input file (:func:`check_input_file` first); one-line errors (:class:`SpecError`, key
    ``-``) naming the file."""
    p = Path(path)
    check_input_file(p, expected)
    note_read(p)
    try:
        with open(p, "rb") as fh:
            return fh.read(max_input_bytes() + 1)
    except FileNotFoundError:
        raise SpecError("file not found", file=str(path), key="-") from None
    except IsADirectoryError:
        raise SpecError(f"is a directory, expected {expected}", file=str(path), key="-") from None
    except OSError as exc:
        raise SpecError(f"cannot read file ({exc.strerror})", file=str(path), key="-") from None


def decode_text(raw: bytes, file: str, fallback: str | None = None) -> str:
    """Text of an input file: UTF-8 (a byte-order mark accepted), UTF-16 with its byte-order mark (Excel's
    "Unicode text"), else ``fallback`` (e.g. cp1252); a file of NUL bytes or of UTF-16 without a mark is
    not taken for text."""
    if raw[:2] in (b"\xff\xfe", b"\xfe\xff"):
        try:
            return raw.decode("utf-16")
        except UnicodeDecodeError:
            raise SpecError("not readable UTF-16 text (it starts with a UTF-16 byte-order mark); save the file "
                            "as UTF-8", file=file, key="-") from None
    if b"\x00" in raw[:4096]:
        hint = (" — it looks like UTF-16 without a byte-order mark: save it as UTF-8"
                if raw[1:4096:2].count(0) > len(raw[1:4096:2]) // 2 or raw[0:4096:2].count(0) > len(raw[0:4096:2]) // 2
                else "")
        raise SpecError(f"not a text file (it holds NUL bytes){hint}", file=file, key="-")
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        if fallback:
            try:
                return raw.decode(fallback)
            except UnicodeDecodeError:
                pass
        raise SpecError(f"not UTF-8 text (byte {exc.start}: {raw[exc.start:exc.start + 1]!r}); save the file "
                        "as UTF-8", file=file, key="-") from None


def read_text(path: str | Path, expected: str = "a text file") -> tuple[str, str]:
    """``(text, sha256)`` of a UTF-8 input file (a byte-order mark, as some Windows editors write, is accepted;
    UTF-16 with its mark too)."""
    raw = read_bytes(path, expected)
    return decode_text(raw, str(path)), hashlib.sha256(raw).hexdigest()


def read_toml(path: str | Path) -> tuple[dict, str]:
    """Read a TOML file; return ``(table, sha256)``. Raises :class:`SpecError`."""
    text, sha = read_text(path, "a TOML file")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(f"invalid TOML ({exc})", file=str(path), key="-") from None
    except RecursionError:
        raise SpecError(TOO_DEEP, file=str(path), key="-") from None
    return data, sha


#: the reason of a file whose arrays or tables nest deeper than a parser can follow
TOO_DEEP = "too deeply nested (arrays or tables within each other, deeper than rvtol's parser follows)"


class Params:
    """A read-tracking view of one TOML table.

    >>> p = Params({"n": 3, "name": "x"}, file="f.toml", key="study")
    >>> p.int("n", min=1)
    3
    >>> p.str("name")
    'x'
    >>> p.finish()
    """

    def __init__(self, data: dict | None, *, file: str | None = None, key: str = ""):
        if data is None:
            data = {}
        if not isinstance(data, dict):
            raise SpecError(f"expected a table, got {_typename(data)}", file=file, key=key or "-")
        self.data = data
        self.file = file
        self.key = key
        self._read: set[str] = set()
        self._probed: set[str] = set()  # names looked for with ``name in params`` (optional alternatives)

    # -- helpers -----------------------------------------------------------
    def path(self, name: str) -> str:
        return f"{self.key}.{name}" if self.key else name

    def error(self, name: str | None, reason: str) -> SpecError:
        """An error on key ``name`` of this table; an absent ``name`` next to a misspelt key blames the typo."""
        if name and name.isidentifier() and name not in self.data:
            typo = self._typo(extra=(name,))
            if typo is not None:
                return typo
        return SpecError(reason, file=self.file, key=self.path(name) if name else (self.key or "-"))

    def _vocabulary(self, allow: Iterable[str] = ()) -> list[str]:
        """Keys this table is known to take: read, looked for, or allowed."""
        return sorted(self._read | self._probed | set(allow))

    def _typo(self, extra: Iterable[str] = (), allow: Iterable[str] = ()) -> SpecError | None:
        """The error for an unread key that looks like a known key missing from the table, if any."""
        vocab = [k for k in [*self._vocabulary(allow), *extra] if k not in self.data]
        for k in self.data:
            if k in self._read or k in self._probed or k in set(allow):
                continue
            hint = did_you_mean(k, vocab, cutoff=KEY_CUTOFF)
            if hint:
                return SpecError(f"unknown key{hint}", file=self.file, key=self.path(k))
        return None

    def __contains__(self, name: str) -> bool:
        self._probed.add(name)
        return name in self.data

    def keys(self):
        return self.data.keys()

    def raw(self, name: str, default: Any = _MISSING) -> Any:
        self._read.add(name)
        if name not in self.data:
            if default is _MISSING:
                raise self.error(name, "missing required key")
            return default
        return self.data[name]

    def sub(self, name: str, default: Any = _MISSING) -> "Params":
        """A nested table as Params (``{}`` if absent and a default is given)."""
        v = self.raw(name, default)
        if v is None:
            v = {}
        if not isinstance(v, dict):
            raise self.error(name, f"expected a table, got {_typename(v)}")
        return Params(v, file=self.file, key=self.path(name))

    def tables(self, name: str) -> list["Params"]:
        """An array of tables (``[[name]]``) as a list of Params."""
        v = self.raw(name, [])
        if isinstance(v, dict):
            v = [v]
        if not isinstance(v, list) or not all(isinstance(t, dict) for t in v):
            raise self.error(name, "expected an array of tables")
        return [Params(t, file=self.file, key=f"{self.path(name)}[{i}]") for i, t in enumerate(v)]

    def finish(self, allow: Iterable[str] = ()) -> None:
        """Raise if the table holds keys nobody read (usually typos)."""
        extra = sorted(set(self.data) - self._read - set(allow))
        if extra:
            typo = self._typo(allow=allow)
            if typo is not None:
                raise typo
            known = [k for k in self._vocabulary(allow) if k not in extra]
            raise SpecError(f"unknown key (known here: {', '.join(known) or 'none'})", file=self.file,
                            key=self.path(extra[0]))

    # -- typed getters -----------------------------------------------------
    def str(self, name: str, default: Any = _MISSING, *, choices: Iterable[str] | None = None,
            single_line: bool = False) -> str:
        """A string: never with a control character (:mod:`rvtol.safetext`: no file rvtol writes could hold it
        safely); ``single_line`` (a name: one line, one cell), nor a line break or a tab."""
        v = self.raw(name, default)
        if v is default and default is not _MISSING:
            return v
        if not isinstance(v, str):
            raise self.error(name, f"expected a string, got {_typename(v)}")
        bad = control_character(v, name=single_line)
        if bad:
            raise self.error(name, f"{bad}: {'a name' if single_line else 'text in a study'} may hold none")
        if choices is not None:
            ch = list(choices)
            if v not in ch:
                hint = did_you_mean(v, ch).strip(" ()")
                raise self.error(name, f"unknown value {v!r} ({hint + '; ' if hint else ''}"
                                       f"expected one of: {', '.join(ch)})")
        return v

    def bool(self, name: str, default: Any = _MISSING) -> bool:
        v = self.raw(name, default)
        if v is default and default is not _MISSING:
            return v
        if not isinstance(v, bool):
            raise self.error(name, f"expected true or false, got {_typename(v)}")
        return v

    def float(self, name: str, default: Any = _MISSING, *, min: float | None = None,
              max: float | None = None, positive: bool = False, nonnegative: bool = False) -> float:
        v = self.raw(name, default)
        if v is default and default is not _MISSING:
            return v
        return check_number(v, self.error, name, min=min, max=max, positive=positive,
                            nonnegative=nonnegative)

    def int(self, name: str, default: Any = _MISSING, *, min: int | None = None,
            max: int | None = None) -> int:
        v = self.raw(name, default)
        if v is default and default is not _MISSING:
            return v
        if isinstance(v, bool) or not isinstance(v, int):
            raise self.error(name, f"expected an integer, got {_typename(v)}")
        if min is not None and v < min:
            raise self.error(name, f"must be >= {min}, got {v}")
        if max is not None and v > max:
            raise self.error(name, f"must be <= {max}, got {v}")
        return v

    def floats(self, name: str, default: Any = _MISSING, *, length: int | None = None,
               min_length: int = 0, **checks) -> list[float]:
        v = self.raw(name, default)
        if v is default and default is not _MISSING:
            return v
        if not isinstance(v, list):
            raise self.error(name, f"expected an array of numbers, got {_typename(v)}")
        if length is not None and len(v) != length:
            raise self.error(name, f"expected {length} numbers, got {len(v)}")
        if len(v) < min_length:
            raise self.error(name, f"expected at least {min_length} numbers, got {len(v)}")
        return [check_number(x, self.error, f"{name}[{i}]", **checks) for i, x in enumerate(v)]

    def strs(self, name: str, default: Any = _MISSING, *, min_length: int = 0) -> list[str]:
        v = self.raw(name, default)
        if v is default and default is not _MISSING:
            return v
        if not isinstance(v, list) or not all(isinstance(x, str) for x in v):
            raise self.error(name, "expected an array of strings")
        if len(v) < min_length:
            raise self.error(name, f"expected at least {min_length} strings, got {len(v)}")
        return list(v)

    def unit(self, name: str, default: Any = _MISSING, *, dimension: str | tuple[str, ...] | None = None) -> str:
        v = self.str(name, default)
        return None if v is None else self.canonical_unit(name, v, dimension=dimension)

    def canonical_unit(self, name: str, text: str, *, dimension: str | tuple[str, ...] | None = None) -> str:
        """The unit ``text`` of the key ``name`` (read already, e.g. by a declared schema) in its canonical
        spelling, of ``dimension`` if given; or the located error."""
        return located_unit(text, self.error, name, dimension)

    def quantity(self, name: str, unit: str, default: Any = _MISSING, **checks) -> float:
        """A number in base units, written as ``x`` (in ``unit``) or ``{value = x, unit = "..."}``.

        ``unit`` is the unit assumed for a bare number; it also fixes the
        dimension a ``{value, unit}`` table must have.  Checks (``positive``,
        ``min``...) apply to the value as written.
        """
        v = self.raw(name, default)
        if v is default and default is not _MISSING:
            return v
        u = unit
        if isinstance(v, dict):
            sub = Params(v, file=self.file, key=self.path(name))
            u = sub.unit("unit", unit, dimension=units.dimension(unit))
            v = sub.raw("value")
            sub.finish()
        x = check_number(v, self.error, name, **checks)
        return float(units.to_base(x, u))

    def path_value(self, name: str, base_dir: Path, default: Any = _MISSING, *, existing: bool = False) -> Path | None:
        """A file path, relative to ``base_dir`` unless absolute; ``existing``: a file that is not there is an error
        at this key (the study's key names what the missing file was to be)."""
        v = self.str(name, default)
        if v is None:
            return None
        p = Path(v)
        p = p if p.is_absolute() else (base_dir / p)
        if existing and not p.exists():      # a directory or a device: the reader says what it is
            raise self.error(name, f"file not found: {p}")
        return p


def located_unit(text: str, error, key: str, dimension: str | tuple[str, ...] | None = None) -> str:
    """The unit ``text`` in its canonical spelling, of ``dimension`` if given; or ``error(key, reason)`` (a table's
    located error) raised."""
    try:
        u = units.canonical(text, dimension)
        if dimension is not None:
            units.require_dimension(u, dimension)
    except InputError as exc:
        raise error(key, exc.reason) from None
    return u


def check_number(v: Any, error, name: str, *, min: float | None = None, max: float | None = None,
                 positive: bool = False, nonnegative: bool = False) -> float:
    """Validate one number (int or float, finite, in range); return it as float."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise error(name, f"expected a number, got {_typename(v)}")
    x = float(v)
    if not math.isfinite(x):
        raise error(name, f"must be a finite number, got {v}")
    if positive and not x > 0:
        raise error(name, f"must be > 0, got {v}")
    if nonnegative and x < 0:
        raise error(name, f"must be >= 0, got {v}")
    if min is not None and x < min:
        raise error(name, f"must be >= {min}, got {v}")
    if max is not None and x > max:
        raise error(name, f"must be <= {max}, got {v}")
    return x


def _typename(v: Any) -> str:
    if isinstance(v, bool):
        return "a boolean"
    if isinstance(v, dict):
        return "a table"
    if isinstance(v, list):
        return "an array"
    if isinstance(v, str):
        return f"the string {v!r}"
    return type(v).__name__
