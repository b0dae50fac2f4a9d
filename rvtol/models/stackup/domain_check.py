"""Deviation domains checked: the moments derived in closed form against samples drawn inside the domain.

:func:`domain_from_table` reads one ``[[analysis.domain]]`` table (``kind`` = "plane", "cylinder" or
"clearance", :mod:`.domains`); :func:`check_domains` returns a :class:`DomainCheck`: per domain and
distribution (uniform, truncated normal) the derived mean and σ of each degree of freedom beside those
of ``n`` samples, with ``z = (sampled − derived) / standard error``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ...distributions import from_params
from ...errors import InputError
from ...options import read_options
from ...records import frame_records
from ...sampling import substream_seed
from . import domains as dm
from .assembly_tables import DOMAIN_KEYS, DomainTable

KINDS = tuple(DOMAIN_KEYS)
MIN_MOVING = 1000  # samples that must deviate from zero before a z test of the sampled moments means anything


def _mm_dist(p):
    d = from_params(p)
    p.finish()
    return d


def domain_from_table(t) -> tuple[str, object]:
    """``(name, domain)`` of one ``[[analysis.domain]]`` table (:class:`rvtol.params.Params`), read by its declared
    schema (:class:`.assembly_tables.DomainTable`: ``rvtol kinds domain``)."""
    o = read_options(DomainTable, t)
    t.finish()
    for k in ("t1", "t2", "t", "clearance", "length", "width", "hole", "shaft"):
        if getattr(o, k) is not None and k not in DOMAIN_KEYS[o.kind]:
            raise t.error(k, f"a domain of kind {o.kind!r} takes no {k!r} (it takes: {', '.join(DOMAIN_KEYS[o.kind])})")
    for k in DOMAIN_KEYS[o.kind]:
        if getattr(o, k) is None:
            raise t.error(k, "missing required key")
    name = o.kind if o.name is None else o.name
    try:
        if o.kind == "plane":
            d = dm.ParallelPlaneZone(o.t1, o.t2, o.length, o.width, o.k)
        elif o.kind == "cylinder":
            d = dm.CylindricalZone(o.t, o.length, o.k)
        else:
            d = dm.ClearanceFit(o.clearance, _mm_dist(o.hole), _mm_dist(o.shaft), o.length, o.k)
    except InputError as exc:  # a domain's own check (e.g. t1 < t2): name the table it came from
        raise exc.located(file=t.file, key=t.key) from None
    return name, d


def moments_with_errors(x: np.ndarray) -> tuple[float, float, float, float]:
    """Sample mean and σ with their standard errors (σ's from the sample 4th moment, any distribution)."""
    n = len(x)
    m = float(x.mean())
    c = x - m
    v = float(np.mean(c * c))
    s = float(np.sqrt(v * n / (n - 1)))
    se_v = float(np.sqrt(max(np.mean(c**4) - v * v, 0.0) / n))
    return m, s, s / np.sqrt(n), se_v / (2 * s) if s > 0 else 0.0


def describe_domain(d) -> str:
    if isinstance(d, dm.ParallelPlaneZone):
        return (f"planar face {d.L:g} × {d.W:g} mm between w = {d.t1 * 1e3:g} and {d.t2 * 1e3:g} µm "
                f"(exact domain |w−m| + |α|W/2 + |β|L/2 ≤ Δt/2)")
    if isinstance(d, dm.CylindricalZone):
        return f"axis of length {d.L:g} mm in a cylindrical zone ⌀{d.t * 1e3:g} µm"
    return (f"shaft in hole, nominal clearance {d.c0 * 1e3:g} µm, hole {d.hole.describe('mm')}, "
            f"shaft {d.shaft.describe('mm')}, engagement {d.L:g} mm")


@dataclass
class DomainMoments:
    """One domain: ``moments`` per distribution and degree of freedom; ``few``: distribution -> samples that
    deviate from zero where they are too few for a z test; ``samples``: uniform samples for the figure
    (planar zones); ``worst_case``: a clearance fit's worst radial offset and tilt."""

    name: str
    domain: object
    moments: pd.DataFrame
    few: dict = field(default_factory=dict)
    samples: np.ndarray | None = None
    worst_case: dict | None = None

    @property
    def description(self) -> str:
        return describe_domain(self.domain)

    def plot(self):
        from ...plotting.stackup import planar_domain

        return planar_domain(self.domain, self.samples)

    def summary(self) -> dict:
        out = {"domain": self.description, "moments": frame_records(self.moments)}
        if self.few:
            out["samples_deviating"] = self.few
        if self.worst_case is not None:
            out["worst_case"] = self.worst_case
        return out


@dataclass
class DomainCheck:
    n: int
    domains: list[DomainMoments]

    def to_frame(self) -> pd.DataFrame:
        return pd.concat([d.moments.assign(domain=d.name) for d in self.domains], ignore_index=True)

    def summary(self) -> dict:
        return {d.name: d.summary() for d in self.domains}

    def plot(self, domain: str | None = None):
        """The report's figure of a planar zone ``domain`` (default: the first): its uniform samples, the exact
        domain and its box.  Other domains have no figure (the report shows their moments as tables): naming one
        is an error."""
        from .domains import ParallelPlaneZone

        planar = [d for d in self.domains if isinstance(d.domain, ParallelPlaneZone)]
        if domain is None:
            if not planar:
                raise ValueError("no planar zone among the domains: no figure (the moments are tables)")
            return planar[0].plot()
        for d in self.domains:
            if d.name == domain:
                if d not in planar:
                    raise ValueError(f"domain {domain!r} is not a planar zone: no figure (its moments are a table)")
                return d.plot()
        raise ValueError(f"no domain {domain!r} (domains: {', '.join(d.name for d in self.domains)})")


def domain_moments(name: str, d, n: int, seed: int, figure_seed: int | None = None) -> DomainMoments:
    """Derived against sampled moments of the domain ``d`` (``seed``: of the ``n`` samples; ``figure_seed``:
    of the 3000 uniform samples a planar zone's figure shows)."""
    rows, few = [], {}
    for dist in dm.DISTRIBUTIONS:
        E = d.sample(n, dist, seed=seed)
        mean, cov = d.mean(dist), d.cov(dist)
        moving = int(np.count_nonzero(np.any(E != 0.0, axis=1)))
        testable = moving >= MIN_MOVING
        if not testable:
            few[dist] = moving
        for j in d.dofs:
            f = 1e3 if j < 3 else 1e6
            m_s, s_s, se_m, se_s = moments_with_errors(E[:, j])
            sd = np.sqrt(cov[j, j])
            rows.append({"distribution": dist, "dof": dm.DOF[j], "unit": "µm" if j < 3 else "µrad",
                         "mean derived": mean[j] * f, "mean sampled": m_s * f,
                         "z(mean)": (m_s - mean[j]) / se_m if se_m > 0 and testable else np.nan,
                         "σ derived": sd * f, "σ sampled": s_s * f,
                         "z(σ)": (s_s - sd) / se_s if se_s > 0 and testable else np.nan})
    out = DomainMoments(name, d, pd.DataFrame(rows), few)
    if isinstance(d, dm.ParallelPlaneZone):
        out.samples = d.sample(3000, "uniform", seed=figure_seed)
    if isinstance(d, dm.ClearanceFit):
        out.worst_case = d.worst_case()
    return out


def check_domains(domains, n: int, seed: int) -> DomainCheck:
    """:func:`domain_moments` of each ``(name, domain)``; the i-th domain's samples from the sub-stream
    ``("stackup_domains", i)`` of ``seed``."""
    return DomainCheck(n, [domain_moments(name, d, n, substream_seed(seed, "stackup_domains", i), seed)
                           for i, (name, d) in enumerate(domains)])
