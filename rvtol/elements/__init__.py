"""Machine elements: closed-form stiffness and contact laws shared by the models.

Each module is a small set of pure functions (mm, N, rad inside), with the
formula and its literature source in the docstring:

* :mod:`.hertz` — line-contact approach of two cylinders (doc 004's formula);
* :mod:`.involute` — involute mesh stiffness (ISO 6336-1);
* :mod:`.bearings` — roller-bearing deflection (Palmgren);
* :mod:`.crankshaft` — Timoshenko beam of the crankshaft between its supports;
* :mod:`.carrier` — carrier pillars.
"""
