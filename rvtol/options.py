"""Declarative options: what a study's ``[[analysis]]`` table may hold, as one dataclass per kind.

An analysis declares its keys as dataclass fields; each field's type, default and constraints
(the role scikit-learn's parameter constraints play) are enough to read and check the table —
no hand-written parsing — and to list every key with its meaning (``rvtol kinds KIND``)::

    @dataclass
    class Options(SensitivityOptions):
        n: int = option(1024, "base samples N (a power of 2: the Sobol' sequence's balance)",
                        min=2, power_of_two=True)
        second_order: bool = option(True, "also the second-order indices S2")

Types understood: ``int``, ``float``, ``bool``, ``str``, ``Literal[...]`` (one of the values),
``list[str]``, ``list[float]``, ``list[int]``, ``dict[str, float]`` (a table of numbers),
``dict[str, str]`` (a table of strings), ``dict`` (a table, read as it is), ``Path`` (a file, relative
to the study's folder), another options dataclass (a sub-table ``[analysis.<key>]`` with keys of its
own; absent or ``true``: every default — give the class itself as the default; ``false``: None when
typed ``| None``), ``list[<options dataclass>]``
(an array of tables ``[[analysis.<key>]]``), ``Params`` (a sub-table handed on unread: the code that
takes it reads and finishes it; ``list[Params]``: an array of such tables), and any of them
``| None`` (absent → the default).  Rules:

====================  =====================================================================
``choices``           the values a string may take (or type it ``Literal[...]``)
``min``, ``max``      bounds of a number (inclusive)
``positive``          a number > 0; ``nonnegative``: >= 0
``power_of_two``      an integer power of 2; ``even``: an even integer
``zero_or_min``       0 (meaning "all"/"off") or at least this value
``min_length``        a list with at least this many entries
``unit``              a quantity: a bare number in this unit or ``{value = x, unit = "..."}``,
                      held in base units (mm, N, rad, s); typed ``float | str``, a string is
                      left as written (a name the loader resolves)
``names``             a list (or a string) whose entries name the study's ``"outputs"``,
                      ``"factors"``, ``"requirements"`` or the model's ``"stages"``;
                      ``"all"`` stands for every output when ``all_ok``
``key``               the TOML key, when it is not a Python identifier
====================  =====================================================================

Checks that involve several keys or the study (a default that depends on another key, a count
that must exceed another) go in the options class' ``complete(self, study, error)`` method,
called after every key is read: ``error(key, reason)`` returns the located one-line error to
raise.
"""
from __future__ import annotations

import dataclasses
import types
import typing
from dataclasses import MISSING, dataclass, field, fields
from pathlib import Path
from typing import Any, Literal

from .errors import did_you_mean

#: the default of an option a study must give
REQUIRED = MISSING

_RULES = ("choices", "min", "max", "positive", "nonnegative", "power_of_two", "even", "zero_or_min", "min_length",
          "unit", "names", "all_ok", "key", "single_line")


@dataclass(frozen=True)
class Rule:
    """The meaning and constraints of one option (a field's metadata)."""

    help: str
    choices: tuple | None = None
    min: float | None = None
    max: float | None = None
    positive: bool = False
    nonnegative: bool = False
    power_of_two: bool = False
    even: bool = False
    zero_or_min: float | None = None
    min_length: int = 0
    unit: str | None = None
    names: str | None = None
    all_ok: bool = False
    key: str | None = None
    single_line: bool = False

    def constraint(self) -> str:
        """The constraints in words, for ``rvtol kinds``."""
        out = []
        if self.choices:
            out.append("one of " + ", ".join(map(repr, self.choices)))
        if self.positive:
            out.append("> 0")
        if self.nonnegative:
            out.append(">= 0")
        if self.zero_or_min is not None:
            out.append(f"0 or >= {self.zero_or_min:g}")
        if self.min is not None:
            out.append(f">= {self.min:g}")
        if self.max is not None:
            out.append(f"<= {self.max:g}")
        if self.power_of_two:
            out.append("a power of 2")
        if self.even:
            out.append("even")
        if self.min_length:
            out.append(f"at least {self.min_length}")
        if self.unit:
            out.append(f"in {self.unit} (or {{value, unit}})")
        if self.names:
            out.append(f"names of the study's {self.names}" + (' or "all"' if self.all_ok else ""))
        if self.single_line:
            out.append("one line")
        return ", ".join(out)


