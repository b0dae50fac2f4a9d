"""Mutation testing of the modules that decide numbers (issue 37): do the tests catch a planted fault?

Each module of ``tests/mutation.toml`` is mutated by cosmic-ray (every operator, every number, every comparison —
module-level tables included) and each mutant is run against the test files that guard that module, stopping at
the first failure.  A mutant the tests fail on is *killed*; one they pass is a *survivor*: a fault the tests
would not see (or an equivalent mutant, which no test can tell from the code: those are listed in the config
with the reason, and left out of the kill rate)::

    pip install -e '.[mutation]'
    python tests/mutation.py                  # every module, resuming where an earlier run stopped
    python tests/mutation.py units verdict    # some of them
    python tests/mutation.py --jobs 2         # two modules at a time (one mutant at a time each)
    python tests/mutation.py --report         # only the report of what has run so far
    python tests/mutation.py --rerun-survivors verdict   # after adding tests: only the survivors again
    python tests/mutation.py --check-equivalents         # are the [[equivalent]] ids still at their lines? (no run)

Each module runs in its own copy of the committed tree (``git archive HEAD``: uncommitted changes are not tested) under
``--work`` (default ``reports/mutation/work/<module>``): cosmic-ray writes each mutant into that copy's file, so the
working tree is never touched.  The session (``session.sqlite``, cosmic-ray's) keeps every result: an interrupted run
continues with the mutants not yet run; a change of what the tests can read (the package, the tests, data, studies,
pyproject.toml) or of the module's entry in the config starts it afresh — not a change of README or of the
equivalent mutants listed.  After tests were added, ``--rerun-survivors`` takes the new commit and runs again only
the survivors, keeping every other result (the mutated module's own file must be unchanged: its mutants are the
same).

Before the first mutant the module's tests run on the unmutated copy under coverage (they must pass; their time
sets the timeout), which records the tests that run each line — in the test process and in every Python process a
test starts (the CLI as a subprocess, spawned workers: coverage's start-up hook, the test's id as that process's
context).  The mutants then run in a test server forked from a process that has already imported the third-party
libraries those tests use (numpy, scipy, pandas, pytest, ...: seconds a mutant): cosmic-ray's test command asks the
server, which runs, in a fresh fork each, first the tests that ran the mutated lines.  One of them failing kills
the mutant.  If they all pass and every mutated line is inside a function's body, the mutant survives: no other test
runs those lines in any process, so none can fail.  A mutant elsewhere (a module constant, a default argument, a
decorator, a class attribute: evaluated at import, seen by every test) or on a line no test ran is judged by all of
the module's test files.  A line run only in a forked child that is not a fresh interpreter is not recorded: such a
mutant may be judged by fewer tests than could kill it, never more — the kill rate is a lower bound.
Mutants in annotations (never evaluated under ``from __future__ import annotations``) and the operators the config
excludes are skipped.

The report (``reports/mutation/mutation.md`` and ``.json``) gives per module the mutants, killed, survived, timeout,
errors, equivalent and pending, the kill rate of the non-equivalent mutants, and every survivor with its line and
change.
"""
from __future__ import annotations

import argparse
import ast
import compileall
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import time
import tomllib
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

HERE = Path(__file__).resolve()
ROOT = HERE.parents[1]
CONFIG = ROOT / "tests" / "mutation.toml"
OUT = ROOT / "reports" / "mutation"
#: what the tests can read: a change here (not in README, docs or this harness) starts a module afresh
READ_PATHS = ("rvtol", "tests", "data", "studies", "pyproject.toml")
HARNESS = ("tests/mutation.py", "tests/mutation.toml")


def git(*args: str) -> str:
    return subprocess.run(["git", "-C", str(ROOT), *args], check=True, capture_output=True, text=True).stdout


