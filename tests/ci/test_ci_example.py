"""The documented CI examples (studies/ci/: a GitHub Actions workflow and a GitLab job) parse, name the same
rvtol commands, and those commands do what the comments say on a tiny study: run the baseline tree's study,
then sign the change off against it with JUnit and Markdown outputs, failing the job when a gate fails."""
import os
import stat
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import yaml

from conftest import GAP_MODEL, ROOT, gap_factors

CI = ROOT / "studies" / "ci"


STUDY = """
[study]
name = "tiny"
spec = "../data/tiny_spec.toml"
""" + GAP_MODEL + """[sampling]
n = 3000
method = "lhs"
seed = 3
[[requirement]]
output = "gap"
upper = 25.0
unit = "um"
min_yield = 0.99
[[gate]]
kind = "requirements"
[[gate]]
kind = "output"
output = "gap"
statistic = "P99.865"
max_increase = 0.5
"""


def github_commands() -> tuple[dict, list[str]]:
    wf = yaml.safe_load((CI / "github-actions.yml").read_text())
    steps = wf["jobs"]["signoff"]["steps"]
    trigger = wf.get("on", wf.get(True))  # YAML 1.1 reads the key `on` as true
    assert "pull_request" in trigger
    return wf["env"], [s["run"].strip() for s in steps if "rvtol " in s.get("run", "")]


def gitlab_commands() -> tuple[dict, list[str]]:
    job = yaml.safe_load((CI / "gitlab-ci.yml").read_text())["tolerance-signoff"]
    assert job["artifacts"]["reports"]["junit"] == "reports/junit.xml"
    return job["variables"], [line.strip() for line in job["script"] if "rvtol " in line]


def test_both_examples_parse_and_name_the_same_commands():
    genv, gh = github_commands()
    lenv, gl = gitlab_commands()
    assert len(gh) == 2 and [" ".join(c.split()) for c in gh] == [" ".join(c.split()) for c in gl]
    assert genv["STUDY"] == lenv["STUDY"] and (ROOT / genv["STUDY"]).exists()
    assert "--baseline reports/baseline" in gh[1] and "--junit reports/junit.xml" in gh[1]


def tree(root: Path, T: float) -> None:
    (root / "studies").mkdir(parents=True)
    (root / "data").mkdir()
    (root / "studies" / "tiny.toml").write_text(STUDY)
    (root / "data" / "tiny_spec.toml").write_text(gap_factors(T))


def shim(tmp_path: Path) -> Path:
    """A ``rvtol`` command on PATH that runs this checkout (the editable install may point elsewhere)."""
    bin_ = tmp_path / "bin"
    bin_.mkdir()
    exe = bin_ / "rvtol"
    exe.write_text(f'#!/bin/sh\nexec "{sys.executable}" -m rvtol "$@"\n')
    exe.chmod(exe.stat().st_mode | stat.S_IXUSR)
    return bin_


@pytest.mark.parametrize("system,T_new,signoff_rc", [("github", 36.0, 1), ("gitlab", 24.0, 0)])
def test_the_commands_run_on_a_tiny_study(tmp_path, system, T_new, signoff_rc):
    """GitHub: a loosened tolerance fails the P99.865 gate (job fails); GitLab: a tightened one passes."""
    tree(tmp_path / "base", 30.0)      # what `git worktree add $BASE_TREE origin/main` would check out
    tree(tmp_path / "repo", T_new)     # the pull request
    _, commands = github_commands() if system == "github" else gitlab_commands()
    env = dict(os.environ, STUDY="studies/tiny.toml", BASE_TREE=str(tmp_path / "base"),
               PATH=f"{shim(tmp_path)}{os.pathsep}{os.environ['PATH']}",
               PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    env.pop("GITHUB_STEP_SUMMARY", None)
    codes = []
    for i, cmd in enumerate(commands):  # each step as its CI system runs it: bash, stop on error
        if system == "github":  # GitHub gives every step its own summary file
            env["GITHUB_STEP_SUMMARY"] = str(tmp_path / f"step_summary_{i}.md")
        r = subprocess.run(["bash", "-eo", "pipefail", "-c", cmd], cwd=tmp_path / "repo", env=env,
                           capture_output=True, text=True, timeout=300)
        codes.append(r.returncode)
        assert r.returncode in (0, 1), (cmd, r.stderr)
    assert codes == [0, signoff_rc]
    reports = tmp_path / "repo" / "reports"
    assert (reports / "baseline" / "summary.json").exists() and (reports / "signoff" / "comparison.json").exists()
    suite = ET.parse(reports / "junit.xml").getroot().find("testsuite")
    names = [c.get("name") for c in suite.iter("testcase")]
    assert names == ["gap ≤ 25 µm", "no requirement may get worse", "P99.865 of gap may not grow by more than 0.5 µm"]
    assert suite.get("failures") == str(signoff_rc)
    md = (reports / "signoff.md").read_text()
    assert "Against the baseline" in md and "**paired** on common random numbers" in md
    if system == "github":
        assert (tmp_path / "step_summary_1.md").read_text().strip() == md.strip()
