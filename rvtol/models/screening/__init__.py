"""Doc 001's screening estimate beside the 20-DOF torsion curve: the bridge between the two models.

* :mod:`.bridge` — one sample's factors in both vocabularies (doc 001's and the 20-DOF's), doc 001's
  model in both modes for them, and the 20-DOF backlash rates per doc-001 factor;
* :mod:`.beside_torsion_curve` — both models on the same reducers
  (:func:`.beside_torsion_curve.screening_comparison`);
* :mod:`.analyses` — ``ANALYSES["lost_motion_screening"]``, laid out by :mod:`.texts`.

A package of its own because it depends on both :mod:`rvtol.models.lost_motion` and
:mod:`rvtol.models.torsion_curve`, which do not depend on it.
"""
