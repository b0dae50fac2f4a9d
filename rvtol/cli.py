"""``rvtol`` command line: ``main(argv) -> int``.

Exit codes (``rvtol docs command-line``: rvtol/docs/command_line.md):

====  ==========================================================================
0     every requirement demonstrated (verdict PASS), or an exploratory study;
      ``compare``: every gate holds
1     a requirement fails (FAIL), or a gate of the baseline comparison fails
2     bad input: one line ``rvtol: error: FILE: KEY: reason``, nothing written
      (also: ``--out`` not writable, not enough memory or disk for n, more
      workers than the machine holds, contradicting execution flags, an
      output file that is an input or not rvtol's, the output folder locked
      by another run)
3     internal error — a bug: please report it with the ``--debug`` output
4     no requirement checked (verdict NO REQUIREMENTS): nothing is demonstrated
130   interrupted (SIGINT, Ctrl-C); 143 terminated (SIGTERM, a CI cancel):
      workers stopped, nothing written, finished chunks kept for ``--resume``
====  ==========================================================================
"""
from __future__ import annotations

import argparse
import contextlib
import errno
import json
import os
import secrets
import sys
import textwrap
import time
from pathlib import Path

from . import __version__
from .errors import InputError, ModelCodeError

EXIT_PASS, EXIT_FAIL, EXIT_INPUT, EXIT_INTERNAL, EXIT_NO_REQUIREMENTS = 0, 1, 2, 3, 4
#: the reader of standard output closed it (a shell's 128 + SIGPIPE)
EXIT_BROKEN_PIPE = 141

#: exit code of each study verdict (rvtol.verdict.study_verdict)
VERDICT_EXIT = {"PASS": EXIT_PASS, "FAIL": EXIT_FAIL, "NO REQUIREMENTS": EXIT_NO_REQUIREMENTS, "EXPLORATORY": EXIT_PASS}

#: errors of the machine, not of rvtol: reported as bad input (exit 2), never as an internal error
_ENVIRONMENT_ERRNOS = {errno.ENOSPC, errno.EACCES, errno.EROFS, errno.EDQUOT, errno.EPERM, errno.ENAMETOOLONG}


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit 2, like every other bad input
        self.exit(EXIT_INPUT, f"rvtol: error: <command line>: -: {message}\n")


