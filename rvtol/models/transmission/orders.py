"""Which error families produce which orders of the transmission-error spectrum.

Orders are per output revolution (the carrier angle θ_c).  Over one output
revolution the bodies turn, absolutely: housing 0, carrier and discs 1,
cranks and their eccentrics 1 − z_b = −z_c, sun i (doc 000's nominal motion,
:mod:`.geometry`).  The cycloid–pin mesh is fixed to the eccentric (the loaded
pins are those near φ0 = arccos K1 from the eccentric direction), so an error
fixed in a body meets the mesh as often as that body turns relative to the
eccentric, and an error pattern of order n in the body's own angle n times
as often:

======================  ===================  ======================================================
error fixed in          relative turns        orders of an order-n pattern
======================  ===================  ======================================================
housing (pins, A_c)     z_c (= z_b − 1)       n·z_c (a single pin: every multiple of z_c)
disc (profile, holes)   z_b                   n·z_b
carrier (crank bores)   z_b                   multiples of z_b
crank (cams, planets,   z_b (relative to the  multiples of z_b (3·z_b for a pattern identical on
needle clearances)      carrier/disc holes)   all three cranks)
sun                     i − 1 (vs. carrier)   multiples of 3(i − 1) (three planets on a floating sun)
======================  ===================  ======================================================

Two refinements, both checked by ``tests/test_transmission_orders.py``:

* **the two discs** meet the pins with opposite sides (eccentrics 180° apart),
  so disc 2 sees an order-n pattern shifted by n·180°: an error common to
  both discs (the pin ring, a carrier bore, the same field on both discs)
  cancels at odd multiples to first order and shows at the even ones (a
  single pin: 2·z_c, 4·z_c, …; the carrier offset A_c: 2·z_c);
* **the discrete pins** sample every pattern at the mesh order Z = z_b·z_c, so
  each order k also has sidebands |k ± Z|; a uniform error round the pin ring
  (pin-circle radius, uniform pin clearance, profile modification) has no
  order of its own: it changes the mean and the nominal ripple (multiples of
  2·z_b and Z).

Interactions (products of two errors in the nonlinear contacts) give sums and
differences of the families' orders; the one a measurement notices is order
z_b − z_c = 1 from a housing-fixed error (pin ring, A_c) with a disc-, crank-
or carrier-fixed one.  A spectrum sampled at N positions per revolution shows
an order t > N/2 aliased at |t − N·round(t/N)|.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from .geometry import RVGeometry


#: harmonics of a base order listed as expected (nonlinear contacts and pulse-like single-pin effects
#: give several; the tests show the first few carry nearly everything)
HARMONICS = 12


@dataclass(frozen=True)
class Family:
    """An error family: the base orders of its errors as functions of the geometry.

    ``bases``: ``(order(g), harmonics)`` pairs — the orders m·b, m = 1 … harmonics, are expected (b × n
    for a pattern of order n when ``patterned``).
    """

    key: str
    label: str
    bases: tuple
    patterned: bool = True


def _zb(g):
    return g.z_b


def _zc(g):
    return g.z_c


def _mesh(g):
    return g.z_b * g.z_c


FAMILIES = {f.key: f for f in (
    Family("pin_ring", "pin ring (housing-fixed: pin positions, diameters, pin-ring patterns)", ((_zc, HARMONICS),)),
    Family("carrier_offset", "carrier axis offset in the housing (A_c)",
           ((_zc, HARMONICS), (lambda g: 3, 2))),
    Family("pin_uniform", "uniform round the pin ring (pin circle, uniform pin clearance, profile modification)",
           ((lambda g: 2 * g.z_b, 6), (_mesh, 2)), patterned=False),
    Family("disc_profile", "disc profile and pitch (disc-fixed)", ((_zb, HARMONICS),)),
    Family("disc_holes", "disc crank holes (disc-fixed)", ((_zb, HARMONICS),)),
    Family("crank", "cranks: cams, planets, needle and crank-bearing clearances (crank-fixed)", ((_zb, HARMONICS),)),
    Family("carrier_bores", "carrier crank bores (carrier-fixed)", ((_zb, HARMONICS),)),
    Family("sun", "sun eccentricity (sun-fixed)", ((lambda g: round(g.ratio) - 1, 6),)),
    Family("input_support", "sun support offset, carrier-housing clearance (housing vs carrier)",
           ((lambda g: 1, 3), (lambda g: 3, 2))),
    Family("nominal", "nominal reducer (no error): crank bearings and discrete pins",
           ((lambda g: 2 * g.z_b, 6), (_mesh, 2)), patterned=False),
)}

#: factor base name -> family key (phase factors have none: they act through their amplitude)
FAMILY_OF = {
    **dict.fromkeys(("R_pin", "AP_pin", "R_pin_h", "AP_pin_h", "R_pin_c", "R_pin_s", "AP_pin_c", "AP_pin_s"),
                    "pin_ring"),
    "A_c": "carrier_offset",
    **dict.fromkeys(("R_pc", "equidistance_mod", "moved_distance_mod"), "pin_uniform"),
    **dict.fromkeys(("R_cyc", "AP_cyc", "R_cyc_h", "AP_cyc_h", "R_cyc_c", "R_cyc_s", "AP_cyc_c", "AP_cyc_s"),
                    "disc_profile"),
    "E_h": "disc_holes",
    **dict.fromkeys(("E_c", "E_p", "delta_b", "delta_oc"), "crank"),
    "E_ca": "carrier_bores",
    "E_s": "sun",
    **dict.fromkeys(("A_s", "delta_ca"), "input_support"),
}


def family_of(binding, harmonic: int) -> tuple[str, int] | None:
    """``(family key, pattern order n)`` of a factor binding (:class:`.factors.ErrorFactors`), or None.

    ``delta_pin``/``delta_th`` are per pin with an index and uniform without one; the Table 3 groups
    ``R_pin``, ``AP_pin``, ``R_cyc``, ``AP_cyc`` are patterns of order ``harmonic``; a single pin
    (``R_pin[k]`` …) contains every order, n = 1.
    """
    base, index = binding.base, binding.index
    if base in ("delta_pin", "delta_th"):
        return ("pin_ring", 1) if index else ("pin_uniform", 1)
    key = FAMILY_OF.get(base)
    if key is None:
        return None
    if base in ("R_pin", "AP_pin", "R_cyc", "AP_cyc"):
        return (key, harmonic) if not index else (key, 1)
    if base.startswith(("R_pin_", "AP_pin_")):
        return key, index[0]
    if base.startswith(("R_cyc_", "AP_cyc_")):
        return key, index[1]
    return key, 1


def order_spectrum(te: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(orders, amplitude)`` of a signal sampled uniformly over one output revolution.

    Amplitude of order k ≥ 1 is 2|X_k|/N (a sinusoid of amplitude A gives A);
    order 0 is the mean.
    """
    n = te.size
    X = np.fft.rfft(te)
    amp = np.abs(X) / n
    amp[1:] *= 2.0
    if n % 2 == 0:
        amp[-1] /= 2.0
    return np.arange(amp.size), amp


