"""The wing is an installed plug-in: its kinds come from the rvtol.analyses entry points of this checkout."""
import inspect
import tomllib
from pathlib import Path

import pytest

pytest.importorskip("rvtol_reproduction", reason="the reproduction wing is not installed "
                                                  "(python -m pip install -e studies/reproduction)")

from rvtol.registry import ANALYSES, plugin_analyses

WING = Path(__file__).resolve().parents[1]
#: the kinds the wing's pyproject.toml registers
WING_KINDS = set(tomllib.loads((WING / "pyproject.toml").read_text(encoding="utf-8"))
                 ["project"]["entry-points"]["rvtol.analyses"])


def test_the_reproduction_wing_is_an_installed_plug_in():
    """The test command installs studies/reproduction; its kinds come from the rvtol.analyses entry points."""
    eps = plugin_analyses()
    assert WING_KINDS <= set(eps), "install the wing: python -m pip install -e studies/reproduction"
    for k in WING_KINDS:
        assert eps[k].value.startswith("rvtol_reproduction.analyses:") and k not in ANALYSES
        assert Path(inspect.getfile(eps[k].load())).resolve().is_relative_to(WING.resolve()), \
            "the installed wing is not this checkout's"
