"""The shape of the package: no import cycles, layers import downward, the plug-in registry keeps its contract."""
import ast
import importlib
import inspect
import re
import tomllib
from pathlib import Path

import pytest

import rvtol
import rvtol.plugin
from rvtol.analysis import Analysis
from rvtol.registry import ANALYSES, MODELS, plugin_analyses, plugin_models

from conftest import ROOT, WING_KINDS

PKG = ROOT / "rvtol"
#: the reproduction wing: a distribution of its own (studies/reproduction, its tests in studies/reproduction/tests),
#: installed by the test command; the core suite passes without it (tests/conftest.py)
WING = ROOT / "studies" / "reproduction"


def all_analyses() -> dict[str, str]:
    """Every analysis kind a study can name: built in, and registered by installed packages (entry points)."""
    return {**{k: ep.value for k, ep in plugin_analyses().items()}, **ANALYSES}


def _modules() -> dict[str, Path]:
    out = {}
    for p in PKG.rglob("*.py"):
        parts = list(p.relative_to(ROOT).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = p
    return out


def import_graph() -> dict[str, set[str]]:
    """Module -> rvtol modules it imports, at any depth of the file (function-level imports included)."""
    mods = _modules()
    graph = {m: set() for m in mods}
    for m, p in mods.items():
        pkg = m if p.name == "__init__.py" else m.rsplit(".", 1)[0]
        for n in ast.walk(ast.parse(p.read_text(encoding="utf-8"))):
            targets = []
            if isinstance(n, ast.ImportFrom):
                base = n.module or ""
                if n.level:
                    b = pkg.split(".")
                    b = b[:len(b) - (n.level - 1)]
                    base = ".".join(b + ([base] if base else []))
                targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in mods else base for a in n.names]
            elif isinstance(n, ast.Import):
                targets = [a.name for a in n.names]
            for t in targets:
                while t and t not in mods:
                    t = t.rsplit(".", 1)[0] if "." in t else ""
                if t and t != m and t != "rvtol" and m != "rvtol":
                    graph[m].add(t)
    return graph


def strongly_connected(graph: dict[str, set[str]]) -> list[list[str]]:
    """Tarjan's algorithm (iterative): components with more than one module are import cycles."""
    index, low, on, stack, out, counter = {}, {}, set(), [], [], [0]
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root)
        on.add(root)
        while work:
            v, it = work[-1]
            w = next(it, None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = counter[0]
                    counter[0] += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(graph[w]))))
                elif w in on:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    out.append(sorted(comp))
    return out


def test_cycle_finder_finds_a_planted_cycle():
    g = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}, "e": set()}
    assert strongly_connected(g) == [["a", "b", "c"]]
    assert strongly_connected({"a": {"b"}, "b": set()}) == []


def test_no_import_cycles():
    assert strongly_connected(import_graph()) == []


# layers that build reports: everything else is computation and must not import the report layer
REPORT_LAYER = re.compile(r"^rvtol\.(report(\..*)?|study(\..*)?|cli|__main__|analysis|.*\.analyses|.*\.texts)$")


def test_computation_does_not_import_the_report_layer():
    bad = [(m, t) for m, ts in import_graph().items() for t in ts
           if t.startswith("rvtol.report") and not REPORT_LAYER.match(m)]
    assert bad == []


def _imports(path: Path) -> set[str]:
    out = set()
    for n in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(n, ast.ImportFrom) and n.module and not n.level:
            out.add(n.module)
        elif isinstance(n, ast.Import):
            out |= {a.name for a in n.names}
    return out


def test_the_library_does_not_import_the_reproduction_wing():
    assert not (PKG / "reproduction").exists(), "the wing lives in studies/reproduction, outside the package"
    bad = [str(p.relative_to(ROOT)) for p in PKG.rglob("*.py")
           if any(m.split(".")[0] == "rvtol_reproduction" for m in _imports(p))]
    assert bad == []