class Module:
    """One module's run: its copy of the tree, cosmic-ray config and session under ``work/<key>``."""

    def __init__(self, key: str, spec: dict, run: dict, work: Path, commit: str):
        self.key, self.path, self.tests = key, spec["path"], list(spec["tests"])
        self.run, self.commit = run, commit
        self.dir = work / key
        self.src, self.session, self.config = self.dir / "src", self.dir / "session.sqlite", self.dir / "cosmic-ray.toml"
        self.stamp = self.dir / "stamp.json"        # written last: the setup of a session is complete
        listing = [x for x in git("ls-tree", "-r", commit, "--", *READ_PATHS).splitlines() if not x.endswith(HARNESS)]
        self.fingerprint = hashlib.sha256(json.dumps([listing, spec, run], sort_keys=True).encode()).hexdigest()

    def session_commit(self) -> str | None:
        """The commit the session's copy was taken from (None: no complete setup)."""
        return json.loads(self.stamp.read_text())["commit"] if self.stamp.exists() else None

    @property
    def env(self) -> dict:
        paths = [str(self.src), str(self.src / "studies" / "reproduction")]
        return {**os.environ, "PYTHONPATH": os.pathsep.join(paths), "OMP_NUM_THREADS": "1",
                "OPENBLAS_NUM_THREADS": "1", "MPLBACKEND": "Agg"}

    def prepare(self, rerun_survivors: bool = False) -> None:
        """A fresh copy and session unless this commit's exist; the baseline; the filters.  ``rerun_survivors``: a
        session of a commit whose module file is the same takes this commit's copy and forgets its survivors."""
        if self.stamp.exists():
            old = json.loads(self.stamp.read_text())
            if old["fingerprint"] == self.fingerprint:
                if json.loads((self.dir / "baseline.json").read_text()).get("version") != BASELINE_VERSION:
                    self.restore()
                    self.run_baseline()
                    print(f"{self.key}: its baseline taken again (version {BASELINE_VERSION})")
                return
            if rerun_survivors and git("rev-parse", f"{old['commit']}:{self.path}") == git(
                    "rev-parse", f"{self.commit}:{self.path}"):
                self.copy_tree()
                forgotten = self.forget_survivors()
                self.stamp.write_text(json.dumps({"commit": self.commit, "fingerprint": self.fingerprint}))
                print(f"{self.key}: {forgotten} survivors of {old['commit'][:10]} run again on {self.commit[:10]}")
                return
            print(f"{self.key}: the code or tests changed since the run of {old['commit'][:10]}: afresh")
        shutil.rmtree(self.dir, ignore_errors=True)
        self.copy_tree()
        subprocess.run(["cosmic-ray", "init", str(self.config), str(self.session)], cwd=self.src, check=True)
        self.skip_filtered()
        self.stamp.write_text(json.dumps({"commit": self.commit, "fingerprint": self.fingerprint}))

    def copy_tree(self) -> None:
        """This commit's tree in ``src``, its tests' baseline under coverage, the cosmic-ray config."""
        shutil.rmtree(self.src, ignore_errors=True)
        self.src.mkdir(parents=True)
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", self.commit], check=True, capture_output=True)
        subprocess.run(["tar", "-x", "-C", str(self.src)], input=archive.stdout, check=True)
        compileall.compile_dir(self.src / "rvtol", quiet=1)       # mutants recompile only the mutated module
        (self.dir / "module.json").write_text(json.dumps({"path": self.path, "tests": self.tests}), encoding="utf-8")
        self.run_baseline()

    def run_baseline(self) -> None:
        """The tests on the unmutated copy (``baseline``), the timeout they set, the cosmic-ray config."""
        clean = subprocess.run([sys.executable, str(HERE), "--baseline", str(self.dir)], cwd=self.src, env=self.env,
                               capture_output=True, text=True)
        if clean.returncode != 0:
            raise SystemExit(f"{self.key}: the tests fail on the unmutated code:\n{clean.stdout[-3000:]}{clean.stderr}")
        seconds = json.loads((self.dir / "baseline.json").read_text())["seconds"]
        limit = self.run["timeout_factor"] * seconds + self.run["timeout_slack"]
        (self.dir / "limit").write_text(f"{limit:.0f}")   # the server's: cosmic-ray's is a minute longer
        command = f"{sys.executable} {HERE} --client {self.dir}"
        self.config.write_text(f'[cosmic-ray]\nmodule-path = "{self.path}"\ntimeout = {limit + 60:.0f}\n'
                               f'excluded-modules = []\ntest-command = "{command}"\n\n'
                               '[cosmic-ray.distributor]\nname = "local"\n', encoding="utf-8")

    def forget_unverified(self) -> int:
        """Delete the results recorded as killed that are neither a test's failure nor a timeout — recorded before
        the client said how (a test server that had stopped made every later mutant 'killed'), or an error (no
        answer from the server, pytest's own failure): they are pending again."""
        import sqlite3
        with sqlite3.connect(self.session) as db:
            return db.execute("DELETE FROM work_results WHERE worker_outcome = 'NORMAL' AND test_outcome = 'KILLED' "
                              "AND NOT (output LIKE 'killed:%' OR output = 'timeout')").rowcount

    def forget_survivors(self) -> int:
        """Delete the survivors' results from the session: they are pending again."""
        import sqlite3
        with sqlite3.connect(self.session) as db:
            return db.execute("DELETE FROM work_results WHERE worker_outcome = 'NORMAL' "
                              "AND test_outcome = 'SURVIVED'").rowcount

    def skip_filtered(self) -> None:
        """Mark skipped: the excluded operators, and every mutant inside an annotation of a module whose annotations
        are never evaluated (``from __future__ import annotations``)."""
        from cosmic_ray.work_db import WorkDB, use_db
        from cosmic_ray.work_item import WorkerOutcome, WorkResult

        excluded = re.compile("|".join(f"(?:{e})" for e in self.run["exclude_operators"]))
        spans = annotation_spans((self.src / self.path).read_text(encoding="utf-8"))
        with use_db(str(self.session), WorkDB.Mode.open) as db:
            for item in db.pending_work_items:
                m = item.mutations[0]
                why = ("excluded operator" if excluded.match(m.operator_name) else
                       "annotation" if any(a <= tuple(m.start_pos) < b for a, b in spans) else None)
                if why:
                    db.set_result(item.job_id, WorkResult(output=why, worker_outcome=WorkerOutcome.SKIPPED))

    def restore(self) -> None:
        """The module's own file back in the copy (a killed run may have left a mutant in it)."""
        (self.src / self.path).write_text(git("show", f"{self.session_commit()}:{self.path}"), encoding="utf-8")

    def execute(self) -> None:
        """Run every pending mutant (the module's file restored first: a killed run may have left a mutant in it),
        through the test server."""
        self.restore()
        unverified = self.forget_unverified()
        if unverified:
            print(f"{self.key}: {unverified} results recorded as killed without how run again", flush=True)
        socket_path = self.dir / "server.sock"
        socket_path.unlink(missing_ok=True)
        with open(self.dir / "exec.log", "a", encoding="utf-8") as log:
            server = subprocess.Popen([sys.executable, str(HERE), "--serve", str(self.dir)], cwd=self.src,
                                      env=self.env, stdout=log, stderr=subprocess.STDOUT)
            try:
                while not socket_path.exists():
                    if server.poll() is not None:
                        raise SystemExit(f"{self.key}: the test server stopped (see {self.dir / 'exec.log'})")
                    time.sleep(0.5)
                subprocess.run(["cosmic-ray", "exec", str(self.config), str(self.session)], cwd=self.src,
                               env=self.env, stdout=log, stderr=subprocess.STDOUT, check=True)
            finally:
                server.terminate()
                server.wait()

    def results(self, equivalent: dict) -> dict:
        """Counts, the kill rate of the non-equivalent mutants and the survivors (with their change)."""
        from cosmic_ray.work_db import WorkDB, use_db
        from cosmic_ray.work_item import TestOutcome, WorkerOutcome

        counts = dict.fromkeys(("killed", "timeout", "survived", "equivalent", "errors", "pending", "skipped"), 0)
        survivors, stale = [], dict(equivalent)
        lines = (self.src / self.path).read_text(encoding="utf-8").splitlines()
        with use_db(str(self.session), WorkDB.Mode.open) as db:
            done = dict(db.results)
            for item in db.work_items:
                m, r = item.mutations[0], done.get(item.job_id)
                mid, line = f"{m.operator_name}#{m.occurrence}", m.start_pos[0]
                if r is None:
                    kind = "pending"
                elif r.worker_outcome == WorkerOutcome.SKIPPED:
                    kind = "skipped"
                elif r.worker_outcome != WorkerOutcome.NORMAL or r.test_outcome == TestOutcome.INCOMPETENT:
                    kind = "errors"
                elif r.test_outcome == TestOutcome.KILLED:
                    out = (r.output or "").strip()
                    kind = ("timeout" if out == "timeout" else "killed" if out.startswith("killed:") else
                            "errors" if out.startswith("error:") else "pending")   # unsaid: run again (forget_unverified)
                elif equivalent.get(mid, {}).get("line") == line:
                    kind = "equivalent"
                    stale.pop(mid)
                else:
                    kind = "survived"
                    change = [x for x in (r.diff or "").splitlines() if x[:1] in "+-" and x[:3] not in ("+++", "---")]
                    survivors.append({"mutant": mid, "line": line, "code": lines[line - 1].strip(), "change": change})
                counts[kind] += 1
        detected = counts["killed"] + counts["timeout"]
        rated = detected + counts["survived"]
        return {"module": self.path, "tests": self.tests, "commit": self.session_commit(),
                "mutants": sum(counts.values()) - counts["skipped"], **counts,
                "kill_rate": detected / rated if rated else None,
                "survivors": sorted(survivors, key=lambda s: s["line"]),
                "stale_equivalents": sorted(stale)}