def _parser() -> argparse.ArgumentParser:
    p = _Parser(prog="rvtol", description="Probabilistic tolerance and Monte Carlo analysis of RV reducers.")
    p.add_argument("--version", action="version", version=f"rvtol {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")

    run = sub.add_parser("run", help="run a study and write its report folder")
    run.add_argument("study", help="study file (TOML)")
    run.add_argument("--out", help="output folder (default: reports/<study name>)")
    run.add_argument("--executor", choices=("serial", "process", "dask"), help="where model evaluations run")
    run.add_argument("--workers", type=int, help="worker processes (default: every core)")
    run.add_argument("--scheduler", help="Dask scheduler address (implies --executor dask)")
    run.add_argument("--n", type=int, help="number of Monte Carlo samples")
    run.add_argument("--seed", type=int, help="random seed")
    run.add_argument("--method", choices=("random", "lhs", "sobol"), help="sampling method")
    run.add_argument("--until-decided", action="store_true",
                     help="sample batches of n until every requirement is PASS or FAIL at its confidence by an "
                          "anytime-valid rule, or --max-n samples are drawn (a sequential run; random sampling)")
    run.add_argument("--max-n", type=int, help="the sample budget of --until-decided (default: 20 n)")
    run.add_argument("--tails", action="store_true",
                     help="decide the yield requirements the Monte Carlo leaves UNDECIDED by tail estimators "
                          "(importance sampling, subset simulation; rvtol.tail_decision), cross-checked against it")
    run.add_argument("--chunk-size", type=int, help="samples per task (default: automatic)")
    run.add_argument("--task-log", metavar="FILE", help="write every parallel call's tasks and their CPU seconds "
                     "(JSON) with the run projected on as many dedicated cores as it had workers: run with "
                     "--workers 16 to see the run on 16 cores from a smaller machine")
    run.add_argument("--resume", action="store_true",
                     help="continue an interrupted run of the same --out from its finished chunks")
    run.add_argument("--baseline", metavar="DIR", help="compare with this accepted report folder (or summary.json) "
                     "and apply the study's gates")
    _ci_outputs(run)
    run.add_argument("--no-pdf", action="store_true", help="skip report.pdf")
    run.add_argument("--tables", choices=("csv", "xlsx"), action="append",
                     help="also write samples and statistics as CSV or XLSX beside samples.parquet (repeatable)")
    run.add_argument("--quiet", action="store_true", help="no progress bar, only the verdict line")
    run.add_argument("--debug", action="store_true", help="show tracebacks of internal errors")

    cmp_ = sub.add_parser("compare", help="compare two runs (report folders or summary.json) and apply the gates")
    cmp_.add_argument("base", help="the accepted baseline: report folder or summary.json")
    cmp_.add_argument("new", help="the run to judge: report folder or summary.json")
    cmp_.add_argument("--out", metavar="FILE", help="write the comparison as JSON")
    _ci_outputs(cmp_)
    cmp_.add_argument("--debug", action="store_true")

    ini = sub.add_parser("init", help="write a first study (study.toml and spec.csv) that runs as written")
    ini.add_argument("dir", nargs="?", default=".", help="folder to write into (default: the current folder)")

    chk = sub.add_parser("check", help="validate a study and everything it names, without running it")
    chk.add_argument("study")
    chk.add_argument("--execute", action="store_true",
                     help="also run the code of a Python model's factory (by default it is checked, not run)")
    chk.add_argument("--debug", action="store_true")

    kinds = sub.add_parser("kinds", help="list the model and analysis kinds a study can use; with KIND, the keys of "
                                         "that analysis kind (type, default, meaning)")
    kinds.add_argument("kind", nargs="?", help="an analysis kind: list its keys")

    docs = sub.add_parser("docs", help="list the guides shipped with rvtol; with NAME, print one (Markdown)")
    docs.add_argument("name", nargs="?", help="a document, e.g. writing-a-study")

    spec = sub.add_parser("spec", help="tolerance specs: convert between TOML and tables")
    ssub = spec.add_subparsers(dest="spec_command", metavar="SPEC_COMMAND")
    exp = ssub.add_parser("export", help="write a spec (TOML, CSV or XLSX) as a CSV or XLSX table")
    exp.add_argument("spec", help="spec file (.toml, .csv, .tsv or .xlsx)")
    exp.add_argument("--out", required=True, help="the table to write (.csv, .tsv or .xlsx)")
    exp.add_argument("--sheet", help="the sheet to read from an .xlsx spec (default: its only visible sheet, or the "
                                      "one it opens on when that is also its first)")
    exp.add_argument("--force", action="store_true", help="replace --out if it exists")
    return p


def _ci_outputs(p) -> None:
    p.add_argument("--junit", metavar="FILE", help="write a JUnit XML report (one test case per requirement and gate)")
    p.add_argument("--markdown", metavar="FILE", help="write a Markdown summary (also appended to "
                   "$GITHUB_STEP_SUMMARY when that is set)")


