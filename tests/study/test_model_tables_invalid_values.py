"""Every key of every example study's ``[model]`` table, given a value of the wrong kind, is refused with one located
error — never a traceback (the bad-input contract for the model tables, which are read by hand-written code: issue
38's common invalid-value check, as tests/options/test_options_invalid_values.py makes it for the analyses' declared
options).

For each single-model study in ``studies/`` that loads in well under a second, each ``key = value`` line of its
``[model]`` table gets a table, a word or a number in place of its value; loading it must either raise an
:class:`rvtol.errors.InputError` naming the study file and a key of ``model`` (the key itself or inside it) or — a
value that happens to be valid — load.
"""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from conftest import ROOT, write
from rvtol.errors import InputError
from rvtol.study import load_study

STUDIES = ["linear_stackup", "stack_handbook_motor", "stack_clutch", "stack_clutch_loop", "stack_floating_fastener",
           "stack_mitcalc_demo", "lost_motion_doc_example", "lost_motion_rv80e", "stackup_shaft_hole",
           "stackup_rv_crank_chain", "stiffness_rv80e", "torsion_curve_rv80e", "transmission_error_rv80e",
           "gauge_rr_axial_stack"]
REPLACEMENTS = ('{ a = 1 }', '"ten"', "3", "-1", "true", '["x"]')


def _model_lines(text: str):
    """``(line index, key)`` of every one-line ``key = value`` of the ``[model]`` table and its sub-tables and arrays
    of tables (``[model.define]``, ``[[model.output]]``, …)."""
    lines = text.splitlines()
    inside = False
    for i, line in enumerate(lines):
        if line.startswith("["):
            inside = line.strip().strip("[]").split(".")[0] == "model"
            continue
        m = re.match(r"^([A-Za-z_][\w]*)\s*=\s*(.+)$", line)
        if inside and m and m.group(1) != "kind" and not m.group(2).rstrip().endswith(("[", "{", '"""')):
            yield i, m.group(1)


def _study_lines(text: str):
    """``(line index, section, key)`` of every one-line ``key = value`` outside ``[model]`` ([study], [sampling],
    [[requirement]], [[analysis]], …)."""
    section = ""
    for i, line in enumerate(text.splitlines()):
        if line.startswith("["):
            section = line.strip().strip("[]")
            continue
        m = re.match(r"^([A-Za-z_][\w]*)\s*=\s*(.+)$", line)
        if section and section.split(".")[0] != "model" and m and m.group(1) != "kind" \
                and not m.group(2).rstrip().endswith(("[", "{", '"""')):
            yield i, section, m.group(1)


def _cases():
    for name in STUDIES:
        text = (ROOT / "studies" / f"{name}.toml").read_text("utf-8")
        for i, key in _model_lines(text):
            for rep in REPLACEMENTS:
                yield pytest.param(name, i, key, rep, id=f"{name}.model.{key}={rep}")
        for i, section, key in _study_lines(text):
            for rep in REPLACEMENTS[:3]:
                yield pytest.param(name, i, key, rep, id=f"{name}.{section}.{key}={rep}")


CASES = list(_cases())


def test_the_check_reaches_every_studys_model_keys():
    assert {c.values[0] for c in CASES} == set(STUDIES)
    # found by it: a [[model.cycloid_factor]] factor given as a table or an array was an internal error (unhashable)
    print(f"{len(STUDIES)} studies, {len({(c.values[0], c.values[1]) for c in CASES})} keys, {len(CASES)} values")


@pytest.mark.parametrize("name,line,key,rep", CASES)
def test_a_wrong_value_in_a_model_table_is_a_located_error_or_reads(tmp_path, name, line, key, rep):
    text = (ROOT / "studies" / f"{name}.toml").read_text("utf-8").replace('"../', f'"{ROOT}/')
    lines = text.splitlines()
    lines[line] = f"{key} = {rep}"
    path = write(tmp_path / f"{name}.toml", "\n".join(lines) + "\n")
    try:
        load_study(path, execute=False)
    except InputError as e:
        # located: the key, or where the changed value shows (an output renamed "ten" that a requirement names); an
        # analysis' input file named "ten" that is not there (or not a table) is named by its own path
        assert e.file and e.key and (e.key != "-" or Path(e.file).name == "ten"), (e.file, e.key, e.reason)