def option(default: Any = REQUIRED, help: str = "", **rules) -> Any:
    """A declared option: its default (:data:`REQUIRED` if the study must give it), meaning and rules."""
    bad = set(rules) - set(_RULES)
    if bad:
        raise TypeError(f"unknown option rule(s): {', '.join(sorted(bad))}")
    if "choices" in rules:
        rules["choices"] = tuple(rules["choices"])
    meta = {"rvtol": Rule(help, **rules)}
    if isinstance(default, type) and dataclasses.is_dataclass(default):    # a sub-table: every default
        return field(default_factory=default, metadata=meta, kw_only=True)
    if isinstance(default, (list, dict)):
        return field(default_factory=lambda d=default: type(d)(d), metadata=meta, kw_only=True)
    return field(default=default, metadata=meta, kw_only=True)   # keyword-only: a required option may follow others


@dataclass
class Option:
    """One option as ``rvtol kinds`` lists it."""

    key: str
    type: str
    default: Any
    required: bool
    help: str
    constraint: str


def rule_of(f: dataclasses.Field) -> Rule:
    return f.metadata.get("rvtol") or Rule("")


def key_of(f: dataclasses.Field) -> str:
    return rule_of(f).key or f.name


def describe(cls, prefix: str = "") -> list[Option]:
    """Every option of an options dataclass: key, type, default, meaning and constraints (the keys of a
    sub-table as ``table.key``, of an array of tables as ``table[].key``)."""
    hints = typing.get_type_hints(cls)
    out = []
    for f in fields(cls):
        if not f.init:
            continue
        r = rule_of(f)
        if f.default is not MISSING:
            default, required = f.default, False
        elif f.default_factory is not MISSING:
            default, required = f.default_factory(), False
        else:
            default, required = None, True
        tp = hints[f.name]
        nested = _nested(tp)
        if nested is not None:
            default = {} if dataclasses.is_dataclass(default) else default      # a sub-table: its keys' defaults
        out.append(Option(prefix + key_of(f), _type_name(tp), default, required, r.help, r.constraint()))
        if nested is not None:
            sub, many = nested
            out += describe(sub, f"{prefix}{key_of(f)}{'[]' if many else ''}.")
    return out


def _nested(tp) -> tuple[type, bool] | None:
    """``(options class, is an array of tables)`` of a sub-table option, else None."""
    _, tp = _unoptional(tp)
    if dataclasses.is_dataclass(tp):
        return tp, False
    if typing.get_origin(tp) is list:
        (item,) = typing.get_args(tp) or (Any,)
        if dataclasses.is_dataclass(item):
            return item, True
    return None


def read_options(cls, params, study=None):
    """An instance of the options dataclass ``cls`` read from ``params`` (:class:`rvtol.params.Params`).

    Every field is read and checked; an absent optional key takes its default; the class'
    ``complete(study, error)`` (if any) then fills study-dependent defaults and checks
    relations between keys.  Raises the one-line :class:`rvtol.errors.SpecError` of the
    first bad key.  Keys the table holds but the class does not declare are left for the
    caller's ``params.finish()`` (which names them as typos).
    """
    hints = typing.get_type_hints(cls)
    values = {}
    for f in fields(cls):
        if not f.init:
            continue
        key, r = key_of(f), rule_of(f)
        if f.default is not MISSING:
            default = f.default
        elif f.default_factory is not MISSING:
            default = f.default_factory()
        else:
            default = MISSING
        values[f.name] = _read(params, key, hints[f.name], default, r, study)
    obj = cls(**values)
    complete = getattr(obj, "complete", None)
    if complete is not None:
        complete(study, params.error)
    return obj


