"""The reproduction wing: each reference document's printed figures against rvtol.

One module per document, each a study analysis that sets the document's
printed figures beside what rvtol computes, with the reason for every
difference:

======================================  ==================================================  ===============================
module                                  document                                            ``[[analysis]] kind``
======================================  ==================================================  ===============================
:mod:`.doc000_transmission_error`       doc 000: 20-DOF transmission error, sensitivities   ``transmission_error_reproduction``
:mod:`.doc001_lost_motion`              doc 001: statistical geometric lost motion          ``lost_motion_reproduction``
:mod:`.doc002_adjustment`               doc 002: LQR adjustment and tolerance allocation    ``adjustment_reproduction``
:mod:`.doc003_stackup`                  doc 003: 6-DOF stack-up, shaft–hole example         ``stackup_shaft_hole``
:mod:`.doc004_stiffness`                doc 004: torsional stiffness, Tables 2–5            ``stiffness_reproduction``
======================================  ==================================================  ===============================

The printed numbers live in ``data/reproduction/docNNN_*.toml`` (each with
its place in the document and a quotation), read by :func:`.printed.load_printed`;
every verdict comes from the one rule :data:`.printed.RULE`.  The library
never imports this package (``tests/test_architecture.py``): it only uses the library.
"""
