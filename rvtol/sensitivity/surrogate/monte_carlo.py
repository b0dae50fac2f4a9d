r"""Sobol indices of a model's outputs from a PCE fitted on the Monte Carlo samples of a study: no model run.

What an unreliable fit's indices become
    An output whose fit is not reliable (:mod:`rvtol.sensitivity.surrogate.indices`) has its
    indices withheld (NaN in ``frame``, the raw values in ``raw``) with a
    :class:`PoorSurrogateWarning`, or raises :class:`SurrogateError` (``on_poor_fit="raise"``),
    or keeps them with the warning (``on_poor_fit="warn"``).

When it fails
    A peak-to-peak output with clearances is far from polynomial: on the TE study's 10 000
    Monte Carlo runs (te_pp, 35 factors) the best sparse expansion reaches Q² ≈ 0.65 (LOO) /
    0.60 (hold-out), ~0.8 even in the Cartesian components of the eccentricity vectors, so its
    indices are withheld; the given-data first-order indices
    (:mod:`rvtol.sensitivity.given_data`) are the ones to read there.

Independence
    PCE Sobol indices assume independent factors.  A correlated spec (or a sample whose rank
    correlations say so) gets a :class:`CorrelatedInputsWarning` and a note; the indices are
    then those of the surrogate with independent margins and the delta index is the valid
    measure.
"""
from __future__ import annotations

import itertools
import warnings
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
import pandas as pd

from ...errors import InputError, RvtolError
from ...model import Model
from ...records import frame_records
from ...sampling import SampleSet, substream
from ...spec import ToleranceSpec
from .._given import CorrelatedInputsWarning, correlated_pairs, describe_pairs, given_samples, u_from_samples
from ..common import factor_indices, output_indices
from ..global_ import GlobalSensitivityResult
from .. import notes as N
from .basis import families_for_spec, germ_families
from .indices import MIN_Q2, pce_indices

POOR_FIT = ("withhold", "warn", "raise")


class SurrogateError(RvtolError, RuntimeError):
    """The surrogate is not accurate enough for its indices to be used (``on_poor_fit="raise"``)."""


class PoorSurrogateWarning(UserWarning):
    """The surrogate's validation Q² is below the threshold: its indices are not reliable."""



# --------------------------------------------------------------------------- model-level analysis
PCE_COLUMNS = ["S1", "S1_conf", "ST", "ST_conf", "S1_low", "S1_high", "ST_low", "ST_high"]


@dataclass
class SurrogateSensitivityResult(GlobalSensitivityResult):
    """PCE Sobol indices: ``frame`` as for Sobol (``S1, S1_conf, ST, ST_conf`` + percentile bounds).

    Outputs whose surrogate failed validation have NaN indices in ``frame`` (with
    ``on_poor_fit="withhold"``); ``raw`` always holds the surrogate's values.  ``validation``
    has one row per output (Q², relative RMSE, degree, terms, ``reliable``, ``bias_bound``);
    ``fits`` the fitted expansions by output name; ``independent`` is False when the inputs are
    dependent (see notes).
    """

    validation: pd.DataFrame | None = None
    raw: pd.DataFrame | None = None
    fits: dict = field(default_factory=dict)
    independent: bool = True

    def summary(self) -> dict:
        out = super().summary()
        out["validation"] = frame_records(self.validation) if self.validation is not None else []
        out["independent"] = self.independent
        return out