# --------------------------------------------------------------------------- the plug-in API (issue 38)
def _rvtol_imports(path: Path) -> list[tuple[int, str, list[str]]]:
    """``(line, module, names)`` of each import of rvtol in a file (``names``: what ``from module import`` takes)."""
    out = []
    for n in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(n, ast.ImportFrom) and n.module and not n.level and n.module.split(".")[0] == "rvtol":
            out.append((n.lineno, n.module, [a.name for a in n.names]))
        elif isinstance(n, ast.Import):
            out += [(n.lineno, a.name, []) for a in n.names if a.name.split(".")[0] == "rvtol"]
    return out


def test_the_wing_imports_rvtol_only_through_the_plugin_api():
    """Every import of rvtol in the wing's package (function-level ones too) is ``rvtol.plugin`` or a public name
    of the top-level ``rvtol`` (its ``__all__``; not a submodule such as ``from rvtol import units``)."""
    files = sorted((WING / "rvtol_reproduction").rglob("*.py"))
    assert files
    bad = [f"{p.relative_to(ROOT)}:{line}: {module} {names}" for p in files for line, module, names in _rvtol_imports(p)
           if not (module == "rvtol.plugin" or module == "rvtol" and set(names) <= set(rvtol.__all__))]
    assert bad == []


def test_the_import_check_finds_a_private_import(tmp_path):
    p = tmp_path / "m.py"
    p.write_text("from rvtol.plugin import units\nfrom rvtol import units\n\ndef f():\n    import rvtol.stats\n")
    assert [(line, m) for line, m, _ in _rvtol_imports(p)] == [(1, "rvtol.plugin"), (2, "rvtol"), (5, "rvtol.stats")]
    assert not {"units"} <= set(rvtol.__all__)


def _is_shim(path: Path) -> bool:
    """A module that only imports names from elsewhere (a docstring and imports, nothing defined): a second path to
    something that lives in another module.  A package's ``__init__`` gathering its own modules' names is not one."""
    body = ast.parse(path.read_text(encoding="utf-8")).body
    if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
        body = body[1:]
    return bool(body) and all(isinstance(n, (ast.Import, ast.ImportFrom)) for n in body)


def test_no_module_is_a_shim_of_another():
    """Every name has one import path: a module that only re-exports another's names is gone, not kept as an alias."""
    bad = [str(p.relative_to(ROOT)) for p in PKG.rglob("*.py") if p.name != "__init__.py" and _is_shim(p)]
    assert bad == []


def test_the_shim_check_finds_a_shim(tmp_path):
    p = tmp_path / "sections.py"
    p.write_text('"""Moved."""\nfrom ..blocks import Figure, Table  # noqa: F401\n')
    assert _is_shim(p)
    p.write_text('"""Not moved."""\nfrom ..blocks import Figure\n\nCAPTION = "x"\n')
    assert not _is_shim(p)


def test_no_library_module_imports_the_plugin_api():
    """The plug-in API is the boundary seen from outside: nothing of the library depends on it."""
    bad = [m for m, ts in import_graph().items() if "rvtol.plugin" in ts]
    assert bad == []


def test_the_plugin_api_exports_exactly_its_documented_names():
    """Every name of ``__all__`` resolves and has its one line in the module docstring (``- ``name`` — what it is``);
    the module holds no other public name, so a new export is a deliberate, documented one."""
    api = rvtol.plugin
    for name in api.__all__:
        assert getattr(api, name) is not None, name
        assert re.search(rf"^- ``{re.escape(name)}`` — \S", api.__doc__, re.M), f"{name}: no line in the docstring"
    documented = re.findall(r"^- ``(\w+)`` — ", api.__doc__, re.M)
    assert sorted(documented) == sorted(api.__all__) and len(set(api.__all__)) == len(api.__all__)
    public = {n for n in vars(api) if not n.startswith("_")} - {"annotations", "TYPE_CHECKING"}
    assert public <= set(api.__all__), public - set(api.__all__)


def test_importing_the_plugin_api_does_not_import_matplotlib():
    import subprocess
    import sys

    code = "import sys, rvtol.plugin; print('matplotlib' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"


