"""``rvtol`` command line: ``main(argv) -> int``.

Exit codes: 0 every requirement holds, 1 a requirement fails, 2 bad input
(one line ``rvtol: error: FILE: KEY: reason``, nothing written), 3 an
internal error (a bug: please report it with ``--debug`` output), 130
interrupted.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from . import __version__
from .errors import InputError

EXIT_PASS, EXIT_FAIL, EXIT_INPUT, EXIT_INTERNAL = 0, 1, 2, 3


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
    run.add_argument("--chunk-size", type=int, help="samples per task (default: automatic)")
    run.add_argument("--no-pdf", action="store_true", help="skip report.pdf")
    run.add_argument("--tables", choices=("csv", "xlsx"), action="append",
                     help="also write samples and statistics as CSV or XLSX beside samples.parquet (repeatable)")
    run.add_argument("--quiet", action="store_true", help="no progress bar, only the verdict line")
    run.add_argument("--debug", action="store_true", help="show tracebacks of internal errors")

    chk = sub.add_parser("check", help="validate a study and everything it names, without running it")
    chk.add_argument("study")
    chk.add_argument("--debug", action="store_true")

    sub.add_parser("kinds", help="list the model and analysis kinds a study can use")

    spec = sub.add_parser("spec", help="tolerance specs: convert between TOML and tables")
    ssub = spec.add_subparsers(dest="spec_command", metavar="SPEC_COMMAND")
    exp = ssub.add_parser("export", help="write a spec (TOML, CSV or XLSX) as a CSV or XLSX table")
    exp.add_argument("spec", help="spec file (.toml, .csv, .tsv or .xlsx)")
    exp.add_argument("--out", required=True, help="the table to write (.csv, .tsv or .xlsx)")
    exp.add_argument("--sheet", help="the sheet to read from an .xlsx spec (default: the first)")
    exp.add_argument("--force", action="store_true", help="replace --out if it exists")
    return p


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    if args.command is None:
        _parser().print_help()
        return EXIT_INPUT
    try:
        if args.command == "kinds":
            return _kinds()
        if args.command == "check":
            return _check(args)
        if args.command == "spec":
            return _spec(args)
        return _run(args)
    except InputError as exc:
        print(f"rvtol: error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except KeyboardInterrupt:
        print("rvtol: interrupted (nothing written)", file=sys.stderr)
        return 130
    except Exception as exc:  # a bug, not bad input
        if getattr(args, "debug", False):
            raise
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
              scheduler=args.scheduler, chunk_size=args.chunk_size)
    if args.no_pdf:
        ov["pdf"] = False
    if args.tables:
        ov["tables"] = tuple(dict.fromkeys(args.tables))
    if args.quiet:
        ov["progress"] = False
    return ov


def _check(args) -> int:
    from .study import load_study

    st = load_study(args.study)
    print(f"rvtol: {st.file}: ok — model {type(st.model).__name__}, {len(st.spec)} factors, "
          f"{len(st.model.outputs)} outputs, {len(st.requirements)} requirements, {len(st.analyses)} analyses")
    return EXIT_PASS


def _spec(args) -> int:
    import os

    from .inputs.sheets import WRITE_SUFFIXES
    from .inputs.table_spec import write_table_spec
    from .spec import load_spec

    if args.spec_command != "export":
        _parser().parse_args(["spec", "--help"])
    out = Path(args.out)
    if out.suffix.lower() not in WRITE_SUFFIXES:
        raise InputError(f"unknown table format {out.suffix!r} (expected {', '.join(WRITE_SUFFIXES)})",
                         file=str(out), key="--out")
    if out.exists() and not args.force:
        raise InputError("exists; give --force to replace it", file=str(out), key="--out")
    spec = load_spec(args.spec, sheet=args.sheet)
    tmp = out.with_name(f".{out.stem}.tmp{out.suffix}")
    try:
        write_table_spec(spec, tmp)
        os.replace(tmp, out)
    finally:
        tmp.unlink(missing_ok=True)
    print(f"rvtol: wrote {out} ({len(spec)} factors of spec {spec.name!r})")
    return EXIT_PASS


def _kinds() -> int:
    from .registry import ANALYSES, MODELS, plugin_models

    print("models:   " + ", ".join(sorted(MODELS)))
    plugins = plugin_models()
    if plugins:
        print("models from installed packages: " + ", ".join(f"{k} ({ep.value})" for k, ep in sorted(plugins.items())))
    print("analyses: " + ", ".join(sorted(ANALYSES)))
    return EXIT_PASS


def _run(args) -> int:
    from .study import check_out_dir, load_study, result_files, run_study, write_outputs

    study = load_study(args.study, **_overrides(args))
    out = check_out_dir(Path(args.out) if args.out else Path("reports") / study.name)  # before the run
    result = run_study(study)
    write_outputs(result, out)
    if not args.quiet:
        _print_result(result)
    verdict = "PASS" if result.passed else "FAIL"
    print(f"verdict: {verdict} — report: {out / 'report.html'}"
          + f" (+ {', '.join(result_files(study.options))})")
    return EXIT_PASS if result.passed else EXIT_FAIL


def _print_result(result) -> None:
    mc, st = result.mc, result.study
    print(f"rvtol {__version__} · study {st.name} · {mc.n} samples ({st.options.method}, seed {st.options.seed})"
          f" · {result.executor} · {result.elapsed:.1f} s")
    stt = mc.statistics()
    print(f"{'output':<28}{'unit':>8}{'mean':>12}{'std':>12}{'P99.865':>12}{'failed':>8}")
    for name, r in stt.iterrows():
        if r.get("n", 0):
            print(f"{name:<28}{r['unit']:>8}{r['mean']:>12.4g}{r['std']:>12.4g}{r['P99.865']:>12.4g}"
                  f"{int(r['failed']):>8}")
        else:
            print(f"{name:<28}{r['unit']:>8}{'—':>12}{'—':>12}{'—':>12}{int(r['failed']):>8}")
    for v in mc.verdicts():
        y = v.yield_
        cpk = v.capability["cpk"]
        print(f"  {'PASS' if v.passed else 'FAIL'}  {v.requirement.label}: yield {y.estimate:.5f} "
              f"[{y.lo:.5f}, {y.hi:.5f}], {y.ppm:.0f} ppm, Cpk {cpk:.3f}" if cpk is not None else
              f"  {'PASS' if v.passed else 'FAIL'}  {v.requirement.label}: yield {y.estimate:.5f}")
        for why in v.reasons:
            print(f"        {why}")


def entry_point() -> None:
    sys.exit(main())


if __name__ == "__main__":  # pragma: no cover
    entry_point()
