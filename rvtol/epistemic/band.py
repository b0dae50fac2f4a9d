"""``epistemic_band``: a prediction over what is not known of the design, beside the tolerance scatter.

::

    from rvtol.epistemic import StudyVariants, design_inputs, epistemic_band
    study = load_study("studies/rv80e_signoff.toml")
    res = epistemic_band(study.design, StudyVariants(study.file), ["torsion.torsional_rigidity", "te.te_pp"],
                         n=32, seed=1, tolerance_samples=16)
    res.to_frame()          # per output: the design as written, its tolerance band, the epistemic band, drivers
    res.sensitivity         # S1 of each estimated number on each output (given data, or a PCE)
    res.plot()

**What it computes.**  The tolerance Monte Carlo answers "how do units made to this drawing scatter?".  It takes
the design's numbers as exact; an estimated number (a needle row's length, a preload nobody published) is a
second, *epistemic* uncertainty: not a scatter between units but what the model does not know of every unit.
Each estimated number carries a plausible range and its basis (:mod:`rvtol.design`: ``range``, ``basis``,
``step``); the band samples them and nothing else:

1. the design's uncertain numbers (:meth:`rvtol.design.Design.uncertain`, or the ``keys`` given) become uniform
   inputs over their ranges (a number with a ``step`` — a count, a standard size — uniform over its grid points);
   ``n`` designs are drawn (``method``: LHS, Sobol, random; :func:`rvtol.sampling.sample`);
2. each design is built as a variant of the design (:meth:`~rvtol.design.Design.with_values`: the computed numbers
   that follow a sampled one are recomputed) into the study's whole model (``maker``: values -> model and spec,
   :class:`StudyVariants`), and evaluated at **nominal tolerances** (the spec's nominal point: every drawing
   tolerance, gauge and process factor at its nominal) — the epistemic band of the prediction;
3. optionally each design also over the same ``tolerance_samples`` units of its tolerance spec (common random
   numbers: the spread that remains between designs is the design's, not the sampling's) — the tolerance band of
   each design and the combined band of design × units;
4. the first-order index of each estimated number on each output from those same ``n`` designs
   (:func:`rvtol.sensitivity.given_data.first_order_given_data`: the Kelley-corrected correlation ratio over classes of
   at least 4 designs, bootstrap intervals — with a few dozen designs a ranking, not a measurement; or a sparse PCE, :func:`rvtol.sensitivity.surrogate.indices.pce_indices`, with its Q² check) — no further
   model run: which estimated numbers could move an output, i.e. explain a validation miss.

Nothing is fitted: the ranges come with the design file, each with its basis; the band is what they give.  A
variant whose model cannot be built (an element refusing its dimensions) or evaluated is a failed design, listed
with its reason; the band is over the designs that succeed.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np
import pandas as pd

from .. import units
from ..errors import InputError, RvtolError
from ..model import Quantity
from ..records import frame_records
from ..sampling import sample, substream, substream_seed
from ..spec import ToleranceSpec

#: how the first-order indices are estimated from the designs (module doc, item 4)
SENSITIVITY_METHODS = ("given_data", "pce")


@dataclass(frozen=True)
class EpistemicInput:
    """One estimated number: its key, unit, value as written, range, grid step (None: continuous), basis."""

    name: str
    unit: str
    value: float
    low: float
    high: float
    step: float | None
    basis: str

    def from_unit(self, u: np.ndarray) -> np.ndarray:
        """Values (in ``unit``) of uniform variates ``u`` in [0, 1): over the range, or over its grid points."""
        u = np.asarray(u, dtype=float)
        if self.step is None:
            return self.low + u * (self.high - self.low)
        k = int(round((self.high - self.low) / self.step))
        return self.low + self.step * np.minimum(np.floor(u * (k + 1)), k)


def design_inputs(design, keys: Sequence[str] | None = None) -> tuple[EpistemicInput, ...]:
    """The design's uncertain numbers (a range, no ``formula``), or those of ``keys``."""
    params = design.uncertain()
    if keys is not None:
        by = {p.name: p for p in params}
        for k in keys:
            if k not in by:
                why = ("not a number of the design" if k not in design else
                       "is a formula of other numbers (computed)" if design.param(k).formula else
                       "has no range")
                raise InputError(f"{k!r} cannot be sampled: it {why}", key="keys")
        params = [by[k] for k in dict.fromkeys(keys)]
    if not params:
        raise InputError("the design states no range for any number (range = [lo, hi] with its basis)", key="keys")
    return tuple(EpistemicInput(p.name, p.unit, float(p.value), p.range[0], p.range[1], p.step, p.basis)
                 for p in params)


