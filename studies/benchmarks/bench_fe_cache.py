"""Finite-element seats benchmark: the first build of the product's chain in a fresh process, cold cache against warm.

Every run of the sign-off, every test process, every benchmark builds the RV-80E product's elements
(``ReducerStiffness.from_design``), whose plane-stress seats — the disc round its crank holes, the two carrier
plates, the housing ring (``rvtol.elements.fe_seats``) — took most of the build.  They are now kept on disk by
their inputs (``rvtol.elements.fe_cache``).  Each row is a **fresh Python process** (a new ``rvtol run``, a
pytest-xdist worker) that loads the design and builds the chain once; only the build is timed (the imports are
printed apart), then a second build in the same process (the per-process memo).  Cold: an empty cache folder;
warm: the folder the cold process filled.  The warm and cold processes' seats must agree bit for bit.

    python studies/benchmarks/bench_fe_cache.py [--quick | --smoke]

``--smoke`` builds one small housing ring instead of the product (seconds); ``--quick`` one cold/warm pair;
the full size the best of three pairs.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _timing import add_size_options, by_size, print_table

ROOT = Path(__file__).resolve().parents[2]
PRODUCT = ROOT / "data/products/rv80e/design.toml"
#: the smoke size's seat: a coarse 12-pin housing ring at one crank angle
SMALL_RING = dict(r_inner=45.0, r_outer=50.0, thickness=24.0, z_p=12, z_c=11, R_p=40.0, ecc=1.5, E=210e3, nu=0.3,
                  angles=1, n_r=2, per_pitch=2)


def child(what: str) -> dict:
    """In the fresh process: import, build ``what`` ("product" or "ring") twice; the times and the seats' bits."""
    t0 = time.perf_counter()
    from rvtol.design import load_design
    from rvtol.elements import fe_seats
    from rvtol.models.stiffness.torsion_angle import ReducerStiffness
    t_import = time.perf_counter() - t0

    def build():
        if what == "ring":
            return [fe_seats.housing_ring_work(3e5, **SMALL_RING).compliance]
        chain = ReducerStiffness.from_design(load_design(PRODUCT)).chain
        return [chain.disc_seat_compliance, *chain.carrier_seat_compliance, chain.housing_ring_compliance]

    t1 = time.perf_counter()
    seats = build()
    t_first = time.perf_counter() - t1
    t2 = time.perf_counter()
    build()
    t_second = time.perf_counter() - t2
    return {"import": t_import, "first": t_first, "second": t_second, "seats": [float(c).hex() for c in seats]}


def run_child(what: str, cache: str) -> dict:
    env = {**os.environ, "RVTOL_CACHE_DIR": cache,
           "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    out = subprocess.run([sys.executable, __file__, "--child", what], check=True, capture_output=True, text=True,
                         env=env, cwd=ROOT).stdout
    return json.loads(out.strip().splitlines()[-1])


def main(size: str = "full") -> None:
    what = by_size(size, "ring", "product", "product")
    cold, warm = None, None
    for _ in range(by_size(size, 1, 1, 3)):
        with tempfile.TemporaryDirectory(prefix="rvtol-bench-fe-cache-") as d:
            c = run_child(what, d)
            w = run_child(what, d)
        if c["seats"] != w["seats"]:
            raise SystemExit(f"the warm cache's seats {w['seats']} differ from the cold build's {c['seats']}")
        cold = c if cold is None or c["first"] < cold["first"] else cold
        warm = w if warm is None or w["first"] < warm["first"] else warm
    label = "RV-80E product's chain" if what == "product" else "small housing ring"
    rows = [(f"{label}: first build, fresh process, cold cache", f"{cold['first']:.2f} s", "reference"),
            (f"{label}: first build, fresh process, warm cache", f"{warm['first']:.3f} s",
             f"{cold['first'] / warm['first']:.1f}× faster; seats bit-identical to the cold build's"),
            (f"{label}: second build in the same process (memo)", f"{warm['second']:.3f} s",
             f"{cold['first'] / warm['second']:.1f}× faster than the cold build"),
            ("imports of the fresh process (not timed above)", f"{cold['import']:.2f} s",
             f"cold; {warm['import']:.2f} s warm")]
    print_table(rows, ("measurement", "time", "ratio"))


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_size_options(ap)
    ap.add_argument("--child", choices=("product", "ring"), help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        print(json.dumps(child(a.child)))
    else:
        main(a.size)
