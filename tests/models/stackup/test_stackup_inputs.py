"""Bad input in the stack-up's data files: one line `rvtol: error: FILE: KEY: reason`, exit code 2.

Each case copies the real RV crank-chain study (assembly, spec, design, study) into a temp folder,
breaks one thing and runs `rvtol check` on it.
"""
import re

import pytest

from rvtol.cli import main

from conftest import ROOT, needs_wing

SOURCES = {
    "assembly.toml": ROOT / "data/assemblies/rv_crank_chain.toml",
    "spec.toml": ROOT / "data/specs/stackup_rv_crank_chain.toml",
    "design.toml": ROOT / "data/designs/rv80e_te.toml",
}
STUDY = """
[study]
name = "t"
design = "design.toml"
spec = "spec.toml"
[model]
kind = "stackup"
assembly = "assembly.toml"
sequence = "carrier_first"
[[analysis]]
kind = "stackup_linear"
[[analysis]]
kind = "stackup_sequences"
"""


def setup(tmp_path, file=None, old=None, new=None, study=STUDY):
    texts = {name: p.read_text(encoding="utf-8") for name, p in SOURCES.items()}
    texts["study.toml"] = study
    if file is not None:
        assert old in texts[file], f"test setup: {old!r} not in {file}"
        texts[file] = texts[file].replace(old, new, 1)
    for name, t in texts.items():
        (tmp_path / name).write_text(t, encoding="utf-8")
    return tmp_path / "study.toml"


def check(path, capsys):
    code = main(["check", str(path)])
    err = capsys.readouterr().err.strip()
    return code, err


def test_valid_copy_passes(tmp_path, capsys):
    code, err = check(setup(tmp_path), capsys)
    assert code == 0, err


