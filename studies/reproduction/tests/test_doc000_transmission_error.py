"""Doc 000: the transmission-error study names the reproduction beside the library's analyses."""
from pathlib import Path

import pytest

pytest.importorskip("rvtol_reproduction", reason="the reproduction wing is not installed "
                                                  "(python -m pip install -e studies/reproduction)")

from rvtol.study import load_study

ROOT = Path(__file__).resolve().parents[3]   # the repository


def test_the_rv80e_study_loads():
    st = load_study(ROOT / "studies/transmission_error_rv80e.toml")
    assert st.model.inputs == st.spec.names and len(st.spec.names) == 35
    kinds = [type(a).__name__ for a in st.analyses]
    assert "TEReproduction" in kinds and "TECurve" in kinds   # doc 000's §3–4 study (a TESensitivity)
