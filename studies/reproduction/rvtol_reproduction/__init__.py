"""The reproduction wing: each reference document's printed figures against rvtol — a plug-in of rvtol.

A distribution of its own (``rvtol-reproduction``, ``studies/reproduction/pyproject.toml``), outside the
``rvtol`` package and its wheel: it registers its study analyses through the ``rvtol.analyses``
entry-point group like any plug-in, and uses the library only through its plug-in API, :mod:`rvtol.plugin`
(``tests/architecture/test_architecture.py`` checks every import); its tests are in ``studies/reproduction/tests``.  One
module per document computes the comparison (a plain function returning a result dataclass), :mod:`.analyses` holds
the thin analyses, :mod:`.texts` their prose and layout:

=================================  ================================================  ===================================
module                             document                                          ``[[analysis]] kind``
=================================  ================================================  ===================================
:mod:`.doc000_transmission_error`  doc 000: 20-DOF transmission error, sensitivities  ``transmission_error_reproduction``
:mod:`.doc001_lost_motion`         doc 001: statistical geometric lost motion        ``lost_motion_reproduction``
:mod:`.doc002_adjustment`          doc 002: LQR adjustment and tolerance allocation  ``adjustment_reproduction``
:mod:`.doc003_stackup`             doc 003: 6-DOF stack-up, shaft–hole example and   ``stackup_shaft_hole``
                                   the planar zone's printed formulas
:mod:`.doc004_stiffness`           doc 004: torsional stiffness, Tables 2–5          ``stiffness_reproduction``
=================================  ================================================  ===================================

The printed numbers live in ``data/reproduction/docNNN_*.toml`` (each with its place in the document and a
quotation), read by :func:`.printed.load_printed`; every verdict comes from the one rule
:data:`.printed.RULE`.  The library never imports this package (``tests/architecture/test_architecture.py``).
"""