def design_spec(inputs: Sequence[EpistemicInput]) -> ToleranceSpec:
    """The estimated numbers as a spec of uniform factors on [0, 1) (the sampled variates; :meth:`EpistemicInput.
    from_unit` turns them into values) — so the study's samplers and sensitivity estimators apply unchanged."""
    from ..spec import spec_from_table

    table = {"factor": [{"name": i.name, "unit": "1", "dist": "uniform", "lower": 0.0, "upper": 1.0,
                         "source": f"range [{i.low:g}, {i.high:g}] {i.unit}: {i.basis}"} for i in inputs]}
    return spec_from_table(table, name="epistemic")


class StudyVariants:
    """``values -> (model, spec)``: the study rebuilt on a variant of its design (``values``: design key -> value in
    base units; ``{}``: the design as written).  Picklable: it travels to the workers of a process pool as the two
    file names, and each worker reads the design once."""

    def __init__(self, study_file, design_file):
        self.study_file, self.design_file = str(study_file), str(design_file)
        self._design = None

    def __getstate__(self):
        return {"study_file": self.study_file, "design_file": self.design_file, "_design": None}

    def design(self):
        if self._design is None:
            from ..design import load_design

            self._design = load_design(self.design_file)
        return self._design

    def __call__(self, values: dict):
        from ..study import load_study

        st = load_study(self.study_file, design=self.design().with_values(**values), analyses=False)
        return st.model, st.spec


def evaluate_variant(maker, values: dict, outputs: Sequence[str], tolerance_rows: np.ndarray | None):
    """One design: ``(y at nominal tolerances [m], Y over the tolerance rows [t, m] or None, failure reason)`` in the
    outputs' display units; a design whose model cannot be built or evaluated gives NaNs and its reason."""
    m = len(outputs)
    try:
        model, spec = maker(values)
        sub = model.restricted(list(outputs)) if hasattr(model, "restricted") else model
        X = spec.nominal_base()[None, :]
        if tolerance_rows is not None:
            X = np.vstack([X, tolerance_rows])
        Y, status = sub.evaluate_with_status(X)
    except RvtolError as exc:
        return np.full(m, np.nan), (None if tolerance_rows is None else np.full((len(tolerance_rows), m), np.nan)), \
            str(exc)
    names = [q.name for q in sub.outputs]
    cols = [names.index(o) for o in outputs]
    D = np.column_stack([sub.outputs[j].to_display(np.asarray(Y[:, j], dtype=float)) for j in cols])
    D[np.asarray(status) != 0] = np.nan
    reason = "" if status[0] == 0 else sub.status_reasons.get(int(status[0]), f"status {int(status[0])}")
    return D[0], (D[1:] if tolerance_rows is not None else None), reason


