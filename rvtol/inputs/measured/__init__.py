"""A factor's distribution from measured values (a CMM export, a CSV column).

Three ways, each a distribution with the interface rvtol samples through (``ppf`` of a
uniform u, ``cdf``, ``mean``, ``std``, ``tolerance``, ``scaled``, ``describe``), so it plugs
into :class:`rvtol.spec.Factor` and the inverse-CDF sampling of :mod:`rvtol.sampling`:
resampling the values (``empirical``), their kernel density (``kde``) or a parametric family
fitted to them (``fit``, ranked by AIC, with a goodness-of-fit test).

===========================================  =============================================================
module                                       what it holds
===========================================  =============================================================
:mod:`rvtol.inputs.measured.read`            one column of a CSV/TSV/TXT or XLSX file of measured values
:mod:`rvtol.inputs.measured.values`          the values checked, and corrected for the gauge's uncertainty
                                             (``measurement_sigma``: the moment deconvolution)
:mod:`rvtol.inputs.measured.nonparametric`   the empirical distribution and the kernel density of the values
:mod:`rvtol.inputs.measured.parametric`      maximum-likelihood fits of candidate families ranked by AIC,
                                             the Anderson–Darling bootstrap test, Q-Q data (``FitReport``)
:mod:`rvtol.inputs.measured.factor`          a factor's distribution by method, from Python
                                             (``from_measurements``) or a spec's ``[[factor]]`` table
                                             (``measured_factor``), and its record ``Measured``
:mod:`rvtol.inputs.measured.report_tables`   what a report shows of a measured factor
===========================================  =============================================================

The data flow one way: read and values → nonparametric and parametric → factor → report_tables.
"""
from .factor import Measured, from_measurements, measured_factor, measured_from_params
from .nonparametric import empirical, kde
from .parametric import FAMILIES, fit, fit_family
from .read import read_measurements
from .report_tables import evidence
from .values import deconvolve

__all__ = ["FAMILIES", "Measured", "deconvolve", "empirical", "evidence", "fit", "fit_family", "from_measurements",
           "kde", "measured_factor", "measured_from_params", "read_measurements"]
