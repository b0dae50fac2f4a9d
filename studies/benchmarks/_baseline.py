"""The 20-DOF kernels of an earlier commit, run beside today's in one process (the "before" columns).

The machines are shared and noisy: a speed-up is only worth quoting when the old and the new code run side by side on
the same inputs in one run.  :func:`kernels` extracts ``layout.py`` and ``_kernels.py`` of
``rvtol/models/transmission`` (where the 20-DOF kernels lived before ``rvtol/models/reducer_20dof``) at a git revision
(default :data:`BASELINE_REV`, the starting point of issue 15) into ``reports/.bench-baseline/<rev>/`` as a package of
its own and imports it (numba caches its compilation there); :class:`BaselineTEModel` is the TE model on those kernels
(picklable: process pool workers load the same package).  The call signatures are today's except ``qs_sequence``'s
predictor ``period`` (issue 15), which :class:`_Kernels` drops: the baseline extrapolates linearly, as it did.

When git or the revision is not available the benchmarks skip the "before" rows and say so.
"""
from __future__ import annotations

import importlib
import subprocess
import sys
from pathlib import Path

from rvtol.models.transmission_error.model import TransmissionErrorModel
from rvtol.models.reducer_20dof.newmark import NewmarkSolver
from rvtol.models.reducer_20dof.quasistatic import QuasiStaticSolver

ROOT = Path(__file__).resolve().parents[2]
#: the commit issue 15 started from
BASELINE_REV = "5ccaab7"
FILES = ("layout.py", "_kernels.py")


def _extract(rev: str) -> Path:
    out = ROOT / "reports" / ".bench-baseline" / rev
    pkg = out / f"rvtol_kernels_{rev}"
    if not (pkg / "_kernels.py").exists():
        pkg.mkdir(parents=True, exist_ok=True)
        for f in FILES:
            text = subprocess.run(["git", "-C", str(ROOT), "show", f"{rev}:rvtol/models/transmission/{f}"],
                                  check=True, capture_output=True, text=True).stdout
            (pkg / f).write_text(text)
        (pkg / "__init__.py").write_text(f'"""rvtol 20-DOF kernels at {rev} (benchmark baseline)."""\n')
    return out


class _Kernels:
    """An earlier kernel module called with today's signatures."""

    PERIOD = 22          # position of ``period`` in today's qs_sequence arguments

    def __init__(self, module):
        self.module = module

    def __getattr__(self, name):
        return getattr(self.module, name)

    def qs_sequence(self, *args):
        return self.module.qs_sequence(*args[:self.PERIOD], *args[self.PERIOD + 1:])


def kernels(rev: str = BASELINE_REV):
    """The kernel module at ``rev``, or None when it cannot be extracted (no git, unknown revision)."""
    try:
        path = _extract(rev)
    except (OSError, subprocess.CalledProcessError):
        return None
    if str(path) not in sys.path:
        sys.path.insert(0, str(path))
    return _Kernels(importlib.import_module(f"rvtol_kernels_{rev}._kernels"))


class BaselineSolver(QuasiStaticSolver):
    """The quasi-static solver on the baseline kernels."""

    kernels = property(lambda self: kernels())


class BaselineNewmark(NewmarkSolver):
    """Newmark-β on the baseline kernels (the initial static equilibrium on today's)."""

    kernels = property(lambda self: kernels())


class BaselineTEModel(TransmissionErrorModel):
    """The TE model on the baseline kernels, same options (quasi-static only, no test rig); Δθ_er of the sweep's
    positions, as at the baseline (no refinement of the extremes: the baseline kernels have none).

    :meth:`_sweep` has today's signature (the error state and a rig's measurement ``terms``, always None here) and
    returns no extremes, so ``_row`` takes Δθ_er as max − min of the positions' TE."""

    def _sweep(self, st, terms=None):
        sweep = BaselineSolver(self.geometry, st, **self.solver_options).rotation(self.load_torque,
                                                                                  self.per_crank_rev)
        return sweep, None, None

    @classmethod
    def of(cls, model: TransmissionErrorModel) -> "BaselineTEModel":
        """The baseline twin of ``model`` (same geometry, inputs and options)."""
        if model.mode != "quasistatic" or model.rig is not None:
            raise ValueError("the baseline TE model is quasi-static, without a test rig")
        out = cls.__new__(cls)
        out.__dict__.update(model.__dict__)
        return out
