"""Compare a run with the accepted baseline: spec diff, output changes, verdict changes, gates.

:func:`load_run` reads a report folder (``summary.json`` and, if present,
``samples.parquet``) or a ``summary.json``; :meth:`RunData.from_result` wraps
a run in memory.  :func:`compare` then gives a :class:`Comparison`:

* the spec diff: factors added, removed and changed (old → new distribution
  and tolerance band);
* per output the change of the mean, σ and P99.865 (and of any statistic a
  gate names) with its interval; when both runs drew the same sample design
  (same seed, n, method and factors) the interval is the *paired* one on
  common random numbers, shown beside the unpaired one with the gain (how
  many times narrower) — see :mod:`rvtol.ci.differences`;
* per requirement its state before and after (PASS, UNDECIDED, FAIL:
  :func:`rvtol.verdict.requirement_state`) and the change of its
  non-conforming ppm with its interval;
* the gates of the new run (:mod:`rvtol.ci.gates`; by default: no requirement
  may get worse) and the comparison's verdict, PASS or FAIL.

Without samples (summaries only) the intervals are unpaired and
approximate: Welch for the mean, normal theory for σ, the two runs'
percentile intervals combined in quadrature, Newcombe for ppm.
"""
from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import units
from ..errors import InputError
from ..precision import shown, summary_scale
from ..sampling import substream
from ..verdict import state_of
from . import differences as df
from .gates import DEFAULT_GATES, Gate

#: the version tag of comparison.json
COMPARISON_FORMAT = "rvtol-comparison/1"
#: the statistics every output's change reports
STATISTICS = ("mean", "std", "P99.865")


# --------------------------------------------------------------------------- runs
class RunData:
    """One run as the comparison sees it: its summary and (lazily) its per-sample outputs."""

    def __init__(self, summary: dict, source: str, samples_path: Path | None = None, frame=None):
        self.summary = summary
        self.source = source
        self._samples_path = samples_path
        self._frame = frame

    @classmethod
    def from_result(cls, result) -> "RunData":
        """The run in memory (``rvtol run --baseline``)."""
        return cls(result.summary(), "this run", frame=result.mc.to_frame())

    @property
    def has_samples(self) -> bool:
        return self._frame is not None or self._samples_path is not None

    def frame(self):
        if self._frame is None and self._samples_path is not None:
            import pandas as pd

            try:
                self._frame = pd.read_parquet(self._samples_path)
            except Exception as exc:  # a damaged or foreign file: say which
                raise InputError(f"cannot read samples ({type(exc).__name__}: {exc})",
                                 file=str(self._samples_path), key="-") from None
        return self._frame

    def output(self, name: str):
        """``(values in the output's unit, ok mask)`` per sample, or None without samples."""
        f = self.frame()
        if f is None:
            return None
        col = f"{name} [{self.summary['outputs'][name]['unit']}]"
        if col not in f.columns or "status" not in f.columns:
            raise InputError(f"no column {col!r} or 'status'", file=str(self._samples_path or self.source), key="-")
        y = f[col].to_numpy(dtype=float)
        return y, (f["status"].to_numpy() == 0) & np.isfinite(y)

    @property
    def factor_names(self) -> list[str]:
        return [f["name"] for f in self.summary.get("spec", {}).get("factors", [])] or \
            list(self.summary.get("model", {}).get("inputs", []))

    def requirements(self) -> dict[str, dict]:
        return {r["requirement"]: r for o in self.summary["outputs"].values() for r in o.get("requirements", [])}

    def gates(self) -> list[Gate]:
        return [Gate.from_dict(g) for g in self.summary.get("gates", [])]


def load_run(path: str | Path, key: str = "-") -> RunData:
    """A report folder or a summary.json (validated against the schema). Raises InputError."""
    from .schema import validate_summary

    p = Path(path)
    summary_path = p / "summary.json" if p.is_dir() else p
    if not summary_path.exists():
        raise InputError("no such report folder or summary.json" if not p.exists() else
                         "no summary.json in this folder: not an rvtol report", file=str(path), key=key)
    from ..params import TOO_DEEP, note_read, read_text

    try:
        summary = json.loads(read_text(summary_path, "a summary.json file")[0])
    except InputError as exc:
        raise InputError(f"cannot read summary.json ({exc.reason})", file=str(summary_path), key=key) from None
    except ValueError as exc:
        raise InputError(f"cannot read summary.json ({exc})", file=str(summary_path), key=key) from None
    except RecursionError:
        raise InputError(f"cannot read summary.json ({TOO_DEEP})", file=str(summary_path), key=key) from None
    validate_summary(summary, str(summary_path))
    samples = summary_path.parent / "samples.parquet"
    if samples.exists():
        note_read(samples)      # read when a comparison pairs the samples: an input all the same
    return RunData(summary, str(path), samples if samples.exists() else None)


