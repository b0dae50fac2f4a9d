"""Declarative options (rvtol.options): each rule accepts what it should and refuses the rest with the key located.

Every rule of the module's table is exercised at its bound (accepted) and one step beyond it (refused): choices
and ``Literal``, ``min``/``max`` (inclusive), ``positive``, ``nonnegative``, ``power_of_two``, ``even``,
``zero_or_min``, ``min_length`` on every list type, ``unit``, ``names`` and ``"all"``; a sub-table absent, ``true``,
``false`` and with a bad key.  The expected values are typed here (a fake study holds the names)."""
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from types import SimpleNamespace
from typing import Literal

import pytest

from rvtol.errors import InputError
from rvtol.options import REQUIRED, describe, option, read_options
from rvtol.params import Params

OUTPUTS = ("gap", "play", "tilt")
STUDY = SimpleNamespace(
    model=SimpleNamespace(output_names=OUTPUTS, stages=(SimpleNamespace(name="stackup"), SimpleNamespace(name="te"))),
    spec=SimpleNamespace(names=("a", "b")),
    requirements=(SimpleNamespace(label="gap ≤ 5"),),
)


def read(cls, table: dict, study=STUDY):
    return read_options(cls, Params(table, file="s.toml", key="analysis[0]"), study)


def refused(cls, table: dict, key: str, match: str, study=STUDY) -> None:
    """``table`` is refused on ``analysis[0].<key>`` with a reason matching ``match``."""
    with pytest.raises(InputError, match=match) as e:
        read(cls, table, study)
    assert (e.value.file, e.value.key) == ("s.toml", f"analysis[0].{key}")


# ---------------------------------------------------------------------------------------------- names and "all"
@dataclass
class Named:
    outputs: list[str] | None = option(None, "outputs", names="outputs", all_ok=True, min_length=1)
    factors: list[str] | None = option(None, "factors", names="factors", min_length=1)
    output: str | None = option(None, "one output", names="outputs")
    stage: str | None = option(None, "a stage", names="stages")
    requirement: str | None = option(None, "a requirement", names="requirements")
    weights: dict[str, float] | None = option(None, "per factor", names="factors", positive=True)


def test_all_expands_to_every_output_of_the_study():
    assert read(Named, {"outputs": "all"}).outputs == list(OUTPUTS)
    other = SimpleNamespace(model=SimpleNamespace(output_names=("x",)))
    assert read(Named, {"outputs": "all"}, study=other).outputs == ["x"]


def test_all_read_from_a_study_file_expands_too():
    # a string parsed from TOML is a new object, not the interned constant "all"
    assert read(Named, tomllib.loads('outputs = "all"')).outputs == list(OUTPUTS)


def test_all_is_a_name_only_where_the_option_allows_it():
    refused(Named, {"output": "all"}, "output", "unknown output name 'all'")
    refused(Named, {"factors": "all"}, "factors", "expected an array of strings")


def test_names_are_checked_against_the_study():
    o = read(Named, {"outputs": ["tilt", "gap"], "factors": ["b"], "output": "play", "stage": "te",
                     "requirement": "gap ≤ 5", "weights": {"a": 2.0}})
    assert (o.outputs, o.factors, o.output, o.stage, o.requirement, o.weights) == (
        ["tilt", "gap"], ["b"], "play", "te", "gap ≤ 5", {"a": 2.0})
    refused(Named, {"outputs": ["gap", "gapp"]}, "outputs", r"unknown output name 'gapp'.*did you mean 'gap'")
    refused(Named, {"factors": ["c"]}, "factors", r"unknown factor name 'c' \(spec has: a, b\)")
    refused(Named, {"stage": "tee"}, "stage", "unknown model name 'tee'")
    refused(Named, {"requirement": "gap < 5"}, "requirement", "unknown requirement name")
    refused(Named, {"weights": {"c": 1.0}}, "weights.c", "unknown factor name 'c'")
    refused(Named, {"weights": {"a": 0.0}}, "weights.a", "> 0")


