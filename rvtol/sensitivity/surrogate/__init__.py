r"""Sobol indices from a polynomial chaos expansion (PCE) fitted on samples already computed.

The Monte Carlo of a study already holds n model runs ``(X, Y)``.  A PCE fitted on them gives
first-, total- and second-order Sobol indices *analytically from its coefficients*, with no
further model run (Sudret 2008).  The Saltelli route (:func:`rvtol.sensitivity.sobol`) stays
available; this one costs a least-squares fit instead of n·(k+2) runs.

===============================================  ========================================================
module                                           what it holds
===============================================  ========================================================
:mod:`rvtol.sensitivity.surrogate.basis`         the germs (Legendre, Hermite), the orthonormal
                                                 polynomials, the truncated multi-index sets and the
                                                 design matrix
:mod:`rvtol.sensitivity.surrogate.fit`           least squares with the corrected leave-one-out error,
                                                 the selection of terms (OMP, LARS) and degree, the
                                                 fitted expansion (``fit_pce``) and the Sobol indices of
                                                 its coefficients
:mod:`rvtol.sensitivity.surrogate.indices`       one output's indices from ``(U, y)``: the hold-out
                                                 check, reliability and the intervals (``pce_indices``)
:mod:`rvtol.sensitivity.surrogate.monte_carlo`   a model's outputs from the study's Monte Carlo samples
                                                 (``pce``, ``pce_given``), what an unreliable fit's
                                                 indices become, correlated inputs
===============================================  ========================================================

The data flow one way: basis → fit → indices → monte_carlo.

References
    * B. Sudret (2008), Global sensitivity analysis using polynomial chaos expansions,
      Reliability Engineering & System Safety 93(7), 964–979.
    * G. Blatman, B. Sudret (2010), An adaptive algorithm to build up sparse polynomial chaos
      expansions for stochastic finite element analysis, Prob. Eng. Mech. 25(2), 183–197.
    * G. Blatman, B. Sudret (2011), Adaptive sparse polynomial chaos expansion based on least
      angle regression, J. Comput. Phys. 230(6), 2345–2367 (hyperbolic truncation, hybrid
      selection + OLS, corrected LOO).
    * O. Chapelle, V. Vapnik, Y. Bengio (2002), Model selection for small sample regression,
      Machine Learning 48, 9–23.
    * Y. C. Pati, R. Rezaiifar, P. S. Krishnaprasad (1993), Orthogonal matching pursuit,
      Proc. 27th Asilomar Conference on Signals, Systems and Computers, 40–44.
    * J. D. Jakeman, M. S. Eldred, K. Sargsyan (2015), Enhancing ℓ1-minimization estimates of
      polynomial chaos expansions using basis selection, J. Comput. Phys. 289, 18–34.
    * D. Xiu, G. E. Karniadakis (2002), The Wiener–Askey polynomial chaos for stochastic
      differential equations, SIAM J. Sci. Comput. 24(2), 619–644.
"""
from .basis import design_matrix, families_for_spec, germ, multi_indices, orthonormal_1d
from .fit import METHODS, Q_NORM, fit_pce, sobol_from_coefficients
from .indices import CI_METHODS, MIN_Q2, pce_indices
from .monte_carlo import POOR_FIT, PoorSurrogateWarning, SurrogateError, pce, pce_given

__all__ = ["CI_METHODS", "METHODS", "MIN_Q2", "POOR_FIT", "PoorSurrogateWarning", "Q_NORM", "SurrogateError",
           "design_matrix", "families_for_spec", "fit_pce", "germ", "multi_indices", "orthonormal_1d", "pce",
           "pce_given", "pce_indices", "sobol_from_coefficients"]
