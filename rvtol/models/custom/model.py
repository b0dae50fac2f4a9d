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
from dataclasses import dataclass
from pathlib import Path

from ...errors import InputError, ModelCodeError, describe_exception
from ...model import Model
from ...model_kind import ModelKind
from ...options import REQUIRED, option


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
    except ImportError as exc:  # not found, or an import inside it fails: a bad reference or installation
        raise InputError(f"cannot import module {mod!r} ({type(exc).__name__}: {exc})"
                         + ("" if path is not None else "; is it installed, or give 'path' to its folder?")) from None
    except (Exception, SystemExit) as exc:  # raised (or sys.exit) while the module's own code runs
        raise ModelCodeError(f"module {mod!r} {describe_exception(exc)} while imported", key="factory") from None
    if getattr(m, "__file__", None):
        from ...params import note_read

        note_read(m.__file__)   # the model's own file: an input of the run, which no output may replace
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
    """A model made by user code (``kind = "python"``): its module imported from ``path`` in worker processes
    too (see the module docstring), and anything its code raises — or a ``sys.exit`` — turned into a
    :class:`~rvtol.errors.ModelCodeError` naming the factory (the CLI: exit 3 with that message, never a
    silent exit 0)."""

    def __init__(self, model: Model, path: str | None, factory: str = ""):
        self.model, self.path, self.factory = model, path, factory
        self.inputs, self.input_units, self.outputs = tuple(model.inputs), tuple(model.input_units), tuple(model.outputs)
        self.status_reasons = dict(model.status_reasons)
        if hasattr(model, "gradient"):
            self.gradient = self._guarded(model.gradient)

    def _guarded(self, fn):
        def call(X):
            try:
                return fn(X)
            except (Exception, SystemExit) as exc:
                if isinstance(exc, ModelCodeError):
                    raise
                raise ModelCodeError(f"the model of factory {self.factory!r} {describe_exception(exc)}",
                                     key="model.factory") from None
        return call

    def evaluate(self, X):
        return self._guarded(self.model.evaluate)(X)

    def evaluate_with_status(self, X):
        return self._guarded(self.model.evaluate_with_status)(X)

    def __reduce__(self):
        return (_restore, (self.path, pickle.dumps(self.model), self.factory))


def _restore(path: str | None, blob: bytes, factory: str = "") -> ImportedModel:
    if path is not None:
        _on_path(path)
    return ImportedModel(pickle.loads(blob), path, factory)


@dataclass
class Options:
    """The keys rvtol reads of ``[model] kind = "python"``; the table's other keys are the factory's own."""

    factory: str = option(REQUIRED, '"module:function", called as function(params, design, spec) -> rvtol.model.Model '
                                    "(params: this table, its other keys the factory's to read)")
    path: Path | None = option(None, "the folder the module is imported from (default: the study's folder)")


def build(o: Options, design, spec, params) -> Model:
    """The study factory of ``kind = "python"`` (see the module docstring)."""
    ref, path = o.factory, o.path
    try:
        fn = resolve(ref, path)
    except InputError as exc:
        raise params.error("path" if path is not None and "is not a folder" in exc.reason else "factory",
                           exc.reason) from None
    except ModelCodeError as exc:
        raise ModelCodeError(exc.reason, file=params.file, key=params.path("factory")) from None
    if not callable(fn):
        raise params.error("factory", f"{ref!r} is not callable")
    try:
        made = fn(params, design, spec)
    except InputError:
        raise
    except (Exception, SystemExit) as exc:
        raise ModelCodeError(f"factory {ref!r} {describe_exception(exc)}", file=params.file,
                             key=params.path("factory")) from None
    model = check_model(made, f"factory {ref!r}")
    return ImportedModel(model, str(path.resolve()) if path is not None else None, ref)


from_study = ModelKind(Options, build, "a model written in Python: a factory function of the study's folder",
                       open=True)


def check_without_running(params) -> str:
    """Validate a ``kind = "python"`` model table without running any of its code: the reference's form, the
    folder, the module's source found and parsed (:mod:`ast`), the function defined at its top level.
    Returns what was checked; one-line :class:`InputError` (key ``factory``/``path``) otherwise."""
    import ast
    import importlib.machinery

    ref = params.str("factory")
    base = Path(params.file).parent if params.file else Path(".")
    path = params.path_value("path", base, None)
    mod, sep, attr = ref.partition(":")
    if not sep or not mod.strip() or not attr.strip():
        raise params.error("factory", f"expected 'module:function', got {ref!r}")
    if path is not None and not path.is_dir():
        raise params.error("path", f"path {str(path)!r} is not a folder")
    search = [str(path)] if path is not None else list(sys.path)
    source = None
    parts = mod.strip().split(".")
    for i, part in enumerate(parts):   # find the module's file without importing (executing) its packages
        spec = importlib.machinery.PathFinder.find_spec(part, search)
        if spec is None:
            raise params.error("factory", f"cannot find module {mod.strip()!r}"
                               + ("" if path is not None else "; is it installed, or give 'path' to its folder?"))
        if i < len(parts) - 1:
            search = list(spec.submodule_search_locations or [])
        else:
            source = spec.origin
    if not source or not source.endswith(".py"):
        return f"factory {ref!r}: module {mod.strip()!r} found (compiled: not parsed)"
    from ...params import read_text

    text, _ = read_text(source, "a Python module")
    try:
        tree = ast.parse(text, filename=source)
    except SyntaxError as exc:
        raise params.error("factory", f"{Path(source).name} line {exc.lineno}: {exc.msg}") from None
    top = attr.strip().split(".")[0]
    names = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef))}
    for n in tree.body:
        targets = n.targets if isinstance(n, ast.Assign) else [n.target] if isinstance(n, ast.AnnAssign) else []
        names |= {t.id for t in targets if isinstance(t, ast.Name)}
        if isinstance(n, (ast.Import, ast.ImportFrom)):
            names |= {(a.asname or a.name).split(".")[0] for a in n.names}
    if top not in names:
        raise params.error("factory", f"module {mod.strip()!r} ({Path(source).name}) defines no {top!r} at its top "
                                      "level")
    return f"factory {ref!r} found in {Path(source).name} (not run)"