def main(argv: list[str] | None = None) -> int:
    from .runguard import Interrupted, stopping_on_signals

    args = _parser().parse_args(argv)
    if args.command is None:
        _parser().print_help()
        return EXIT_INPUT
    try:
        with stopping_on_signals():
            if args.command == "kinds":
                return _kinds(args.kind)
            if args.command == "docs":
                return _docs(args.name)
            if args.command == "check":
                return _check(args)
            if args.command == "init":
                return _init(args)
            if args.command == "compare":
                return _compare(args)
            if args.command == "spec":
                return _spec(args)
            return _run(args)
    except InputError as exc:
        print(f"rvtol: error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except ModelCodeError as exc:   # the user's model code raised or exited: its message, exit 3, never 0
        print(f"rvtol: error: {exc} (the model's own code; nothing written)", file=sys.stderr)
        return EXIT_INTERNAL
    except SystemExit as exc:       # sys.exit() in code rvtol called (a plug-in): never a silent exit 0
        print(f"rvtol: error: <model>: -: code rvtol ran called sys.exit({exc.code!r}) (nothing written)",
              file=sys.stderr)
        return EXIT_INTERNAL
    except Interrupted as exc:
        return _stopped(exc)
    except KeyboardInterrupt:
        print("rvtol: interrupted (nothing written)", file=sys.stderr)
        return 130
    except MemoryError:
        print("rvtol: error: <command line>: --n: out of memory during the run; lower n", file=sys.stderr)
        return EXIT_INPUT
    except BrokenPipeError:         # the reader of the output stopped reading (rvtol kinds | head): not a bug
        _quiet_stdout()
        return EXIT_BROKEN_PIPE
    except OSError as exc:
        if exc.errno not in _ENVIRONMENT_ERRNOS or getattr(args, "debug", False):
            return _internal(args, exc)
        print(f"rvtol: error: {exc.filename or '<output>'}: -: cannot write ({exc.strerror})", file=sys.stderr)
        return EXIT_INPUT
    except Exception as exc:  # a bug, not bad input — unless it came from code unwinding a stop signal
        stop = _interruption(exc)
        return _stopped(stop) if stop is not None else _internal(args, exc)


def _stopped(exc) -> int:
    """A run stopped by a signal: what was kept, and the signal's exit code (130, 143)."""
    kept = f"; {exc.kept_chunks} finished chunks kept: rerun with --resume to continue" if exc.kept_chunks else ""
    print(f"rvtol: stopped by {exc.name}: workers stopped, nothing written{kept}", file=sys.stderr)
    return exc.exit_code


def _interruption(exc: BaseException | None):
    """The stop signal (:class:`rvtol.runguard.Interrupted`) an exception was raised while handling, if any: a library
    interrupted mid-write may fail again as it unwinds (a ZIP archive closed over a half-written member), and the run
    was still stopped, not broken."""
    from .runguard import Interrupted

    seen: set[int] = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, Interrupted):
            return exc
        seen.add(id(exc))
        exc = exc.__context__
    return None


