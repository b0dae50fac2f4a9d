"""Declarative description of an assembly process: KCs, datum flow chains, steps.

File format (``data/assemblies/*.toml``)::

    [assembly]
    name = "bx40e_2d"
    title = "..."
    source = "doc 002, case study"
    components = ["x"]          # angular components per KC: ["x"] (2-D) or ["x", "y", "z"] (3-D)
    angle_unit = "mrad"         # unit of the sigmas written in this file

    [weights]                   # the LQR weights of doc 002
    accuracy = 10               # Q: Q(N) = Q·I on the final observation; "inf" = terminal constraint
    effort_adjustable = 5       # R(k) entry of a KC that may be adjusted at step k
    effort_locked = 1000        # R(k) entry of every other KC (not yet installed, or locked)

    [measurement]               # what the state estimator (a Kalman filter) assumes
    noise_sigma = 0.0           # σ of the measurement noise v(k)
    prior_sigma = 1.0           # σ of a part's angular error Δθ (prior; a KC may override it)

    [[chain]]                   # one datum flow chain, from the datum (KC0) outwards
    name = "DFC1"
    kcs = ["KC1", "KC2"]

    [[kc]]
    name = "KC1"
    part = "Crankshaft 1"       # the part whose installation creates this KC
    error = "dtheta_1"          # factor name of its angular error (component letter appended in 3-D)
    W = [[1.0]]                 # d×d: part frame -> datum frame (default: identity)

    [[step]]                    # in assembly order
    install = "KC1"
    measure = ["KC1"]           # KCs measured after the installation (default: the one installed)
    adjust = ["KC1"]            # KCs that may be adjusted at this step (default: all installed)

    [[observation]]             # optional: rows of C(N), the final KC relationships; default: each KC vs datum
    name = "KC1"
    terms = { KC1 = 1.0 }

Each table is read by its declared schema (:mod:`.description_tables`; ``rvtol kinds adjustment_kc`` lists a
table's keys).  The propagation along a chain is doc 002's δ_n = δ_{n-1} + W_n Δθ_n: the
error of part n reaches its own KC and every KC after it in the chain
through W_n, which makes F block lower-triangular per chain.  The
adjustment of a KC moves the state the way its part's error does (doc 002:
"B(k) and F(k) are structurally identical"), so B = [F columns of all KCs].
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ... import units
from ...options import read_options
from ...params import Params, check_number, read_toml
from .description_tables import (AdjustmentHead, AdjustmentKCTable, AdjustmentStepTable, ChainTable,
                                 MeasurementTable, ObservationTable, WeightsTable)

COMPONENT_NAMES = ("x", "y", "z")


@dataclass(frozen=True)
class KC:
    name: str
    part: str
    error: str
    W: np.ndarray  # d×d
    prior_sigma: float  # rad
    chain: str
    source: str = ""


@dataclass(frozen=True)
class Step:
    install: str
    measure: tuple[str, ...]
    adjust: tuple[str, ...]


@dataclass(frozen=True)
class Observation:
    name: str
    terms: tuple[tuple[str, float], ...]


@dataclass(frozen=True)
class AssemblyDescription:
    """A validated assembly description (angles in base units, rad)."""

    name: str
    title: str
    components: tuple[str, ...]
    kcs: tuple[KC, ...]
    chains: tuple[tuple[str, tuple[str, ...]], ...]
    steps: tuple[Step, ...]
    observations: tuple[Observation, ...]
    accuracy: float  # Q (math.inf: terminal constraint)
    effort_adjustable: float
    effort_locked: float
    noise_sigma: float  # rad
    source: str = ""
    file: str | None = field(default=None, compare=False)

    # -- sizes and names --------------------------------------------------------
    @property
    def d(self) -> int:
        return len(self.components)

    @property
    def n_kc(self) -> int:
        return len(self.kcs)

    @property
    def n_state(self) -> int:
        return self.n_kc * self.d

    @property
    def n_steps(self) -> int:
        return len(self.steps)

    def kc_index(self, name: str) -> int:
        return [k.name for k in self.kcs].index(name)

    def suffixed(self, base: str) -> list[str]:
        """``base`` per angular component: ``[base]`` in 2-D, ``[base+'x', base+'y', ...]`` in 3-D."""
        return [base] if self.d == 1 else [f"{base}{c}" for c in self.components]

    def state_names(self) -> list[str]:
        return [n for k in self.kcs for n in self.suffixed(k.name)]

    def part_error_names(self) -> list[str]:
        """Factor names of the part errors, in installation order (step by step)."""
        return [n for s in self.steps for n in self.suffixed(self.kcs[self.kc_index(s.install)].error)]

    def noise_names(self) -> list[str]:
        """Factor names of the measurement noise, step by step: ``v{step}_{KC}{component}``."""
        return [n for i, s in enumerate(self.steps, 1) for m in s.measure for n in self.suffixed(f"v{i}_{m}")]

    def observation_names(self) -> list[str]:
        return [n for o in self.observations for n in self.suffixed(o.name)]

    def rows(self, kc: str) -> slice:
        i = self.kc_index(kc)
        return slice(i * self.d, (i + 1) * self.d)

    # -- matrices of the state-space model ----------------------------------------
    def F_full(self) -> np.ndarray:
        """``δ = F_full · Δθ`` (all parts, KC order): W_n on KC n and every later KC of its chain."""
        F = np.zeros((self.n_state, self.n_state))
        for _, kcs in self.chains:
            for a, name in enumerate(kcs):
                W = self.kcs[self.kc_index(name)].W
                for later in kcs[a:]:
                    F[self.rows(later), self.rows(name)] = W
        return F

    def F_step(self, k: int) -> np.ndarray:
        """F(k): the columns of the part installed at step k (n_state × d)."""
        return self.F_full()[:, self.rows(self.steps[k].install)]

    def B_step(self, k: int) -> np.ndarray:
        """B(k) = F_full: the adjustment of each KC acts like its part's error (doc 002)."""
        return self.F_full()

    def C_step(self, k: int) -> np.ndarray:
        """C(k): rows that read the measured KCs of step k."""
        rows = [np.eye(self.n_state)[self.rows(m)] for m in self.steps[k].measure]
        return np.vstack(rows)

    def C_final(self) -> np.ndarray:
        """C(N): the final KC relationships the accuracy weight acts on."""
        rows = []
        for o in self.observations:
            blk = np.zeros((self.d, self.n_state))
            for kc, coef in o.terms:
                blk[:, self.rows(kc)] += coef * np.eye(self.d)
            rows.append(blk)
        return np.vstack(rows)

    def R_step(self, k: int) -> np.ndarray:
        """R(k): effort_adjustable on the KCs adjustable at step k, effort_locked elsewhere."""
        adjustable = set(self.steps[k].adjust)
        r = [self.effort_adjustable if kc.name in adjustable else self.effort_locked
             for kc in self.kcs for _ in range(self.d)]
        return np.diag(r)

    def prior_cov(self, k: int) -> np.ndarray:
        """Prior covariance of the error of the part installed at step k (d×d)."""
        return self.kcs[self.kc_index(self.steps[k].install)].prior_sigma ** 2 * np.eye(self.d)

    def noise_cov(self, k: int) -> np.ndarray:
        m = len(self.steps[k].measure) * self.d
        return self.noise_sigma ** 2 * np.eye(m)

    def with_weights(self, accuracy: float | None = None, effort_adjustable: float | None = None,
                     effort_locked: float | None = None) -> "AssemblyDescription":
        from dataclasses import replace

        return replace(self, accuracy=self.accuracy if accuracy is None else accuracy,
                       effort_adjustable=self.effort_adjustable if effort_adjustable is None else effort_adjustable,
                       effort_locked=self.effort_locked if effort_locked is None else effort_locked)

    def to_frame(self):
        """One row per step: what is installed, measured, adjustable."""
        import pandas as pd

        return pd.DataFrame({
            "step": range(1, self.n_steps + 1),
            "install": [f"{s.install} ({self.kcs[self.kc_index(s.install)].part})" for s in self.steps],
            "measured": [", ".join(s.measure) for s in self.steps],
            "adjustable (R = %g)" % self.effort_adjustable: [", ".join(s.adjust) for s in self.steps],
        })


