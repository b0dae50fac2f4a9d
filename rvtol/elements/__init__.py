"""First-principles compliance elements of the RV reducer (issue 12, item 2).

Pure NumPy/SciPy functions in rvtol's base units (mm, N, rad, N·mm, MPa).  Each
module states its formulas, symbols, units and literature sources:

* :mod:`.chain` — series/parallel, ``K = k r²``, ratio transforms, arcsec,
  virtual-work breakdown, nonlinear springs in series;
* :mod:`.rolling_bearings` — tapered roller bearing pair with preload and
  needle roller bearing with clearance (Palmgren line contact, roller load
  distribution solved for equilibrium);
* :mod:`.shafts` — Timoshenko beam (stepped, hollow) on elastic supports,
  shaft torsion;
* :mod:`.carrier_structure` — carrier pillars (fixed–guided beams with
  elastic end fixity), end-plate rotation at a pillar root (Kirchhoff plate),
  carrier torsional stiffness;
* :mod:`.contacts` — pin in a housing groove (conforming line contact), in
  series with the disc–pin contact;
* :mod:`.disc_web` — in-plane torsion of the cycloid disc web.

The integration of these elements into the reducer models is not done here.
"""
