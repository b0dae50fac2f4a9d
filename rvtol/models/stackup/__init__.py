"""Deviation stack-up (doc 003): 6-DOF deviation vectors, transforms, domains and assembly propagation.

* :mod:`.transforms` — small-angle and exact ``Trans × Rot`` transforms, composition, extraction;
* :mod:`._kernels` / :mod:`.program` — the fused numba chain kernel and its NumPy twin;
* :mod:`.deviation` — multivariate normal model, ‖e(E)‖ and ‖ε(E)‖;
* :mod:`.domains` — parallel-plane, cylindrical and clearance-fit domains with derived moments;
* :mod:`.graph` — the assembly graph (features, fits, flows f1–f5, sequences, KCs);
* :mod:`.model` — the chain as a :class:`~rvtol.model.Model` (``MODELS["stackup"]``);
* :mod:`.overview`, :mod:`.sequences`, :mod:`.domain_check` — the assembly graph, the sequences side by side,
  the domains' moments checked;
* :mod:`.analyses` — ``ANALYSES["stackup_*"]``, laid out by :mod:`.texts`.

The chain's worst case, RSS and loop-method signs (``stackup_linear``) are stack-up conventions, with the others
in :mod:`rvtol.stacking.chain_conventions`.

Doc 003's shaft–hole example and planar-zone formulas are compared in the reproduction wing
(``studies/reproduction``).
"""