def test_an_empty_list_of_names_is_refused():
    refused(Named, {"outputs": []}, "outputs", "at least 1 strings, got 0")
    refused(Named, {"factors": []}, "factors", "at least 1 strings, got 0")


# ---------------------------------------------------------------------------------------------- lists
@dataclass
class Leaf:
    t: float = option(1.0, "a thickness", positive=True)


@dataclass
class Lists:
    names: list[str] = option(["x", "y"], "strings", min_length=2)
    values: list[float] = option([0.0, 1.0, 2.0], "numbers", min_length=3, nonnegative=True)
    counts: list[int] = option([1, 2], "integers", min_length=2, min=1, max=9)
    leaves: list[Leaf] = option([], "tables", min_length=2)
    orders: list[int] = option([2], "even integers", even=True)


@pytest.mark.parametrize("key, at_least, item", [("names", 2, "x"), ("values", 3, 1.0), ("counts", 2, 3)])
def test_a_list_at_its_minimum_length_is_read_and_one_shorter_is_refused(key, at_least, item):
    assert getattr(read(Lists, {key: [item] * at_least}), key) == [item] * at_least
    refused(Lists, {key: [item] * (at_least - 1)}, key, f"at least {at_least} ")


def test_an_array_of_tables_at_its_minimum_length():
    o = read(Lists, {"leaves": [{"t": 2.0}, {}]})
    assert [x.t for x in o.leaves] == [2.0, 1.0]
    assert [x.t for x in read(Lists, {"leaves": [{}, {"t": 3.0}, {}]}).leaves] == [1.0, 3.0, 1.0]   # more is fine
    refused(Lists, {"leaves": [{"t": 2.0}]}, "leaves", r"at least 2 \[\[analysis\[0\]\.leaves\]\] tables")
    refused(Lists, {"leaves": [{"t": 2.0}, {"t": -1.0}]}, "leaves[1].t", "> 0")
    refused(Lists, {"leaves": [{"t": 2.0}, {"thickness": 1.0}]}, "leaves[1].thickness", "unknown key")


def test_one_missing_table_is_named_in_the_singular():
    @dataclass
    class One:
        leaves: list[Leaf] = option([], "at least one table", min_length=1)

    refused(One, {"leaves": []}, "leaves", r"give at least 1 \[\[analysis\[0\]\.leaves\]\] table$")


def test_list_items_keep_their_bounds():
    refused(Lists, {"values": [0.0, -0.5, 1.0]}, "values[1]", ">= 0")
    assert read(Lists, {"counts": [1, 9]}).counts == [1, 9]
    refused(Lists, {"counts": [0, 2]}, "counts", r"integers in \[1, 9\], got 0")
    refused(Lists, {"counts": [1, 10]}, "counts", r"integers in \[1, 9\], got 10")
    refused(Lists, {"counts": [1, 2.0]}, "counts", "expected an array of integers")
    refused(Lists, {"counts": [1, True]}, "counts", "expected an array of integers")
    assert read(Lists, {"orders": [2, 4, 0]}).orders == [2, 4, 0]
    refused(Lists, {"orders": [2, 3]}, "orders", "must be even, got 3")


def test_list_defaults_are_fresh_copies():
    a, b = read(Lists, {}), read(Lists, {})
    a.names.append("z")
    assert b.names == ["x", "y"]


# ---------------------------------------------------------------------------------------------- sub-tables
@dataclass
class Sub:
    depth: int = option(3, "a depth", min=1)
    label: str = option("x", "a label")


@dataclass
class WithSub:
    sub: Sub = option(Sub, "a sub-table, every default when absent or true")
    maybe: Sub | None = option(Sub, "a sub-table that false switches off")


def test_a_sub_table_absent_or_true_takes_every_default():
    for table in ({}, {"sub": True, "maybe": True}):
        o = read(WithSub, table)
        assert o.sub == Sub(depth=3, label="x") and o.maybe == Sub(depth=3, label="x")


def test_a_sub_table_is_read_by_its_own_rules():
    o = read(WithSub, {"sub": {"depth": 5}, "maybe": {"label": "y"}})
    assert o.sub == Sub(depth=5, label="x") and o.maybe == Sub(depth=3, label="y")
    refused(WithSub, {"sub": {"depth": 0}}, "sub.depth", ">= 1")
    refused(WithSub, {"sub": {"dept": 5}}, "sub.dept", "unknown key")


