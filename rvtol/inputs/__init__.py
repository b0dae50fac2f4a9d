"""Engineers' inputs: drawing notation, ISO 286 limits and fits, table specs, measured data.

=============================  ===========================================================
module                         what it gives
=============================  ===========================================================
:mod:`rvtol.inputs.iso286`     ISO 286-1 tolerance grades, fundamental deviations, fits
:mod:`rvtol.inputs.notation`   drawing tolerance text (``25 +0.10/-0.00``, ``Ø7 h5``,
                               ``H7/g6``, ``Cpk 1.33 k 0.25``…) → limits + a factor table
:mod:`rvtol.inputs.sheets`     spreadsheet files both ways (CSV/TSV/XLSX rows with their sheet,
                               row and column; DataFrames written as CSV/XLSX)
:mod:`rvtol.inputs.table_spec` a spec as a CSV/XLSX table (one row per factor), both ways
:mod:`rvtol.inputs.measured`   a factor distribution from measured values: empirical,
                               kernel density, fitted families ranked by AIC
=============================  ===========================================================

Formulas of the factors (no Python) are a model kind: :mod:`rvtol.models.formula`, written in the
one expression language :mod:`rvtol.expressions`.
"""
