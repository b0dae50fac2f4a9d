"""Deviation stack-up (doc 003): 6-DOF deviation vectors, transforms, domains and assembly propagation.

* :mod:`.transforms` — small-angle and exact ``Trans × Rot`` transforms, composition, extraction;
* :mod:`._kernels` / :mod:`.program` — the fused numba chain kernel and its NumPy twin;
* :mod:`.deviation` — multivariate normal model, ‖e(E)‖ and ‖ε(E)‖;
* :mod:`.domains` — parallel-plane, cylindrical and clearance-fit domains with derived moments;
* :mod:`.graph` — the assembly graph (features, fits, flows f1–f5, sequences, KCs);
* :mod:`.model` — the chain as a :class:`~rvtol.model.Model` (``MODELS["stackup"]``);
* :mod:`.linearise` — worst case / RSS / loop signs of the linearised chain;
* :mod:`.analyses` — the linearised chain beside the Monte Carlo, graph, sequences and domains
  (``ANALYSES["stackup_*"]``); doc 003's shaft–hole figures: :mod:`rvtol.reproduction.doc003_stackup`.
"""
