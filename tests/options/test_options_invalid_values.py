"""Every analysis and model kind refuses every invalid value of every key with one located error (issue 38 item 1).

For each registered kind (built in and from installed plug-ins; a model kind's ``[model]`` table as an analysis
kind's ``[[analysis]]`` table), each key of its declarative ``Options`` gets values
its type or rule forbids — a word for a number, a fraction for an integer, a number for text or a list, a value off its
``choices``, a number below ``min`` / ``positive`` / ``nonnegative``, a list shorter than ``min_length``, a table for a
scalar — read alone from an ``[[analysis]]`` table (as scikit-learn's common test feeds every estimator invalid
parameters).  The error must be an :class:`rvtol.errors.InputError` naming the file and a key of that table: the bad
key itself, or a required key the table lacks that is read before it (never a traceback, never another key's blame).
"""
from __future__ import annotations

import dataclasses
import typing
from pathlib import Path

import pytest

from conftest import ab_study, write
from rvtol.errors import InputError
from rvtol.options import REQUIRED, key_of, read_options, rule_of
from rvtol.params import Params
from rvtol.model_kind import Where
from rvtol.registry import MODELS, TABLES, analysis_function, ANALYSES, model_factory, plugin_analyses, table_options

KINDS = sorted(set(ANALYSES) | set(plugin_analyses()))
MODEL_KINDS = sorted(MODELS)
#: what a kind is, the kinds, and the key its table is read at
GROUPS = (("analysis", KINDS, "analysis[0]"), ("model", MODEL_KINDS, "model"), ("table", sorted(TABLES), None))


def _base(tp):
    """The type inside ``X | None``."""
    args = typing.get_args(tp)
    if type(None) in args:
        rest = [a for a in args if a is not type(None)]
        return rest[0] if len(rest) == 1 else tp
    return tp


def _invalid(tp, rule) -> list:
    """Values the type or the rule forbid."""
    tp = _base(tp)
    origin = typing.get_origin(tp)
    out: list = [{"a": {"b": 1}}] if tp not in (dict,) and origin is not dict else []   # a table for anything else
    if tp is bool:
        return out + ["yes", 2]
    if tp is int:
        out += ["ten", 1.5]
    elif tp is float:
        out += ["ten"] if rule.unit is None else ["ten", {"value": "ten"}]
    elif tp is str or origin is typing.Literal:
        out += [3]
        if rule.choices or origin is typing.Literal:
            out.append("no-such-choice-xyz")
    elif tp is Path:
        out += [3]
    elif origin is list:
        inner = typing.get_args(tp)[0] if typing.get_args(tp) else str
        if inner in (float, int):
            out += ["ten", ["ten"]]
        elif inner is str:
            out += [[3]] if not rule.names else []
        if rule.min_length and rule.min_length > 0 and inner in (float, int, str) and not rule.names:
            out.append([] if inner is not str else [])
    if tp in (int, float):
        if rule.min is not None:
            out.append(rule.min - 1)
        if rule.positive:
            out.append(0)
        if rule.nonnegative:
            out.append(-1)
    return out


def _keys(opts, path: tuple = ()):
    """``(path of keys, type, rule, the first required key read before it or None)`` of every scalar or list key
    of the options class ``opts``, into its sub-tables (``[analysis.<key>]``)."""
    hints = typing.get_type_hints(opts)
    order = [f for f in dataclasses.fields(opts) if f.init]
    for i, f in enumerate(order):
        tp = _base(hints[f.name])
        if "Params" in str(tp) or tp is dict or typing.get_origin(tp) is dict or tp is object:
            continue          # handed on unread; free tables; a value of several forms the build reads
        required = [key_of(g) for g in order[:i] if g.default is REQUIRED and g.default_factory is dataclasses.MISSING]
        if dataclasses.is_dataclass(tp):
            if not required:  # a sub-table read only once every required key before it is given
                yield from _keys(tp, path + (key_of(f),))
            continue
        if typing.get_origin(tp) is list and typing.get_args(tp) and dataclasses.is_dataclass(typing.get_args(tp)[0]):
            if not required:  # an array of tables: the keys of its first table
                yield from _keys(typing.get_args(tp)[0], path + (key_of(f) + "[0]",))
            continue
        yield path + (key_of(f),), hints[f.name], rule_of(f), (required[0] if required else None)


def _options(what: str, kind: str):
    if what == "table":
        return table_options(kind)
    return (analysis_function(kind, "s.toml", "kind") if what == "analysis" else model_factory(kind, "s.toml")).Options


def _cases():
    for what, kinds, _ in GROUPS:
        for kind in kinds:
            for path, tp, rule, first_required in _keys(_options(what, kind)):
                for bad in _invalid(tp, rule):
                    yield pytest.param(what, kind, path, bad, first_required,
                                       id=f"{what}:{kind}.{'.'.join(path)}={bad!r}"[:90])


CASES = list(_cases())


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    from rvtol.study import load_study

    return load_study(write(tmp_path_factory.mktemp("s") / "s.toml", ab_study(requirements=(
        '[[requirement]]\nname = "gap"\noutput = "y"\nlower = 5.8\nupper = 6.2\nunit = "mm"\n'))), execute=False)


def test_the_common_test_covers_every_kind():
    for what, kinds, _ in GROUPS:
        cases = [c for c in CASES if c.values[0] == what]
        covered = {c.values[1] for c in cases}
        assert covered == set(kinds), set(kinds) - covered
        print(f"{what}: {len(kinds)} kinds, {len({(c.values[1], c.values[2]) for c in cases})} keys, {len(cases)} "
              "invalid values")
    assert len(KINDS) >= 30 and len(MODEL_KINDS) >= 12


@pytest.mark.parametrize("what,kind,path,bad,first_required", CASES)
def test_an_invalid_value_is_one_located_error(study, what, kind, path, bad, first_required):
    table: dict = {} if what == "table" else {"kind": kind}
    inner = table
    for k in path[:-1]:
        inner = inner.setdefault(k[:-3], [{}])[0] if k.endswith("[0]") else inner.setdefault(k, {})
    inner[path[-1]] = bad
    where = next(w for g, _, w in GROUPS if g == what) or kind
    with pytest.raises(InputError) as ei:
        read_options(_options(what, kind), Params(table, file="s.toml", key=where),
                     study if what == "analysis" else Where(Path(".")))
    e = ei.value
    assert e.file == "s.toml" and e.key and e.key.startswith(where + "."), (e.key, e.reason)
    blamed = e.key[len(where) + 1:]
    key = ".".join(path)
    outer_required = f"{'.'.join(path[:-1]) + '.' if path[:-1] else ''}{first_required}" if first_required else None
    # the key itself (or a place inside the value: an entry of a list, a key of a table given for a quantity), or a
    # required key its table lacks that is read before it
    assert blamed == key or blamed.startswith((key + "[", key + ".")) or blamed == outer_required, (e.key, e.reason)
