"""Bad input in assembly descriptions, the adjusted-assembly model and the adjustment analysis."""
import re
import textwrap

import pytest

from rvtol.models.adjustment import load_assembly
from rvtol.errors import InputError
from rvtol.study import load_study

from conftest import BX40E_STUDY_HEAD, write

GOOD = textwrap.dedent("""
    [assembly]
    name = "t"
    components = ["x"]

    [weights]
    accuracy = 10
    effort_adjustable = 5
    effort_locked = 1000

    [[chain]]
    name = "C1"
    kcs = ["K1", "K2"]

    [[kc]]
    name = "K1"
    error = "e1"

    [[kc]]
    name = "K2"
    error = "e2"

    [[step]]
    install = "K1"

    [[step]]
    install = "K2"
    adjust = ["K1", "K2"]
""")


def test_good_description_loads(tmp_path):
    d = load_assembly(write(tmp_path / "a.toml", GOOD))
    assert d.part_error_names() == ["e1", "e2"] and d.noise_names() == ["v1_K1", "v2_K2"]


BAD = [
    # (replace this, by this, key expected in the message, reason fragment)
    ('install = "K2"', 'install = "K9"', "step[1].install", "unknown KC"),
    ('install = "K2"', 'install = "K1"', "step[1].install", "installed twice"),
    ('[[step]]\ninstall = "K1"\n\n[[step]]\ninstall = "K2"', '[[step]]\ninstall = "K2"\n\n[[step]]\ninstall = "K1"',
     "step[0].install", "before 'K1'"),
    ('adjust = ["K1", "K2"]', 'adjust = ["K1", "K3"]', "step[1].adjust", "unknown KC"),
    ('[[step]]\ninstall = "K1"\n', '[[step]]\ninstall = "K1"\nadjust = ["K2"]\n', "step[0].adjust", "not installed yet"),
    ('[[step]]\ninstall = "K1"\n', '[[step]]\ninstall = "K1"\nmeasure = ["K2"]\n', "step[0].measure",
     "not installed yet"),
    ('accuracy = 10', 'accuracy = "lots"', "weights.accuracy", 'a number or "inf"'),
    ('accuracy = 10', 'accuracy = -1', "weights.accuracy", ">= 0"),
    ('effort_locked = 1000', 'effort_locked = 0', "weights.effort_locked", "> 0"),
    ('effort_locked = 1000', 'effort_locked = nan', "weights.effort_locked", "finite"),
    ('components = ["x"]', 'components = ["x", "x"]', "assembly.components", "distinct"),
    ('components = ["x"]', 'components = ["q"]', "assembly.components", "distinct"),
    ('error = "e2"', 'error = "e1"', "kc[1].error", "duplicate error factor"),
    ('error = "e2"', 'error = "e2"\nW = [[0.0]]', "kc[1].W", "singular"),
    ('error = "e2"', 'error = "e2"\nW = [[1.0, 0.0]]', "kc[1].W[0]", "expected 1 numbers"),
    ('error = "e2"', 'error = "e2"\nW = [[1.0], [2.0]]', "kc[1].W", "expected a 1×1 matrix"),
    ('kcs = ["K1", "K2"]', 'kcs = ["K1"]', "kc[1].name", "in no [[chain]]"),
    ('kcs = ["K1", "K2"]', 'kcs = ["K1", "K2", "K3"]', "kc", "has no [[kc]] table"),
    ('[weights]', '[weights]\nacuracy = 3', "weights.acuracy", "unknown key"),
    ('[[step]]\ninstall = "K2"\nadjust = ["K1", "K2"]\n', '', "step", "never installed"),
]


@pytest.mark.parametrize("old,new,key,reason", BAD)
def test_bad_description(tmp_path, old, new, key, reason):
    assert old in GOOD, old
    path = write(tmp_path / "a.toml", GOOD.replace(old, new, 1))
    with pytest.raises(InputError) as ei:
        load_assembly(path)
    e = ei.value
    assert e.file == str(path)
    assert e.key == key, (e.key, e.reason)
    assert reason in e.reason


def test_inf_accuracy_accepted(tmp_path):
    for v in ('"inf"', "inf"):
        d = load_assembly(write(tmp_path / "a.toml", GOOD.replace("accuracy = 10", f"accuracy = {v}")))
        assert d.accuracy == float("inf")


STUDY = BX40E_STUDY_HEAD + textwrap.dedent("""
    [[analysis]]
    kind = "adjustment"
    part_errors = "example.part_errors"
""")


def _study(tmp_path, root, text):
    return write(tmp_path / "s.toml", text.replace("{root}", str(root)))


@pytest.mark.parametrize("old,new,key,reason", [
    ('part_errors = "example.part_errors"', 'part_errors = "example.nothing"', "analysis[0].part_errors",
     "no parameter"),
    ('part_errors = "example.part_errors"', 'part_errors = "example.accuracy_weights"', "analysis[0].part_errors",
     "not an angle"),
    ('part_errors = "example.part_errors"', 'part_errors = [1.0, 2.0]', "analysis[0].part_errors",
     "expected 4 part errors"),
    ('part_errors = "example.part_errors"', 'part_errors = "example.part_errors"\naccuracy_weights = [1, "x"]',
     "analysis[0].accuracy_weights.1", 'a number or "inf"'),
    ('assembly = "{root}/data/assemblies/bx40e_2d.toml"', 'assembly = "{root}/data/assemblies/bx40e_3d.toml"',
     "factor", "unknown factor name 'dtheta_1'"),
    ('assembly = "{root}/data/assemblies/bx40e_2d.toml"',
     'assembly = "{root}/data/assemblies/bx40e_2d.toml"\naccuracy_weight = "high"', "model.accuracy_weight",
     'a number or "inf"'),
    ('kind = "adjusted_assembly"\n', 'kind = "adjusted_assembly"\nasembly = 1\n', "model.asembly", "unknown key"),
])
def test_bad_study_inputs(tmp_path, root, old, new, key, reason):
    assert old in STUDY
    path = _study(tmp_path, root, STUDY.replace(old, new, 1))
    with pytest.raises(InputError) as ei:
        load_study(path)
    assert ei.value.key == key, (ei.value.key, ei.value.reason)
    assert reason in ei.value.reason


def test_adjustment_analysis_needs_the_adjusted_model(tmp_path, root):
    text = STUDY.replace('kind = "adjusted_assembly"\nassembly = "{root}/data/assemblies/bx40e_2d.toml"',
                         'kind = "linear"\n[[model.output]]\nname = "y"\nunit = "rad"\n'
                         'coefficients = { dtheta_1 = 1.0 }')
    with pytest.raises(InputError, match=re.escape("needs the study model kind 'adjusted_assembly'")):
        load_study(_study(tmp_path, root, text))


@pytest.mark.parametrize("file", ["bx40e_2d.toml", "bx40e_3d.toml"])
def test_every_key_of_the_descriptions_is_declared(root, file):
    """rvtol kinds adjustment_<table> lists every key the BX40E descriptions write (issue 38 item 1)."""
    import tomllib

    from rvtol.options import describe
    from rvtol.registry import table_options

    data = tomllib.loads((root / "data/assemblies" / file).read_text(encoding="utf-8"))
    for table, value in data.items():
        declared = {o.key for o in describe(table_options(f"adjustment_{table}"))}
        for t in value if isinstance(value, list) else [value]:
            assert set(t) <= declared, (table, set(t) - declared)