def test_false_switches_off_only_an_optional_sub_table():
    assert read(WithSub, {"maybe": False}).maybe is None
    refused(WithSub, {"sub": False}, "sub", "expected a table, got")
    refused(WithSub, {"sub": 3}, "sub", "expected a table, got")


def test_the_numbers_0_and_1_are_not_false_and_true_for_a_sub_table():
    refused(WithSub, {"maybe": 0}, "maybe", "expected a table, got int")
    refused(WithSub, {"sub": 1}, "sub", "expected a table, got int")
    refused(WithSub, {"maybe": 1.0}, "maybe", "expected a table, got")


@dataclass
class OffByDefault:
    extra: Sub | None = option(None, "a sub-table that is off unless given")


def test_a_sub_table_with_the_default_none_is_none_unless_given():
    assert read(OffByDefault, {}).extra is None
    assert read(OffByDefault, {"extra": {"depth": 7}}).extra == Sub(depth=7, label="x")
    assert read(OffByDefault, {"extra": True}).extra == Sub(depth=3, label="x")
    assert read(OffByDefault, {"extra": False}).extra is None


# ---------------------------------------------------------------------------------------------- numbers, strings, units
@dataclass
class Numbers:
    n: int = option(REQUIRED, "a required count", min=2, max=64)
    x: float = option(0.5, "a fraction", min=0.0, max=1.0)
    p: float = option(1.0, "positive", positive=True)
    q: float = option(0.0, "nonnegative", nonnegative=True)
    k: int = option(1, "a power of two", power_of_two=True)
    levels: int = option(2, "even", even=True)
    size: int = option(0, "0 or at least 100", zero_or_min=100)
    method: str = option("lhs", "a method", choices=("lhs", "sobol"))
    side: Literal["upper", "lower"] = option("upper", "a side")
    length: float = option(1.0, "a length", unit="mm", positive=True)


@pytest.mark.parametrize("key, accepted, refused_value, reason", [
    ("n", [2, 64], [1, 65, 2.0, True], ["must be >= 2", "must be <= 64", "expected an integer", "expected an integer"]),
    ("x", [0.0, 1.0], [-1e-9, 1.000001], ["must be >= 0", "must be <= 1"]),
    ("p", [1e-12], [0.0, -1.0], ["> 0", "> 0"]),
    ("q", [0.0], [-1e-12], [">= 0"]),
    ("k", [1, 2, 64], [0, 3, 6, 96], ["power of 2"] * 4),
    ("levels", [2, 0, 10], [3, 7], ["must be even"] * 2),
    ("size", [0, 100, 5000], [1, 99], ["must be 0 or >= 100"] * 2),
    ("method", ["lhs", "sobol"], ["LHS", "random"], ["expected one of: lhs, sobol"] * 2),
    ("side", ["upper", "lower"], ["both"], ["expected one of: upper, lower"]),
])
def test_each_number_and_choice_rule(key, accepted, refused_value, reason):
    for v in accepted:
        assert getattr(read(Numbers, {"n": 8, key: v}), key) == v
    for v, why in zip(refused_value, reason):
        refused(Numbers, {"n": 8, key: v}, key, why)


@dataclass
class Counts:
    count: int = option(1, "a positive integer", positive=True)
    offset: int = option(0, "a nonnegative integer", nonnegative=True)
    shift: int = option(0, "any integer")


@pytest.mark.parametrize("key, accepted, refused_value, reason", [
    ("count", [1, 7], [0, -1], ["must be > 0"] * 2),
    ("offset", [0, 7], [-1, -2], ["must be >= 0"] * 2),
    ("shift", [-3, 0, 3], [], []),
])
def test_each_integer_sign_rule(key, accepted, refused_value, reason):
    for v in accepted:
        assert getattr(read(Counts, {key: v}), key) == v
    for v, why in zip(refused_value, reason):
        refused(Counts, {key: v}, key, why)


