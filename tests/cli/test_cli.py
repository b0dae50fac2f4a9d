"""The CLI end to end on the first study: files written, PDF valid, summary consistent, exit codes."""
import hashlib
import json
import re
import subprocess
import sys

import pandas as pd
import pytest

from rvtol import __version__
from rvtol.cli import main

from conftest import ROOT


@pytest.fixture(scope="module")
def linear_run(tmp_path_factory):
    root = ROOT
    out = tmp_path_factory.mktemp("rep") / "linear"
    rc = main(["run", str(root / "studies" / "linear_stackup.toml"), "--out", str(out), "--n", "4000",
               "--executor", "process", "--workers", "2", "--quiet"])
    return root, out, rc


def test_linear_study_passes_and_writes_everything(linear_run):
    root, out, rc = linear_run
    assert rc == 0
    for f in ("summary.json", "samples.parquet", "report.html", "report.pdf"):
        assert (out / f).stat().st_size > 0, f
    pdf = (out / "report.pdf").read_bytes()
    assert pdf.startswith(b"%PDF-") and b"%%EOF" in pdf[-1024:]


def test_summary_format_and_values(linear_run):
    root, out, _ = linear_run
    s = json.loads((out / "summary.json").read_text())
    assert s["format"] == "rvtol-summary/1" and s["rvtol_version"] == __version__
    assert s["study"] == "linear_stackup" and s["n"] == 4000 and s["seed"] == 20261121
    # input hashes are the files' own SHA-256
    for role in ("study", "spec", "requirements"):
        p = s["inputs"][role]["path"]
        assert s["inputs"][role]["sha256"] == hashlib.sha256(open(p, "rb").read()).hexdigest()
    o = s["outputs"]["axial_clearance"]
    assert o["unit"] == "um" and o["n"] == 4000 and o["failed"] == 0
    # closed form: mean 94 µm, σ = sqrt(3.5² + 2·1.8333²·1.5) µm
    assert o["mean"] == pytest.approx(94.0, abs=4 * 4.73 / 4000**0.5)
    sigma = (3.5**2 + 2 * (0.011 / 6 * 1e3) ** 2 * 1.5) ** 0.5  # closed form, µm (normal: s.e. of s = σ/√(2n))
    assert abs(o["std"] - sigma) < 4 * sigma / (2 * 4000) ** 0.5
    assert o["percentiles"]["P0.135"]["ci"][0] < o["percentiles"]["P0.135"]["value"]
    req = o["requirements"][0]
    assert req["passed"] is True and req["yield"] == 1.0 and s["verdict"] == "PASS"
    samples = pd.read_parquet(out / "samples.parquet")
    assert len(samples) == 4000 and "axial_clearance [um]" in samples.columns and "status" in samples.columns
    assert samples["axial_clearance [um]"].mean() == pytest.approx(o["mean"])


def test_html_escapes_names_from_input_files(tmp_path, root):
    spec = tmp_path / "spec.toml"
    spec.write_text('[[factor]]\nname = "a"\nunit = "um"\ndist = "normal"\nsigma = 1.0\n'
                    'group = "<script>alert(1)</script>"\n')
    study = tmp_path / "s.toml"
    study.write_text('[study]\nname = "esc"\ntitle = "<b>bold</b> & co"\nspec = "spec.toml"\n'
                     '[model]\nkind = "linear"\n[[model.output]]\nname = "y"\nunit = "mm"\n'
                     'coefficients = { a = 1.0 }\n[sampling]\nn = 200\n')
    out = tmp_path / "out"
    # no requirement: verdict NO REQUIREMENTS, exit 4 (the report is still written)
    assert main(["run", str(study), "--out", str(out), "--no-pdf", "--executor", "serial", "--quiet"]) == 4
    html = (out / "report.html").read_text()
    assert "<script>alert(1)</script>" not in html and "&lt;script&gt;" in html
    assert "<b>bold</b>" not in html


