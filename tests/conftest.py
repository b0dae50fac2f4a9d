import importlib.metadata
import importlib.util
import os
import sys
import textwrap
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

# --------------------------------------------------------------------------- the reproduction wing
# The core suite passes without the wing (studies/reproduction, a plug-in distribution; its own tests are in
# studies/reproduction/tests): what needs it skips with a reason when it is not installed.  RVTOL_TESTS_WITHOUT_WING=1
# runs the suite as if it were not installed, in this process and its xdist workers (the studies' subprocesses load
# no conftest and still see it).

#: the wing's package and the analysis kinds it registers (rvtol.analyses entry points)
WING_PACKAGE = "rvtol_reproduction"
WING_KINDS = frozenset({"transmission_error_reproduction", "lost_motion_reproduction", "adjustment_reproduction",
                        "stackup_shaft_hole", "stiffness_reproduction"})
WITHOUT_WING = "the reproduction wing is not installed (python -m pip install -e studies/reproduction)"


def hide_the_wing() -> None:
    """Make this process see an environment without the wing: its package cannot be imported (``sys.modules``
    holds None for it) and :func:`importlib.metadata.entry_points` selects none of its entry points (the registry
    selects by group; the unselected form, Python 3.11's dict of groups, is passed through)."""
    sys.modules[WING_PACKAGE] = None
    listed = importlib.metadata.entry_points

    def entry_points(**selection):
        if not selection:
            return listed()
        return importlib.metadata.EntryPoints(ep for ep in listed(**selection)
                                              if ep.module.split(".")[0] != WING_PACKAGE)

    importlib.metadata.entry_points = entry_points


if os.environ.get("RVTOL_TESTS_WITHOUT_WING"):
    hide_the_wing()


def wing_installed() -> bool:
    return importlib.util.find_spec(WING_PACKAGE) is not None


def names_a_wing_kind(study: Path) -> bool:
    """Whether a study file's ``[[analysis]]`` tables name a kind of the wing."""
    data = tomllib.loads(study.read_text(encoding="utf-8"))
    return any(t.get("kind") in WING_KINDS for t in data.get("analysis", []))


#: the mark of a test that needs the wing installed
needs_wing = pytest.mark.skipif(not wing_installed(), reason=WITHOUT_WING)


def study_param(study: Path, id: str | None = None):
    """``study`` as a pytest parameter, skipped with the reason when it names a wing kind and the wing is absent."""
    skip = pytest.mark.skipif(not wing_installed() and names_a_wing_kind(study), reason=WITHOUT_WING)
    return pytest.param(study, marks=skip, id=id or study.stem)

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


# The a − b study of the input and output tests: two ±0.05-mm drawing tolerances, y = a − b (6 ± 0.2 mm holds for
# every sample: σ_y = 0.0236 mm).
AB_SPEC_CSV = "name,nominal,tolerance,unit\na,10,±0.05,mm\nb,4,±0.05,mm\n"
AB_FACTORS = ('[[factor]]\nname = "a"\nunit = "mm"\nnominal = 10\ntolerance = "±0.05"\n'
              '[[factor]]\nname = "b"\nunit = "mm"\nnominal = 4\ntolerance = "±0.05"\n')


def ab_requirement(name: str = '"gap"', output: str = "y") -> str:
    """A ``[[requirement]]`` on y within 6 ± 0.2 mm at yield 0.9 (``name`` as TOML: quoted)."""
    return (f'[[requirement]]\nname = {name}\noutput = "{output}"\nlower = 5.8\nupper = 6.2\nunit = "mm"\n'
            'min_yield = 0.9\n')


def ab_study(name: str = "s", *, head: str = "", spec: str | None = None, output: str = "y", requirements: str = "",
             n: int = 300, seed: int | None = None) -> str:
    """The a − b study as TOML: its factors in the study (or ``spec``, a spec file beside it), ``head`` lines in its
    [study] table, output ``output``, the ``requirements`` tables; serial, no PDF."""
    study = f'[study]\nname = "{name}"\n' + (f'spec = "{spec}"\n' if spec else "") + (head + "\n" if head else "")
    sampling = f"[sampling]\nn = {n}\n" + (f"seed = {seed}\n" if seed is not None else "")
    return (study + ("" if spec else AB_FACTORS)
            + f'[model]\nkind = "formula"\n[[model.output]]\nname = "{output}"\nformula = "a - b"\nunit = "mm"\n'
            + requirements + sampling + '[execution]\nexecutor = "serial"\n[report]\npdf = false\n')


#: a BX40E study head ({root}: the repository), shared by the adjusted-assembly tests
#: (tests/models/adjustment/test_adjustment_inputs.py, tests/allocation/test_allocation_study.py)
BX40E_STUDY_HEAD = textwrap.dedent("""
    [study]
    name = "adj"
    design = "{root}/data/designs/bx40e.toml"
    spec = "{root}/data/specs/bx40e_assembly_2d.toml"
    [model]
    kind = "adjusted_assembly"
    assembly = "{root}/data/assemblies/bx40e_2d.toml"
    [sampling]
    n = 100
    seed = 3
""")


def run_cli(args, capsys) -> tuple[int, list[str]]:
    """``rvtol args``: its exit code and the lines it wrote to stderr."""
    from rvtol.cli import main

    rc = main([str(a) for a in args])
    return rc, capsys.readouterr().err.strip().splitlines()


def assert_refused(spec_path: Path, study_path: Path, capsys, key: str, words: str) -> None:
    """The spec at ``spec_path`` is refused at ``key`` with ``words`` in the reason, and ``rvtol check`` of the study
    that reads it says so in one located line with exit code 2."""
    from rvtol.errors import InputError
    from rvtol.spec import load_spec

    with pytest.raises(InputError) as ei:
        load_spec(spec_path)
    assert ei.value.key == key and words in ei.value.reason, (ei.value.key, ei.value.reason)
    rc, err = run_cli(["check", study_path], capsys)
    assert rc == 2 and len(err) == 1 and spec_path.name in err[0] and words in err[0], err


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
    from rvtol.models.reducer_20dof.geometry import geometry_from_design
    return geometry_from_design(te_design)