def test_zero_or_min_refuses_a_negative_number():
    refused(Numbers, {"n": 8, "size": -1}, "size", "must be 0 or >= 100")
    refused(Numbers, {"n": 8, "size": -500}, "size", "must be 0 or >= 100")


def test_a_required_option_must_be_given():
    refused(Numbers, {}, "n", "missing required key")
    assert read(Numbers, {"n": 8}).n == 8


def test_a_quantity_is_held_in_base_units():
    assert read(Numbers, {"n": 8, "length": 250}).length == pytest.approx(250.0)               # mm
    assert read(Numbers, {"n": 8, "length": {"value": 25, "unit": "um"}}).length == pytest.approx(0.025)
    assert read(Numbers, {"n": 8, "length": {"value": 2, "unit": "in"}}).length == pytest.approx(50.8)
    refused(Numbers, {"n": 8, "length": {"value": 2, "unit": "deg"}}, "length.unit", "expected length")
    refused(Numbers, {"n": 8, "length": 0}, "length", "> 0")



@dataclass
class QuantityOrName:
    length: float | str = option(REQUIRED, "a length or a name the loader resolves", unit="mm", positive=True)


def test_a_quantity_or_a_name_keeps_the_name_as_written():
    """``float | str`` with a unit: a number or ``{value, unit}`` in base units, a string as written."""
    assert read(QuantityOrName, {"length": 2.5}).length == pytest.approx(2.5)
    assert read(QuantityOrName, {"length": {"value": 2, "unit": "cm"}}).length == pytest.approx(20.0)
    assert read(QuantityOrName, {"length": "-crank_radius"}).length == "-crank_radius"
    refused(QuantityOrName, {"length": 0}, "length", "> 0")
    refused(QuantityOrName, {"length": True}, "length", "expected a number or a string")

# ---------------------------------------------------------------------------------------------- the class' own checks
@dataclass
class Related:
    lo: float = option(0.0, "low")
    hi: float = option(1.0, "high")

    def complete(self, study, error):
        if not self.hi > self.lo:
            raise error("hi", f"must exceed lo ({self.lo:g})")


def test_complete_checks_relations_between_keys():
    assert read(Related, {"lo": 1.0, "hi": 2.0}).hi == 2.0
    refused(Related, {"lo": 1.0, "hi": 1.0}, "hi", r"must exceed lo \(1\)")


def test_an_unknown_rule_is_a_programming_error():
    with pytest.raises(TypeError, match="unknown option rule"):
        option(1, "x", minimum=0)


def test_describe_lists_each_key_with_its_constraints():
    d = {o.key: o for o in describe(Numbers)}
    assert d["n"].required and d["n"].constraint == ">= 2, <= 64"
    assert d["size"].constraint == "0 or >= 100" and d["k"].constraint == "a power of 2"
    assert d["method"].constraint == "one of 'lhs', 'sobol'" and d["side"].type == "'upper' | 'lower'"
    assert d["length"].constraint == "> 0, in mm (or {value, unit})"
    n = {o.key: o for o in describe(Named)}
    assert n["outputs"].constraint == 'at least 1, names of the study\'s outputs or "all"'
    s = {o.key: o for o in describe(WithSub)}
    assert s["sub"].type == "table" and s["sub.depth"].default == 3 and s["maybe.label"].default == "x"
    assert {o.key: o for o in describe(Lists)}["leaves[].t"].constraint == "> 0"


# ---------------------------------------------------------------------------------------------- tables of values
@dataclass
class Mappings:
    labels: dict[str, str] = option({}, "a label per name")
    table: dict = option({}, "a table read as it is")
    series: dict[str, list] = option({}, "an array per name, read as it is")


def test_a_table_of_strings_takes_only_strings():
    assert read(Mappings, {"labels": {"a": "x", "b": "y"}}).labels == {"a": "x", "b": "y"}
    refused(Mappings, {"labels": {"a": 1}}, "labels.a", "expected a string")
    refused(Mappings, {"labels": "x"}, "labels", "expected a table, got")