# --------------------------------------------------------------------------- results
@dataclass
class Change:
    """The change of one statistic from base to new."""

    statistic: str
    base: float | None
    new: float | None
    change: float | None
    ci: tuple[float | None, float | None]
    unpaired_ci: tuple[float | None, float | None] | None = None

    @property
    def gain(self) -> float | None:
        """How many times narrower the paired interval is than the unpaired one."""
        if self.unpaired_ci is None or None in self.ci or None in self.unpaired_ci:
            return None
        w, wu = self.ci[1] - self.ci[0], self.unpaired_ci[1] - self.unpaired_ci[0]
        # a paired interval of zero width (nothing changed, or every sample moved alike) has no finite gain:
        # None rather than "inf× narrower"
        return wu / w if w > 0 else None

    def to_dict(self) -> dict:
        return {"statistic": self.statistic, "base": self.base, "new": self.new, "change": self.change,
                "ci": list(self.ci), "unpaired_ci": list(self.unpaired_ci) if self.unpaired_ci else None,
                "gain": self.gain}


@dataclass
class GateResult:
    gate: Gate
    passed: bool
    reasons: list[str]
    figures: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        return {"gate": self.gate.to_dict(), "name": self.gate.name, "passed": self.passed, "reasons": self.reasons,
                "figures": self.figures}


@dataclass
class Comparison:
    base: dict
    new: dict
    paired: bool
    pairing: str
    confidence: float
    spec_changes: list[dict]
    outputs: dict[str, dict]               # name -> {"unit", "changes": [Change], "scale": rvtol.precision's}
    requirements: list[dict]
    gates: list[GateResult]

    @property
    def passed(self) -> bool:
        return all(g.passed for g in self.gates)

    @property
    def verdict(self) -> str:
        return "PASS" if self.passed else "FAIL"

    def one_line(self) -> str:
        bad = [g for g in self.gates if not g.passed]
        if not bad:
            return f"{len(self.gates)} gate{'s' if len(self.gates) != 1 else ''} hold against {self.base['source']}"
        return "; ".join(f"{g.gate.name}: {g.reasons[0]}" for g in bad)

    def to_dict(self) -> dict:
        return _clean({
            "format": COMPARISON_FORMAT, "base": self.base, "new": self.new, "paired": self.paired,
            "pairing": self.pairing, "confidence": self.confidence, "spec_changes": self.spec_changes,
            "outputs": {k: {"unit": v["unit"], "changes": [c.to_dict() for c in v["changes"]]}
                        for k, v in self.outputs.items()},
            "requirements": self.requirements, "gates": [g.to_dict() for g in self.gates],
            "verdict": self.verdict, "passed": self.passed})

    def text(self) -> str:
        """The comparison as plain text (the CLI prints it)."""
        lines = [f"baseline {self.base['source']} (n {self.base['n']}, seed {self.base['seed']}) → "
                 f"{self.new['source']} (n {self.new['n']}, seed {self.new['seed']}): "
                 f"{'paired on common random numbers' if self.paired else 'unpaired'} — {self.pairing}"]
        for c in self.spec_changes:
            lines.append(f"  spec: {c['factor']} {c['change']}: {c.get('old') or '—'} → {c.get('new') or '—'}")
        pct = f"{100 * self.confidence:g} %"
        for name, o in self.outputs.items():       # in the output's unit: the decimals resolve its band
            s = o.get("scale")
            for c in o["changes"]:
                gain = f", {c.gain:.3g}× narrower than unpaired {_ci(c.unpaired_ci, s)}" if c.gain else ""
                lines.append(f"  {name} {c.statistic}: {_g(c.base, s)} → {_g(c.new, s)} {units.label(o['unit'])}, "
                             f"change {_g(c.change, s)} [{pct}: {_ci(c.ci, s)}]{gain}")
        for r in self.requirements:
            lines.append(f"  requirement {r['requirement']}: {r['base_verdict']} → {r['new_verdict']}, ppm "
                         f"{_g(r['ppm']['base'])} → {_g(r['ppm']['new'])} (change {_g(r['ppm']['change'])} "
                         f"[{_ci(r['ppm']['ci'])}])")
        for g in self.gates:
            lines.append(f"  gate {'PASS' if g.passed else 'FAIL'}: {g.gate.name}"
                         + (f" — {'; '.join(g.reasons)}" if g.reasons else ""))
        return "\n".join(lines)


