"""Local and global sensitivity of any :class:`rvtol.model.Model` over a :class:`rvtol.spec.ToleranceSpec`.

Local (five-point, doc 000 section 2) — :mod:`rvtol.sensitivity.local`::

    res = five_point(model, spec, factors=None, outputs=None, percent=10.0, abs_step=None, evaluate=None)
    res.frame            # one row per (output, factor): S, S_low_end, S_high_end, S_unit ("arcsec/um"), sign, ...
    res.gradient("lost_motion", spec.names)   # base units, for linearisation
    curve = sensitivity_curve(model, spec, ["E_c"], magnitudes=[0.5, 1, 5, 15], unit="um")
    stencil_central(f, h), stencil_forward(f, h), stencil_backward(f, h), stencil_all(f, h)   # pure stencils

Linearisation (RSS view) — :mod:`rvtol.sensitivity.linearisation`::

    pred = contributions(model, spec, output="lost_motion")     # five-point + linear_prediction
    pred.mean, pred.std, pred.worst_low, pred.worst_high; pred.frame["variance_pct"]
    linear_prediction(spec, gradient_base, y0_base, output=..., out_unit=...)   # any gradient
    high_low_table(model, spec)   # model evaluated at each factor's low / median / high limit
    factor.band                   # the band (low, high) of a factor, in its unit (rvtol.spec.Factor)

Global (SALib, each factor's own distribution) — :mod:`rvtol.sensitivity.global_`::

    sobol(model, spec, n=1024, second_order=True, seed=...)        # S1, ST, S2 with CIs
    morris(model, spec, trajectories=20, levels=4, seed=...)       # mu, mu_star (CI), sigma
    fast(model, spec, n=1024, M=4, seed=...)                       # eFAST S1, ST
    rbd_fast(model, spec, samples=mc.samples, Y=mc.Y)              # RBD-FAST S1 on given samples
    delta(model, spec, samples=mc.samples, Y=mc.Y)                 # delta + S1, correlated inputs OK

Every function takes ``evaluate`` — an :class:`rvtol.mc.Evaluator`
(``evaluate(model, X, desc) -> Evaluation``, base units); studies pass the
study's (``ctx.evaluator``: its executor and progress bar), library users may
omit it (serial).  Results are dataclasses with ``frame``/``to_frame()`` and
``plot(output, ax=None)``; global results have ``summary()`` for JSON.

Study analyses (``[[analysis]] kind = ...``): ``local_sensitivity``,
``sensitivity_curve``, ``contributions``, ``sobol``, ``morris``, ``fast``,
``delta`` (see :mod:`rvtol.sensitivity.analyses`).
"""
from .global_ import GlobalSensitivityResult, delta, design_to_factors, fast, morris, rbd_fast, sobol
from .linearisation import HighLowResult, LinearPrediction, contributions, high_low_table, linear_prediction
from .local import (LocalSensitivityResult, SensitivityCurveResult, five_point, sensitivity_curve, stencil_all,
                    stencil_backward, stencil_central, stencil_forward)

__all__ = [
    "five_point", "sensitivity_curve", "LocalSensitivityResult", "SensitivityCurveResult",
    "stencil_central", "stencil_forward", "stencil_backward", "stencil_all",
    "contributions", "linear_prediction", "high_low_table", "LinearPrediction", "HighLowResult",
    "sobol", "morris", "fast", "rbd_fast", "delta", "design_to_factors", "GlobalSensitivityResult",
]
