"""A study that extends another: the base's product (spec, models, requirements), its own name, options and analyses."""
import pytest

from conftest import write
from rvtol.errors import InputError
from rvtol.study import load_study

BASE = """
[study]
name = "base"
title = "the base"
[[factor]]
name = "a"
unit = "um"
dist = "normal"
sigma = 1.0
[model]
kind = "linear"
[[model.output]]
name = "y"
unit = "um"
coefficients = { a = 2.0 }
[[requirement]]
output = "y"
upper = 5.0
unit = "um"
[sampling]
n = 300
seed = 4
[execution]
executor = "serial"
[[analysis]]
kind = "contributions"
"""

DERIVED = """
[study]
extends = "base.toml"
title = "derived"
[sampling]
n = 50
[[requirement]]
output = "y"
lower = -5.0
unit = "um"
[[analysis]]
kind = "local_sensitivity"
"""


def test_a_derived_study_takes_the_product_and_keeps_its_own_name_options_and_analyses(tmp_path):
    base = write(tmp_path / "base.toml", BASE)
    st = load_study(write(tmp_path / "derived.toml", DERIVED))
    assert st.name == "derived" and st.title == "derived"
    assert st.options.n == 50 and st.options.seed == 4 and st.options.executor == "serial"
    assert [(r.lower, r.upper) for r in st.requirements] == [(None, 5.0), (-5.0, None)]
    assert [type(a).__name__ for a in st.analyses] == ["LocalSensitivity"]
    assert st.model.output_names == ("y",)
    assert st.inputs["extends"]["path"] == str(base)


@pytest.mark.parametrize("change, key", [
    (lambda d: d.replace('extends = "base.toml"', 'extends = "sub/base.toml"'), "study.extends"),
    (lambda d: d.replace('extends = "base.toml"', 'extends = "derived.toml"'), "study.extends"),
    (lambda d: d + '[[factor]]\nname = "b"\nunit = "um"\ndist = "normal"\nsigma = 1\n', "factor"),
    (lambda d: d.replace('extends = "base.toml"', 'extends = "nothere.toml"'), "-"),
])
def test_bad_extends_names_the_key(tmp_path, change, key):
    write(tmp_path / "base.toml", BASE)
    write(tmp_path / "sub/base.toml", BASE)
    with pytest.raises(InputError) as exc:
        load_study(write(tmp_path / "derived.toml", change(DERIVED)))
    assert exc.value.key == key, (exc.value.file, exc.value.key, exc.value.reason)