CASES = [
    # (file, old, new, file named in the message, key pattern, reason pattern)
    ("assembly.toml", 'base = "carrier.crank_hole_1"', 'base = "carrier.crank_hole_9"',
     "assembly.toml", r"fit\[1\]\.base", "unknown feature"),
    ("assembly.toml", 'name = "needle_1"\nbase = "crank_1.eccentric"\nmate = "cycloid.crank_hole_1"\ntype = "Mgg"',
     'name = "needle_1"\nbase = "crank_1.eccentric"\nmate = "cycloid.crank_hole_1"\ntype = "MgD"',
     "assembly.toml", r"fit\[3\]\.type", "declared MgD but the features make it Mgg"),
    ("assembly.toml", 'name = "pin_axis"\ndatum = true', 'name = "pin_axis"\ndatum = true\nz = 1.0',
     "assembly.toml", r"part\[0\]\.feature\[0\]\.datum", "origin and rotation must be zero"),
    ("assembly.toml", 'name = "crank_hole_2"\nradius = "crank_radius"\nangle = 120',
     'name = "crank_hole_2"\nradius = "crank_radius"\nangle = 121',
     "assembly.toml", r"fit\[", "nominal geometry does not close"),
    ("assembly.toml", 'length = "crank_bearing_span"', 'length = "crank_span"',
     "assembly.toml", r"deviation\[0\]\.length", "unknown dimension 'crank_span'"),
    ("assembly.toml", 'eccentricity = { design = "cycloid.eccentricity"', 'eccentricity = { design = "cycloid.eccentric"',
     "assembly.toml", r"dimensions\.eccentricity\.design", "has no parameter"),
    ("assembly.toml", 'needle_clearance = { value = 0.010, unit = "mm"', 'needle_clearance = { value = 0.010, unit = "N"',
     "assembly.toml", r"dimensions\.needle_clearance", "length or an angle"),
    ("assembly.toml", '{ part = "crank_2", by = "crank_bearing_2" },\n]\n\n[[sequence]]',
     '{ part = "crank_2", by = "crank_bearing_2" },\n  { part = "crank_1", by = "crank_bearing_1" },\n]\n\n[[sequence]]',
     "assembly.toml", r"sequence\[0\]\.steps\[4\]\.part", "placed twice"),
    ("assembly.toml", '{ part = "cycloid", by = "needle_1" },\n  { part = "crank_2", by = "crank_bearing_2" },',
     '{ part = "cycloid", by = "needle_1" },', "assembly.toml", r"sequence\[0\]\.steps", "never placed"),
    ("assembly.toml", '{ part = "crank_1", by = "needle_1" },', '{ part = "crank_1", by = "crank_bearing_2" },',
     "assembly.toml", r"sequence\[1\]\.steps\[1\]\.by", "does not touch part 'crank_1'"),
    ("assembly.toml", 'components = ["radial", "tilt", "u"]', 'components = ["radial", "twist", "u"]',
     "assembly.toml", r"kc\[0\]\.components", "unknown component 'twist'"),
    ("assembly.toml", 'float = "uniform"', 'float = "random"', "assembly.toml", r"fit\[3\]\.float", "unknown value"),
    ("assembly.toml", 'name = "main_seats"\ndescription',
     'name = "main_seats"\nform = "housing.main_seats.form"\ndescription',
     "assembly.toml", r"fit\[0\]\.clearance", "acts only through"),
    ("spec.toml", 'name = "housing.main_seats.coaxiality.x1"', 'name = "housing.main_seats.coaxiality.z1"',
     "spec.toml", "factor", "unknown factor name 'housing.main_seats.coaxiality.z1'"),
    ("spec.toml", 'name = "needle_1.a1"\nunit = "1"\ndist = "uniform"\nlower = -1.0',
     'name = "needle_1.a1"\nunit = "1"\ndist = "uniform"\nlower = -1.5',
     "spec.toml", "factor 'needle_1.a1'", "normalised clearance disc"),
    ("spec.toml", 'name = "carrier.crank_hole_1.position.x1"\nunit = "um"\ndist = "normal"\nsigma = 1.7445',
     'name = "carrier.crank_hole_1.position.x1"\nunit = "um"\ndist = "normal"\nsigma = 2.5',
     "spec.toml", "factor 'carrier.crank_hole_1.position.x1'", "leaves the axis zone"),
    ("spec.toml", 'name = "crank_1.eccentric.size"\nunit = "um"', 'name = "crank_1.eccentric.size"\nunit = "arcsec"',
     "spec.toml", "factor.unit", "expects a length"),
    ("study.toml", 'sequence = "carrier_first"', 'sequence = "pins_first"',
     "study.toml", r"model\.sequence", "unknown sequence 'pins_first'"),
    ("study.toml", 'sequence = "carrier_first"', 'sequence = "carrier_first"\nrotation = "euler"',
     "study.toml", r"model\.rotation", "unknown value 'euler'"),
    ("study.toml", 'sequence = "carrier_first"', 'sequence = "carrier_first"\n[model.floats]\nneedle_1 = "worst"',
     "study.toml", r"model\.floats\.needle_1", "unknown value 'worst'"),
    ("study.toml", 'sequence = "carrier_first"', 'sequence = "carrier_first"\noutputs = ["cycloid_axis.twist"]',
     "study.toml", "outputs", "unknown output 'cycloid_axis.twist'"),
    ("study.toml", 'kind = "stackup_sequences"', 'kind = "stackup_sequences"\nsequences = ["carrier_first"]',
     "study.toml", r"analysis\[1\]\.sequences", "at least 2"),
    ("study.toml", 'kind = "stackup_linear"', 'kind = "stackup_linear"\nfigures = ["crank_axis.wobble"]',
     "study.toml", r"analysis\[0\]\.figures", "not among the analysed outputs"),
]


@pytest.mark.parametrize("file,old,new,where,key,reason", CASES, ids=[f"{c[0]}:{c[5][:30]}" for c in CASES])
def test_bad_input_is_one_line_with_file_and_key(tmp_path, capsys, file, old, new, where, key, reason):
    code, err = check(setup(tmp_path, file, old, new), capsys)
    assert code == 2, err
    assert err.count("\n") == 0 and err.startswith("rvtol: error: "), err
    m = re.match(r"rvtol: error: (.+?): (.+?): (.+)$", err)
    assert m, err
    assert m.group(1).endswith(where), err
    assert re.search(key, m.group(2)), err
    assert reason in m.group(3), err