# --------------------------------------------------------------------------- loading
def load_assembly(path: str | Path) -> AssemblyDescription:
    data, _ = read_toml(path)
    return assembly_from_table(data, file=str(path))


def weight_of(v, error, name: str, allow_inf: bool = False) -> float:
    """The value ``v`` of the weight ``name`` checked: a number >= 0, or ``"inf"`` (or TOML ``inf``) where
    ``allow_inf``; ``error(name, reason)`` raises the located error."""
    if allow_inf and (v == "inf" or (isinstance(v, float) and v == math.inf)):
        return math.inf
    if isinstance(v, str):
        what = 'a number or "inf"' if allow_inf else "a number"
        raise error(name, f"expected {what}, got the string {v!r}")
    return check_number(v, error, name, nonnegative=True)


def _read(cls, p: Params):
    """The table ``p`` read by its declared schema ``cls`` (:mod:`.description_tables`); no key left unread."""
    o = read_options(cls, p)
    p.finish()
    return o


def assembly_from_table(data: dict, *, file: str | None = None) -> AssemblyDescription:
    root = Params(data, file=file)
    head = root.sub("assembly")
    h = _read(AdjustmentHead, head)
    comps = tuple(h.components)
    if len(set(comps)) != len(comps) or not set(comps) <= set(COMPONENT_NAMES):
        raise head.error("components", f"components must be distinct names out of {', '.join(COMPONENT_NAMES)}")
    aunit = head.canonical_unit("angle_unit", h.angle_unit, dimension="angle")
    d = len(comps)

    w = root.sub("weights")
    weights = _read(WeightsTable, w)
    accuracy = weight_of(weights.accuracy, w.error, "accuracy", allow_inf=True)
    m = _read(MeasurementTable, root.sub("measurement", {}))

    chains = _chains(root)
    kc_chain = {k: cname for cname, kcs in chains for k in kcs}
    kcs = _kcs(root, kc_chain, d, m.prior_sigma, aunit)
    names = [k.name for k in kcs]        # the state vector's KC order: the [[kc]] order
    steps = _steps(root, names, dict(chains), kc_chain)
    obs = _observations(root, names)
    root.finish()
    return AssemblyDescription(h.name, h.name if h.title is None else h.title, comps, tuple(kcs), tuple(chains),
                               tuple(steps), tuple(obs), accuracy, weights.effort_adjustable, weights.effort_locked,
                               float(units.to_base(m.noise_sigma, aunit)), h.source, file)