def _quiet_stdout() -> None:
    """Standard output whose reader has gone: what is still buffered goes nowhere (else Python's exit flush
    fails again and prints its own traceback)."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())


def _internal(args, exc: BaseException) -> int:
    if getattr(args, "debug", False):
        raise exc
    print(f"rvtol: internal error: {type(exc).__name__}: {exc} (rerun with --debug for the traceback)",
          file=sys.stderr)
    return EXIT_INTERNAL


def _overrides(args) -> dict:
    for name in ("n", "workers", "chunk_size"):
        v = getattr(args, name, None)
        if v is not None and v < (2 if name == "n" else 1):
            raise InputError(f"must be >= {2 if name == 'n' else 1}, got {v}", file="<command line>",
                             key=f"--{name.replace('_', '-')}")
    if args.seed is not None and args.seed < 0:
        raise InputError(f"must be >= 0, got {args.seed}", file="<command line>", key="--seed")
    ov = dict(n=args.n, seed=args.seed, method=args.method, executor=args.executor, workers=args.workers,
              scheduler=args.scheduler, chunk_size=args.chunk_size, until_decided=args.until_decided or None,
              max_n=args.max_n, tails=args.tails or None)
    if args.no_pdf:
        ov["pdf"] = False
    if args.tables:
        ov["tables"] = tuple(dict.fromkeys(args.tables))
    if args.quiet:
        ov["progress"] = False
    return ov


def _init(args) -> int:
    from .init_template import write_template

    files = write_template(args.dir)
    study = files[0]
    print(f"rvtol: wrote {', '.join(str(f) for f in files)} — a first study that runs as written:\n"
          f"  rvtol run {study}\n"
          "then replace the parts in spec.csv and the formulas in study.toml with your own "
          "(every key: rvtol docs writing-a-study)")
    return EXIT_PASS


def _check(args) -> int:
    from .model import model_label
    from .study import NotRunModel, load_study

    st = load_study(args.study, execute=args.execute)
    if isinstance(st.model, NotRunModel):
        print(f"rvtol: {st.file}: ok — {len(st.spec)} factors, {len(st.requirements)} requirements; "
              + "; ".join(st.model.notes))
        print("rvtol: note: the model's code was not run, so its outputs, the requirements' and gates' outputs "
              "and the analyses are unchecked: rvtol check --execute runs it")
        return EXIT_PASS
    failures = _formula_failures(st)
    if failures:
        for key, text in failures:
            print(f"rvtol: error: {st.file}: {key}: {text}", file=sys.stderr)
        return EXIT_INPUT
    print(f"rvtol: {st.file}: ok — model {model_label(st.model)}, {len(st.spec)} factors, "
          f"{len(st.model.outputs)} outputs, {len(st.requirements)} requirements, {len(st.gates)} gates, "
          f"{len(st.analyses)} analyses")
    for note in st.notes:
        print(f"rvtol: note: {note}")
    if not st.requirements:
        print("rvtol: note: " + ("an exploratory study: it checks no requirement (verdict EXPLORATORY, exit 0)"
                                 if st.exploratory else "no requirement: a run's verdict will be NO REQUIREMENTS "
                                 "(exit 4); add [[requirement]] tables or declare [study] exploratory = true"))
    return EXIT_PASS


def _formula_failures(st) -> list[tuple[str, str]]:
    """A formula model evaluated at the nominal and the corners of the bands: (key, where and why) per output
    that fails (rvtol.models.formula.probe)."""
    probe = getattr(st.model, "probe", None)      # models that can be probed without running user code
    if probe is None:
        return []
    return [(f"model.output[{f.output}].formula", f.describe()) for f in probe(st.spec, st.options.seed)]


def _spec(args) -> int:
    from .inputs.sheets import WRITE_SUFFIXES
    from .inputs.table_spec import read_spec_table, write_table_spec
    from .spec import TABLE_SUFFIXES, load_spec

    if args.spec_command != "export":
        _parser().parse_args(["spec", "--help"])
    out = Path(args.out)
    if out.suffix.lower() not in WRITE_SUFFIXES:
        raise InputError(f"unknown table format {out.suffix!r} (expected {', '.join(WRITE_SUFFIXES)})",
                         file=str(out), key="--out")
    if out.exists() and not args.force:
        raise InputError("exists; give --force to replace it", file=str(out), key="--out")
    spec = load_spec(args.spec, sheet=args.sheet)
    _refuse_spec_inputs(out, spec, Path(args.spec))
    # a table's comment rows and notes columns are not part of the spec: carried over from the table itself
    keep = read_spec_table(args.spec, sheet=spec.sheet) if Path(args.spec).suffix.lower() in TABLE_SUFFIXES else None
    with _replacing(out) as tmp:
        write_table_spec(spec, tmp, keep=keep, shown=str(out))
    print(f"rvtol: wrote {out} ({len(spec)} factors of spec {spec.name!r}"
          + (f", sheet {spec.sheet!r}" if spec.sheet else "") + ")")
    return EXIT_PASS


def _refuse_spec_inputs(out: Path, spec, source: Path) -> None:
    """``spec export --out`` is never a file the spec is read from — the spec itself (by any name: a symlink, a
    hard link) or a measured factor's data: replacing it, even with --force, would lose what only it holds."""
    if not out.exists():
        return
    inputs = [source] + [Path(f.measured.data) if Path(f.measured.data).is_absolute()
                         else source.parent / f.measured.data
                         for f in spec.factors if getattr(f, "measured", None) is not None]
    for p in inputs:
        if p.exists() and os.path.samefile(p, out):
            what = "the spec being exported" if p == source else f"the measured data of the spec ({p.name})"
            raise InputError(f"is {what}: write the table to another file (--force replaces only files the spec "
                             "is not read from)", file=str(out), key="--out")


def _kinds(kind: str | None = None) -> int:
    from .registry import ANALYSES, MODELS, analysis_function, model_factory, plugin_analyses, plugin_models

    from .registry import TABLE_FILES, TABLES, table_options

    if kind in TABLES:
        options = table_options(kind)
        head = " ".join(options.__doc__.split("\n\n")[0].replace("``", "").split())   # "[sampling]: how many ..."
        _keys(head, options)
        return EXIT_PASS
    if kind is not None:
        is_model = kind in MODELS or kind in plugin_models()
        if is_model:
            _model_keys(model_factory(kind, "<command line>"), kind)
        if not is_model or kind in ANALYSES or kind in plugin_analyses():   # a name both kinds use: both
            cls = analysis_function(kind, "<command line>", "kind")
            _keys(f"{kind} (analysis): {cls.title}", cls.Options)
        return EXIT_PASS
    print("models:   " + ", ".join(sorted(MODELS)))
    plugins = plugin_models()
    if plugins:
        print("models from installed packages: " + ", ".join(f"{k} ({ep.value})" for k, ep in sorted(plugins.items())))
    print("analyses: " + ", ".join(sorted(ANALYSES)))
    plugins = plugin_analyses()
    if plugins:
        print("analyses from installed packages: " + ", ".join(f"{k} ({ep.value})" for k, ep in
                                                                sorted(plugins.items())))
    print("tables, by the file they are in:")
    width = max(len(f) for f in TABLE_FILES) + 4
    for f, names in TABLE_FILES.items():
        print(textwrap.fill(", ".join(names), width=110, initial_indent=f"  {f + ':':{width - 2}}",
                            subsequent_indent=" " * width))
    print("rvtol kinds KIND lists the keys of a model or an analysis kind, or of a table")
    return EXIT_PASS