def annotation_spans(source: str) -> list[tuple[tuple[int, int], tuple[int, int]]]:
    """``((line, col), (end_line, end_col))`` of every annotation, if the module postpones their evaluation."""
    tree = ast.parse(source)
    future = any(isinstance(n, ast.ImportFrom) and n.module == "__future__" and
                 any(a.name == "annotations" for a in n.names) for n in tree.body)
    if not future:
        return []
    found = []
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            a = node.args
            found += [x.annotation for x in (*a.posonlyargs, *a.args, *a.kwonlyargs, a.vararg, a.kwarg) if x]
            found.append(node.returns)
        elif isinstance(node, ast.AnnAssign):
            found.append(node.annotation)
    return [((n.lineno, n.col_offset), (n.end_lineno, n.end_col_offset)) for n in found if n is not None]


#: decorators that keep a function's result for the process: coverage records its lines only in the first test that
#: called it, yet every later test reads what it returned
MEMOISING = {"cache", "lru_cache", "cached_property"}


def function_body_lines(source: str) -> set[int]:
    """The lines inside a function's body: run when the function is called, never when the module is imported (a
    mutant anywhere else — a constant, a default, a decorator, a class attribute — may change what every test sees).
    None in a module that memoises a function (``@cache``, ``@lru_cache``, ``@cached_property``): the tests recorded
    as running a line are then only the first caller's, and neither the memoised function's lines nor those of what
    it calls can be told apart from a static reading."""
    tree = ast.parse(source)
    found: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            for d in node.decorator_list:
                d = d.func if isinstance(d, ast.Call) else d
                if (d.attr if isinstance(d, ast.Attribute) else getattr(d, "id", None)) in MEMOISING:
                    return set()
            found.update(range(node.body[0].lineno, node.end_lineno + 1))
            found.discard(node.lineno)          # a one-line def: its defaults are evaluated at import
    return found


