"""Exception hierarchy of rvtol.

Every problem with what a user gave us (a file, a key, a value) is an
:class:`InputError`; the CLI prints it as one line ``rvtol: error: FILE: KEY:
reason`` and exits with code 2.  Solver failures on individual Monte Carlo
samples are *not* exceptions: models report them per sample through status
codes (see :mod:`rvtol.model`).
"""
from __future__ import annotations

import difflib
import re
from typing import Iterable


#: what a suggestion may be: a name (at most 64 characters, no character a line of a configuration or credential
#: file is made of — ``=``, ``:``, ``$``, ... —, no control character, single spaces)
_WORD = r"[^\s=:$;{}<>|!?~&@#`\\\x00-\x1f\x7f-\x9f]+"
_SUGGESTIBLE = re.compile(rf"(?=.{{1,64}}$){_WORD}(?: {_WORD})*")


def did_you_mean(word: str, candidates: Iterable[str], cutoff: float = 0.6) -> str:
    """`` (did you mean 'x'?)`` for the closest of ``candidates`` to a misspelt ``word``, else ``""``.

    Closeness is :mod:`difflib`'s ratio (case-insensitive) of at least ``cutoff``.  Only a candidate that reads as a
    name is suggested (:data:`_SUGGESTIBLE`): candidates can come from a file a study names (a measured file's
    header), whose first line may hold anything — a hint never echoes ``password=…`` or a line of /etc/shadow.

    >>> did_you_mean("tolerence", ["sigma", "tolerance", "mean"])
    " (did you mean 'tolerance'?)"
    >>> did_you_mean("password", ["password=hunter2"])
    ''
    """
    cands = [c for c in dict.fromkeys(candidates) if isinstance(c, str) and c != word and _SUGGESTIBLE.fullmatch(c)]
    by_lower = {c.lower(): c for c in cands}
    hit = difflib.get_close_matches(str(word).lower(), list(by_lower), n=1, cutoff=cutoff)
    return f" (did you mean {by_lower[hit[0]]!r}?)" if hit else ""


class RvtolError(Exception):
    """Base class of every error rvtol raises on purpose."""


class InputError(RvtolError, ValueError):
    """Bad user input: names the file and the key it came from, and why.

    ``file`` and ``key`` may be filled in later by the code that knows them
    (:meth:`located`), so low-level validators only need to know the reason.
    """

    def __init__(self, reason: str, *, file: str | None = None, key: str | None = None):
        super().__init__(reason)
        self.reason = reason
        self.file = file
        self.key = key

    def located(self, *, file: str | None = None, key: str | None = None) -> "InputError":
        """Fill in a missing file and/or prefix the key with an outer key."""
        if file is not None and self.file is None:
            self.file = file
        if key is not None:
            self.key = key if not self.key else f"{key}.{self.key}"
        return self

    def __str__(self) -> str:
        return f"{self.file or '<input>'}: {self.key or '-'}: {self.reason}"


class SpecError(InputError):
    """A tolerance specification, design, requirement or study file is invalid."""


class UnitError(InputError):
    """An unknown unit, or a unit of the wrong dimension."""


class ModelCodeError(RvtolError):
    """A user's model code (a ``kind = "python"`` factory or its model) raised or called ``sys.exit``: not bad
    input (the study is fine) and not an rvtol bug — the CLI prints the message and exits 3."""

    def __init__(self, reason: str, *, file: str | None = None, key: str | None = None):
        super().__init__(reason)
        self.reason, self.file, self.key = reason, file, key

    def __reduce__(self):   # crosses process boundaries (worker → main) intact
        return (_model_code_error, (self.reason, self.file, self.key))

    def __str__(self) -> str:
        return f"{self.file or '<input>'}: {self.key or '-'}: {self.reason}"


def _model_code_error(reason, file, key):
    return ModelCodeError(reason, file=file, key=key)


def describe_exception(exc: BaseException) -> str:
    """``raised ValueError: boom`` / ``called sys.exit(0)`` — what a piece of user code did."""
    if isinstance(exc, SystemExit):
        return f"called sys.exit({exc.code!r})"
    msg = str(exc).strip().splitlines()[0][:300] if str(exc).strip() else ""
    return f"raised {type(exc).__name__}" + (f": {msg}" if msg else "")


class ModelError(RvtolError):
    """A model was used wrongly by code (wrong array shape, unknown output)."""


class SolverError(RvtolError, RuntimeError):
    """A numerical solver failed in a way that is not a per-sample status."""
