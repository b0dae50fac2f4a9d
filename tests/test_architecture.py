"""The shape of the package: no import cycles, layers import downward, the plug-in registry keeps its contract."""
import ast
import importlib
import inspect
import re
import tomllib
from pathlib import Path

import pytest

from rvtol.analysis import Analysis
from rvtol.registry import ANALYSES, MODELS, plugin_analyses, plugin_models

ROOT = Path(__file__).resolve().parents[1]
PKG = ROOT / "rvtol"
#: the reproduction wing: a distribution of its own (studies/reproduction), installed by the test command
WING = ROOT / "studies" / "reproduction"
WING_KINDS = {"transmission_error_reproduction", "lost_motion_reproduction", "adjustment_reproduction",
              "stackup_shaft_hole", "stiffness_reproduction"}


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
REPORT_LAYER = re.compile(r"^rvtol\.(report(\..*)?|study|cli|__main__|analysis|.*\.analyses|.*\.texts)$")


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


#: what only the reproduction wing may say: it reads a document's printed figures
PRINTED_FIGURES = re.compile(r"data/reproduction|load_printed|printed figure|printed box|printed value", re.I)


def test_no_library_module_mentions_a_documents_printed_figures():
    bad = [f"{p.relative_to(ROOT)}:{i}" for p in PKG.rglob("*.py")
           for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1) if PRINTED_FIGURES.search(line)]
    assert bad == []


def test_the_reproduction_wing_is_an_installed_plug_in():
    """The test command installs studies/reproduction; its kinds come from the rvtol.analyses entry points."""
    eps = plugin_analyses()
    assert WING_KINDS <= set(eps), "install the wing: python -m pip install -e studies/reproduction"
    for k in WING_KINDS:
        assert eps[k].value.startswith("rvtol_reproduction.analyses:") and k not in ANALYSES
        assert Path(inspect.getfile(eps[k].load())).resolve().is_relative_to(WING.resolve()), \
            "the installed wing is not this checkout's"


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
    reason="no package in this environment registers an rvtol.models entry point (tests/test_model_kinds.py "
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
    tests = " ".join(p.read_text(encoding="utf-8") for p in (ROOT / "tests").glob("test_*.py"))
    used |= set(re.findall(r'kind = "(\w+)"', tests))
    missing = sorted((set(MODELS) | set(all_analyses())) - used)
    assert missing == []


def test_every_kind_a_study_names_is_registered():
    for p in (ROOT / "studies").glob("*.toml"):
        for k in _kinds_named_by(p):
            assert k in MODELS or k in all_analyses(), (p.name, k)


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
    assert set(SEVERAL_SECTIONS) <= set(all_analyses())


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


#: modules outside rvtol/models that may import a model package: the loader composing a study's models and the
#: registry; physics-specific code lives beside its physics
MODEL_IMPORTS_ALLOWED = re.compile(r"^rvtol\.(models\..*|registry|study)$")


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
