"""Validation against published measurements: predict first, calibrate after, say where the model misses.

Published figures of real reducers (a measured TE peak-to-peak, the orders of its spectrum, a catalogue's
lost-motion bound, ...) are stored one source per TOML file with the full citation, the figure or table each
number came from and how it was read (:mod:`.published`; ``data/measurements/published/``).  :func:`validate`
predicts each figure of the study's reducer with the model as it is — the nominal point and a Monte Carlo
sample of the tolerance spec — and compares them (:mod:`.agreement`: ratio, the measured value's percentile among
the predicted units, inside or outside the central interval; catalogue bounds as bounds); then fits one
parameter to one figure and predicts the others (hold-out)::

    from rvtol.validation import load_published_files, validate
    res = validate(model, spec, load_published_files(paths), {"transmission_error_pp": "te.te_pp"},
                   reducer="RV-80E", n=400, seed=1, calibrate_on="yang2021_mmt:te_pp_prototype_1")
    res.to_frame(); res.orders; res.calibration; res.misses()

The study analysis is ``[[analysis]] kind = "validation"`` (:mod:`.analyses`); notes: ``studies/validation.md``.
"""
from .agreement import compare_limit, compare_orders, compare_value, median_interval
from .published import (KINDS, STATUSES, MissingItem, PublishedQuantity, PublishedSource, load_published,
                        load_published_files)
from .validate import ScaleFit, ValidationResult, validate

__all__ = ["compare_limit", "compare_orders", "compare_value", "median_interval", "KINDS", "STATUSES",
           "MissingItem", "PublishedQuantity", "PublishedSource", "load_published", "load_published_files",
           "ScaleFit", "ValidationResult", "validate"]