# --------------------------------------------------------------------------- reading one key
def _read(params, key: str, tp, default, r: Rule, study):
    optional, tp = _unoptional(tp)
    if dataclasses.is_dataclass(tp):                  # a sub-table; ``true`` (or absent, with such a default): its
        raw = params.raw(key) if default is MISSING else params.raw(key, _ABSENT)    # defaults; ``false``: None
        if raw is _ABSENT and not dataclasses.is_dataclass(default):
            return default
        if optional and raw is False:
            return None
        if raw is True or raw is _ABSENT:
            from .params import Params

            return _read_table(tp, Params({}, file=params.file, key=params.path(key)), study)
        return _read_table(tp, params.sub(key), study)
    if default is MISSING:
        raw = params.raw(key)
    else:
        raw = params.raw(key, _ABSENT)
        if raw is _ABSENT:
            return default
    if raw is None and optional:
        return None
    members = _union_members(tp)
    if members:                                         # A | B: the first member the value reads as
        from .errors import InputError

        errors = []
        for m in members:
            try:
                return _read(params, key, m, default, r, study)
            except InputError as exc:
                errors.append((m, exc))
        own = [exc for m, exc in errors if _holds(m, raw)]
        if len(own) == 1:                               # the member of the value's own form: its reason
            raise own[0]
        raise params.error(key, "expected " + " or ".join(_type_word(m) for m in members))
    if tp is list:
        v = params.raw(key)
        if not isinstance(v, list):
            raise params.error(key, "expected an array")
        return v
    if r.names and r.all_ok and raw == "all":
        return list(_known(r.names, study) or [])
    if r.unit is not None and tp is float:      # a quantity (in a union ``float | str``, the text is the str's)
        return params.quantity(key, r.unit, **_number_checks(r))
    origin = typing.get_origin(tp)
    if tp is Path:
        return params.path_value(key, Path(study.base_dir) if study is not None else Path("."))
    if _is_params(tp):
        return params.sub(key)
    if tp is bool:
        return params.bool(key)
    if tp is int:
        v = params.int(key, min=_int_or_none(r.min), max=_int_or_none(r.max))
        return _check_number(params, key, v, r)
    if tp is float:
        v = params.float(key, min=r.min, max=r.max, positive=r.positive, nonnegative=r.nonnegative)
        return _check_number(params, key, v, r)
    if origin is Literal:
        return params.str(key, choices=[str(a) for a in typing.get_args(tp)])
    if tp is str:
        v = params.str(key, choices=r.choices, single_line=r.single_line)
        if r.names:
            _check_names(params, key, [v], r.names, study)
        return v
    if origin is list:
        (item,) = typing.get_args(tp) or (Any,)
        if item is str:
            v = params.strs(key, min_length=r.min_length)
            if r.names:
                _check_names(params, key, v, r.names, study)
            return v
        if item is float:
            v = params.floats(key, min_length=r.min_length, min=r.min, max=r.max, positive=r.positive,
                              nonnegative=r.nonnegative)
            return v
        if item is int:
            v = params.raw(key)
            if not isinstance(v, list) or any(isinstance(x, bool) or not isinstance(x, int) for x in v):
                raise params.error(key, "expected an array of integers")
            if len(v) < r.min_length:
                raise params.error(key, f"expected at least {r.min_length} integers, got {len(v)}")
            for x in v:
                if (r.min is not None and x < r.min) or (r.max is not None and x > r.max):
                    raise params.error(key, f"expected integers in [{r.min if r.min is not None else '-∞'}, "
                                            f"{r.max if r.max is not None else '∞'}], got {x}")
            return [_check_number(params, f"{key}", x, r) for x in v]
        if dataclasses.is_dataclass(item) or _is_params(item):
            tables = params.tables(key)
            if len(tables) < r.min_length:
                raise params.error(key, f"give at least {r.min_length} [[{params.path(key)}]] table"
                                        f"{'s' if r.min_length > 1 else ''}")
            return tables if _is_params(item) else [_read_table(item, t, study) for t in tables]
        return params.raw(key)
    if origin is dict or tp is dict:
        args = typing.get_args(tp)
        sub = params.sub(key)
        if args and args[1] is float:
            out = {k: sub.float(k, min=r.min, max=r.max, positive=r.positive, nonnegative=r.nonnegative)
                   for k in list(sub.keys())}
            if r.names:
                for k in out:
                    _check_names(sub, k, [k], r.names, study)
            return out
        if args and args[1] is str:
            return {k: sub.str(k) for k in list(sub.keys())}
        return dict(sub.data)
    return params.raw(key)


_ABSENT = object()


def _read_table(cls, sub, study):
    """A sub-table read by its own options class; keys it does not declare are errors (typos)."""
    obj = read_options(cls, sub, study)
    sub.finish()
    return obj


def _is_params(tp) -> bool:
    return getattr(tp, "__name__", None) == "Params" and getattr(tp, "__module__", "") == "rvtol.params"