def test_failing_requirement_exits_1(tmp_path, root):
    req = tmp_path / "req.toml"
    req.write_text('[[requirement]]\noutput = "axial_clearance"\nlower = 50\nupper = 100\nunit = "um"\n'
                   'min_cpk = 1.33\n')
    text = (root / "studies" / "linear_stackup.toml").read_text()
    text = text.replace('"../data/requirements/rv80e_axial_stack.toml"', f'"{req}"')
    text = text.replace('"../data/specs/', f'"{root}/data/specs/')
    study = tmp_path / "s.toml"
    study.write_text(text)
    out = tmp_path / "out"
    rc = main(["run", str(study), "--out", str(out), "--n", "2000", "--no-pdf", "--executor", "serial",
               "--quiet"])
    assert rc == 1
    s = json.loads((out / "summary.json").read_text())
    assert s["verdict"] == "FAIL"
    assert "Cpk" in s["outputs"]["axial_clearance"]["requirements"][0]["reasons"][0]


def test_version_and_kinds():
    r = subprocess.run([sys.executable, "-m", "rvtol", "--version"], capture_output=True, text=True)
    assert r.returncode == 0 and r.stdout.strip() == f"rvtol {__version__}"
    r = subprocess.run([sys.executable, "-m", "rvtol", "kinds"], capture_output=True, text=True)
    assert r.returncode == 0 and "linear" in r.stdout


