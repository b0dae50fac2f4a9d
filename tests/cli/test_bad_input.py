"""Bad input: one line `rvtol: error: FILE: KEY: reason`, exit code 2, nothing written.

Each case starts from a valid study (study.toml + spec.toml + req.toml + design.toml in a temp
folder), breaks one thing, runs the real CLI and checks the line, the code and the output folder.
"""
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rvtol.cli import main
from rvtol.errors import InputError
from rvtol.sampling import sample
from rvtol.spec import spec_from_table

from bad_input_study import DESIGN, REQ, SPEC, STUDY, run, setup


def test_the_valid_setup_runs(tmp_path, capsys):
    rc, err, out = run(tmp_path, capsys, setup(tmp_path))
    assert rc == 0, err
    assert (out / "summary.json").exists()


CASES = [
    # (id, change, expected file, expected key fragment, reason fragment)
    ("study missing", lambda s: {"study": None}, "study.toml", "-", "file not found"),
    ("invalid toml", lambda s: {"study": STUDY + "\n[[[broken"}, "study.toml", "-", "invalid TOML"),
    ("no model kind", lambda s: {"study": STUDY.replace('kind = "linear"', "")}, "study.toml", "model.kind",
     "missing required key"),
    ("unknown model kind", lambda s: {"study": STUDY.replace('"linear"', '"quadratic"')}, "study.toml",
     "model.kind", "unknown model kind"),
    ("spec missing", lambda s: {"spec": None}, "spec.toml", "-", "file not found"),
    ("spec is a directory", lambda s: {"study": STUDY.replace('"spec.toml"', '".."')}, "..", "-", "directory"),
    ("factor without unit", lambda s: {"spec": SPEC.replace('unit = "um"\ndist = "normal"', 'dist = "normal"')},
     "spec.toml", "factor[0].unit", "missing unit"),
    ("unknown unit", lambda s: {"spec": SPEC.replace('"um"', '"milimeter"', 1)}, "spec.toml", "factor[0].unit",
     "unknown unit"),
    ("unknown distribution", lambda s: {"spec": SPEC.replace('"normal"', '"gaussian"')}, "spec.toml",
     "factor[0].dist", "unknown value"),
    ("negative tolerance", lambda s: {"spec": SPEC.replace("tolerance = 30.0", "tolerance = -30.0")},
     "spec.toml", "factor[0].tolerance", "must be > 0"),
    ("zero sigma", lambda s: {"spec": SPEC.replace("tolerance = 30.0", "sigma = 0.0")}, "spec.toml",
     "factor[0].sigma", "must be > 0"),
    ("nan value", lambda s: {"spec": SPEC.replace("mean = 0.0", "mean = nan")}, "spec.toml", "factor[0].mean",
     "finite"),
    ("inf value", lambda s: {"spec": SPEC.replace("upper = 5.0", "upper = inf")}, "spec.toml",
     "factor[1].upper", "finite"),
    ("uniform bounds reversed", lambda s: {"spec": SPEC.replace("lower = -5.0", "lower = 6.0")}, "spec.toml",
     "factor[1].upper", "greater than lower"),
    ("triangular mode outside", lambda s: {"spec": SPEC.replace('"uniform"', '"triangular"').replace(
        "upper = 5.0", "upper = 5.0\nmode = 9.0")}, "spec.toml", "factor[1].mode", "outside"),
    ("duplicate factor", lambda s: {"spec": SPEC.replace('name = "b"', 'name = "a"')}, "spec.toml",
     "factor[1].name", "duplicate"),
    ("invalid factor name", lambda s: {"spec": SPEC.replace('name = "b"', 'name = ""')}, "spec.toml",
     "factor[1].name", "invalid factor name"),
    ("unknown key in factor", lambda s: {"spec": SPEC.replace("mean = 0.0", "mean = 0.0\nmaen = 1.0")},
     "spec.toml", "factor[0].maen", "unknown key"),
    ("correlation not positive definite", lambda s: {"spec": SPEC + '\n[[correlation]]\npair = ["a", "b"]\nrho = 1.0\n'},
     "spec.toml", "correlation", "positive definite"),
    ("correlation unknown factor", lambda s: {"spec": SPEC + '\n[[correlation]]\npair = ["a", "z"]\nrho = 0.5\n'},
     "spec.toml", "correlation[0].pair", "unknown factor name"),
    ("coefficient for unknown factor", lambda s: {"study": STUDY.replace("b = -1.0", "b = -1.0, c = 2.0")},
     "study.toml", "model.output[0].coefficients.c", "unknown factor name"),
    ("requirement on unknown output", lambda s: {"req": REQ.replace('"gap"', '"gpa"')}, "req.toml",
     "requirement[0].output", "unknown output name"),
    ("requirement limits reversed", lambda s: {"req": REQ.replace("upper = 40.0", "upper = 40.0\nlower = 50.0")},
     "req.toml", "requirement[0].upper", "wrong order"),
    ("requirement without limits", lambda s: {"req": REQ.replace("upper = 40.0", "")}, "req.toml",
     "requirement[0].upper", "needs 'lower' and/or 'upper'"),
    ("requirement unit of wrong dimension", lambda s: {"req": REQ.replace('"um"', '"arcsec"')}, "req.toml",
     "requirement[0].unit", "does not fit"),
    ("min_yield above 1", lambda s: {"req": REQ + "min_yield = 1.5\n"}, "req.toml", "requirement[0].min_yield",
     "(0, 1)"),
    ("unknown yield interval", lambda s: {"req": REQ + 'interval = "jeffreys"\n'}, "req.toml",
     "requirement[0].interval", "unknown value"),
    ("n of the wrong type", lambda s: {"study": STUDY.replace("n = 2000", 'n = "many"')}, "study.toml",
     "sampling.n", "expected an integer"),
    ("unknown sampling method", lambda s: {"study": STUDY.replace('"lhs"', '"halton"')}, "study.toml",
     "sampling.method", "unknown value"),
    ("typo in sampling key", lambda s: {"study": STUDY.replace("seed = 1", "seeed = 1")}, "study.toml",
     "sampling.seeed", "unknown key"),
    ("design number without source", lambda s: {"design": DESIGN.replace(', source = "doc 000 Table 1"', "")},
     "design.toml", "pin.radius.source", "missing required key"),
    ("design value not a number", lambda s: {"design": DESIGN.replace("value = 3.0", "value = true")},
     "design.toml", "pin.radius.value", "expected a number"),
    # misspelt keys and names: the typo is blamed, with the name it resembles (not the key asked for next)
    ("misspelt tolerance", lambda s: {"spec": SPEC.replace("tolerance = 30.0", "tolerence = 30.0")}, "spec.toml",
     "factor[0].tolerence", "unknown key (did you mean 'tolerance'?)"),
    ("misspelt sampling key", lambda s: {"study": STUDY.replace("seed = 1", "seeed = 1")}, "study.toml",
     "sampling.seeed", "did you mean 'seed'?"),
    ("misspelt model kind", lambda s: {"study": STUDY.replace('"linear"', '"linaer"')}, "study.toml",
     "model.kind", "unknown model kind 'linaer' (did you mean 'linear'?)"),
    ("misspelt output name", lambda s: {"req": REQ.replace('"gap"', '"gpa"')}, "req.toml",
     "requirement[0].output", "did you mean 'gap'?"),
    ("misspelt distribution", lambda s: {"spec": SPEC.replace('"uniform"', '"unifrom"')}, "spec.toml",
     "factor[1].dist", "unknown value 'unifrom' (did you mean 'uniform'?"),
    ("misspelt unit", lambda s: {"spec": SPEC.replace('"um"', '"umm"', 1)}, "spec.toml", "factor[0].unit",
     "did you mean"),
    ("misspelt coefficient name", lambda s: {"study": STUDY.replace("b = -1.0", "bb = -1.0")}, "study.toml",
     "model.output[0].coefficients.bb", "did you mean 'b'?"),
    ("empty requirements file", lambda s: {"req": "# nothing yet\n"}, "req.toml", "requirement",
     "at least one [[requirement]]"),
    ("not UTF-8", lambda s: {"study": STUDY.replace("name = \"t\"", "name = \"t\" # \udcff")}, "study.toml", "-",
     "not UTF-8"),
    ("spec given twice", lambda s: {"study": STUDY + '\n[[factor]]\nname = "x"\nunit = "um"\ndist = "normal"\nsigma = 1.0\n'},
     "study.toml", "factor", "either in the spec file or here"),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_bad_input_one_line_exit_2_nothing_written(tmp_path, capsys, case):
    _, change, efile, ekey, reason = case
    files = {"study": STUDY, "spec": SPEC, "req": REQ, "design": DESIGN}
    files.update(change(None))
    path = setup(tmp_path, files["study"], files["spec"], files["req"], files["design"])
    if files["study"] is None:
        (tmp_path / "study.toml").unlink(missing_ok=True)
    rc, err, out = run(tmp_path, capsys, path)
    assert rc == 2
    assert len(err) == 1, err
    m = re.match(r"^rvtol: error: (.+?): (\S+): (.+)$", err[0])
    assert m, err[0]
    assert m.group(1).endswith(efile), err[0]
    assert ekey in m.group(2), err[0]
    assert reason in m.group(3), err[0]
    assert not out.exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".out")]  # no temp folder left


