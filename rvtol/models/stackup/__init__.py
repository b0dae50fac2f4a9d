"""Deviation stack-up (doc 003): 6-DOF deviation vectors, transforms, domains and assembly propagation.

* :mod:`.transforms` — small-angle and exact ``Trans × Rot`` transforms, composition, extraction;
* :mod:`._kernels` / :mod:`.program` — the fused numba chain kernel and its NumPy twin;
* :mod:`.deviation` — multivariate normal model, ‖e(E)‖ and ‖ε(E)‖;
* :mod:`.domains` — parallel-plane, cylindrical and clearance-fit domains with derived moments;
* :mod:`.graph` — the assembly graph (features, fits, flows f1–f5, sequences, KCs);
* :mod:`.model` — the chain as a :class:`~rvtol.model.Model` (``MODELS["stackup"]``);
* :mod:`.linearise`, :mod:`.analyses` — worst case / RSS / loop signs beside the Monte Carlo,
  graph, sequences, domains and the doc 003 shaft–hole record (``ANALYSES["stackup_*"]``).
"""