def _chains(root: Params) -> list[tuple[str, tuple[str, ...]]]:
    """The ``[[chain]]`` tables: ``(name, KCs)``, each KC in one chain."""
    chains: list[tuple[str, tuple[str, ...]]] = []
    kc_chain: dict[str, str] = {}
    for t in root.tables("chain"):
        c = _read(ChainTable, t)
        for k in c.kcs:
            if k in kc_chain:
                raise t.error("kcs", f"KC {k!r} is already in chain {kc_chain[k]!r} (a KC belongs to one chain)")
            kc_chain[k] = c.name
        chains.append((c.name, tuple(c.kcs)))
    if not chains:
        raise root.error("chain", "an assembly needs at least one [[chain]]")
    return chains


def _kcs(root: Params, kc_chain: dict[str, str], d: int, prior: float, aunit: str) -> list[KC]:
    """The ``[[kc]]`` tables, each of a chain's KCs once, with distinct error factors."""
    kcs: list[KC] = []
    errors_seen: set[str] = set()
    for t in root.tables("kc"):
        o = _read(AdjustmentKCTable, t)
        if o.name in [k.name for k in kcs]:
            raise t.error("name", f"duplicate KC name {o.name!r}")
        if o.name not in kc_chain:
            raise t.error("name", f"KC {o.name!r} is in no [[chain]]")
        if o.error in errors_seen:
            raise t.error("error", f"duplicate error factor name {o.error!r}")
        errors_seen.add(o.error)
        W = _matrix(t, "W", o.W, d)
        ps = prior if o.prior_sigma is None else o.prior_sigma
        kcs.append(KC(o.name, o.name if o.part is None else o.part, o.error, W, float(units.to_base(ps, aunit)),
                      kc_chain[o.name], o.source))
    missing = [k for k in kc_chain if k not in [c.name for c in kcs]]
    if missing:
        raise root.error("kc", f"chain KC {missing[0]!r} has no [[kc]] table")
    return kcs


