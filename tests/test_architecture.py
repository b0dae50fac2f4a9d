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
REPORT_LAYER = re.compile(r"^rvtol\.(report(\..*)?|study|cli|__main__|analysis|reproduction(\..*)?|.*\.analyses)$")


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