def alias(t: int, n_positions: int) -> int:
    """Where order ``t`` shows in the spectrum of ``n_positions`` samples per revolution."""
    return abs(t - n_positions * round(t / n_positions))


def expected_orders(g: RVGeometry, key: str, n: int, n_positions: int) -> dict[int, str]:
    """Resolved orders (1 … N/2) the family ``key`` with pattern order ``n`` is expected at, each with how.

    The harmonics m·b of every base order b (b × n for patterned families), their first mesh
    sidebands |Z ± m·b|, all aliased into the resolved band of N = ``n_positions`` samples per
    revolution.  A direct harmonic wins over a sideband, a resolved order over an aliased one.
    """
    fam = FAMILIES[key]
    Z = _mesh(g)
    half = n_positions // 2
    out: dict[int, tuple[int, str]] = {}   # order -> (rank, how)
    names = {g.z_b: "z_b", g.z_c: "z_c", Z: "Z"}
    for base, harmonics in fam.bases:
        b0 = base(g)
        nn = n if fam.patterned else 1
        sym = names.get(b0, str(b0))
        for m in range(1, harmonics + 1):
            t = m * nn * b0
            label = sym if m * nn == 1 else f"{m * nn}·{sym}"
            for tt, tag in ((t, ""), (abs(Z - t), f"Z − {label}"), (Z + t, f"Z + {label}")):
                if tt == 0 or (tag and t == Z):
                    continue
                k = alias(tt, n_positions)
                if not 1 <= k <= half:
                    continue
                rank = (1 if tag else 0) + (2 if tt > half else 0)
                how = (tag or label) + (f" (aliased from {tt})" if tt > half else "")
                if k not in out or rank < out[k][0]:
                    out[k] = (rank, how)
    return {k: how for k, (rank, how) in out.items()}