def _g(v, scale: float | None = None) -> str:
    """A number: with ``scale``, the decimals that resolve it (:func:`rvtol.precision.shown`), else 4 digits."""
    return shown(v, scale)


def _ci(ci, scale: float | None = None) -> str:
    if not ci or None in ci:
        return "—"
    return f"{_g(ci[0], scale)}, {_g(ci[1], scale)}"


def _clean(obj):
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return float(obj) if math.isfinite(obj) else None
    return obj


# --------------------------------------------------------------------------- the comparison
def same_study(base: RunData, new: RunData, key: str = "BASE", file: str | None = None) -> None:
    """A comparison of runs of two different studies compares nothing: refused (InputError naming both)."""
    a, b = base.summary.get("study"), new.summary.get("study")
    if a != b:
        raise InputError(f"the baseline is a run of study {a!r}, this is a run of study {b!r}: compare runs of one "
                         "study", file=file or base.source, key=key)


def compare(base: RunData, new: RunData, seed: int | None = None, gates: list[Gate] | None = None) -> Comparison:
    """Compare ``new`` with ``base``; ``gates`` default to those recorded in ``new`` (else DEFAULT_GATES)."""
    bs, ns = base.summary, new.summary
    conf = float(ns.get("confidence") or 0.95)
    paired, why = _pairing(base, new)
    gates = list(gates if gates is not None else (new.gates() or DEFAULT_GATES))
    cmp = Comparison(_ident(base), _ident(new), paired, why, conf, spec_changes(bs, ns), {}, [], [])
    wanted = {name: list(STATISTICS) for name in ns["outputs"] if name in bs["outputs"]}
    for g in gates:
        if g.kind == "output" and g.output in wanted and g.statistic not in wanted[g.output]:
            wanted[g.output].append(g.statistic)
    for j, (name, stats_) in enumerate(wanted.items()):
        unit = ns["outputs"][name]["unit"]
        cmp.outputs[name] = {"unit": unit, "scale": summary_scale(ns["outputs"][name]), "changes": [
            _change(base, new, name, unit, s, paired, conf, substream(seed, "compare_bootstrap", j, k))
            for k, s in enumerate(stats_)]}
    cmp.requirements = _requirement_changes(base, new, paired, conf)
    cmp.gates = [_judge_gate(g, cmp) for g in gates]
    return cmp


def _ident(run: RunData) -> dict:
    s = run.summary
    return {"source": run.source, "study": s.get("study"), "created": s.get("created"), "n": s.get("n"),
            "seed": s.get("seed"), "method": s.get("method"), "verdict": s.get("verdict"),
            "samples": run.has_samples}


def _pairing(base: RunData, new: RunData) -> tuple[bool, str]:
    bs, ns = base.summary, new.summary
    if not (base.has_samples and new.has_samples):
        return False, "samples.parquet missing: intervals from the summaries (approximate)"
    for k in ("seed", "n", "method"):
        if bs.get(k) != ns.get(k):
            return False, f"different {k} ({bs.get(k)} → {ns.get(k)}): independent samples"
    if bs.get("seed") is None:
        return False, "no seed: independent samples"
    if base.factor_names != new.factor_names:
        return False, "different factors: different sample designs"
    return True, "same seed, n, method and factors: sample i of both runs shares its random numbers"


def spec_changes(bs: dict, ns: dict) -> list[dict]:
    """Factors added, removed and changed (distribution, band or unit) between two summaries."""
    old = {f["name"]: f for f in bs.get("spec", {}).get("factors", [])}
    new = {f["name"]: f for f in ns.get("spec", {}).get("factors", [])}

    def text(f):
        lo, hi = f["band"]
        return f"{f['distribution']}; band [{lo:.6g}, {hi:.6g}] {units.label(f['unit'])}"

    out = []
    for name in [*old, *(n for n in new if n not in old)]:
        a, b = old.get(name), new.get(name)
        if a is None:
            out.append({"factor": name, "change": "added", "old": None, "new": text(b)})
        elif b is None:
            out.append({"factor": name, "change": "removed", "old": text(a), "new": None})
        elif (a["unit"] != b["unit"] or not _same_description(a["distribution"], b["distribution"])
              or not np.allclose(a["band"], b["band"], rtol=1e-12, atol=0)
              or not np.isclose(a["mean"], b["mean"], rtol=1e-12, atol=0)
              or not np.isclose(a["std"], b["std"], rtol=1e-12, atol=0)):
            out.append({"factor": name, "change": "changed", "old": text(a), "new": text(b)})
    return out


