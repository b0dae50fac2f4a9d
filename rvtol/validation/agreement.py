"""How far one published figure agrees with the model's prediction of it.

A prediction is a distribution: the model evaluated on a Monte Carlo sample of the tolerance spec (the
reducers the drawing admits) plus its nominal point.  The measured unit is one draw from what the maker
built, so a measured value is judged against the predicted *spread*, never against one number:

* ``value`` / ``range`` (a range's width, e.g. a TE's peak-to-peak from its printed extremes): the ratio
  predicted median / measured, the measured value's percentile in the predicted distribution, and whether
  it lies inside the central predicted interval (``interval``, default 95 %: P2.5–P97.5), its reading
  uncertainty allowed for;
* ``upper_limit`` / ``lower_limit`` (a catalogue bound every shipped unit meets): the ratio predicted
  median / limit, the predicted fraction of units within it, and *consistent* (the whole central interval
  within), *partly* (the median within, the tail not) or *contradicts* (the median beyond the limit);
* ``orders`` (the orders a measured TE spectrum shows as strong): per order the predicted amplitude
  (median over several predicted reducers) and its share of the largest order's; *present* when that
  share reaches ``threshold`` (default 10 %), else *absent* — a statement about the spectrum's shape only,
  since the measured amplitudes are not known;
* ``order_amplitudes`` (a measured spectrum's amplitude per order) against the predicted spectra in
  *shape* (:func:`compare_shape`): each order's amplitude over a reference order's, measured (with its
  relative reading uncertainty, the two orders' in quadrature) against the predicted units' central
  interval of the same ratio; *consistent* when they overlap, else *misses* by the factor predicted
  median / measured.  Shape, not size, because such a spectrum may be of another reducer with the same
  order lattice (the same pins and ratio), and its test conditions (load, speed) are not the model's.

The predicted median carries its own sampling uncertainty: the distribution-free interval of a median
from two order statistics (:func:`median_interval`).
"""
from __future__ import annotations

import numpy as np
from scipy import stats

INSIDE, ABOVE, BELOW = "inside the predicted interval", "above the predicted interval", "below the predicted interval"
CONSISTENT, PARTLY, CONTRADICTS = "consistent", "partly", "contradicts"
PRESENT, ABSENT = "present", "absent"


