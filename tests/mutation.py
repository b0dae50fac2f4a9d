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

Each module runs in its own copy of the committed tree (``git archive HEAD``: uncommitted changes are not
tested) under ``--work`` (default ``reports/mutation/work/<module>``): cosmic-ray writes each mutant into that
copy's file, so the working tree is never touched.  The session (``session.sqlite``, cosmic-ray's) keeps every
result: an interrupted run continues with the mutants not yet run; a change of what the tests can read (the
package, the tests, data, studies, pyproject.toml) or of the module's entry in the config starts it afresh — not
a change of README or of the equivalent mutants listed.
Before the first mutant the module's tests run on the unmutated copy (they must pass; their time sets the
timeout).  Mutants in annotations (never evaluated under ``from __future__ import annotations``) and the
operators the config excludes are skipped.  The report (``reports/mutation/mutation.md`` and ``.json``) gives per
module the mutants, killed, survived, timeout, errors, equivalent and pending, the kill rate of the
non-equivalent mutants, and every survivor with its line and change.
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

ROOT = Path(__file__).resolve().parents[1]
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

    def test_command(self) -> list[str]:
        return [sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", *self.tests]

    def prepare(self) -> None:
        """A fresh copy and session unless this commit's exist; the baseline; the filters."""
        if self.stamp.exists():
            old = json.loads(self.stamp.read_text())
            if old["fingerprint"] == self.fingerprint:
                return
            print(f"{self.key}: the code or tests changed since the run of {old['commit'][:10]}: afresh")
        shutil.rmtree(self.dir, ignore_errors=True)
        self.src.mkdir(parents=True)
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", self.commit], check=True, capture_output=True)
        subprocess.run(["tar", "-x", "-C", str(self.src)], input=archive.stdout, check=True)
        compileall.compile_dir(self.src / "rvtol", quiet=1)       # mutants recompile only the mutated module
        t0 = time.perf_counter()
        clean = subprocess.run(self.test_command(), cwd=self.src, env=self.env, capture_output=True, text=True)
        if clean.returncode != 0:
            raise SystemExit(f"{self.key}: the tests fail on the unmutated code:\n{clean.stdout[-3000:]}")
        timeout = self.run["timeout_factor"] * (time.perf_counter() - t0) + self.run["timeout_slack"]
        command = " ".join(self.test_command())
        self.config.write_text(f'[cosmic-ray]\nmodule-path = "{self.path}"\ntimeout = {timeout:.0f}\n'
                               f'excluded-modules = []\ntest-command = "{command}"\n\n'
                               '[cosmic-ray.distributor]\nname = "local"\n', encoding="utf-8")
        subprocess.run(["cosmic-ray", "init", str(self.config), str(self.session)], cwd=self.src, check=True)
        self.skip_filtered()
        self.stamp.write_text(json.dumps({"commit": self.commit, "fingerprint": self.fingerprint}))

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

    def execute(self) -> None:
        """Run every pending mutant (the module's file restored first: a killed run may have left a mutant in it)."""
        (self.src / self.path).write_text(git("show", f"{self.session_commit()}:{self.path}"), encoding="utf-8")
        with open(self.dir / "exec.log", "a", encoding="utf-8") as log:
            subprocess.run(["cosmic-ray", "exec", str(self.config), str(self.session)], cwd=self.src, env=self.env,
                           stdout=log, stderr=subprocess.STDOUT, check=True)

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
                    kind = "timeout" if r.output == "timeout" else "killed"
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


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("modules", nargs="*", help="module keys of tests/mutation.toml (default: all)")
    ap.add_argument("--jobs", type=int, default=1, help="modules run at the same time (default 1)")
    ap.add_argument("--work", type=Path, default=OUT / "work", help="where the copies and sessions live")
    ap.add_argument("--out", type=Path, default=OUT, help="where mutation.md and mutation.json are written")
    ap.add_argument("--report", action="store_true", help="only write the report of what has run")
    args = ap.parse_args(argv)
    cfg = tomllib.loads(CONFIG.read_text(encoding="utf-8"))
    unknown = [k for k in args.modules if k not in cfg["module"]]
    if unknown:
        ap.error(f"unknown module {unknown[0]!r} (tests/mutation.toml has: {', '.join(cfg['module'])})")
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
            m.prepare()
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