def test_the_wing_registers_its_kinds_in_the_plugin_apis_entry_point_group():
    project = tomllib.loads((WING / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert set(project["entry-points"][rvtol.plugin.ANALYSIS_ENTRY_POINT_GROUP]) == WING_KINDS
    assert project["dependencies"] == ["rvtol"]


#: what only the reproduction wing may say: it reads a document's printed figures
PRINTED_FIGURES = re.compile(r"data/reproduction|load_printed|printed figure|printed box|printed value", re.I)


def test_no_library_module_mentions_a_documents_printed_figures():
    bad = [f"{p.relative_to(ROOT)}:{i}" for p in PKG.rglob("*.py")
           for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1) if PRINTED_FIGURES.search(line)]
    assert bad == []


def test_plotting_imports_no_computation():
    allowed = ("rvtol.plotting", "rvtol.units")
    bad = [(m, t) for m, ts in import_graph().items() if m.startswith("rvtol.plotting") for t in ts
           if not t.startswith(allowed)]
    assert bad == []


def test_numba_lives_only_in_kernel_modules():
    for m, p in _modules().items():
        if "import numba" in p.read_text(encoding="utf-8") or "from numba" in p.read_text(encoding="utf-8"):
            assert p.name == "_kernels.py", m


# --------------------------------------------------------------------------- registry contract
def _resolve(entry: str):
    mod, attr = entry.split(":")
    return getattr(importlib.import_module(mod), attr)


@pytest.mark.parametrize("kind", sorted(MODELS))
def test_every_model_factory_resolves_with_the_documented_signature(kind):
    f = _resolve(MODELS[kind])
    assert callable(f)
    assert list(inspect.signature(f).parameters) == ["params", "design", "spec"]
    assert MODELS[kind].startswith(f"rvtol.models.{MODELS[kind].split('.')[2]}.model:"), \
        "a model's factory lives in its package's model.py"


@pytest.mark.parametrize("kind", sorted(plugin_models()) or [pytest.param(None, marks=pytest.mark.skip(
    reason="no package in this environment registers an rvtol.models entry point (tests/models/test_model_kinds.py "
           "installs one)"))])
def test_every_installed_model_plugin_has_the_documented_signature(kind):
    f = plugin_models()[kind].load()
    assert callable(f) and len(inspect.signature(f).parameters) == 3


@pytest.mark.parametrize("kind", sorted(all_analyses()))
def test_every_analysis_is_an_analysis_with_options_and_run(kind):
    cls = _resolve(all_analyses()[kind])
    assert inspect.isclass(cls) and issubclass(cls, Analysis)
    assert "__init__" not in vars(cls), "construction goes through Analysis.__init__ (reads the Options)"
    assert not hasattr(cls, "setup"), "no hand-read form of the [[analysis]] table"
    assert list(inspect.signature(cls.run).parameters) == ["self", "ctx"]
    assert not inspect.isabstract(cls)
    assert all_analyses()[kind].split(":")[0].endswith(".analyses"), "analyses live in a package's analyses.py"


def _kinds_named_by(path: Path) -> set[str]:
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    models = data.get("model", [])                     # [model], or [[model]] tables of a composed study
    models = models if isinstance(models, list) else [models]
    return {t["kind"] for t in data.get("analysis", [])} | {m["kind"] for m in models}


def test_every_registered_kind_is_used_by_a_study_or_a_test():
    used = set()
    for p in (ROOT / "studies").glob("*.toml"):
        used |= _kinds_named_by(p)
    tests = " ".join(p.read_text(encoding="utf-8") for p in (ROOT / "tests").rglob("test_*.py"))
    used |= set(re.findall(r'kind = "(\w+)"', tests))
    missing = sorted((set(MODELS) | set(all_analyses())) - used)
    assert missing == []


def test_every_kind_a_study_names_is_registered():
    for p in (ROOT / "studies").glob("*.toml"):
        for k in _kinds_named_by(p):       # the wing's kinds: registered when it is installed (its test_reproduction_plugin.py)
            assert k in MODELS or k in all_analyses() or k in WING_KINDS, (p.name, k)


# --------------------------------------------------------------------------- the analysis shape (issue 26)
#: analyses that report several sections — one summary.json entry each, kept so that the summaries of the studies
#: stay what they were: a small report(result) of their own, one layout per section (kind: the reason)
SEVERAL_SECTIONS = {
    "torsion_curve": "the curves, lost motion against clearances and rigidity: three comparisons of one reducer",
    "stiffness_breakdown": "the torsion-angle components and the cycloid–pin load distribution",
    "stiffness_reproduction": "doc 004's five studies (Tables 2–5, sweeps) and the reproduction table",
    "allocation": "the cost–tolerance models and the allocation",
}


@pytest.mark.parametrize("kind", sorted(all_analyses()))
def test_an_analysis_is_a_thin_adapter(kind):
    """Declared options (a dataclass), one capability call (``compute``), the generic report with the layout of
    the capability's texts module — no ``run`` or ``setup`` of its own doing the work."""
    import dataclasses

    cls = _resolve(all_analyses()[kind])
    assert cls.Options is not None and dataclasses.is_dataclass(cls.Options), "declare the keys as Options"
    assert "run" not in vars(cls) and "setup" not in vars(cls), "compute() and the generic report, no own run/setup"
    if "report" in vars(cls):
        assert kind in SEVERAL_SECTIONS, "one section, the generic report (or a reason in SEVERAL_SECTIONS)"
        assert len(inspect.getsource(cls.report).splitlines()) <= 12, "report(): one layout per section, no more"
    assert "compute" in {n for c in cls.__mro__ for n in vars(c) if c is not Analysis}
    assert cls.layout is not None and cls.layout.__module__.endswith(".texts"), "the layout lives in a texts module"
    src = inspect.getsource(cls.compute)
    assert len(src.splitlines()) <= 15, "compute() is one library call, not the computation itself"


def test_several_sections_list_names_only_registered_kinds():
    assert set(SEVERAL_SECTIONS) <= set(all_analyses()) | WING_KINDS


#: words a string literal of an analyses.py may hold before it counts as report prose (prose lives in texts.py)
PROSE_WORDS = 16


def test_analyses_modules_hold_no_prose():
    bad = []
    for p in [*PKG.rglob("analyses.py"), *WING.rglob("analyses.py")]:
        module = ".".join(p.relative_to(WING if p.is_relative_to(WING) else ROOT).with_suffix("").parts)
        kinds = {k for k, v in all_analyses().items() if v.split(":")[0] == module}
        tree = ast.parse(p.read_text(encoding="utf-8"))
        docs = {id(n.body[0].value) for n in ast.walk(tree)
                if isinstance(n, (ast.Module, ast.ClassDef, ast.FunctionDef)) and n.body
                and isinstance(n.body[0], ast.Expr) and isinstance(n.body[0].value, ast.Constant)}
        docs |= {id(c) for n in ast.walk(tree) if isinstance(n, ast.Call) and getattr(n.func, "id", "") == "option"
                 for c in ast.walk(n)}                       # an option's meaning, listed by `rvtol kinds`
        for n in ast.walk(tree):
            if isinstance(n, ast.Constant) and isinstance(n.value, str) and id(n) not in docs \
                    and len(n.value.split()) > PROSE_WORDS:
                bad.append(f"{p.relative_to(ROOT)}:{n.lineno}")
    assert bad == []


def _package(module: str) -> str:
    parts = module.split(".")
    return ".".join(parts[:3]) if len(parts) >= 3 and parts[1] == "models" else ".".join(parts[:2])


def package_graph() -> dict[str, set[str]]:
    g: dict[str, set[str]] = {}
    for m, ts in import_graph().items():
        a = _package(m)
        g.setdefault(a, set())
        for t in ts:
            b = _package(t)
            if b != a:
                g[a].add(b)
                g.setdefault(b, set())
    return g


#: package-level cycles still to break (the list only shrinks)
PACKAGE_CYCLES_LEFT = []


def test_packages_form_no_cycle():
    assert strongly_connected(package_graph()) == PACKAGE_CYCLES_LEFT


#: modules outside rvtol/models that may import a model package: the loader composing a study's models, the
#: registry and the plug-in API (its model entry points); physics-specific code lives beside its physics
MODEL_IMPORTS_ALLOWED = re.compile(r"^rvtol\.(models\..*|registry|study\.(load|model)|plugin)$")


def test_model_agnostic_packages_import_no_model():
    bad = sorted({m for m, ts in import_graph().items() for t in ts
                  if t.startswith("rvtol.models.") and not MODEL_IMPORTS_ALLOWED.match(m)})
    assert bad == []


def _result_class(cls):
    """The class of the result ``cls.compute`` returns: the return annotation of the library function whose call
    gives the returned value (``return f(...)``, or ``x = f(...)`` … ``return x``)."""
    import textwrap
    import typing

    fn = next(c.__dict__["compute"] for c in cls.__mro__ if "compute" in c.__dict__)
    tree = ast.parse(textwrap.dedent(inspect.getsource(fn)))
    ret = [n.value for n in ast.walk(tree) if isinstance(n, ast.Return) and n.value is not None][-1]
    if not isinstance(ret, ast.Call):
        ret = next(n.value for n in ast.walk(tree) if isinstance(n, ast.Assign) and isinstance(n.value, ast.Call)
                   and any(ast.unparse(t) == ast.unparse(ret) for t in n.targets))
    scope = vars(importlib.import_module(fn.__module__))
    f = ret.func
    target = scope[f.id] if isinstance(f, ast.Name) else getattr(scope[f.value.id], f.attr)
    return typing.get_type_hints(target)["return"]


@pytest.mark.parametrize("kind", sorted(all_analyses()))
def test_every_result_has_to_frame_summary_and_the_reports_figure(kind):
    """What an analysis' compute returns is a result object: ``to_frame()`` and ``summary()``, and ``plot()``
    where the report shows a figure of it (its layout, or its own report, lays out a Figure)."""
    cls = _resolve(all_analyses()[kind])
    res = _result_class(cls)
    assert inspect.isclass(res), f"{kind}: compute's library function has no result class as its return annotation"
    for name in ("to_frame", "summary"):
        assert callable(getattr(res, name, None)), f"{res.__name__} has no {name}()"
    shown = inspect.getsource(cls.layout) + (inspect.getsource(cls.report) if "report" in vars(cls) else "")
    if "Figure(" in shown:
        assert callable(getattr(res, "plot", None)), f"{res.__name__}: the report shows a figure, it has no plot()"


#: the analyses that set stack-up conventions (worst case, RSS, …) beside the Monte Carlo, each computed in one home
STACK_CONVENTION_KINDS = ("stack_conventions", "stackup_linear")


@pytest.mark.parametrize("kind", STACK_CONVENTION_KINDS)
def test_every_stack_up_convention_is_computed_in_rvtol_stacking(kind):
    """One home for the stacking conventions: whichever package an analysis of them belongs to, the capability it
    calls (and its result) lives in rvtol.stacking."""
    res = _result_class(_resolve(all_analyses()[kind]))
    assert res.__module__.startswith("rvtol.stacking."), (kind, res.__module__)


#: the 20-DOF reducer of doc 000: a core with no model of its own, and the model packages built on it
CORE_20DOF = "rvtol.models.reducer_20dof"
BUILT_ON_20DOF = {"transmission_error", "torsion_curve", "pin_ring", "calibration", "screening", "lost_motion"}


def test_the_20dof_core_is_named_for_itself_and_the_models_build_on_it_alone():
    """The 20-DOF core imports no other model package and registers no kind; the packages that use the 20-DOF model
    import its core, never the transmission-error capability (one capability built on the core among others)."""
    g = package_graph()
    assert {t for t in g[CORE_20DOF] if t.startswith("rvtol.models.")} == set()
    assert not any(v.startswith(CORE_20DOF + ".") for v in {**MODELS, **ANALYSES}.values())
    assert {p.split(".")[2] for p, ts in g.items() if CORE_20DOF in ts and p.startswith("rvtol.models.")} \
        == BUILT_ON_20DOF
    assert {p for p, ts in g.items() if "rvtol.models.transmission_error" in ts and p.startswith("rvtol.models.")} \
        == set()


#: a concept the package listing shows once: the word in a module's name -> the one module named with it
ONE_MODULE_PER_CONCEPT = {
    "signoff": "rvtol.signoff",                          # the digest and the first page (not three modules)
    "bearing": "rvtol.elements.rolling_bearings",        # doc 004's closed form and the load distributions
    "compar": "rvtol.ci.compare",                        # two runs compared; results set beside others say so
}


@pytest.mark.parametrize("word", sorted(ONE_MODULE_PER_CONCEPT))
def test_one_module_per_concept(word):
    named = sorted(m for m in _modules() if word in m.rsplit(".", 1)[-1])
    assert named == [ONE_MODULE_PER_CONCEPT[word]]


# --------------------------------------------------------------------------- options a schema, the plan what is built
def _option_classes(opts) -> list:
    """The options dataclass, its bases and the dataclasses of its sub-tables (``[analysis.<key>]``)."""
    import dataclasses
    import typing

    out, todo = [], [opts]
    while todo:
        c = todo.pop()
        for k in c.__mro__:
            if dataclasses.is_dataclass(k) and k not in out:
                out.append(k)
                hints = typing.get_type_hints(k)
                types_ = [hints[f.name] for f in dataclasses.fields(k) if f.name in hints]
                while types_:
                    t = types_.pop()
                    types_ += typing.get_args(t)
                    if isinstance(t, type) and dataclasses.is_dataclass(t):
                        todo.append(t)
    return out


def _writes(fn) -> list[str]:
    """What ``fn`` assigns: ``self.<attr>`` (the attribute's name), and anything of the study (``study...``)."""
    import textwrap

    tree = ast.parse(textwrap.dedent(inspect.getsource(fn)))
    out = []
    for n in ast.walk(tree):
        targets = n.targets if isinstance(n, ast.Assign) else [n.target] if isinstance(n, ast.AugAssign) else []
        if isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute) and n.func.attr in (
                "update", "setdefault", "append", "extend", "pop", "clear"):
            targets = [n.func.value]
        for t in targets:
            root = t
            while isinstance(root, (ast.Attribute, ast.Subscript)):
                root = root.value
            if isinstance(root, ast.Name) and root.id == "study":
                out.append(ast.unparse(t))
            elif isinstance(t, ast.Attribute) and isinstance(t.value, ast.Name) and t.value.id == "self":
                out.append(t.attr)
    return out