def active_families(bindings, values, harmonic: int) -> dict[tuple[str, int], list[str]]:
    """``{(family, n): [factor names]}`` of the factors that are non-zero in ``values`` (plus the nominal ripple)."""
    out: dict[tuple[str, int], list[str]] = {("nominal", 1): []}
    for b, v in zip(bindings, values):
        fam = family_of(b, harmonic)
        if fam is None or v == 0.0:
            continue
        out.setdefault(fam, []).append(b.name)
    return out


def order_table(te: np.ndarray, g: RVGeometry, bindings, values, harmonic: int, top: int = 12,
                min_fraction: float = 0.01, interactions: int = 4) -> pd.DataFrame:
    """The largest orders of a TE curve (uniform over one output revolution) with the families expected there.

    Rows: the ``top`` largest orders ≥ ``min_fraction`` × the largest.  ``expected from``: the active
    families (non-zero factors, plus the nominal ripple) whose orders (:func:`expected_orders`) contain
    it, with how (e.g. "pin ring: 2·z_c"); ``interaction`` (for orders no family explains alone): two
    base orders b1 ≠ b2 of active families (the nominal ripple left out) with p·b1 ± q·b2 equal to it,
    p, q ≤ ``interactions``.
    """
    k, a = order_spectrum(np.asarray(te, dtype=float))
    n_pos = np.asarray(te).size
    fams = active_families(bindings, values, harmonic)
    expected = {f: expected_orders(g, f[0], f[1], n_pos) for f in fams}
    bases = [(f, b(g) * (f[1] if FAMILIES[f[0]].patterned else 1)) for f in fams if f[0] != "nominal"
             for b, _ in FAMILIES[f[0]].bases]
    amp = a[1:]
    biggest = amp.max() if amp.size else 0.0
    rows = []
    for o in np.argsort(amp)[::-1][:top] + 1:
        if biggest <= 0 or a[o] < min_fraction * biggest:
            break
        hits = [f"{_label(f, fams[f])}: {expected[f][o]}" for f in fams if o in expected[f]]
        pairs = {}
        for x, (f1, b1) in enumerate(bases if not hits else []):
            for f2, b2 in bases[x + 1:]:
                if b1 == b2:
                    continue
                hit = next((f"{p}·{b1} {s} {q}·{b2}" for p in range(1, interactions + 1)
                            for q in range(1, interactions + 1) for s in ("+", "−")
                            if abs(p * b1 + (q if s == "+" else -q) * b2) == o), None)
                if hit:
                    names = _short(f1) if f1 == f2 else f"{_short(f1)} × {_short(f2)}"
                    pairs.setdefault(f"{names} ({hit})", None)
        rows.append({"order [1/rev]": int(o), "amplitude [arcsec]": float(a[o]),
                     "of largest [%]": 100.0 * float(a[o] / biggest),
                     "expected from": "; ".join(hits) if hits else "—",
                     "interaction": "; ".join(pairs) if pairs else "—"})
    return pd.DataFrame(rows, columns=["order [1/rev]", "amplitude [arcsec]", "of largest [%]", "expected from",
                                       "interaction"])


def _short(fam: tuple[str, int]) -> str:
    return FAMILIES[fam[0]].label.split(" (")[0]


def _label(fam: tuple[str, int], names: list[str]) -> str:
    key, n = fam
    lab = _short(fam)
    if n > 1 and FAMILIES[key].patterned:
        lab += f", order {n}"
    if names:
        shown = ", ".join(names[:3]) + (f" +{len(names) - 3}" if len(names) > 3 else "")
        lab += f" [{shown}]"
    return lab


def families_frame(g: RVGeometry) -> pd.DataFrame:
    """The families, their factors and base orders for this geometry (for reports and the notes)."""
    rows = []
    for key, fam in FAMILIES.items():
        factors = sorted(b for b, f in FAMILY_OF.items() if f == key)
        if key == "pin_ring":
            factors += ["R_pin[k]", "AP_pin[k]", "delta_pin[k]", "delta_th[k]"]
        if key == "pin_uniform":
            factors += ["delta_pin", "delta_th"]
        rows.append({"family": fam.label, "factors": ", ".join(factors) or "—",
                     "base orders": ", ".join(str(b(g)) for b, _ in fam.bases)
                     + (" (× pattern order n)" if fam.patterned else "")})
    return pd.DataFrame(rows)