def _model_keys(factory, kind: str) -> None:
    """The keys of one model kind's ``[model]`` table: from its declared options (a plug-in's plain factory reads
    its own)."""
    options = getattr(factory, "Options", None)
    if options is None:
        print(f"{kind} (model): its factory reads its own keys (none declared)")
        return
    _keys(f"{kind} (model): {factory.title}", options)


def _docs(name: str | None) -> int:
    """``rvtol docs``: the shipped documents, one a line; ``rvtol docs NAME``: that document's text."""
    from . import docs

    if name is not None:
        sys.stdout.write(docs.text(name))
        return EXIT_PASS
    shipped = docs.documents()
    width = max(map(len, shipped))
    for doc, title in shipped.items():
        print(f"{doc:<{width}}  {title}")
    print("rvtol docs NAME prints one (Markdown); paths it names (studies/, data/, tests/) are in the rvtol repository")
    return EXIT_PASS


def _keys(heading: str, options) -> None:
    """A kind's keys from its declared options: type, default, rule and meaning."""
    from .options import describe

    print(heading)
    for o in describe(options):
        default = "required" if o.required else f"default {o.default!r}"
        rule = f"; {o.constraint}" if o.constraint else ""
        print(f"  {o.key} ({o.type}; {default}{rule})")
        if o.help:
            print(f"      {o.help}")


def _run(args) -> int:
    from .executors import discard_early

    ov = _overrides(args)
    _start_workers_early(args)
    try:
        return _run_study(args, ov)
    finally:
        discard_early()


def _start_workers_early(args) -> None:
    """Start the run's executor while the study loads (:func:`rvtol.executors.start_early`): the one the command line
    or the study file's ``[execution]`` table asks for (a study whose file cannot be read gets none: its loading
    reports why; one the loaded study then contradicts is closed unused)."""
    import tomllib

    from .executors import start_early
    from .params import Params
    from .runguard import workers_problem
    from .study import execution_keys, read_table_options

    try:
        root = Params(tomllib.loads(Path(args.study).read_text(encoding="utf-8")), file=args.study)
        v = execution_keys(read_table_options(root, "execution"),
                           {k: getattr(args, k) for k in ("executor", "workers", "scheduler")}, root.error)
    except (OSError, ValueError, RecursionError):    # the study's loading says what is wrong (InputError included)
        return
    kind, workers, scheduler = v["executor"], v["workers"], v["scheduler"]
    if workers_problem(kind, workers, scheduler):    # more than the machine holds: the checks refuse it, unstarted
        return
    start_early(kind, workers, scheduler)