def _steps(root: Params, names: list[str], chains: dict[str, tuple[str, ...]], kc_chain: dict[str, str]) -> list[Step]:
    """The ``[[step]]`` tables in assembly order: every KC installed once, after the KC before it in its chain."""
    steps: list[Step] = []
    installed: list[str] = []
    for t in root.tables("step"):
        o = _read(AdjustmentStepTable, t)
        inst = o.install
        if inst not in names:
            raise t.error("install", f"unknown KC {inst!r} (known: {', '.join(names)})")
        if inst in installed:
            raise t.error("install", f"KC {inst!r} is installed twice")
        chain = chains[kc_chain[inst]]
        pos = chain.index(inst)
        if pos > 0 and chain[pos - 1] not in installed:
            raise t.error("install", f"KC {inst!r} is installed before {chain[pos - 1]!r}, which precedes it "
                                     f"in chain {kc_chain[inst]!r}")
        installed.append(inst)
        meas = (inst,) if o.measure is None else tuple(o.measure)
        adj = tuple(installed) if o.adjust is None else tuple(o.adjust)
        for key, group in (("measure", meas), ("adjust", adj)):
            for k in group:
                if k not in names:
                    raise t.error(key, f"unknown KC {k!r} (known: {', '.join(names)})")
                if k not in installed:
                    raise t.error(key, f"KC {k!r} is not installed yet at this step")
            if len(set(group)) != len(group):
                raise t.error(key, "a KC is named twice")
        steps.append(Step(inst, meas, adj))
    if not steps:
        raise root.error("step", "an assembly needs at least one [[step]]")
    if set(installed) != set(names):
        left = [n for n in names if n not in installed]
        raise root.error("step", f"KC {left[0]!r} is never installed")
    return steps


def _observations(root: Params, names: list[str]) -> list[Observation]:
    """The ``[[observation]]`` tables (default: each KC against the datum)."""
    obs: list[Observation] = []
    for t in root.tables("observation"):
        o = _read(ObservationTable, t)
        for k in o.terms:
            if k not in names:
                raise t.error(f"terms.{k}", f"unknown KC {k!r} (known: {', '.join(names)})")
        if not o.terms or all(c == 0 for c in o.terms.values()):
            raise t.error("terms", "an observation needs at least one non-zero term")
        if o.name in [x.name for x in obs]:
            raise t.error("name", f"duplicate observation name {o.name!r}")
        obs.append(Observation(o.name, tuple(o.terms.items())))
    return obs or [Observation(n, ((n, 1.0),)) for n in names]


def _matrix(t: Params, key: str, rows: list | None, d: int) -> np.ndarray:
    """The d×d matrix ``rows`` of the key ``key`` (default: identity), non-singular."""
    if rows is None:
        return np.eye(d)
    if len(rows) != d:
        raise t.error(key, f"expected a {d}×{d} matrix (list of {d} rows)")
    W = np.array([Params({f"{key}[{i}]": r}, file=t.file, key=t.key).floats(f"{key}[{i}]", length=d)
                  for i, r in enumerate(rows)])
    if abs(np.linalg.det(W)) < 1e-9:
        raise t.error(key, "W is singular (a part's error must reach its KC)")
    return W