def _unoptional(tp):
    """``(optional, T)`` for ``T | None`` (and ``Optional[T]``), ``(False, tp)`` otherwise."""
    origin = typing.get_origin(tp)
    if origin in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(tp) if a is not type(None)]
        if len(args) == 1 and len(args) < len(typing.get_args(tp)):
            return True, args[0]
    return False, tp


def _union_members(tp) -> tuple:
    """The members of a union ``A | B`` (None left out) when more than one remain, else ()."""
    if typing.get_origin(tp) in (typing.Union, types.UnionType):
        args = tuple(a for a in typing.get_args(tp) if a is not type(None))
        return args if len(args) > 1 else ()
    return ()


def _type_word(tp) -> str:
    """A type in a user's words (an error's ``expected …``)."""
    origin = typing.get_origin(tp)
    if tp is list or origin is list:
        return "an array"
    if origin is Literal:
        return " or ".join(repr(a) for a in typing.get_args(tp))
    if tp is Path:
        return "a file name"
    return {str: "a string", int: "an integer", float: "a number", bool: "true or false"}.get(tp, "a table")


def _holds(tp, value) -> bool:
    """Whether ``value`` has the TOML form of a union member ``tp`` (a string for text, a number for a number, an
    array for a list, a table for a table): that member's own reason is the one to give."""
    origin = typing.get_origin(tp)
    if tp is bool:
        return isinstance(value, bool)
    if tp in (int, float):
        return isinstance(value, (int, float)) and not isinstance(value, bool)
    if tp in (str, Path) or origin is Literal:
        return isinstance(value, str)
    if tp is list or origin is list:
        return isinstance(value, list)
    return isinstance(value, dict)


def _int_or_none(v):
    return None if v is None else int(v)


def _number_checks(r: Rule) -> dict:
    return {k: getattr(r, k) for k in ("min", "max", "positive", "nonnegative") if getattr(r, k) not in (None, False)}


def _check_number(params, key, v, r: Rule):
    if r.zero_or_min is not None and v != 0 and v < r.zero_or_min:
        raise params.error(key, f"must be 0 or >= {r.zero_or_min:g}, got {v}")
    if r.positive and not v > 0:
        raise params.error(key, f"must be > 0, got {v}")
    if r.nonnegative and v < 0:
        raise params.error(key, f"must be >= 0, got {v}")
    if r.power_of_two and (v < 1 or int(v) & (int(v) - 1)):
        raise params.error(key, f"must be a power of 2, got {v}")
    if r.even and int(v) % 2:
        raise params.error(key, f"must be even, got {v}")
    return v


def _known(what: str, study) -> list[str] | None:
    if study is None:
        return None
    if what == "outputs":
        return list(study.model.output_names)
    if what == "factors":
        return list(study.spec.names)
    if what == "requirements":
        return [r.label for r in study.requirements]
    if what == "stages":
        return [s.name for s in getattr(study.model, "stages", ())]
    raise ValueError(f"unknown name kind {what!r}")


_NAMED = {"outputs": "output", "factors": "factor", "requirements": "requirement", "stages": "model"}
_HOLDER = {"outputs": "model has", "factors": "spec has", "requirements": "study has",
           "stages": "the study's models"}


def _check_names(params, key, values, what: str, study) -> None:
    known = _known(what, study)
    if known is None:
        return
    for v in values:
        if v not in known:
            raise params.error(key, f"unknown {_NAMED[what]} name {v!r}{did_you_mean(v, known)} "
                                    f"({_HOLDER[what]}: {', '.join(known) or 'none'})")


def _type_name(tp) -> str:
    optional, tp = _unoptional(tp)
    origin = typing.get_origin(tp)
    members = _union_members(tp)
    if members:                 # A | B (| None): each member's name
        return " or ".join(_type_name(m) for m in members) + (", optional" if type(None) in typing.get_args(tp)
                                                               else "")
    if origin is Literal:
        name = " | ".join(repr(a) for a in typing.get_args(tp))
    elif origin is list:
        (item,) = typing.get_args(tp) or (Any,)
        name = ("array of tables" if dataclasses.is_dataclass(item) or _is_params(item)
                else f"list of {getattr(item, '__name__', str(item))}")
    elif origin is dict or tp is dict or dataclasses.is_dataclass(tp) or _is_params(tp):
        name = "table"
    elif tp is Path:
        name = "file"
    else:
        name = getattr(tp, "__name__", str(tp))
    return name + (", optional" if optional else "")
