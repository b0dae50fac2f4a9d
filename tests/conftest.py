import os
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

# keep BLAS single-threaded in tests: results are compared bit for bit across executors
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


# The gap study several tests share: gap = a − b (µm), a normal with tolerance T, b uniform ±5 µm.
def gap_factors(tolerance: float, mean: float | None = None) -> str:
    """The two ``[[factor]]`` tables (a spec file, or part of a study)."""
    m = "" if mean is None else f"mean = {mean}\n"
    return (f'[[factor]]\nname = "a"\nunit = "um"\ndist = "normal"\n{m}tolerance = {tolerance}\n'
            '[[factor]]\nname = "b"\nunit = "um"\ndist = "uniform"\nlower = -5.0\nupper = 5.0\n')


#: the ``[model]`` table of the gap study
GAP_MODEL = """[model]
kind = "linear"
[[model.output]]
name = "gap"
unit = "mm"
display_unit = "um"
coefficients = { a = 1.0, b = -1.0 }
"""


@pytest.fixture
def root() -> Path:
    return ROOT


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture(scope="session")
def te_design():
    """The RV-80E design of the 20-DOF transmission-error model (data/designs/rv80e_te.toml)."""
    from rvtol.design import load_design
    return load_design(ROOT / "data/designs/rv80e_te.toml")


@pytest.fixture(scope="session")
def te_geom(te_design):
    """Its solver geometry."""
    from rvtol.models.transmission.geometry import geometry_from_design
    return geometry_from_design(te_design)