def _run_study(args, ov: dict) -> int:
    from .checkpoint import run_key
    from .params import recording_reads
    from .runguard import RunFolder, check_not_input, check_resources, check_writable, estimate_run, time_pilot
    from .study import check_out_dir, load_study, run_study, write_outputs, written_files

    with recording_reads() as inputs:       # every file the run reads: nothing it writes may replace one
        study = load_study(args.study, **ov)
        baseline = None
        if args.baseline:
            from .ci.compare import load_run

            baseline = load_run(args.baseline, key="--baseline")
            if baseline.summary.get("study") != study.name:
                raise InputError(f"the baseline is a run of study {baseline.summary.get('study')!r}, this is study "
                                 f"{study.name!r}: compare runs of one study", file=args.baseline, key="--baseline")
    # everything that can be checked is checked before computing (exit 2, nothing written)
    out = check_out_dir(Path(args.out) if args.out else Path("reports") / study.name)
    check_not_input(out, inputs, "--out")
    check_writable(out, "--out")
    _check_file_targets(args, ("junit", "markdown", "task_log"), inputs, out)
    est = estimate_run(study)
    n_at = (("<command line>", "--max-n") if args.max_n is not None else (study.file, "sampling.max_n")) \
        if study.options.until_decided else \
        (("<command line>", "--n") if args.n is not None else (study.file, "sampling.n"))
    check_resources(est, out, *n_at,
                    study.options, ("<command line>", "--workers") if args.workers is not None else
                    (study.file, "execution.workers"))
    if not args.quiet:
        print(f"rvtol: {time_pilot(est, study).describe()}", file=sys.stderr)
        _note_shared_cores(study.options)

    o = study.options
    key = run_key({"rvtol": __version__, "inputs": {r: v["sha256"] for r, v in study.inputs.items()},
                   "n": o.n, "seed": o.seed, "method": o.method, "chunk_size": o.chunk_size,
                   **({"until_decided": True, "max_n": o.max_n} if o.until_decided else {}),
                   "model": type(study.model).__name__})
    with RunFolder(out) as folder:
        store, note = folder.open_store(key, args.resume)
        if note:
            print(f"rvtol: {note}", file=sys.stderr)
        result = run_study(study, store=store, baseline=baseline, record_calls=bool(args.task_log))
        comparison = result.comparison
        extra = {}
        if comparison is not None:
            extra["comparison.json"] = json.dumps(comparison.to_dict(), indent=2, ensure_ascii=False, allow_nan=False)
        t0 = time.perf_counter()
        write_outputs(result, out, extra_files=extra)
        t_report = time.perf_counter() - t0
    if store.reused:
        print(f"rvtol: resumed: {store.reused} chunks ({store.reused_rows} evaluations) reused, "
              f"{store.saved} computed", file=sys.stderr)
    if not args.quiet:
        _print_result(result)
        phases = [*result.timings.items(), ("writing", t_report)]
        print("time by phase: " + " · ".join(f"{k} {v:.1f} s" for k, v in phases))
        if comparison is not None:
            print(comparison.text())
    _write_ci_outputs(args, result.summary(), comparison)
    if args.task_log:
        from .scaling import task_log

        with _replacing(Path(args.task_log)) as tmp:
            tmp.write_text(json.dumps(task_log(result), indent=1, allow_nan=False), encoding="utf-8")
    verdict = result.verdict
    print(f"verdict: {verdict} — report: {out / 'report.html'}"
          + f" (+ {', '.join(written_files(out))})")
    if comparison is not None:
        print(f"gates: {comparison.verdict} — {comparison.one_line()}")
        if not comparison.passed:
            return EXIT_FAIL
    return VERDICT_EXIT[verdict]


def _note_shared_cores(o) -> None:
    """A note when the local workers outnumber the cores: they share them (what ``--task-log`` is run so for)."""
    from .runguard import local_workers

    w, cores = local_workers(o.executor, o.workers, o.scheduler), os.cpu_count() or 1
    if w > cores:
        print(f"rvtol: note: {w} workers share {cores} cores: the run is no faster than on {cores} (--task-log "
              f"projects it on {w} dedicated cores)", file=sys.stderr)


@contextlib.contextmanager
def _replacing(out: Path):
    """A temporary file beside ``out`` that replaces it when the block ends without an error: ``out`` is never
    half-written."""
    from .runguard import TMP_SUFFIX

    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(f".{out.stem}{TMP_SUFFIX}{secrets.token_hex(6)}{out.suffix}")   # the suffix: its format
    try:
        yield tmp
        os.replace(tmp, out)
    finally:
        tmp.unlink(missing_ok=True)


#: the kind of file each flag writes (rvtol.runguard.OWN_FILES)
_FILE_KINDS = {"junit": "junit", "markdown": "markdown", "task_log": "task_log", "out": "comparison"}


def _check_file_targets(args, flags, inputs, out: Path | None = None) -> None:
    """The files the flags name can be written (:func:`rvtol.runguard.check_output_file`: none replaces an input of
    the run, a file rvtol did not write, or the report folder ``out``), and no two flags name one file."""
    from .runguard import check_distinct_targets, check_output_file

    given = {f"--{flag.replace('_', '-')}": (flag, getattr(args, flag)) for flag in flags if getattr(args, flag)}
    for key, (flag, path) in given.items():
        check_output_file(path, _FILE_KINDS[flag], key, inputs, out)
    check_distinct_targets({key: path for key, (_, path) in given.items()})