def test_a_plain_table_and_a_table_of_other_values_are_read_as_they_are():
    raw = {"a": [1, 2], "b": {"c": 2.5}, "d": "x"}
    assert read(Mappings, {"table": raw}).table == raw
    assert read(Mappings, {"series": {"a": [1.0, 2.0], "b": []}}).series == {"a": [1.0, 2.0], "b": []}
    refused(Mappings, {"table": 3}, "table", "expected a table, got int")
    refused(Mappings, {"series": [1.0]}, "series", "expected a table, got")


# ---------------------------------------------------------------------------------------------- files, other types
@dataclass
class Files:
    data: Path = option(Path("data.csv"), "a file")


def test_a_file_is_relative_to_the_studys_folder_unless_absolute():
    study = SimpleNamespace(base_dir="/studies/gearbox")
    assert read(Files, {"data": "runs/a.csv"}, study=study).data == Path("/studies/gearbox/runs/a.csv")
    assert read(Files, {"data": "/srv/b.csv"}, study=study).data == Path("/srv/b.csv")
    assert read(Files, {"data": "runs/a.csv"}, study=None).data == Path("runs/a.csv")    # no study: the cwd


#: classes named Params from elsewhere than rvtol.params: not the sub-table handed on
ForeignParams = type("Params", (), {})
LibParams = type("Params", (), {"__module__": "lib.params"})


@dataclass
class Others:
    foreign: ForeignParams | None = option(None, "a value of another library's Params type")
    lib: LibParams | None = option(None, "the same, from a module that sorts before rvtol's")
    either: int | str | None = option(None, "a count or a word: a union rvtol does not unpick, read as it is")
    kind: type = option(float, "a default that is a class but not an options class is the default itself")


def test_types_rvtol_does_not_read_are_handed_on_as_written():
    o = read(Others, {"foreign": {"k": 1}, "lib": 3, "either": "many"})
    assert (o.foreign, o.lib, o.either, o.kind) == ({"k": 1}, 3, "many", float)
    assert read(Others, {"either": 4}).either == 4
    d = {o.key: o.type for o in describe(Others)}
    assert d == {"foreign": "Params, optional", "lib": "Params, optional", "either": "int or str, optional",
                 "kind": "type"}


# ---------------------------------------------------------------------------------------------- the class itself
def test_options_are_keyword_only_and_a_required_one_may_follow_a_default():
    @dataclass
    class Late:
        a: float = option(1.0, "a default first")
        b: int = option(REQUIRED, "then a required one")

    assert Late(b=2) == Late(a=1.0, b=2)
    for call in (lambda: Late(1.0, 2), lambda: Numbers(8), lambda: Lists(["a", "b"]), lambda: WithSub(Sub())):
        with pytest.raises(TypeError, match="positional argument"):
            call()


def test_an_options_class_built_in_code_holds_its_defaults():
    assert WithSub().sub == Sub(depth=3, label="x") and WithSub().maybe == Sub(depth=3, label="x")
    assert WithSub().sub is not WithSub().sub and Lists().names is not Lists().names      # fresh each time
    assert Lists().names == ["x", "y"] and Others().kind is float and OffByDefault().extra is None


@dataclass
class Derived:
    a: float = option(1.0, "read first")
    total: float = field(init=False, default=0.0)
    b: float = option(2.0, "read after the field the class computes")

    def complete(self, study, error):
        self.total = self.a + self.b


def test_a_field_the_class_computes_is_neither_read_nor_listed():
    o = read(Derived, {"a": 3.0, "b": 4.0})
    assert (o.a, o.b, o.total) == (3.0, 4.0, 7.0)
    assert [x.key for x in describe(Derived)] == ["a", "b"]


