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

EXIT_PASS, EXIT_FAIL, EXIT_INPUT, EXIT_INTERNAL, EXIT_NO_REQUIREMENTS = 0, 1, 2, 3, 4

#: exit code of each study verdict (rvtol.verdict.study_verdict)
VERDICT_EXIT = {"PASS": EXIT_PASS, "FAIL": EXIT_FAIL, "NO REQUIREMENTS": EXIT_NO_REQUIREMENTS, "EXPLORATORY": EXIT_PASS}


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
    run.add_argument("--quiet", action="store_true", help="no progress bar, only the verdict line")
    run.add_argument("--debug", action="store_true", help="show tracebacks of internal errors")

    chk = sub.add_parser("check", help="validate a study and everything it names, without running it")
    chk.add_argument("study")
    chk.add_argument("--debug", action="store_true")

    sub.add_parser("kinds", help="list the model and analysis kinds a study can use")
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
    if args.quiet:
        ov["progress"] = False
    return ov


def _check(args) -> int:
    from .study import load_study

    st = load_study(args.study)
    print(f"rvtol: {st.file}: ok — model {type(st.model).__name__}, {len(st.spec)} factors, "
          f"{len(st.model.outputs)} outputs, {len(st.requirements)} requirements, {len(st.analyses)} analyses")
    return EXIT_PASS


def _kinds() -> int:
    from .registry import ANALYSES, MODELS

    print("models:   " + ", ".join(sorted(MODELS)))
    print("analyses: " + ", ".join(sorted(ANALYSES)))
    return EXIT_PASS


def _run(args) -> int:
    from .study import check_out_dir, load_study, run_study, write_outputs

    study = load_study(args.study, **_overrides(args))
    out = check_out_dir(Path(args.out) if args.out else Path("reports") / study.name)  # before the run
    result = run_study(study)
    write_outputs(result, out)
    if not args.quiet:
        _print_result(result)
    verdict = result.verdict
    print(f"verdict: {verdict} — report: {out / 'report.html'}"
          + (" (+ report.pdf, summary.json, samples.parquet)" if study.options.pdf
             else " (+ summary.json, samples.parquet)"))
    return VERDICT_EXIT[verdict]


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
    from .verdict import describe_bound

    for v in mc.verdicts():
        y = v.yield_
        cpk = v.capability["cpk"]
        r = v.requirement
        need = " and ".join([f"yield ≥ {r.min_yield:g}" + (" (default)" if r.yield_defaulted else "")] * (
            r.min_yield is not None) + [f"Cpk ≥ {r.min_cpk:g}"] * (r.min_cpk is not None))
        line = f"  {'PASS' if v.passed else 'FAIL'}  {r.label} (needs {need}, {describe_bound(r)}): " \
               f"yield {y.estimate:.5f} [{y.lo:.5f}, {y.hi:.5f}] bound {v.yield_bound:.5f}, {y.ppm:.0f} ppm"
        if cpk is not None:
            line += f", Cpk {cpk:.3f}" + (f" bound {v.cpk_bound:.3f}" if v.cpk_bound is not None else "")
        print(line)
        for why in v.reasons:
            print(f"        {why}")
    if not mc.verdicts():
        print("  no requirement checked" + (" (exploratory study)" if st.exploratory else
                                            ": nothing is demonstrated (exit 4)"))


def entry_point() -> None:
    sys.exit(main())


if __name__ == "__main__":  # pragma: no cover
    entry_point()