def _write_ci_outputs(args, summary: dict, comparison) -> None:
    """--junit, --markdown and $GITHUB_STEP_SUMMARY (the same Markdown) of a run or a comparison."""
    if args.junit:
        from .ci.junit import write_junit

        with _replacing(Path(args.junit)) as tmp:
            write_junit(tmp, summary, comparison)
    md = None
    if args.markdown or os.environ.get("GITHUB_STEP_SUMMARY"):
        from .ci.markdown import render_markdown

        md = render_markdown(summary, comparison)
    if args.markdown:
        with _replacing(Path(args.markdown)) as tmp:
            tmp.write_text(md, encoding="utf-8")
    step = os.environ.get("GITHUB_STEP_SUMMARY")
    if step:
        with open(step, "a", encoding="utf-8") as f:
            f.write(md + "\n")


def _compare(args) -> int:
    from .ci.compare import compare, load_run

    from .ci.compare import same_study
    from .params import recording_reads

    with recording_reads() as inputs:
        base = load_run(args.base, key="BASE")
        new = load_run(args.new, key="NEW")
    _check_file_targets(args, ("junit", "markdown", "out"), inputs)
    same_study(base, new, key="BASE", file=args.base)
    comparison = compare(base, new, seed=new.summary.get("seed"))
    if args.out:
        with _replacing(Path(args.out)) as tmp:
            tmp.write_text(json.dumps(comparison.to_dict(), indent=2, ensure_ascii=False, allow_nan=False),
                           encoding="utf-8")
    print(comparison.text())
    _write_ci_outputs(args, new.summary, comparison)
    print(f"gates: {comparison.verdict} — {comparison.one_line()}")
    return EXIT_PASS if comparison.passed else EXIT_FAIL


def _print_result(result) -> None:
    from .precision import requirements_scale, shown
    from .verdict import describe_bound

    mc, st = result.mc, result.study
    print(f"rvtol {__version__} · study {st.name} · {mc.n} samples ({st.options.method}, seed {st.options.seed})"
          f" · {result.executor} · {result.elapsed:.1f} s")
    stt = mc.statistics()
    print(f"{'output':<28}{'unit':>8}{'mean':>14}{'std':>14}{'P99.865':>14}{'failed':>8}")
    for name, r in stt.iterrows():      # the decimals resolve the output's band (rvtol.precision)
        scale = requirements_scale(mc.requirements, name, r.get("std"))
        cells = [shown(r[k], scale) if r.get("n", 0) else "—" for k in ("mean", "std", "P99.865")]
        print(f"{name:<28}{r['unit']:>8}" + "".join(f"{c:>14}" for c in cells) + f"{int(r['failed']):>8}")
    if mc.stopping is not None:
        print(mc.stopping.describe())
    for v in mc.verdicts():
        y = v.yield_
        cpk = v.capability["cpk"]
        r = v.requirement
        need = []
        if r.min_yield is not None:
            need.append(f"yield ≥ {r.min_yield:g}" + (" (default)" if r.yield_defaulted else ""))
        if r.min_cpk is not None:
            need.append(f"Cpk ≥ {r.min_cpk:g}")
        need = " and ".join(need)
        if v.statistic is not None:
            est, lo, hi = (f"{x:.5g}" if x is not None else "…" for x in v.statistic)
            print(f"  {v.state:<9}  {r.label} (needs the {r.statistic} within the limits, {describe_bound(r)}): "
                  f"{r.statistic} {est} [{lo}, {hi}]")
            for why in v.reasons:
                print(f"        {why}")
            continue
        line = f"  {v.state:<9}  {r.label} (needs {need}, {describe_bound(r)}): " \
               f"yield {y.estimate:.5f} [{y.lo:.5f}, {y.hi:.5f}] bound {v.yield_bound:.5f}, {y.ppm:.0f} ppm"
        if cpk is not None:
            line += f", Cpk {cpk:.3f}" + (f" bound {v.cpk_bound:.3f}" if v.cpk_bound is not None else "")
        print(line)
        for why in v.reasons:
            print(f"        {why}")
        for note in v.notes:
            print(f"        note: {note}")
    if not mc.verdicts():
        print("  no requirement checked" + (" (exploratory study)" if st.exploratory else
                                            ": nothing is demonstrated (exit 4)"))


def entry_point() -> None:
    sys.exit(main())


if __name__ == "__main__":  # pragma: no cover
    entry_point()