@dataclass
class EpistemicResult:
    """The band of each output over the sampled designs (display units), beside the design as written."""

    inputs: tuple[EpistemicInput, ...]
    outputs: tuple[Quantity, ...]            # display unit in ``shown_unit``
    U: np.ndarray                            # [n, k] the designs' variates in [0, 1)
    values: np.ndarray                       # [n, k] the designs' values (each input's unit)
    Y: np.ndarray                            # [n, m] at nominal tolerances; NaN: failed
    reasons: list[str]                       # per design: '' or why it failed
    nominal: np.ndarray                      # [m] the design as written at nominal tolerances
    tolerance: np.ndarray | None             # [t, m] the design as written over the tolerance samples
    Y_tol: np.ndarray | None                 # [n, t, m] each design over the same tolerance samples
    interval: float
    sensitivity: pd.DataFrame                # output, factor, S1, S1_conf, S1_low, S1_high (, ST …)
    settings: dict = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    requirements: list = field(default_factory=list)   # the study's requirements on these outputs (for the layout)

    @property
    def n(self) -> int:
        return len(self.Y)

    @property
    def ok(self) -> np.ndarray:
        return np.array([r == "" for r in self.reasons])

    def _q(self) -> tuple[float, float]:
        return 50.0 * (1.0 - self.interval), 50.0 * (1.0 + self.interval)

    def band(self, output: str) -> dict:
        """The epistemic band of ``output``: min, the central ``interval``, median, max over the designs at nominal
        tolerances; the tolerance band of the design as written; the combined band of designs × units."""
        j = [q.name for q in self.outputs].index(output)
        y = self.Y[self.ok, j]
        lo, hi = self._q()
        out = {"nominal design": float(self.nominal[j]),
               "epistemic min": float(np.min(y)) if y.size else np.nan,
               "epistemic low": float(np.percentile(y, lo)) if y.size else np.nan,
               "epistemic median": float(np.median(y)) if y.size else np.nan,
               "epistemic high": float(np.percentile(y, hi)) if y.size else np.nan,
               "epistemic max": float(np.max(y)) if y.size else np.nan}
        if self.tolerance is not None:
            t = self.tolerance[:, j]
            t = t[np.isfinite(t)]
            out["tolerance low"] = float(np.percentile(t, lo)) if t.size else np.nan
            out["tolerance high"] = float(np.percentile(t, hi)) if t.size else np.nan
        if self.Y_tol is not None:
            c = self.Y_tol[self.ok][:, :, j].ravel()
            c = c[np.isfinite(c)]
            out["combined low"] = float(np.percentile(c, lo)) if c.size else np.nan
            out["combined high"] = float(np.percentile(c, hi)) if c.size else np.nan
        return out

    def drivers(self, output: str, top: int = 3) -> pd.DataFrame:
        """The estimated numbers with the largest first-order index on ``output`` among those the designs resolve:
        the index's lower confidence bound above zero (with few designs over many numbers the given-data index of
        a number the output does not read is often 0.2 by chance: a ranking of those would look right and be noise)."""
        s = self.sensitivity[self.sensitivity["output"] == output]
        if "S1_low" in s:
            s = s[s["S1_low"] > 0.0]
        return s.sort_values("S1", ascending=False).head(top).reset_index(drop=True)

    def drivers_text(self, output: str, top: int = 3) -> str:
        d = self.drivers(output, top)
        if not len(d):
            return (f"none resolved by {int(self.ok.sum())} designs (every first-order index's confidence interval "
                    "reaches 0: more designs would rank them)")
        return ", ".join(f"{r.factor} ({r.S1:.2f}, CI {r.S1_low:.2f}…{r.S1_high:.2f})" if hasattr(r, "S1_low")
                         else f"{r.factor} ({r.S1:.2f})" for r in d.itertuples())

    def to_frame(self) -> pd.DataFrame:
        rows = []
        for q in self.outputs:
            b = self.band(q.name)
            rows.append({"output": q.name, "unit": q.shown_unit, **b,
                         "designs": int(self.ok.sum()), "failed": int((~self.ok).sum()),
                         "largest drivers (S1)": self.drivers_text(q.name)})
        return pd.DataFrame(rows)

    def inputs_frame(self) -> pd.DataFrame:
        return pd.DataFrame([{"number": i.name, "as written": i.value, "low": i.low, "high": i.high,
                              "step": i.step if i.step is not None else np.nan, "unit": i.unit, "basis": i.basis}
                             for i in self.inputs])

    def failures(self) -> pd.DataFrame:
        rows = [{"design": k, **{i.name: self.values[k, c] for c, i in enumerate(self.inputs)}, "reason": r}
                for k, r in enumerate(self.reasons) if r]
        return pd.DataFrame(rows)

    def plot(self, ax=None):
        from ..plotting.epistemic import band_chart

        return band_chart(self, ax=ax)

    def summary(self) -> dict:
        return {"n": self.n, "interval": self.interval, "settings": self.settings, "notes": self.notes,
                "inputs": frame_records(self.inputs_frame()), "bands": frame_records(self.to_frame()),
                "sensitivity": frame_records(self.sensitivity), "failures": frame_records(self.failures())}


