"""Every data file and study in the repository loads and validates (no physics is run)."""

import pytest

from rvtol.cli import main
from rvtol.spec import load_requirements, load_spec

from conftest import ROOT, study_param


@pytest.mark.parametrize("path", sorted((ROOT / "data" / "specs").glob("*.toml")), ids=lambda p: p.name)
def test_every_spec_loads(path):
    spec = load_spec(path)
    assert len(spec) > 0
    for f in spec.factors:
        assert f.dist.std > 0, f.name


@pytest.mark.parametrize("path", sorted((ROOT / "data" / "requirements").glob("*.toml")), ids=lambda p: p.name)
def test_every_requirements_file_loads(path):
    assert load_requirements(path)


@pytest.mark.parametrize("path", [study_param(p, p.name) for p in sorted((ROOT / "studies").glob("*.toml"))])
def test_every_study_validates(path, capsys):
    assert main(["check", str(path)]) == 0
    assert ": ok" in capsys.readouterr().out