def test_missing_float_factors_when_a_clearance_fit_locates(tmp_path, capsys):
    spec = SOURCES["spec.toml"].read_text(encoding="utf-8")
    cut = spec.index('[[factor]]\nname = "needle_1.a1"')
    end = spec.index('[[factor]]\nname = "pin_ring.a1"')
    path = setup(tmp_path)
    (tmp_path / "spec.toml").write_text(spec[:cut] + spec[end:], encoding="utf-8")
    code, err = check(path, capsys)
    assert code == 2 and "spec.toml" in err and "needs factor 'needle_1.a1'" in err, err
    # the pin-ring float locates only in the other sequence, which stackup_sequences builds: still the spec's fault
    setup(tmp_path)
    (tmp_path / "spec.toml").write_text(spec[:spec.index('[[factor]]\nname = "pin_ring.a1"')], encoding="utf-8")
    code, err = check(path, capsys)
    assert code == 2 and err.startswith(f"rvtol: error: {tmp_path / 'spec.toml'}: factor: "), err
    assert "sequence 'cycloid_first'" in err and "needs factor 'pin_ring.a1'" in err, err
    # a worst-case float needs only the direction factors, and a linearisation refuses it
    study = STUDY.replace('sequence = "carrier_first"', 'sequence = "carrier_first"\n[model.floats]\nneedle_1 = "worst_tilt"')
    setup(tmp_path, study=study)
    code, err = check(tmp_path / "study.toml", capsys)
    assert code == 2 and "analysis[0].kind" in err and "not differentiable" in err, err


SHAFT_HOLE = (ROOT / "studies/stackup_shaft_hole.toml").read_text(encoding="utf-8").replace(
    '"../data/', f'"{ROOT.as_posix()}/data/')


@pytest.mark.parametrize("old,new,key,reason", [
    ('t1 = 0.0\nt2 = 0.020', 't1 = 0.030\nt2 = 0.020', r"analysis\[3\]\.domain\[2\]\.t2", "t1 < t2"),
    # the reproduction wing's planar zone (doc 003's printed formulas): its own keys, located the same way
    ('t1 = 0.0, t2 = 0.020', 't1 = 0.030, t2 = 0.020', r"analysis\[0\]\.planar_zone\.t2", "t1 < t2"),
    ('length = 40.0, width', 'length = -40.0, width', r"analysis\[0\]\.planar_zone\.length", "> 0"),
    ('width = 25.0 }', 'width = 25.0, widht = 3 }', r"analysis\[0\]\.planar_zone\.widht", "unknown key"),
])
@needs_wing
def test_bad_shaft_hole_analysis_tables(tmp_path, capsys, old, new, key, reason):
    """Errors found by the analyses' own checks still name the study file and the full key."""
    assert old in SHAFT_HOLE
    path = tmp_path / "study.toml"
    path.write_text(SHAFT_HOLE.replace(old, new, 1), encoding="utf-8")
    code, err = check(path, capsys)
    assert code == 2 and err.count("\n") == 0, err
    m = re.match(r"rvtol: error: (.+?): (.+?): (.+)$", err)
    assert m and m.group(1).endswith("study.toml") and re.fullmatch(key, m.group(2)) and reason in m.group(3), err


@needs_wing
def test_bad_printed_figure_names_the_data_file(tmp_path, capsys):
    """A printed figure whose unit does not fit its comparison: the data file and the figure's key."""
    data = (ROOT / "data/reproduction/doc003_stackup.toml").read_text(encoding="utf-8")
    old = 'printed = "0.0573"\nunit = "deg"'
    assert old in data
    bad = tmp_path / "printed.toml"
    bad.write_text(data.replace(old, 'printed = "0.0573"\nunit = "mm"'), encoding="utf-8")
    path = tmp_path / "study.toml"
    path.write_text(SHAFT_HOLE.replace(f'"{ROOT.as_posix()}/data/reproduction/doc003_stackup.toml"',
                                       f'"{bad.as_posix()}"'), encoding="utf-8")
    code, err = check(path, capsys)
    assert code == 2 and err.count("\n") == 0, err
    m = re.match(r"rvtol: error: (.+?): (.+?): (.+)$", err)
    assert m and m.group(1).endswith("printed.toml") and m.group(2) == "figure.tilt.unit" and "angle" in m.group(3), err
