"""A Python model named from the study file: ``[model] kind = "python"``.

::

    [model]
    kind = "python"
    factory = "mypkg.gaps:make_model"   # module:function, called as make_model(params, design, spec)
    path = "."                          # optional: a folder (relative to the study) to import from,
                                        # e.g. for gaps.py next to the study file
    # ... the function's own keys, read from params (unread keys are reported as typos)

The function has the contract of every model factory (:mod:`rvtol.registry`): it receives the
``[model]`` table as :class:`rvtol.params.Params`, the study's Design (or None) and its
ToleranceSpec, reads its keys from ``params``, raises :class:`rvtol.errors.InputError` for bad
input and returns a :class:`rvtol.model.Model` — so Monte Carlo, sensitivity, allocation, the
report and the verdict work on it as on any built-in model.  An installed package can register
such a factory under a kind of its own (an entry point in the group ``rvtol.models``) instead.

A model imported from ``path`` is wrapped (:class:`ImportedModel`) so that worker processes
(the process and Dask executors) find its module too: unpickling puts ``path`` on ``sys.path``
before the model's own classes are looked up.
"""
from __future__ import annotations

import importlib
import pickle
import sys
from pathlib import Path

from ...errors import InputError
from ...model import Model


def resolve(reference: str, path: Path | None = None):
    """The object a ``module:attribute`` reference names (``path`` first on ``sys.path``);
    one-line :class:`InputError` when it cannot be imported or found."""
    mod, sep, attr = reference.partition(":")
    if not sep or not mod.strip() or not attr.strip():
        raise InputError(f"expected 'module:function', got {reference!r}")
    mod, attr = mod.strip(), attr.strip()
    if path is not None:
        if not path.is_dir():
            raise InputError(f"path {str(path)!r} is not a folder")
        _on_path(str(path))
    try:
        m = importlib.import_module(mod)
    except Exception as exc:  # ImportError, or an error raised while the module runs
        raise InputError(f"cannot import module {mod!r} ({type(exc).__name__}: {exc})"
                         + ("" if path is not None else "; is it installed, or give 'path' to its folder?")) from None
    obj = m
    for part in attr.split("."):
        try:
            obj = getattr(obj, part)
        except AttributeError:
            raise InputError(f"module {mod!r} has no {attr!r}") from None
    return obj


def _on_path(folder: str) -> None:
    if folder not in sys.path:
        sys.path.insert(0, folder)


def check_model(model, what: str) -> Model:
    """``model`` if it is a :class:`Model` with consistent inputs and units; else a one-line error."""
    if not isinstance(model, Model):
        raise InputError(f"{what} returned {type(model).__name__}, not an rvtol.model.Model")
    if len(tuple(model.inputs)) != len(tuple(model.input_units)):
        raise InputError(f"{what} returned a model with {len(model.inputs)} inputs but "
                         f"{len(model.input_units)} input units")
    if not model.outputs:
        raise InputError(f"{what} returned a model without outputs")
    return model


class ImportedModel(Model):
    """A model whose module is imported from a study-relative folder (see the module docstring)."""

    def __init__(self, model: Model, path: str):
        self.model, self.path = model, path
        self.inputs, self.input_units, self.outputs = tuple(model.inputs), tuple(model.input_units), tuple(model.outputs)
        self.status_reasons = dict(model.status_reasons)
        if hasattr(model, "gradient"):
            self.gradient = model.gradient

    def evaluate(self, X):
        return self.model.evaluate(X)

    def evaluate_with_status(self, X):
        return self.model.evaluate_with_status(X)

    def __reduce__(self):
        return (_restore, (self.path, pickle.dumps(self.model)))


def _restore(path: str, blob: bytes) -> ImportedModel:
    _on_path(path)
    return ImportedModel(pickle.loads(blob), path)


def from_study(params, design, spec) -> Model:
    """The study factory of ``kind = "python"`` (see the module docstring)."""
    ref = params.str("factory")
    base = Path(params.file).parent if params.file else Path(".")
    path = params.path_value("path", base, None)
    try:
        fn = resolve(ref, path)
    except InputError as exc:
        raise params.error("path" if path is not None and "is not a folder" in exc.reason else "factory",
                           exc.reason) from None
    if not callable(fn):
        raise params.error("factory", f"{ref!r} is not callable")
    model = check_model(fn(params, design, spec), f"factory {ref!r}")
    return ImportedModel(model, str(path.resolve())) if path is not None else model