# The test server: ``--baseline`` (once per copy), ``--serve`` (for the run) and ``--client`` (cosmic-ray's test
# command) run in the module's copy (cwd), with the paths of ``Module.env``.

def _start(work: Path) -> tuple[dict, Path]:
    sys.path[0] = os.getcwd()           # as ``python -m pytest`` run in the copy: not this file's folder
    return json.loads((work / "module.json").read_text()), Path.cwd()


BASELINE_VERSION = 3        # 3: the lines the tests ran in the processes they started (and their forked workers) too


def baseline(work: Path) -> int:
    """The module's tests on the unmutated copy under coverage: ``baseline.json`` gets their time, for each line of
    the module the tests that ran it (in their order) — in this process and in every Python process a test
    started (the CLI run as a subprocess, spawned pool and dask workers: coverage's start-up hook, with the test's
    id as the process's context) — and the third-party modules they imported."""
    import coverage
    from coverage.data import CoverageData
    import pytest

    spec, src = _start(work)
    target = str(src / spec["path"])
    cov = coverage.Coverage(data_file=None, include=[target])
    order: list[str] = []
    sub = work / "subprocess-coverage"
    shutil.rmtree(sub, ignore_errors=True)
    sub.mkdir()
    rc_file = work / "subprocess-coverage.rc"
    rc_file.write_text(f"[run]\ndata_file = {sub / 'cov'}\nparallel = true\ninclude = {target}\n"
                       "context = ${RVTOL_MUTATION_TEST}\npatch = fork, _exit\n", encoding="utf-8")
    os.environ["COVERAGE_PROCESS_START"] = str(rc_file)

    class Contexts:
        @pytest.hookimpl(hookwrapper=True)
        def pytest_runtest_protocol(self, item, nextitem):
            order.append(item.nodeid)
            os.environ["RVTOL_MUTATION_TEST"] = item.nodeid
            cov.switch_context(item.nodeid)
            yield
            cov.switch_context("")
            os.environ["RVTOL_MUTATION_TEST"] = ""

    t0 = time.perf_counter()
    cov.start()
    rc = pytest.main(["-x", "-q", "-p", "no:cacheprovider", *spec["tests"]], plugins=[Contexts()])
    cov.stop()
    seconds = time.perf_counter() - t0
    del os.environ["COVERAGE_PROCESS_START"]
    from rvtol import executors         # the workers a run kept: their coverage is written when they stop
    for live in list(getattr(executors, "_LIVE", ())):
        live.close()
    module = sys.modules.get(spec["path"].removesuffix(".py").replace("/", "."))
    if rc != 0 or module is None or Path(module.__file__).resolve() != (src / spec["path"]).resolve():
        print(f"tests: exit {rc}; module {getattr(module, '__file__', None)} (not the copy's?)")
        return 1
    rank = {n: i for i, n in enumerate(order)}
    ran = {line: set(contexts) for line, contexts in cov.get_data().contexts_by_lineno(target).items()}
    # lines this process ran outside a test (the import, the collection): every test may depend on them
    outside = sorted(line for line, contexts in ran.items() if any(c not in rank for c in contexts))
    for f in sub.glob("cov.*"):
        data = CoverageData(basename=str(f))
        data.read()
        for line, contexts in data.contexts_by_lineno(target).items():
            ran.setdefault(line, set()).update(contexts)
    lines = {line: sorted((c for c in contexts if c in rank), key=rank.get) for line, contexts in ran.items()}
    libs = sorted(name for name, m in list(sys.modules.items()) if (f := getattr(m, "__file__", None))
                  and not Path(f).resolve().is_relative_to(src) and not Path(f).resolve().is_relative_to(ROOT)
                  and name.split(".")[0] not in ("rvtol", "coverage", "__main__"))
    (work / "baseline.json").write_text(json.dumps({"version": BASELINE_VERSION, "seconds": seconds, "lines": lines,
                                                    "outside": outside, "libs": libs, "subprocess_files": len(list(sub.glob("cov.*")))}))
    return 0