#: a number in a factor's description (summary.json's ``distribution``)
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def _same_description(a: str, b: str) -> bool:
    """Two descriptions of one distribution: the same words, the same numbers to the four significant digits every
    rvtol version shows at least (one wrote ``μ=42``, a later one resolves the band: ``μ=42.000``)."""
    na, nb = _NUMBER.findall(a), _NUMBER.findall(b)
    return (_NUMBER.sub("#", a) == _NUMBER.sub("#", b) and len(na) == len(nb)
            and all(math.isclose(float(x), float(y), rel_tol=1e-3, abs_tol=0) for x, y in zip(na, nb)))


def _arrays(base: RunData, new: RunData, name: str, unit: str, paired: bool):
    """Per-sample values of output ``name`` of both runs in ``unit`` (evaluated rows; pairs when paired)."""
    ya, oka = base.output(name)
    yb, okb = new.output(name)
    bu = base.summary["outputs"][name]["unit"]
    if bu != unit:
        ya = np.asarray(units.convert(ya, bu, unit), dtype=float)
    if paired:
        both = oka & okb
        return ya[both], yb[both]
    return ya[oka], yb[okb]


def _change(base, new, name, unit, stat, paired, conf, rng) -> Change:
    if not (base.has_samples and new.has_samples):
        return _change_from_summaries(base.summary["outputs"][name], new.summary["outputs"][name], unit,
                                      base.summary["outputs"][name]["unit"], stat, conf)
    a, b = _arrays(base, new, name, unit, paired)
    if len(a) < 3 or len(b) < 3:
        return Change(stat, None, None, None, (None, None))

    def run(pair: bool):
        if stat == "mean":
            return df.mean_change(a, b, pair, conf)
        if stat == "std":
            return df.std_change(a, b, pair, conf)
        return df.percentile_change(a, b, float(stat[1:]) / 100, pair, conf, rng)

    value = {"mean": np.mean, "std": lambda x: np.std(x, ddof=1)}.get(stat, lambda x: np.quantile(x, float(stat[1:]) / 100))
    d, lo, hi = run(paired)
    unpaired = run(False)[1:] if paired else None
    return Change(stat, float(value(a)), float(value(b)), d, (lo, hi), unpaired)


def _change_from_summaries(oa: dict, ob: dict, unit: str, base_unit: str, stat: str, conf: float) -> Change:
    """Unpaired, approximate: the change's interval from the two summaries' figures."""
    conv = (lambda v: None if v is None else float(units.convert(v, base_unit, unit)))  # noqa: E731
    if not oa.get("n") or not ob.get("n"):
        return Change(stat, None, None, None, (None, None))
    z = float(df.stats.norm.ppf(0.5 + conf / 2))
    if stat in ("mean", "std"):
        ma, mb = conv(oa["mean"]), ob["mean"]
        sa, sb = conv(oa["std"]), ob["std"]
        na, nb = oa["n"], ob["n"]
        if stat == "mean":
            va, vb = sa * sa / na, sb * sb / nb
            d = mb - ma
            h = z * math.sqrt(va + vb)
            return Change(stat, ma, mb, d, (d - h, d + h))
        d = sb - sa
        h = z * math.sqrt(sa * sa / (2 * (na - 1)) + sb * sb / (2 * (nb - 1)))  # normal theory
        return Change(stat, sa, sb, d, (d - h, d + h))
    pa, pb = oa["percentiles"][stat], ob["percentiles"][stat]
    va, vb = conv(pa["value"]), pb["value"]
    ca = [conv(x) for x in pa["ci"]]
    cb = pb["ci"]
    if None in ca or None in cb:
        return Change(stat, va, vb, vb - va, (None, None))
    h = math.sqrt(((ca[1] - ca[0]) / 2) ** 2 + ((cb[1] - cb[0]) / 2) ** 2)
    d = vb - va
    return Change(stat, va, vb, d, (d - h, d + h))


def _out_of_spec(run: RunData, req: dict) -> np.ndarray | None:
    got = run.output(req["output"])
    if got is None:
        return None
    y, ok = got
    out = ~ok
    if req.get("lower") is not None:
        out |= np.nan_to_num(y, nan=-np.inf) < req["lower"]
    if req.get("upper") is not None:
        out |= np.nan_to_num(y, nan=np.inf) > req["upper"]
    return out


