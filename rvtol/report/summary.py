"""summary.json: the machine-readable result of a study (versioned format)."""
from __future__ import annotations

import math

import numpy as np

from datetime import datetime, timezone

from .. import __version__

#: the version tag of summary.json
SUMMARY_FORMAT = "rvtol-summary/1"


def now_iso() -> str:
    """The current UTC time, to the second (ISO 8601)."""
    return datetime.now(timezone.utc).isoformat(timespec="seconds")


def _num(v):
    if v is None:
        return None
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, np.integer)):
        return int(v)
    try:
        f = float(v)
    except (TypeError, ValueError):
        return v
    return f if math.isfinite(f) else None


def clean(obj):
    """Recursively turn numpy scalars/arrays into JSON types; NaN/inf -> null."""
    if isinstance(obj, dict):
        return {str(k): clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [clean(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return [clean(v) for v in obj.tolist()]
    if isinstance(obj, str) or obj is None:
        return obj
    return _num(obj)


def phase_profile(timings: dict, parallel: dict) -> dict:
    """Per phase of the run: its wall time and the part of it spent inside parallel evaluation (s)."""
    return {k: {"wall": round(v, 3), "parallel": round(min(parallel.get(k, 0.0), v), 3)} for k, v in timings.items()}


def build_summary(result) -> dict:
    from ..stats import PERCENTILES

    st, mc = result.study, result.mc
    stats_df = mc.statistics()
    verdicts = mc.verdicts()
    outputs = {}
    for q in mc.outputs:
        r = stats_df.loc[q.name]
        entry = {"unit": q.shown_unit, "n": _num(r.get("n")), "failed": _num(r.get("failed"))}
        if r.get("n", 0):
            entry.update({
                "mean": _num(r["mean"]), "mean_ci": [_num(r["mean_lo"]), _num(r["mean_hi"])],
                "std": _num(r["std"]), "std_ci": [_num(r["std_lo"]), _num(r["std_hi"])],
                "min": _num(r["min"]), "max": _num(r["max"]),
                "percentiles": {f"P{p:g}": {"value": _num(r[f"P{p:g}"]),
                                            "ci": [_num(r[f"P{p:g}_lo"]), _num(r[f"P{p:g}_hi"])]}
                                for p in PERCENTILES},
            })
        entry["requirements"] = [clean(v.to_dict()) for v in verdicts if v.requirement.output == q.name]
        outputs[q.name] = entry
    failures = mc.failures()
    return clean({
        "format": SUMMARY_FORMAT,
        "rvtol_version": __version__,
        "study": st.name,
        "title": st.title,
        "created": now_iso(),
        "seed": st.options.seed,
        "n": mc.n,
        "method": st.options.method,
        **({"sequential": mc.stopping.to_dict()} if mc.stopping is not None else {}),
        **({"tails": {label: d.to_dict() for label, d in mc.tails.items()}} if mc.tails else {}),
        "executor": result.executor,
        "wall_time_s": result.elapsed,
        "timings_s": {k: round(v, 3) for k, v in result.timings.items()},
        "phase_time_s": phase_profile(result.timings, result.parallel),
        "confidence": mc.confidence,
        "inputs": st.inputs,
        "notes": list(getattr(st, "notes", ())),
        "model": {"class": type(st.model).__name__, "inputs": list(st.model.inputs),
                  "outputs": {q.name: q.shown_unit for q in st.model.outputs}},
        "spec": spec_record(st.spec),
        "outputs": outputs,
        "failures": failures.to_dict(orient="records"),
        "verdict": result.verdict,
        "passed": result.verdict == "PASS",
        "requirements_checked": len(verdicts),
        "exploratory": st.exploratory,
        "gates": [g.to_dict() for g in getattr(st, "gates", [])],
        "requirements": [d.to_dict() for d in result.signoff],
        "analyses": {s.key: s.summary for s in result.sections if s.summary},
        **({"build": {**st.build.record(), "usage": result.build_usage.to_dict(orient="records")}}
           if getattr(st, "build", None) is not None else {}),
    })


def spec_record(spec) -> dict:
    """The tolerance spec as summary.json records it: per factor its distribution and tolerance band."""
    return {"name": spec.name, "file": spec.file, "correlated": spec.correlation is not None,
            "factors": [{"name": f.name, "unit": f.unit, "distribution": f.describe(), "mean": f.dist.mean,
                         "std": f.dist.std, "band": list(f.band), "group": f.group} for f in spec.factors]}