def test_a_reader_that_stops_reading_is_no_internal_error():
    """``rvtol kinds | head -1``: the pipe's reader closed before rvtol wrote — a shell's SIGPIPE exit (141), no
    'internal error' and no traceback (the read end is closed before the child has imported rvtol)."""
    p = subprocess.Popen([sys.executable, "-m", "rvtol", "kinds", "transmission_error"], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    p.stdout.close()
    err = p.stderr.read()
    assert p.wait(timeout=120) == 141 and err == "", err


def test_model_kinds_list_their_keys(capsys):
    """``rvtol kinds KIND`` lists a model kind's keys from its declared options, and both kinds of a name two use."""
    assert main(["kinds", "stackup"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("stackup (model):") and "  assembly (file; required)" in out and "  rotation (str; " in out
    assert main(["kinds", "torsion_curve"]) == 0
    out = capsys.readouterr().out
    assert "torsion_curve (model):" in out and "torsion_curve (analysis):" in out and "  friction (bool; " in out


def test_the_study_tables_list_their_keys(capsys):
    """``rvtol kinds`` names the study's own tables; ``rvtol kinds requirement`` lists [[requirement]]'s keys with
    their rules, as ``rvtol kinds sampling`` does [sampling]'s."""
    assert main(["kinds"]) == 0
    out = capsys.readouterr().out
    assert "  the study:" in out and "study, sampling, execution, report, requirement, gate\n" in out
    assert "  a build file:" in out and "build, fit, shim, choice\n" in out
    assert main(["kinds", "study"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("[study]: the study's name and the files it reads") and "  design (file, optional" in out
    assert "  spec (list of str or file, optional; default None; at least 1)" in out
    assert main(["kinds", "requirement"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("[[requirement]]: a limit on one output") and "  output (str; required)" in out
    assert "  name (str; default ''; one line)" in out and "  min_cpk (float, optional; default None; > 0)" in out
    assert main(["kinds", "sampling"]) == 0
    assert capsys.readouterr().out.startswith("[sampling]: how many samples")


def test_check_validates_without_running(root, capsys):
    assert main(["check", str(root / "studies" / "linear_stackup.toml")]) == 0
    assert "ok" in capsys.readouterr().out


def test_readme_quick_start_and_ci_agree(root):
    """README opens with exactly two commands; .ci/run runs the second one verbatim."""
    readme = (root / "README.md").read_text()
    blocks = re.findall(r"```(?:sh|bash)?\n(.*?)```", readme, flags=re.S)
    first_two = [b.strip() for b in blocks[:2]]
    assert len(first_two) == 2 and all("\n" not in b for b in first_two), first_two
    study_cmd, test_cmd = first_two
    assert re.search(r"rvtol run studies/\S+\.toml", study_cmd)
    main_study = re.search(r"rvtol run (studies/\S+\.toml)", study_cmd).group(1)
    assert (root / main_study).exists()
    assert "pytest" in test_cmd
    ci = (root / ".ci" / "run").read_text()
    assert test_cmd in ci.splitlines(), "the README's test command must appear verbatim in .ci/run"


def _linear_args(root, out):
    return ["run", str(root / "studies" / "linear_stackup.toml"), "--out", str(out), "--n", "2000",
            "--no-pdf", "--executor", "serial", "--quiet"]


def test_out_never_replaces_a_folder_that_is_not_a_report(tmp_path, root, capsys):
    out = tmp_path / "precious"
    out.mkdir()
    (out / "thesis.txt").write_text("years of work")
    assert main(_linear_args(root, out)) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"rvtol: error: {out}: --out: exists and is not an rvtol report folder")
    assert (out / "thesis.txt").read_text() == "years of work"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".precious")]


def test_out_replaces_an_earlier_report_and_keeps_normal_permissions(tmp_path, root):
    import os
    import stat

    out = tmp_path / "rep"
    assert main(_linear_args(root, out)) == 0
    first = (out / "summary.json").read_text()
    assert main(_linear_args(root, out) + ["--seed", "7"]) == 0
    assert (out / "summary.json").read_text() != first
    mask = os.umask(0)
    os.umask(mask)
    assert stat.S_IMODE(out.stat().st_mode) == 0o777 & ~mask
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rep"]  # no temporary or old folders left


def test_out_refuses_the_current_folder(tmp_path, root, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "keep.txt").write_text("x")
    assert main(_linear_args(root, ".")) == 2
    assert "refusing to replace the current folder" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.txt"]


def test_script_without_main_guard_gets_a_clear_message(tmp_path):
    script = tmp_path / "study_script.py"
    script.write_text(
        "import numpy as np\n"
        "from rvtol import make_executor, evaluate\n"
        "from rvtol.testing import TrivialModel\n"
        "with make_executor('process', 2) as ex:\n"
        "    evaluate(TrivialModel(3), np.zeros((100, 3)), ex, chunk_size=10, progress=False)\n")
    r = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert r.returncode != 0
    assert 'if __name__ == "__main__":' in r.stderr


def test_a_table_whose_docstring_wraps_or_quotes_its_name_is_listed_on_one_clean_line(capsys):
    """``rvtol kinds part``: the first paragraph of the table's docstring on one line, without reST's quotes (it
    printed ``[[part]]`` followed by two backquotes, and a wrapped first sentence cut at its line end)."""
    assert main(["kinds", "feature"]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert first.startswith("[[part.feature]] of a stack-up's assembly file: ") and "`" not in first
    assert first.endswith("(origin as radius/angle or x/y, not both).")


def test_every_table_is_listed_under_exactly_one_file():
    """``rvtol kinds`` groups the tables by the file they are in (:data:`rvtol.registry.TABLE_FILES`): each registered
    table once, nothing that is not registered."""
    from rvtol.registry import TABLE_FILES, TABLES

    listed = [t for names in TABLE_FILES.values() for t in names]
    assert sorted(listed) == sorted(TABLES) and len(listed) == len(set(listed))


def test_an_error_raised_while_a_stop_signal_unwinds_is_still_the_stop(monkeypatch, capsys):
    """A library interrupted mid-write can fail again as it unwinds (zipfile: "Can't close the ZIP file while there is
    an open writing handle"): the run was stopped by the signal — exit 143 and the stop's message, not an internal
    error (exit 3)."""
    import rvtol.cli as cli
    from rvtol.runguard import Interrupted

    def stopped_mid_write(args):
        try:
            raise Interrupted(15)
        except Interrupted:
            raise ValueError("Can't close the ZIP file while there is an open writing handle on it")

    monkeypatch.setattr(cli, "_run", stopped_mid_write)
    assert main(["run", "study.toml"]) == 143
    assert capsys.readouterr().err.startswith("rvtol: stopped by SIGTERM")
    monkeypatch.setattr(cli, "_run", lambda args: 1 / 0)        # a bug with no signal: still an internal error
    assert main(["run", "study.toml"]) == 3