def _requirement_changes(base: RunData, new: RunData, paired: bool, conf: float) -> list[dict]:
    rb, rn = base.requirements(), new.requirements()
    rows = []
    for label in [*rb, *(k for k in rn if k not in rb)]:
        a, b = rb.get(label), rn.get(label)
        row = {"requirement": label, "base_verdict": _v(a), "new_verdict": _v(b),
               "ppm": {"base": a and a["ppm"], "new": b and b["ppm"], "change": None, "ci": [None, None]}}
        if a is not None and b is not None:
            xa = _out_of_spec(base, a) if base.has_samples else None
            xb = _out_of_spec(new, b) if new.has_samples else None
            if xa is None or xb is None:  # from the counts
                xa = _flags(a["ppm"], base.summary["n"])
                xb = _flags(b["ppm"], new.summary["n"])
                pair = False
            else:
                pair = paired
            d, lo, hi = df.proportion_change(xa, xb, pair, conf)
            row["ppm"].update(change=1e6 * d, ci=[1e6 * lo, 1e6 * hi], paired=pair)
            if pair:
                _, ulo, uhi = df.proportion_change(xa, xb, False, conf)
                row["ppm"]["unpaired_ci"] = [1e6 * ulo, 1e6 * uhi]
        rows.append(row)
    return rows


def _flags(ppm: float | None, n: int) -> np.ndarray:
    k = int(round((ppm or 0.0) * n / 1e6))
    return np.r_[np.ones(k, bool), np.zeros(n - k, bool)]


def _v(r: dict | None) -> str:
    return "—" if r is None else state_of(r)


def _judge_gate(g: Gate, cmp: Comparison) -> GateResult:
    if g.kind == "requirements":
        res = GateResult(g, True, [])
        for r in cmp.requirements:
            label, ppm = r["requirement"], r["ppm"]
            if r["base_verdict"] != "—" and r["new_verdict"] == "—":
                res.reasons.append(f"requirement {label!r} of the baseline is gone")
            elif r["base_verdict"] == "PASS" and r["new_verdict"] != "PASS":
                res.reasons.append(f"{label}: PASS → {r['new_verdict']}")
            elif ppm["ci"][0] is not None and ppm["ci"][0] > g.max_ppm_increase:
                res.reasons.append(f"{label}: non-conforming ppm rose by {ppm['change']:.4g} "
                                   f"[{ppm['ci'][0]:.4g}, {ppm['ci'][1]:.4g}]"
                                   + (f", beyond the allowed {g.max_ppm_increase:g}" if g.max_ppm_increase else ""))
            if ppm["change"] is not None:
                res.figures.append(f"{label}: {r['base_verdict']} → {r['new_verdict']}, ppm {_g(ppm['base'])} → "
                                   f"{_g(ppm['new'])} (change {_g(ppm['change'])} [{_ci(ppm['ci'])}])")
        if not cmp.requirements:
            res.figures.append("neither run states a requirement")
        res.passed = not res.reasons
        return res
    out = cmp.outputs.get(g.output)
    c = next((c for c in out["changes"] if c.statistic == g.statistic), None) if out else None
    if c is None or c.change is None:
        return GateResult(g, False, [f"{g.statistic} of {g.output} is not in both runs"])
    lo, hi = (c.change, c.change) if g.basis == "estimate" else c.ci
    s = out.get("scale")
    fig = (f"{g.statistic} of {g.output}: {_g(c.base, s)} → {_g(c.new, s)} {units.label(g.unit)}, change "
           f"{_g(c.change, s)} [{_ci(c.ci, s)}]")
    reasons = []
    if lo is None or hi is None:
        reasons.append(f"the change of {g.statistic} has no confidence interval (too few samples in the tail)")
    else:
        what = "the change" if g.basis == "estimate" else "the upper end of the change's interval"
        if g.max_increase is not None and hi > g.max_increase:
            reasons.append(f"{what} {_g(hi, s)} {units.label(g.unit)} exceeds the allowed increase {g.max_increase:g}")
        what = "the change" if g.basis == "estimate" else "the lower end of the change's interval"
        if g.max_decrease is not None and lo < -g.max_decrease:
            reasons.append(f"{what} {_g(lo, s)} {units.label(g.unit)} exceeds the allowed decrease {g.max_decrease:g}")
    return GateResult(g, not reasons, reasons, [fig])
