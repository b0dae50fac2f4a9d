"""rvtol — probabilistic tolerance and Monte Carlo assembly analysis of RV reducers.

The public API: specs and designs in, Models evaluated by the Monte Carlo
engine, analyses and reports out.  The guides ship with the package: ``rvtol docs`` lists them
(``rvtol docs api`` the API); README.md of the repository gives a tour.
"""
__version__ = "0.1.0"

from .design import Design, load_design  # noqa: E402
from .distributions import Distribution  # noqa: E402
from .errors import InputError, ModelError, RvtolError, SolverError, SpecError, UnitError  # noqa: E402
from .executors import make_executor  # noqa: E402
from .mc import MonteCarloResult, evaluate, run_monte_carlo  # noqa: E402
from .model import FunctionModel, LinearModel, Model, Quantity  # noqa: E402
from .sampling import SampleSet, sample  # noqa: E402
from .spec import Factor, Requirement, ToleranceSpec, load_requirements, load_spec  # noqa: E402

__all__ = [
    "__version__",
    "Design", "load_design",
    "Distribution",
    "InputError", "ModelError", "RvtolError", "SolverError", "SpecError", "UnitError",
    "make_executor",
    "MonteCarloResult", "evaluate", "run_monte_carlo",
    "FunctionModel", "LinearModel", "Model", "Quantity",
    "SampleSet", "sample",
    "Factor", "Requirement", "ToleranceSpec", "load_requirements", "load_spec",
    "load_study", "run_study", "write_outputs",
]


def __getattr__(name):  # lazy: the study layer imports the report stack
    if name in ("load_study", "run_study", "write_outputs"):
        from . import study

        return getattr(study, name)
    raise AttributeError(name)
