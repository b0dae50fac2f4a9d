"""The shape of the package: no import cycles, layers import downward, the plug-in registry keeps its contract."""
import ast
import importlib
import inspect
import re
import tomllib
from pathlib import Path

import pytest

from rvtol.analysis import Analysis
from rvtol.registry import ANALYSES, MODELS, plugin_models

ROOT = Path(__file__).resolve().parents[1]
PKG = ROOT / "rvtol"


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
REPORT_LAYER = re.compile(r"^rvtol\.(report(\..*)?|study|cli|__main__|analysis|reproduction(\..*)?|.*\.analyses|.*\.texts)$")


def test_computation_does_not_import_the_report_layer():
    bad = [(m, t) for m, ts in import_graph().items() for t in ts
           if t.startswith("rvtol.report") and not REPORT_LAYER.match(m)]
    assert bad == []


def test_the_library_does_not_import_the_reproduction_wing():
    bad = [(m, t) for m, ts in import_graph().items() for t in ts
           if t.startswith("rvtol.reproduction") and not m.startswith("rvtol.reproduction")]
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
    reason="no package in this environment registers an rvtol.models entry point (tests/test_model_kinds.py "
           "installs one)"))])
def test_every_installed_model_plugin_has_the_documented_signature(kind):
    f = plugin_models()[kind].load()
    assert callable(f) and len(inspect.signature(f).parameters) == 3


@pytest.mark.parametrize("kind", sorted(ANALYSES))
def test_every_analysis_is_an_analysis_with_setup_and_run(kind):
    cls = _resolve(ANALYSES[kind])
    assert inspect.isclass(cls) and issubclass(cls, Analysis)
    assert "__init__" not in vars(cls), "construction goes through Analysis.__init__ -> setup"
    assert list(inspect.signature(cls.setup).parameters) == ["self", "params", "study"]
    assert list(inspect.signature(cls.run).parameters) == ["self", "ctx"]
    assert not inspect.isabstract(cls)
    mod = ANALYSES[kind].split(":")[0]
    assert mod.endswith(".analyses") or mod.startswith("rvtol.reproduction.doc"), \
        "analyses live in a package's analyses.py, or in the reproduction wing"


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
    missing = sorted((set(MODELS) | set(ANALYSES)) - used)
    assert missing == []


def test_every_kind_a_study_names_is_registered():
    for p in (ROOT / "studies").glob("*.toml"):
        for k in _kinds_named_by(p):
            assert k in MODELS or k in ANALYSES, (p.name, k)


# --------------------------------------------------------------------------- the analysis shape (issue 26)
#: analysis kinds still written in the older shape (setup() reading the table by hand, run() building sections);
#: the list only shrinks
OLDER_SHAPE = {
    "lost_motion_breakdown", "lost_motion_screening", "transmission_error_curve", "transmission_error_sensitivity",
    "stiffness_breakdown", "torsion_curve", "compliance_breakdown", "stackup_linear", "stackup_graph",
    "stackup_sequences", "stackup_domains", "adjustment",
    "transmission_error_reproduction",
    "lost_motion_reproduction", "adjustment_reproduction", "stackup_shaft_hole", "stiffness_reproduction",
}


@pytest.mark.parametrize("kind", sorted(set(ANALYSES) - OLDER_SHAPE))
def test_an_analysis_is_a_thin_adapter(kind):
    """Declared options (a dataclass), one capability call (``compute``), the generic report with the layout of
    the capability's texts module — no ``run`` or ``setup`` of its own doing the work."""
    import dataclasses

    cls = _resolve(ANALYSES[kind])
    assert cls.Options is not None and dataclasses.is_dataclass(cls.Options), "declare the keys as Options"
    assert "run" not in vars(cls) and "setup" not in vars(cls), "compute() and the generic report, no own run/setup"
    assert "compute" in {n for c in cls.__mro__ for n in vars(c) if c is not Analysis}
    assert cls.layout is not None and cls.layout.__module__.endswith(".texts"), "the layout lives in a texts module"
    src = inspect.getsource(cls.compute)
    assert len(src.splitlines()) <= 15, "compute() is one library call, not the computation itself"


def test_older_shape_list_names_only_registered_kinds():
    assert OLDER_SHAPE <= set(ANALYSES)


#: words a string literal of an analyses.py may hold before it counts as report prose (prose lives in texts.py)
PROSE_WORDS = 16


def test_analyses_modules_hold_no_prose():
    bad = []
    for p in PKG.rglob("analyses.py"):
        kinds = {k for k, v in ANALYSES.items() if v.split(":")[0] == ".".join(p.relative_to(ROOT).with_suffix("").parts)}
        if kinds & OLDER_SHAPE:
            continue
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
PACKAGE_CYCLES_LEFT = [["rvtol.models.lost_motion", "rvtol.models.torsion_curve"]]


def test_packages_form_no_cycle():
    assert strongly_connected(package_graph()) == PACKAGE_CYCLES_LEFT


#: modules outside rvtol/models that may import a model package: the loader composing a study's models, the
#: registry and the reproduction wing; physics-specific code lives beside its physics
MODEL_IMPORTS_ALLOWED = re.compile(r"^rvtol\.(models\..*|registry|study|reproduction(\..*)?)$")


def test_model_agnostic_packages_import_no_model():
    bad = sorted({m for m, ts in import_graph().items() for t in ts
                  if t.startswith("rvtol.models.") and not MODEL_IMPORTS_ALLOWED.match(m)})
    assert bad == []