def epistemic_band(design, maker: Callable, outputs: Sequence[str], *, n: int = 32, method: str = "lhs",
                   seed: int | None = None, keys: Sequence[str] | None = None, tolerance_samples: int = 0,
                   interval: float = 0.95, sensitivity: str = "given_data", num_resamples: int = 200,
                   confidence: float = 0.95, executor=None, known_tolerance: np.ndarray | None = None,
                   output_quantities: Sequence[Quantity] | None = None) -> EpistemicResult:
    """The epistemic band of ``outputs`` over the design's estimated numbers (module doc).

    ``maker(values) -> (model, spec)``: the model built on the design with ``values`` (key -> base units) replaced
    (:class:`StudyVariants` for a study; the design as written with ``{}``).  ``executor``: an
    :class:`rvtol.executors.Executor` to build and evaluate the designs on (each design is one task; the maker and
    the tolerance rows travel to the workers); None: in this process.  ``known_tolerance``: the design as written
    already evaluated over its tolerance samples (the study's Monte Carlo) — used for the tolerance band instead of
    re-evaluating it.  ``output_quantities``: the outputs' quantities (default: the design as written's model's).
    """
    if n < 4:
        raise InputError(f"n must be >= 4 designs, got {n}", key="n")
    if not 0.5 <= interval < 1.0:
        raise InputError(f"interval must lie in [0.5, 1), got {interval}", key="interval")
    if sensitivity not in SENSITIVITY_METHODS:
        raise InputError(f"unknown sensitivity {sensitivity!r} (expected one of: {', '.join(SENSITIVITY_METHODS)})",
                         key="sensitivity")
    outputs = list(outputs)
    inputs = design_inputs(design, keys)
    espec = design_spec(inputs)
    U = sample(espec, n, method, seed).values
    values = np.column_stack([i.from_unit(U[:, c]) for c, i in enumerate(inputs)])
    base = np.column_stack([units.to_base(values[:, c], i.unit) for c, i in enumerate(inputs)])
    model0, spec0 = maker({})
    for o in outputs:
        model0.output(o)
    quantities = tuple(output_quantities) if output_quantities is not None else tuple(model0.output(o) for o in outputs)
    T = None
    if tolerance_samples:
        T = sample(spec0, tolerance_samples, "lhs", substream_seed(seed, "epistemic_tolerance")).values
    tasks = [(maker, {}, tuple(outputs), T if known_tolerance is None else None)]
    tasks += [(maker, {i.name: float(base[r, c]) for c, i in enumerate(inputs)}, tuple(outputs), T)
              for r in range(n)]
    results: list = [None] * len(tasks)
    if executor is None:
        for k, t in enumerate(tasks):
            results[k] = evaluate_variant(*t)
    else:
        for k, res in executor.imap(evaluate_variant, tasks):
            results[k] = res
    y0, t0, r0 = results[0]
    if r0:
        raise InputError(f"the design as written gives no prediction: {r0}", key="design")
    Y = np.vstack([r[0] for r in results[1:]])
    reasons = [r[2] or ("" if np.all(np.isfinite(r[0])) else "an output is not finite") for r in results[1:]]
    Y_tol = np.stack([r[1] for r in results[1:]]) if T is not None else None
    tolerance = known_tolerance if known_tolerance is not None else t0
    res = EpistemicResult(inputs, quantities, U, values, Y, reasons, y0, tolerance, Y_tol, interval,
                          pd.DataFrame(), {"n": n, "method": method, "seed": seed,
                                           "tolerance_samples": tolerance_samples, "sensitivity": sensitivity})
    res.sensitivity = _indices(res, sensitivity, num_resamples, confidence, seed)
    failed = int((~res.ok).sum())
    if failed:
        res.notes.append(f"{failed} of {n} designs gave no prediction (listed with their reasons); the band is over "
                         f"the other {n - failed}.")
    return res


def study_band(ctx, outputs: Sequence[str], **options) -> EpistemicResult:
    """:func:`epistemic_band` of a running study (an analysis' ``ctx``): its design and file rebuilt per design
    (:class:`StudyVariants`), on the study's executor, the tolerance band of the design as written from the study's
    Monte Carlo, the seed the study's unless given; ``options``: :func:`epistemic_band`'s keywords."""
    outputs = list(outputs)
    options.setdefault("seed", ctx.seed)
    maker = StudyVariants(ctx.study.file, ctx.study.inputs["design"]["path"])
    known = np.column_stack([ctx.mc.column(out) for out in outputs])
    res = epistemic_band(ctx.design, maker, outputs, executor=ctx.executor, known_tolerance=known,
                         output_quantities=[ctx.model.output(out) for out in outputs], **options)
    res.requirements = [r for r in ctx.study.requirements if r.output in outputs]
    return res


def _indices(res: EpistemicResult, method: str, num_resamples: int, confidence: float, seed) -> pd.DataFrame:
    """S1 (and ST for a PCE) of each estimated number on each output, from the designs that succeeded."""
    from ..sensitivity.given_data import default_classes, first_order_given_data

    ok = res.ok
    U = res.U[ok]
    rows = []
    for j, q in enumerate(res.outputs):
        y = res.Y[ok, j]
        if y.size < 4 or np.ptp(y) == 0.0:
            est = {c: np.zeros(len(res.inputs)) for c in ("S1", "S1_conf", "S1_low", "S1_high")}
        elif method == "pce":
            from ..sensitivity.surrogate import pce_indices

            r = pce_indices(U, y, "legendre", seed=substream(seed, "epistemic_indices", j), confidence=confidence)
            est = {"S1": r.S1, "S1_conf": r.S1_conf, "S1_low": r.S1_low, "S1_high": r.S1_high, "ST": r.ST,
                   "Q2": np.full(len(res.inputs), min(r.validation.get("q2_loo", np.nan),
                                                      r.validation.get("q2_holdout", np.nan)))}
            if not r.reliable:
                res.notes.append(f"{q.name}: the PCE's Q² is below its threshold — its indices are a rough ranking")
        else:
            M = max(2, min(default_classes(y.size), y.size // 4))      # at least 4 designs per class
            est = first_order_given_data(U, y, M, num_resamples, confidence, substream(seed, "epistemic_indices", j))
        for c, i in enumerate(res.inputs):
            rows.append({"output": q.name, "factor": i.name, **{k: float(v[c]) for k, v in est.items() if k != "M"}})
    return pd.DataFrame(rows)


__all__ = ["EpistemicInput", "EpistemicResult", "SENSITIVITY_METHODS", "StudyVariants", "design_inputs",
           "design_spec", "epistemic_band", "evaluate_variant", "study_band"]