def median_interval(values, confidence: float = 0.95) -> tuple[float, float, float]:
    """``(low, high, coverage)``: the distribution-free confidence interval of the median of the population
    ``values`` were drawn from — the order statistics ``x_(j)`` and ``x_(n+1−j)`` (1-based) with the largest
    ``j`` whose coverage ``1 − 2 B(j − 1; n, ½)`` reaches ``confidence`` (Conover, *Practical Nonparametric
    Statistics*, 3rd ed., Wiley 1999, §3.2; n = 100 at 95 %: x_(40), x_(61), coverage 96.5 %).  With too
    few values for ``confidence`` the widest interval (min, max) and its smaller coverage are returned."""
    x = np.sort(np.asarray(values, dtype=float))
    n = x.size
    if n == 0:
        return float("nan"), float("nan"), float("nan")
    j = np.arange(1, n // 2 + 1) if n > 1 else np.array([1])
    cover = 1.0 - 2.0 * stats.binom.cdf(j - 1, n, 0.5)
    ok = np.flatnonzero(cover >= confidence)
    k = int(j[ok[-1]]) if ok.size else 1
    c = float(1.0 - 2.0 * stats.binom.cdf(k - 1, n, 0.5))
    return float(x[k - 1]), float(x[n - k]), c


def predicted_statistics(values, interval: float = 0.95, confidence: float = 0.95) -> dict:
    """Median (with its interval), the central ``interval`` (percentiles, numpy's linear rule) and n."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        nan = float("nan")
        return {"median": nan, "median_low": nan, "median_high": nan, "median_coverage": nan,
                "low": nan, "high": nan, "n": 0}
    lo_q, hi_q = 50.0 * (1.0 - interval), 50.0 * (1.0 + interval)
    mlo, mhi, cov = median_interval(v, confidence)
    return {"median": float(np.median(v)), "median_low": mlo, "median_high": mhi, "median_coverage": cov,
            "low": float(np.percentile(v, lo_q)), "high": float(np.percentile(v, hi_q)), "n": int(v.size)}


def compare_value(measured: float, uncertainty: float, values, interval: float = 0.95,
                  confidence: float = 0.95) -> dict:
    """A measured value (or a range's width) against the predicted values (same unit): module docstring."""
    st = predicted_statistics(values, interval, confidence)
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    ratio = st["median"] / measured if measured != 0 else float("nan")
    pct = 100.0 * float(np.mean(v <= measured)) if v.size else float("nan")
    if not v.size:
        verdict = "no successful prediction"
    elif measured + uncertainty < st["low"]:
        verdict = BELOW
    elif measured - uncertainty > st["high"]:
        verdict = ABOVE
    else:
        verdict = INSIDE
    return {**st, "ratio": ratio, "percentile": pct, "yield": float("nan"), "verdict": verdict}


def compare_limit(limit: float, upper: bool, values, interval: float = 0.95, confidence: float = 0.95) -> dict:
    """A catalogue bound every unit meets against the predicted values: module docstring."""
    st = predicted_statistics(values, interval, confidence)
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    ratio = st["median"] / limit if limit != 0 else float("nan")
    if not v.size:
        return {**st, "ratio": ratio, "percentile": float("nan"), "yield": float("nan"),
                "verdict": "no successful prediction"}
    within = v <= limit if upper else v >= limit
    tail, med = (st["high"], st["median"])
    if upper:
        verdict = CONSISTENT if tail <= limit else PARTLY if med <= limit else CONTRADICTS
    else:
        verdict = CONSISTENT if st["low"] >= limit else PARTLY if med >= limit else CONTRADICTS
    return {**st, "ratio": ratio, "percentile": 100.0 * float(np.mean(v <= limit)),
            "yield": 100.0 * float(np.mean(within)), "verdict": verdict}


def _shares(spectra) -> tuple[np.ndarray, np.ndarray]:
    """``(amplitude[c, k], share[c, k])`` of spectra (amplitude of order k per output revolution, k = 0 the mean;
    cut to the shortest); share = amplitude / the spectrum's largest amplitude of an order ≥ 1."""
    n = min(len(a) for a in spectra)
    amps = np.array([np.asarray(a, dtype=float)[:n] for a in spectra])
    top = amps[:, 1:].max(axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        share = np.where(top > 0, amps / top, np.nan)
    return amps, share


def compare_orders(orders, spectra, threshold: float = 0.10) -> list[dict]:
    """Per measured strong order: the predicted amplitude and share (medians over the predicted reducers'
    ``spectra``, None for a reducer the solver failed on) and whether the predicted spectrum has it
    (share ≥ ``threshold``); an order above the spectra's highest is *not resolved*."""
    spectra = [a for a in spectra if a is not None and len(a) > 1]
    if not spectra:
        return [{"order": int(o), "amplitude": float("nan"), "share": float("nan"),
                 "verdict": "no successful prediction"} for o in orders]
    amps, share = _shares(spectra)
    rows = []
    for o in orders:
        if o >= amps.shape[1]:
            rows.append({"order": int(o), "amplitude": float("nan"), "share": float("nan"),
                         "verdict": f"not resolved (highest order {amps.shape[1] - 1})"})
            continue
        a, s = float(np.median(amps[:, o])), float(np.median(share[:, o]))
        rows.append({"order": int(o), "amplitude": a, "share": s,
                     "verdict": PRESENT if s >= threshold else ABSENT})
    return rows


def largest_orders(spectra, top: int = 6) -> list[tuple[int, float]]:
    """The ``top`` orders ≥ 1 with the largest median amplitude over ``spectra``: ``[(order, amplitude)]``."""
    spectra = [a for a in spectra if a is not None and len(a) > 1]
    if not spectra:
        return []
    med = np.median(_shares(spectra)[0], axis=0)
    idx = np.argsort(med[1:])[::-1][:top] + 1
    return [(int(i), float(med[i])) for i in idx]


CONSISTENT_SHAPE, REFERENCE = "consistent", "reference order"


def compare_shape(orders, amplitudes, relative_uncertainty, spectra, reference: int,
                  interval: float = 0.95) -> list[dict]:
    """A measured spectrum's shape against the predicted ``spectra`` (module docstring): per order the measured
    amplitude over the ``reference`` order's, m = A_k / A_ref with relative uncertainty u = √(u_k² + u_ref²),
    and the predicted units' ratios a_k / a_ref (median, central ``interval``); *consistent* when
    [m(1 − u), m(1 + u)] meets the predicted interval, else *misses*: predicted median / measured."""
    spectra = [np.asarray(a, dtype=float) for a in spectra if a is not None and len(a) > 1]
    amp = dict(zip(orders, amplitudes))
    unc = dict(zip(orders, relative_uncertainty))
    rows = []
    n = min((len(a) for a in spectra), default=0)
    if reference not in amp:
        raise ValueError(f"the reference order {reference} is not among the measured orders")
    lo_q, hi_q = 50.0 * (1.0 - interval), 50.0 * (1.0 + interval)
    for o in orders:
        m = amp[o] / amp[reference]
        u = 0.0 if o == reference else float(np.hypot(unc[o], unc[reference]))
        row = {"order": int(o), "measured": float(amp[o]), "relative uncertainty": float(unc[o]),
               "measured ratio": float(m), "ratio uncertainty": u, "predicted": float("nan"),
               "predicted ratio": float("nan"), "low": float("nan"), "high": float("nan"),
               "predicted / measured": float("nan"), "n": len(spectra)}
        if not spectra:
            rows.append({**row, "verdict": "no successful prediction"})
            continue
        if max(o, reference) >= n:
            rows.append({**row, "verdict": f"not resolved (highest order {n - 1})"})
            continue
        a = np.array([s[o] for s in spectra])
        with np.errstate(invalid="ignore", divide="ignore"):
            r = a / np.array([s[reference] for s in spectra])
        r = r[np.isfinite(r)]
        med, lo, hi = (float(np.median(r)), float(np.percentile(r, lo_q)), float(np.percentile(r, hi_q))) \
            if r.size else (float("nan"),) * 3
        row.update({"predicted": float(np.median(a)), "predicted ratio": med, "low": lo, "high": hi,
                    "predicted / measured": med / m if m > 0 else float("nan")})
        if o == reference:
            verdict = REFERENCE
        elif not r.size:
            verdict = "no successful prediction"
        elif m * (1.0 + u) >= lo and m * (1.0 - u) <= hi:
            verdict = CONSISTENT_SHAPE
        else:
            verdict = f"misses: predicted / measured ratio {med / m:.2g}"
        rows.append({**row, "verdict": verdict})
    return rows
