"""The estimated design's own uncertainty (issue 39 item 2): the band of a prediction over what is not known of the
design — each estimated number within its stated plausible range (``range``, ``basis`` in the design file) —
beside the tolerance scatter, and which estimated numbers drive each output.

::

    from rvtol.epistemic import StudyVariants, epistemic_band
    res = epistemic_band(study.design, StudyVariants(study.file), ["torsion.torsional_rigidity"], n=32, seed=1)
    res.to_frame(); res.sensitivity; res.plot()

The study analysis is ``[[analysis]] kind = "epistemic_band"`` (:mod:`.analyses`); the validation analysis puts the
band beside each published figure (``epistemic_n``).  Notes: ``studies/epistemic_band.md``.
"""
from .band import (SENSITIVITY_METHODS, EpistemicInput, EpistemicResult, StudyVariants, design_inputs, design_spec,
                   epistemic_band, evaluate_variant, study_band)

__all__ = ["SENSITIVITY_METHODS", "EpistemicInput", "EpistemicResult", "StudyVariants", "design_inputs", "design_spec",
           "epistemic_band", "evaluate_variant", "study_band"]
