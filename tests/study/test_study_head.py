"""``[study]`` read by its declared schema (:class:`rvtol.study.head.StudyHead`): a value of the wrong form is one
located error before any file it names is read, and the keys' relations are checked."""
from __future__ import annotations

import pytest

from conftest import AB_FACTORS, ab_study, write
from rvtol.errors import InputError
from rvtol.study import load_study


@pytest.mark.parametrize("head,key,reason", [
    ("build = true", "study.build", "expected the build rules' file name, or false"),
    ('spec = ["a.toml", ""]', "study.spec", "an empty name is none"),
    ("spec = []", "study.spec", "at least 1"),
    ('spec_sheet = "rev B"', "study.spec_sheet", "no spec file"),
    ("exploratory = 1", "study.exploratory", "expected true or false"),
    ('design = 3\nspec = "missing.toml"', "study.design", "expected a string"),
])
def test_a_bad_study_head_is_one_located_error(tmp_path, head, key, reason):
    p = write(tmp_path / "s.toml", ab_study(head=head))
    with pytest.raises(InputError) as ei:
        load_study(p)
    assert (ei.value.file, ei.value.key) == (str(p), key) and reason in ei.value.reason, ei.value


def test_the_head_is_checked_before_a_file_it_names_is_read(tmp_path):
    """A typo in [study] is named even when the design it names does not exist (the schema reads every key first)."""
    p = write(tmp_path / "s.toml", ab_study(head='design = "no_such_design.toml"\nexploratry = true'))
    with pytest.raises(InputError) as ei:
        load_study(p)
    assert ei.value.key == "study.exploratry" and "exploratory" in ei.value.reason


def test_one_spec_file_and_a_list_of_one_read_the_same_spec(tmp_path):
    write(tmp_path / "spec.toml", AB_FACTORS)
    text = ab_study(spec="spec.toml")
    one = load_study(write(tmp_path / "one.toml", text))
    listed = load_study(write(tmp_path / "two.toml", text.replace('spec = "spec.toml"', 'spec = ["spec.toml"]')))
    assert one.spec.names == listed.spec.names == ("a", "b")
    assert one.inputs["spec"]["path"] == listed.inputs["spec"]["path"] == str(tmp_path / "spec.toml")
