"""Machine elements: closed-form stiffness and contact laws shared by the models.

Pure NumPy/SciPy functions in rvtol's base units (mm, N, rad, N·mm, MPa); each
module states its formulas, symbols, units and literature sources:

* :mod:`.hertz` — line-contact approach of two cylinders (doc 004's formula);
* :mod:`.pin_groove` — the pin in its housing groove: line contact in series with the disc–pin contact,
  and the conforming (pin-in-hole) contact of a tight groove;
* :mod:`.involute` — involute mesh stiffness (ISO 6336-1);
* :mod:`.rolling_bearings` — roller-bearing deflection (Palmgren, Stribeck's most loaded roller) as doc 004's
  model uses it; tapered roller bearing pair with preload and needle roller bearing with clearance (Palmgren
  line contact, roller load distribution solved for equilibrium);
* :mod:`.crankshaft` — Timoshenko beam of the crankshaft between its supports (doc 004's model);
* :mod:`.shafts` — Timoshenko beam (stepped, hollow) on elastic supports, shaft torsion;
* :mod:`.carrier` — carrier pillars (doc 004's model);
* :mod:`.carrier_structure` — carrier pillars (fixed–guided beams with elastic
  end fixity), end-plate rotation at a pillar root (Kirchhoff plate), carrier
  torsional stiffness;
* :mod:`.disc_web` — in-plane torsion of the cycloid disc web;
* :mod:`.plane_fe` — plane-stress finite elements with scikit-fem (meshes, tractions, plates);
* :mod:`.fe_seats` — the disc and carrier seats round the bearings and the housing ring, by plane-stress FE;
* :mod:`.fe_cache` — the FE seats kept on disk by the content of their inputs, across processes and runs;
* :mod:`.roughness` — Greenwood–Williamson normal contact stiffness of rough surfaces;
* :mod:`.bolted_joint` — bolted joint after VDI 2230 (preload, opening, slip, interface);
* :mod:`.chain` — series/parallel, ``K = k r²``, ratio transforms, arcsec,
  virtual-work breakdown, nonlinear springs in series.
"""