def serve(work: Path) -> int:
    """Answer each client with the outcome of the module's tests on the mutant now in the copy's file."""
    import difflib
    import importlib
    import signal
    import socket

    spec, src = _start(work)
    base = json.loads((work / "baseline.json").read_text())
    for name in base["libs"]:
        try:
            importlib.import_module(name)
        except Exception:               # a private or platform module that cannot be imported on its own
            pass
    sys.dont_write_bytecode = True      # each mutant is compiled from its source, never from a cache
    limit = float((work / "limit").read_text())
    original = (src / spec["path"]).read_text(encoding="utf-8").splitlines()
    covering = {int(line): ids for line, ids in base["lines"].items()}
    runtime = function_body_lines("\n".join(original)) - set(base["outside"])

    def pytest_fork(args: list[str], seconds: float) -> int | str:
        pid = os.fork()
        if pid == 0:
            os.setpgid(0, 0)
            out = os.open(work / "last.out", os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
            os.dup2(out, 1)
            os.dup2(out, 2)
            signal.alarm(max(1, int(seconds)))
            import pytest
            rc = 3
            try:
                rc = pytest.main(["-x", "-q", "-p", "no:cacheprovider", *args])
            finally:
                sys.stdout.flush()
                sys.stderr.flush()
                os._exit(int(rc))
        _, status = os.waitpid(pid, 0)
        try:
            os.killpg(pid, signal.SIGKILL)      # whatever the tests started and left
        except ProcessLookupError:
            pass
        if os.WIFSIGNALED(status):
            return "timeout" if os.WTERMSIG(status) == signal.SIGALRM else 128 + os.WTERMSIG(status)
        return os.WEXITSTATUS(status)

    def judge() -> str:
        mutant = (src / spec["path"]).read_text(encoding="utf-8").splitlines()
        changed = set()
        for tag, i1, i2, _, _ in difflib.SequenceMatcher(None, original, mutant, autojunk=False).get_opcodes():
            if tag != "equal":
                changed.update(range(i1 + 1, max(i2, i1 + 1) + 1))
        first = list(dict.fromkeys(n for line in sorted(changed) for n in covering.get(line, ())))
        deadline = time.monotonic() + limit
        if first:
            rc = pytest_fork(first, limit)
            if rc not in (0, 4, 5):     # 4, 5: a node id pytest could not find — the files will tell
                return str(rc)
            if rc == 0 and all(covering.get(line) and line in runtime for line in changed):
                return "0"              # no other test runs a changed line, in any process: none can fail
            if rc != 0:
                first = []
        rest = [*spec["tests"], *(f"--deselect={n}" for n in first)]
        return str(pytest_fork(rest, deadline - time.monotonic()))

    server = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    server.bind(str(work / "server.sock"))
    server.listen(1)
    print(f"serving {spec['path']} with {len(base['libs'])} modules imported", flush=True)
    while True:
        conn, _ = server.accept()
        with conn:
            try:
                conn.recv(16)
                conn.sendall(judge().encode())
            except OSError as exc:      # the client is gone (cosmic-ray's timeout stopped it): serve the next one
                print(f"a client left before its answer ({exc})", flush=True)


#: pytest's exit codes that mean the tests found the mutant: a test failed (1), or collecting them failed (2: the
#: mutant breaks an import)
DETECTED = ("1", "2")


def client(work: Path) -> int:
    """cosmic-ray's test command: exit 0 if the tests pass on the mutant, else 1 — and what it was, as the result's
    output: ``killed: pytest exit N`` (a test failed, or the collection), ``timeout``, or ``error: …`` (pytest's own
    failure, a crashed test process, no answer from the test server): only the first two count as detected
    (:meth:`Module.results`; cosmic-ray records every non-zero exit as killed)."""
    import socket

    try:
        with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as conn:
            conn.connect(str(work / "server.sock"))
            conn.sendall(b"run")
            answer = conn.recv(64).decode()
    except OSError as exc:
        print(f"error: no answer from the test server ({exc})", end="")
        return 1
    if answer == "0":
        return 0
    print("timeout" if answer == "timeout" else f"killed: pytest exit {answer}" if answer in DETECTED else
          f"error: pytest exit {answer}" if answer.isdigit() else f"error: the test server answered {answer!r}", end="")
    return 1


def _rate(r: dict) -> str:
    return "—" if r["kill_rate"] is None else f"{100 * r['kill_rate']:.1f} %"


def markdown(report: list[dict]) -> str:
    """The report: a table of the modules, then each module's survivors."""
    cols = ("mutants", "killed", "timeout", "survived", "equivalent", "errors", "pending")
    out = ["# Mutation run (cosmic-ray, tests/mutation.py)\n\n",
           "| module | commit | " + " | ".join(cols) + " | kill rate |\n", "|---" * (len(cols) + 3) + "|\n"]
    out += [f"| {r['module']} | {r['commit'][:10]} | " + " | ".join(str(r[c]) for c in cols) + f" | {_rate(r)} |\n"
            for r in report]
    for r in report:
        out.append(f"\n## {r['module']}\n\ntests: {', '.join(r['tests'])}\n\n")
        out += [f"- line {s['line']} `{s['mutant']}`: `{s['code']}` → " + "; ".join(f"`{c}`" for c in s["change"])
                + "\n" for s in r["survivors"]]
        out += [f"- stale equivalent entry {e} (its line changed: review it)\n" for e in r["stale_equivalents"]]
    return "".join(out)


def check_equivalents(cfg: dict, keys) -> int:
    """Every ``[[equivalent]]`` of ``keys``' modules checked against cosmic-ray's own numbering of today's file: its
    mutant id must exist at its line (ids count the operator's occurrences through the whole file, so code added above
    an entry renumbers it).  A stale entry is printed with the mutants of its operator at its line; exit 1 if any."""
    from cosmic_ray.commands.init import _all_work_items

    bad = 0
    for key in keys:
        path = ROOT / cfg["module"][key]["path"]
        at = {}
        for item in _all_work_items([path], {}):
            m = item.mutations[0]
            at[f"{m.operator_name}#{m.occurrence}"] = m.start_pos[0]
        for e in (e for e in cfg.get("equivalent", []) if e["module"] == key):
            if at.get(e["mutant"]) == e["line"]:
                continue
            bad += 1
            op = e["mutant"].split("#")[0]
            near = [k for k, line in at.items() if k.split("#")[0] == op and line == e["line"]]
            print(f"stale: {key} {e['mutant']} line {e['line']}: "
                  + (f"now at line {at[e['mutant']]}" if e["mutant"] in at else "no such mutant")
                  + (f"; at line {e['line']}: {', '.join(near)}" if near else ""))
    print(f"{bad} stale equivalent entr{'y' if bad == 1 else 'ies'}")
    return 1 if bad else 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("modules", nargs="*", help="module keys of tests/mutation.toml (default: all)")
    ap.add_argument("--jobs", type=int, default=1, help="modules run at the same time (default 1)")
    ap.add_argument("--work", type=Path, default=OUT / "work", help="where the copies and sessions live")
    ap.add_argument("--out", type=Path, default=OUT, help="where mutation.md and mutation.json are written")
    ap.add_argument("--report", action="store_true", help="only write the report of what has run")
    ap.add_argument("--rerun-survivors", action="store_true",
                    help="a module whose tests changed (not its file): run only its survivors again")
    ap.add_argument("--check-equivalents", action="store_true",
                    help="only check that every [[equivalent]] id is at its line today (no run)")
    for role in ("--baseline", "--serve", "--client"):      # the test server's parts (see above)
        ap.add_argument(role, type=Path, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    for role in (baseline, serve, client):
        if getattr(args, role.__name__) is not None:
            return role(getattr(args, role.__name__))
    cfg = tomllib.loads(CONFIG.read_text(encoding="utf-8"))
    unknown = [k for k in args.modules if k not in cfg["module"]]
    if unknown:
        ap.error(f"unknown module {unknown[0]!r} (tests/mutation.toml has: {', '.join(cfg['module'])})")
    if args.check_equivalents:
        return check_equivalents(cfg, args.modules or list(cfg["module"]))
    commit = git("rev-parse", "HEAD").strip()
    mods = [Module(k, cfg["module"][k], cfg["run"], args.work, commit) for k in (args.modules or cfg["module"])]
    missing = [p for m in mods for p in (m.path, *m.tests) if not (ROOT / p).is_file()]
    if missing:
        ap.error(f"tests/mutation.toml names {missing[0]!r}, which is not a file of the repository")
    if not args.report:
        dirty = git("status", "--porcelain", "--", *{p for m in mods for p in (m.path, *m.tests)}).strip()
        if dirty:
            print(f"note: uncommitted changes are not tested (the run takes the commit {commit[:10]}):\n{dirty}")

        def one(m: Module) -> None:
            m.prepare(args.rerun_survivors)
            m.execute()
            print(f"{m.key}: done")

        with ThreadPoolExecutor(max(1, args.jobs)) as pool:
            list(pool.map(one, mods))
    equivalent: dict[str, dict] = {}
    for e in cfg.get("equivalent", []):
        equivalent.setdefault(e["module"], {})[e["mutant"]] = e
    report = [m.results(equivalent.get(m.key, {})) for m in mods if m.stamp.exists()]
    if not report:
        print("no module has run yet")
        return 1
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "mutation.json").write_text(json.dumps(report, indent=1, ensure_ascii=False), encoding="utf-8")
    (args.out / "mutation.md").write_text(markdown(report), encoding="utf-8")
    for r in report:
        print(f"{r['module']}: {r['mutants']} mutants, {r['killed']} killed, {r['timeout']} timeout, "
              f"{r['survived']} survived, {r['equivalent']} equivalent, {r['errors']} errors, {r['pending']} pending; "
              f"kill rate {_rate(r)}")
    print(f"report: {args.out / 'mutation.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