def test_describe_gives_defaults_and_types():
    d = {o.key: o for o in describe(Numbers)}
    assert not d["x"].required and d["x"].default == 0.5 and d["n"].default is None
    assert {k: d[k].type for k in ("n", "x", "method", "length")} == {
        "n": "int", "x": "float", "method": "str", "length": "float"}
    lists = {o.key: o for o in describe(Lists)}
    assert not lists["names"].required and lists["names"].default == ["x", "y"] and lists["leaves"].default == []
    assert {k: lists[k].type for k in ("names", "values", "counts", "leaves")} == {
        "names": "list of str", "values": "list of float", "counts": "list of int", "leaves": "array of tables"}
    s = {o.key: o for o in describe(WithSub)}
    assert s["sub"].default == {} and s["maybe"].default == {} and s["maybe"].type == "table, optional"
    assert {o.key: o.type for o in describe(Named)}["weights"] == "table, optional"
    assert {o.key: o.type for o in describe(Mappings)} == {"labels": "table", "table": "table", "series": "table"}
    assert describe(Files)[0].type == "file"


@pytest.mark.parametrize("kind", ["factor", "output", "stage", "steps"])
def test_a_names_kind_rvtol_does_not_know_is_a_programming_error(kind):
    @dataclass
    class Misnamed:
        name: str | None = option(None, "a name", names=kind)

    with pytest.raises(ValueError, match=f"unknown name kind '{kind}'"):
        read(Misnamed, {"name": "gap"})


@pytest.mark.parametrize("kind, value", [("output", "tilt"), ("factor", "b"), ("requirement", "gap ≤ 5"),
                                         ("stage", "te")])
def test_a_names_kind_built_at_run_time_names_the_same_things(kind, value):
    @dataclass
    class Built:                    # e.g. options declared in a loop over kinds: the string is made, not written
        name: str | None = option(None, "a name", names="".join([kind, "s"]))

    assert read(Built, {"name": value}).name == value
    with pytest.raises(InputError, match=f"unknown {'model' if kind == 'stage' else kind} name 'zz'"):
        read(Built, {"name": "zz"})


@dataclass
class Unions:
    weights: dict[str, float] | str | None = option(None, "a table of numbers, or the name of a scheme", positive=True)
    part: list[str] | str | None = option(None, "a list of names, or one")
    side: Literal["upper", "lower"] | float | None = option(None, "a side, or a level")


@pytest.mark.parametrize("value, reason", [
    ({"a": "x"}, "weights.a: expected a number, got the string 'x'"),      # a table: the table's own reason
    ({"a": -1.0}, "weights.a: must be > 0, got -1.0"),
    (3, "weights: expected a table or a string"),                        # no member of a number's form
])
def test_a_union_gives_the_reason_of_the_member_of_the_value_s_own_form(value, reason):
    with pytest.raises(InputError) as e:
        read(Unions, {"weights": value})
    assert str(e.value) == f"s.toml: analysis[0].{reason}", str(e.value)


def test_a_union_s_expected_forms_are_said_in_a_user_s_words():
    with pytest.raises(InputError) as e:
        read(Unions, {"part": [3]})
    assert str(e.value) == "s.toml: analysis[0].part: expected an array of strings", str(e.value)
    with pytest.raises(InputError) as e:
        read(Unions, {"side": "middle"})
    assert "unknown value 'middle'" in str(e.value) and "upper" in str(e.value), str(e.value)
    with pytest.raises(InputError) as e:
        read(Unions, {"side": [1]})
    assert str(e.value).endswith("side: expected 'upper' or 'lower' or a number"), str(e.value)
    assert read(Unions, {"side": 0.5}).side == 0.5 and read(Unions, {"side": "lower"}).side == "lower"


def test_a_single_line_option_refuses_a_line_break_that_text_may_hold():
    """``single_line`` (a name: one line, one cell): a line break or a tab is refused at its key; the same option
    without the rule reads it (free text may span lines)."""
    from dataclasses import dataclass

    from rvtol.errors import InputError
    from rvtol.options import option, read_options
    from rvtol.params import Params

    @dataclass
    class Named:
        name: str = option("", "a name", single_line=True)
        note: str = option("", "free text")

    o = read_options(Named, Params({"note": "two\nlines"}, file="s.toml", key="t"))
    assert o.note == "two\nlines" and o.name == ""
    with pytest.raises(InputError) as ei:
        read_options(Named, Params({"name": "gap\nplay"}, file="s.toml", key="t"))
    assert ei.value.key == "t.name" and ei.value.reason.endswith("a name may hold none")