@pytest.mark.parametrize("args,key", [(("--n", "1"), "--n"), (("--seed", "-3"), "--seed"),
                                      (("--workers", "0"), "--workers")])
def test_bad_command_line_values(tmp_path, capsys, args, key):
    rc, err, out = run(tmp_path, capsys, setup(tmp_path), *args)
    assert rc == 2 and len(err) == 1 and f": {key}: " in err[0]
    assert not out.exists()


# --------------------------------------------------------------------------- fuzzing the spec loader
_values = st.one_of(
    st.none(), st.booleans(), st.integers(-10, 10), st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8), st.sampled_from(["normal", "uniform", "truncnorm", "triangular", "rayleigh",
                                          "lognormal", "weibull", "um", "mm", "deg", "furlong"]),
    st.lists(st.floats(-5, 5), max_size=3),
)
_keys = st.sampled_from(["name", "unit", "dist", "mean", "sigma", "tolerance", "lower", "upper", "mode",
                         "median", "shape", "scale", "shift", "sigma_level", "nominal", "group", "junk"])
_factor = st.dictionaries(_keys, _values, max_size=8)


def _drop_none(d):
    return {k: v for k, v in d.items() if v is not None}


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(_factor.map(_drop_none), min_size=0, max_size=3))
def test_fuzz_spec_loader_raises_input_error_or_gives_finite_samples(factors):
    try:
        spec = spec_from_table({"factor": factors}, file="fuzz.toml")
    except InputError as exc:
        assert str(exc).startswith("fuzz.toml: ")
        return
    try:
        x = sample(spec, 64, "random", seed=0).values
    except InputError:
        return  # e.g. a distribution whose quantiles overflow: reported, not silent
    assert np.isfinite(x).all()


def test_a_utf8_byte_order_mark_is_accepted(tmp_path, capsys):
    path = setup(tmp_path)
    path.write_bytes(b"\xef\xbb\xbf" + path.read_bytes())  # what Notepad writes
    rc, err, out = run(tmp_path, capsys, path)
    assert rc == 0, err
    assert (out / "summary.json").exists()


def test_a_typo_in_a_study_cycloid_factor_blames_the_study_key(tmp_path, capsys, root):
    """The study's [[model.cycloid_factor]] names a factor the spec lacks: the study file and that key, not the spec."""
    text = (root / "studies" / "lost_motion_rv80e.toml").read_text(encoding="utf-8")
    text = text.replace('"../data/', f'"{root}/data/').replace('factor = "Delta_r_rp"', 'factor = "Delta_r_rpp"')
    study = tmp_path / "lm.toml"
    study.write_text(text, encoding="utf-8")
    rc = main(["check", str(study)])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1, err
    assert err[0].startswith(f"rvtol: error: {study}: model.cycloid_factor[0].factor: "), err[0]
    assert "'Delta_r_rpp'" in err[0] and "did you mean 'Delta_r_rp'?" in err[0]