def pce(model: Model, spec: ToleranceSpec, samples: SampleSet, Y: np.ndarray, factors: Sequence[str] | None = None,
        outputs: Sequence[str] | None = None, seed: int | None = None, *, germs: str | Sequence[str] = "auto",
        holdout: float = 0.2, ci: str = "bootstrap", num_resamples: int = 100, confidence: float = 0.95,
        min_q2: float = MIN_Q2, on_poor_fit: str = "withhold", second_order: bool = True,
        **fit_options) -> SurrogateSensitivityResult:
    """Sobol S1, ST (and S2) from a PCE fitted on the Monte Carlo ``samples`` and outputs ``Y``.

    ``Y``: every model output in display units (``MonteCarloResult.Y``); no model run is made.
    The expansion uses **all** factors of the spec (they all vary in the sample); ``factors``
    selects the rows reported.  ``germs``: "auto" (Hermite for unbounded factors, Legendre for
    bounded), "legendre", "hermite" or one per factor.  ``on_poor_fit``: "withhold" (default),
    "warn" or "raise" when min(Q²_LOO, Q²_hold-out) < ``min_q2``.  Other keywords: see
    :func:`pce_indices` and :func:`fit_pce` (``fit_options``) and the notes of :mod:`rvtol.sensitivity.surrogate`.
    """
    if on_poor_fit not in POOR_FIT:
        raise InputError(f"unknown on_poor_fit {on_poor_fit!r} (expected one of: {', '.join(POOR_FIT)})",
                         key="on_poor_fit")
    model.check_spec(spec)
    idx, oidx = factor_indices(spec, factors), output_indices(model, outputs)
    X, Yd, n_failed, notes = given_samples(model, spec, samples, Y, oidx)
    U = u_from_samples(spec, X)
    fams = families_for_spec(spec) if germs == "auto" else germ_families(germs, len(spec))
    pairs = correlated_pairs(spec.names, U, spec.correlation)
    independent = not pairs
    if pairs:
        msg = N.PCE_DEPENDENT.format(pairs=describe_pairs(pairs))
        warnings.warn(msg, CorrelatedInputsWarning, stacklevel=2)
        notes.append(msg)
    rng = substream(seed, "pce")
    names = [spec.names[i] for i in idx]
    rows, s2rows, vrows, fits = [], [], [], {}
    for c, j in enumerate(oidx):
        q_ = model.outputs[j]
        y = Yd[:, c]
        base = {"output": q_.name, "unit": q_.shown_unit}
        if len(y) < 2 or np.ptp(y) == 0.0:
            notes.append(N.CONSTANT_OUTPUT.format(output=q_.name))
            rows += [{**base, "factor": nm, **{col: 0.0 for col in PCE_COLUMNS}} for nm in names]
            s2rows += [{"output": q_.name, "factor_i": a, "factor_j": b, "S2": 0.0, "S2_conf": 0.0}
                       for a, b in itertools.combinations(names, 2)]
            vrows.append({"output": q_.name, "reliable": True})
            continue
        res = pce_indices(U, y, fams, holdout=holdout, ci=ci, num_resamples=num_resamples, confidence=confidence,
                          min_q2=min_q2, seed=rng, **fit_options)
        fits[q_.name] = res.fit
        v = res.validation
        vrows.append({"output": q_.name, **v})
        for i, nm in zip(idx, names):
            rows.append({**base, "factor": nm, **{col: float(getattr(res, col)[i]) for col in PCE_COLUMNS}})
        for (a, ia), (b, ib) in itertools.combinations(list(zip(names, idx)), 2):
            lo, hi = min(ia, ib), max(ia, ib)
            s2rows.append({"output": q_.name, "factor_i": a, "factor_j": b, "S2": float(res.S2[lo, hi]),
                           "S2_conf": float(res.S2_conf[lo, hi])})
        if not res.reliable:
            msg = N.PCE_POOR_FIT.format(output=q_.name, q2_loo=v["Q2_loo"], q2_holdout=v["Q2_holdout"], min_q2=min_q2,
                                        bias=v["bias_bound"]) + N.PCE_POOR_FIT_THEN[on_poor_fit]
            if on_poor_fit == "raise":
                raise SurrogateError(msg)
            warnings.warn(msg, PoorSurrogateWarning, stacklevel=2)
            notes.append(msg)
    raw = pd.DataFrame(rows, columns=["output", "unit", "factor", *PCE_COLUMNS])
    validation = pd.DataFrame(vrows)
    frame = raw.copy()
    if on_poor_fit == "withhold":
        bad = set(validation.loc[~validation["reliable"].astype(bool), "output"])
        frame.loc[frame["output"].isin(bad), PCE_COLUMNS] = np.nan
    s2 = None
    if second_order:
        s2 = pd.DataFrame(s2rows, columns=["output", "factor_i", "factor_j", "S2", "S2_conf"])
        if on_poor_fit == "withhold":
            s2.loc[s2["output"].isin(bad), ["S2", "S2_conf"]] = np.nan
    notes.append(N.PCE_INTERVALS.format(ci=ci, resamples=num_resamples, n=len(X)))
    shown = {k: v for k, v in fit_options.items() if k not in ("map", "workers")}     # where it ran: not a setting
    settings = {"n": len(X), "samples": "given", "germs": dict(zip(spec.names, fams)), **shown,
                "holdout": holdout, "ci": ci, "num_resamples": num_resamples, "min_q2": min_q2,
                "on_poor_fit": on_poor_fit}
    return SurrogateSensitivityResult("pce", frame, 0, confidence, settings, s2, n_failed, notes,
                                      validation=validation, raw=raw, fits=fits, independent=independent)


def pce_given(model: Model, spec: ToleranceSpec, samples: SampleSet, Y: np.ndarray, n: int | None = None,
              factors: Sequence[str] | None = None, outputs: Sequence[str] | None = None, seed: int | None = None,
              **options) -> SurrogateSensitivityResult:
    """:func:`pce` fitted on a random subsample of ``n`` rows of the given samples (None: all of them), the
    subsample stated first in the notes; a poor fit and correlated inputs are said in the notes, not warned."""
    from ..given_data import delta_subsample

    samples, Y, note = delta_subsample(samples, Y, n, seed, "pce_subsample", "the surrogate fit")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PoorSurrogateWarning)   # said in the notes
        warnings.simplefilter("ignore", CorrelatedInputsWarning)
        res = pce(model, spec, samples, Y, factors, outputs, seed, **options)
    res.notes.insert(0, note[0].upper() + note[1:] + ".")
    return res