@pytest.mark.parametrize("kind", sorted(all_analyses()))
def test_options_are_a_schema_and_the_plan_is_frozen(kind):
    """An analysis' options (and their sub-tables) declare only keys — no ``field(init=False)`` — and their
    ``complete`` writes nothing but those keys (a check, a normalisation, a default from the table) and nothing of
    the study; what the analysis loads or builds is its plan: ``prepare`` returns a frozen dataclass."""
    import dataclasses
    import typing

    cls = _resolve(all_analyses()[kind])
    for c in _option_classes(cls.Options):
        keys = {f.name for f in dataclasses.fields(c) if f.init}
        derived = [f.name for f in dataclasses.fields(c) if not f.init]
        assert derived == [], f"{c.__qualname__} declares derived state {derived}: it is the plan's (prepare)"
        if "complete" in vars(c):
            bad = [w for w in _writes(c.complete) if w not in keys]
            assert bad == [], f"{c.__qualname__}.complete writes {bad}: what is loaded or built is the plan's"
    owner = next(c for c in cls.__mro__ if "prepare" in vars(c))
    if owner is not Analysis:
        plan = typing.get_type_hints(cls.prepare)["return"]
        assert dataclasses.is_dataclass(plan) and plan.__dataclass_params__.frozen, \
            f"{kind}: prepare returns {plan!r}, not a frozen dataclass"


def test_the_schema_check_finds_derived_state():
    """The check above on planted options: a derived field, a complete() that stores what it built or writes the
    study."""
    import dataclasses

    @dataclasses.dataclass
    class Planted:
        a: int = 1
        built: object = dataclasses.field(init=False, default=None)

        def complete(self, study, error):
            self.a = 2
            self.model = object()
            study.inputs["x"] = {}

    assert [f.name for f in dataclasses.fields(Planted) if not f.init] == ["built"]
    assert _writes(Planted.complete) == ["a", "model", "study.inputs['x']"]
