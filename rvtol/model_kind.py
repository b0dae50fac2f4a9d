"""A model kind: the keys its ``[model]`` table may hold, and what builds the model from them.

The study's ``[model]`` tables use the analyses' idiom (:mod:`rvtol.options`): a kind declares its keys as an
options dataclass — a schema only: types, defaults, rules, cross-key checks, no file I/O and no derived state —
and a ``build(options, design, spec, error)`` that loads what the keys name (an assembly file, a rig) and makes
the :class:`rvtol.model.Model`.  So ``rvtol kinds KIND`` lists a model kind's keys as it lists an analysis
kind's, the one common invalid-value test covers both, and adding a key to a model is one field::

    @dataclass
    class Options:
        percent: float = option(3.0, "± the maker's torque band, % of rated", min=0.01, max=50.0)

    def build(o: Options, design, spec, error) -> Model: ...

    from_study = ModelKind(Options, build, "the 20-DOF torsion (hysteresis) curve")

``error(key, reason)`` is the table's located one-line error (what a bad value found while building raises:
an unknown sequence of the assembly the file names, a missing design).  A plug-in's model kind may still be a
plain ``factory(params, design, spec)``: the registry calls either.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from .options import read_options


@dataclass(frozen=True)
class Where:
    """What a model table's options read from their place: the folder a relative path is taken from."""

    base_dir: Path


@dataclass(frozen=True)
class ModelKind:
    """A model kind: ``Options`` (the table's schema), ``build(options, design, spec, error)`` and its title."""

    Options: type
    build: Callable
    title: str
    #: the table's other keys belong to what the build calls (a user's factory reads them): ``build`` gets the
    #: table (:class:`rvtol.params.Params`, its ``error`` and the keys left) instead of ``error``
    open: bool = False

    def __call__(self, params, design, spec):
        """Read and check the ``[model]`` table ``params`` (every key, then no unknown one), then build."""
        options = read_options(self.Options, params, Where(Path(params.file).parent if params.file else Path(".")))
        if self.open:
            return self.build(options, design, spec, params)
        params.finish()
        return self.build(options, design, spec, params.error)


def require_design(design, error, needs: str) -> None:
    """A model kind that reads the reducer's design refuses a study without one, at ``kind`` (``needs``: e.g. "the
    torsion_curve model needs a 20-DOF design")."""
    if design is None:
        raise error("kind", f"{needs} ([study] design = ...)")


def existing(path: Path | None, key: str, error) -> Path | None:
    """A file a key names must be there (a directory or a device: its reader says what it is)."""
    if path is not None and not path.exists():
        raise error(key, f"file not found: {path}")
    return path
