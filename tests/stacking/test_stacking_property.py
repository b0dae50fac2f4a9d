"""The guard that finds the next silent wrong answer in the stack-up conventions (issue 37): random small stacks —
linear and mildly non-linear (squares, a product of two factors), normal, uniform, asymmetric triangular and
lognormal factors, shifted processes inside drawing limits, random correlation matrices (from random Cholesky
factors) — on which every row that ``compare_conventions`` prints either agrees with a brute-force Monte Carlo
within what the row claims, or says in its own note what it leaves out.

References, nothing of rvtol's sampling, distributions or formula engine in them: NumPy's own sampler (correlated
standard normals through a Cholesky factor, then each factor's inverse CDF from SciPy laws built here, the output
evaluated here as a polynomial), n = 40 000, each comparison within Z = 4.5 of its standard errors (derived from n
and the sample's own moments); and, where the output's moments are a closed computation, the exact ones: for
independent factors the central moments of y by expanding the polynomial (SymPy) over each factor's central moments
(closed forms and exact quadratures), over correlated normals a tensor Gauss–Hermite rule (exact for these
polynomials) — the heavy tails of a squared
lognormal make a sample's skewness (and its error) unreliable.  The claims checked per row:

* worst case (arithmetic): linear — every reference sample whose factors lie inside their bands lies inside it
  (exact, no error); curved — the row says it is linearised;
* worst case (true extreme): every such sample inside it where it says "guaranteed", else it says "not guaranteed";
* RSS, 1.5σ shift: the σ of the same linear stack of normals N(band centre, (t/3)²) (or t/(3 Cpk)) correlated by
  the spec's normal scores; MRSS: its factor times the RSS; statistical, 6σ static: the mean and σ of the
  output; 6σ dynamic: the σ of the stack with each deviation from the mean stretched by 1/(1 − k) — all for a
  linear output (a curved one: the row says it is linearised);
* second order (moments): the mean always (exact for a quadratic), σ unless the note says "σ approximate",
  the skewness where the method claims it exact (no "left out", no "independent" in its note);
* second order tails: for a normal output, the interval holds coverage(3) of the reference within its
  binomial error; otherwise the row says it is a four-moment curve;
* Monte Carlo rows: the mean, σ and range of rvtol's own sample, which a two-sample Kolmogorov–Smirnov test
  (p > 1e-6) does not tell from the reference's.

A row the test does not know fails it: a new convention must say here what it claims.
"""
import math
import re

import numpy as np
import pytest
import sympy
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy import special, stats

from rvtol.distributions import Distribution, coverage
from rvtol.mc import Evaluator, run_monte_carlo
from rvtol.models.formula.model import FormulaModel
from rvtol.spec import Factor, ToleranceSpec
from rvtol.stacking.beside_monte_carlo import compare_conventions

Z = 4.5
N_REF = 40_000
N_MC = 2000
U_EPS = 2.0 ** -53


@st.composite
def factors(draw, i):
    """(rvtol Factor, the SciPy law built here, the law's own record for its raw moments)."""
    kind = draw(st.sampled_from(("normal", "uniform", "triangular", "lognormal")))
    centre = draw(st.floats(-5.0, 5.0))
    s = draw(st.floats(0.05, 1.0))                      # a spread
    shifted = draw(st.booleans())
    name = f"x{i}"
    if kind == "normal":
        shift = draw(st.floats(-1.0, 1.0)) * s if shifted else 0.0
        d = Distribution.make("normal", mean=centre, sigma=s, shift=shift)
        limits = (centre - 3 * s, centre + 3 * s) if shifted else None     # a process off-centre in its drawing band
        return (Factor(name, "mm", d, nominal=centre if shifted else None, limits=limits),
                stats.norm(centre + shift, s), ("normal", centre + shift, s))
    if kind == "uniform":
        shift = draw(st.floats(-0.3, 0.3)) * s if shifted else 0.0
        d = Distribution.make("uniform", lower=centre - s, upper=centre + s, shift=shift)
        lo, hi = centre - s + shift, centre + s + shift
        return (Factor(name, "mm", d, nominal=centre if shifted else None,
                       limits=(centre - 1.5 * s, centre + 1.5 * s) if shifted else None),
                stats.uniform(lo, hi - lo), ("uniform", lo, hi))
    if kind == "triangular":
        lo, hi = centre - s, centre + s
        mode = min(lo + (hi - lo) * draw(st.floats(0.0, 1.0)), hi)
        d = Distribution.make("triangular", lower=lo, upper=hi, mode=mode)
        return (Factor(name, "mm", d), stats.triang((mode - lo) / (hi - lo), loc=lo, scale=hi - lo),
                ("triangular", lo, mode, hi))
    shape = draw(st.floats(0.1, 0.6))
    shift = draw(st.floats(-2.0, 2.0)) if shifted else 0.0
    d = Distribution.make("lognormal", median=s, shape=shape, shift=shift)
    return Factor(name, "mm", d), stats.lognorm(shape, loc=shift, scale=s), ("lognormal", s, shape, shift)


@st.composite
def stacks(draw):
    k = draw(st.integers(2, 4))
    drawn = [draw(factors(i)) for i in range(k)]
    fs = tuple(d[0] for d in drawn)
    laws = [d[1] for d in drawn]
    records = [d[2] for d in drawn]
    R = None
    if draw(st.booleans()):
        L = np.tril(np.array(draw(st.lists(st.floats(-1.0, 1.0), min_size=k * k, max_size=k * k))).reshape(k, k))
        L[np.diag_indices(k)] = np.abs(np.diag(L)) + 0.3      # a valid Cholesky factor, not near-singular
        C = L @ L.T
        R = C / np.sqrt(np.outer(np.diag(C), np.diag(C)))
        R[np.diag_indices(k)] = 1.0
    a = np.array(draw(st.lists(st.floats(0.2, 2.0), min_size=k, max_size=k))) * \
        np.array(draw(st.lists(st.sampled_from((-1.0, 1.0)), min_size=k, max_size=k)))
    sd = np.array([law.std() for law in laws])
    c = np.zeros(k)
    prod = None
    # mild curvature, none or at least 2 % of the linear effect at one σ (a square's ≤ 0.3 of it; a product of two)
    mild = st.one_of(st.just(0.0), st.floats(0.02, 0.3), st.floats(-0.3, -0.02))
    if draw(st.booleans()):
        c = np.array(draw(st.lists(mild, min_size=k, max_size=k))) * np.abs(a) / sd
        p, q = draw(st.sampled_from([(i, j) for i in range(k) for j in range(i + 1, k)]))
        e = draw(mild) * min(abs(a[p]) / sd[q], abs(a[q]) / sd[p])
        prod = (p, q, e) if e else None
    seed = draw(st.integers(0, 2 ** 31 - 1))
    return ToleranceSpec("random stack", fs, R), laws, records, a, c, prod, seed


def formula_and_function(spec, a, c, prod):
    """The output y = Σ aᵢ dᵢ + Σ cᵢ dᵢ² + e·d_p·d_q, dᵢ = xᵢ − nominalᵢ: rvtol's formula text and NumPy's own."""
    n = [float(f.nominal_value) for f in spec.factors]
    terms = [f"{float(a[i])!r}*(x{i} - {n[i]!r})" for i in range(len(a))]
    terms += [f"{float(c[i])!r}*(x{i} - {n[i]!r})**2" for i in range(len(a)) if c[i]]
    if prod:
        p, q, e = prod
        terms.append(f"{float(e)!r}*(x{p} - {n[p]!r})*(x{q} - {n[q]!r})")

    def f(X):
        D = X - np.array(n)
        y = D @ a + (D ** 2) @ c
        if prod:
            y = y + prod[2] * D[:, prod[0]] * D[:, prod[1]]
        return y
    return " + ".join(terms), f


# ----------------------------------------------------------------------------------------------- exact moments
GL_U, GL_W = np.polynomial.legendre.leggauss(8)
GL_U, GL_W = 0.5 * (GL_U + 1.0), 0.5 * GL_W          # on [0, 1]: exact for polynomials of degree ≤ 15
GH_Z, GH_W = np.polynomial.hermite_e.hermegauss(80)
GH_W = GH_W / math.sqrt(2 * math.pi)


def law_mean(record):
    kind = record[0]
    if kind == "normal":
        return record[1]
    if kind == "uniform":
        return 0.5 * (record[1] + record[2])
    if kind == "triangular":
        return (record[1] + record[2] + record[3]) / 3.0
    _, median, shape, shift = record
    return shift + median * math.exp(shape * shape / 2)


def central_moment(record, j):
    """E[(x − μ)ʲ] of a law from its own record, computed without cancellation: closed forms (normal, uniform), the
    triangle's two linear pieces each as (width/(b − a)) ∫₀¹ (x(u) − μ)ʲ 2u du by Gauss–Legendre (exact), the
    lognormal's m(e^{sZ} − e^{s²/2}) by Gauss–Hermite over Z (an entire function)."""
    kind, mu = record[0], law_mean(record)
    if kind == "normal":
        return 0.0 if j % 2 else record[2] ** j * math.prod(range(j - 1, 0, -2))
    if kind == "uniform":
        h = 0.5 * (record[2] - record[1])
        return 0.0 if j % 2 else h ** j / (j + 1)
    if kind == "triangular":
        _, a, c, b = record
        return sum(width / (b - a) * float(GL_W @ ((x - mu) ** j * 2 * GL_U))
                   for width, x in ((c - a, a + (c - a) * GL_U), (b - c, b - (b - c) * GL_U)))
    _, median, shape, _ = record
    return float(GH_W @ (median * (np.exp(shape * GH_Z) - math.exp(shape * shape / 2))) ** j)


def exact_moments(records, R, nominal, a, c, prod):
    """Mean, σ and skewness of the output, exactly, where that is a closed computation: the factors a correlation
    links all normal (the others independent); None otherwise.  y is expanded about the factors' means
    (dᵢ = μᵢ − nominalᵢ + wᵢ) and its central moments taken directly, so nothing cancels: E[Π wᵢ^eᵢ] is the
    product of the independent factors' central moments and, over the correlated normals, a tensor Gauss–Hermite
    rule of 6 nodes (exact to degree 11)."""
    k = len(records)
    linked = [] if R is None else [i for i in range(k) if np.any(np.delete(R[i], i) != 0.0)]
    if any(records[i][0] != "normal" for i in linked):
        return None
    w = sympy.symbols(f"w0:{k}")
    shift = [law_mean(r) - nominal[i] for i, r in enumerate(records)]
    d = [shift[i] + w[i] for i in range(k)]
    y = sum(float(a[i]) * d[i] + float(c[i]) * d[i] ** 2 for i in range(k))
    if prod:
        y += float(prod[2]) * d[prod[0]] * d[prod[1]]
    cm = [[1.0] + [central_moment(r, j) for j in range(1, 7)] for r in records]
    if linked:
        z, wt = np.polynomial.hermite_e.hermegauss(6)
        wt = wt / math.sqrt(2 * math.pi)
        n = len(linked)
        grid = np.array(np.meshgrid(*[z] * n, indexing="ij")).reshape(n, -1).T
        W = np.prod(np.array(np.meshgrid(*[wt] * n, indexing="ij")).reshape(n, -1), axis=0)
        block = (grid @ np.linalg.cholesky(R[np.ix_(linked, linked)]).T) * np.array([records[i][2] for i in linked])

    def expect(poly):
        total = 0.0
        for mon, coef in poly.terms():
            term = float(coef) * math.prod(cm[m][e] for m, e in enumerate(mon) if m not in linked)
            if linked:
                term *= float(W @ np.prod([block[:, q] ** mon[m] for q, m in enumerate(linked)], axis=0))
            total += term
        return total

    y = sympy.Poly(y, *w, domain="RR")
    mean = expect(y)
    m2, m3 = expect((y - mean) ** 2), expect((y - mean) ** 3)
    return mean, math.sqrt(m2), m3 / m2 ** 1.5


# ----------------------------------------------------------------------------------------------- the sampler
def normal_scores(R, k, n, rng):
    Zs = rng.standard_normal((n, k))
    return Zs if R is None else Zs @ np.linalg.cholesky(R).T


def reference_sample(laws, R, n, rng):
    U = np.clip(special.ndtr(normal_scores(R, len(laws), n, rng)), U_EPS, 1 - U_EPS)
    return np.column_stack([law.ppf(U[:, i]) for i, law in enumerate(laws)])


def mean_sd_errors(y):
    """The sample's mean and σ with their standard errors (σ's by the delta method: √((m₄/σ⁴ − 1)/(4n)) σ)."""
    n = len(y)
    m, s = float(np.mean(y)), float(np.std(y, ddof=1))
    kurt = float(np.mean((y - m) ** 4)) / s ** 4
    return m, s, s / math.sqrt(n), s * math.sqrt(max(kurt - 1.0, 0.0) / (4 * n))


def skewness_error(y):
    """Sample skewness and its standard error by its influence function (z³ − γ) − 3z − (3/2)γ(z² − 1)."""
    z = (y - y.mean()) / y.std()
    g = float(np.mean(z ** 3))
    infl = z ** 3 - g - 3 * z - 1.5 * g * (z ** 2 - 1)
    return g, float(np.std(infl)) / math.sqrt(len(y))


def close(value, ref, se, what, slack=0.0):
    assert abs(value - ref) <= Z * se + slack + 1e-9 * max(abs(ref), 1.0), (what, value, ref, se)


@settings(max_examples=10, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(stacks())
def test_every_convention_agrees_with_a_brute_force_monte_carlo_or_says_what_it_leaves_out(case):
    spec, laws, records, a, c, prod, seed = case
    k = len(spec)
    curved = bool(np.any(c) or prod)
    formula, f = formula_and_function(spec, a, c, prod)
    model = FormulaModel({"y": formula}, spec.names, ["mm"] * k, checked=False)
    mc = run_monte_carlo(model, spec, N_MC, "random", seed, progress=False)
    res = compare_conventions(model, spec, ["y"], mc, Evaluator(), six_sigma=(2.0, 1.5), max_evaluations=600,
                              starts=2).outputs["y"]
    rows = {r["convention"]: r for r in res.conventions.frame.to_dict("records")}
    rng = np.random.default_rng(seed)
    X = reference_sample(laws, spec.correlation, N_REF, rng)
    y = f(X)
    m, s, se_m, se_s = mean_sd_errors(y)
    nominal = np.array([f_.nominal_value for f_ in spec.factors])
    exact = exact_moments(records, spec.correlation, nominal, a, c, prod)
    # the bands, centres and half bands as the drawing gives them; the means of the laws built here
    lo = np.array([f_.band[0] for f_ in spec.factors])
    hi = np.array([f_.band[1] for f_ in spec.factors])
    cen, t = 0.5 * (lo + hi), 0.5 * (hi - lo)
    mu = np.array([law.mean() for law in laws])
    y_c = float(a @ (cen - nominal))
    inside = np.all((X >= lo) & (X <= hi), axis=1)
    R = spec.correlation

    def mean_and_sigma(r, what):   # against the exact moments where they are known, else the sample
        if exact is not None:
            assert r["centre"] == pytest.approx(exact[0], rel=1e-7, abs=1e-9 * exact[1]), (what, r["centre"], exact)
            assert r["sigma"] == pytest.approx(exact[1], rel=1e-7), (what, r["sigma"], exact)
        else:
            close(r["centre"], m, se_m, what + " mean")
            close(r["sigma"], s, se_s, what + " σ")

    def normal_stack_sd(sig):   # the σ of Σ aᵢ Nᵢ(0, sigᵢ²) correlated by the normal scores R, sampled
        return mean_sd_errors(normal_scores(R, k, N_REF, rng) @ (a * sig))[1:4:2]

    def linearised_or(name, check):
        r = rows[name]
        if curved:
            assert "linearised at the nominal point" in r["note"], (name, r["note"])
        else:
            check(r)

    seen = set()

    def row(prefix):
        names = [n for n in rows if n.startswith(prefix)]
        seen.update(names)
        return names

    for name in row("worst case (arithmetic)"):
        def wc(r):
            assert r["low"] == pytest.approx(y_c - np.abs(a) @ t) and r["high"] == pytest.approx(y_c + np.abs(a) @ t)
            assert np.all((y[inside] >= r["low"] - 1e-9) & (y[inside] <= r["high"] + 1e-9))
        linearised_or(name, wc)
    for name in row("worst case (true extreme)"):
        r = rows[name]
        if "not guaranteed" not in r["note"]:
            assert "guaranteed" in r["note"] and np.all((y[inside] >= r["low"] - 1e-9) & (y[inside] <= r["high"] + 1e-9))
    rss_sigma = rows["RSS"]["sigma"]
    for name in row("RSS"):
        def rss(r):
            ref, err = normal_stack_sd(t / 3.0)
            close(r["sigma"], ref, err, name)
            assert r["centre"] == pytest.approx(y_c, abs=1e-9)
        linearised_or(name, rss)
    for name in row("MRSS"):
        factor = 1.5 if name == "MRSS, Bender" else float(re.search(r"C_f = (\S+) ×", rows[name]["note"]).group(1))
        assert rows[name]["half_width"] == pytest.approx(factor * 3 * rss_sigma, rel=1e-3), name
        linearised_or(name, lambda r: None)
    for name in row("6σ dynamic, 1.5σ shift"):
        def shift(r):
            ref, err = normal_stack_sd(t / (3.0 * 1.5))
            close(r["sigma"], ref, err, name)
        linearised_or(name, shift)
    for name in row("statistical"):
        linearised_or(name, lambda r: mean_and_sigma(r, name))
    for name in row("6σ static"):
        def static(r):
            mean_and_sigma({"centre": m if exact is None else exact[0], "sigma": r["sigma"]}, name)
            assert r["half_width"] == pytest.approx(np.abs(a) @ np.abs(mu - cen) + 3 * r["sigma"], rel=1e-9, abs=1e-12)
        linearised_or(name, static)
    for name in row("6σ dynamic RSS"):
        def dynamic(r):
            kk = np.abs(mu - cen) / t
            if np.any(kk >= 1.0):
                assert not math.isfinite(r["sigma"]) and any("undefined" in n for n in res.conventions.notes)
                return
            ref = mean_sd_errors(f(mu + (X - mu) / (1.0 - kk)))
            close(r["sigma"], ref[1], ref[3], name)
        linearised_or(name, dynamic)
    for name in row("second order (moments)"):
        r = rows[name]
        if "σ approximate" in r["note"]:
            close(r["centre"], m, se_m, name + " mean")
        else:
            mean_and_sigma(r, name)
        if "left out" not in r["note"] and "independent" not in r["note"]:      # the skewness claimed exact
            shown = float(re.search(r"skewness (\S+),", r["note"]).group(1))    # printed to 3 digits
            g, se_g = (exact[2], 0.0) if exact is not None else skewness_error(y)
            close(shown, g, se_g, name + " skewness", slack=5e-3 * abs(g) + 1e-3)
    for name in row("second order,"):
        r = rows[name]
        assert "quantiles of the curve with the four moments" in r["note"]
        if not curved and all(rec[0] == "normal" for rec in records):
            frac = float(np.mean((y >= r["low"]) & (y <= r["high"])))
            close(frac, coverage(3.0), math.sqrt(coverage(3.0) * (1 - coverage(3.0)) / N_REF), name)
    y_mc = mc.column("y")
    for name in row("Monte Carlo mean"):     # its own sample's mean and σ; that sample drawn from the output's law
        r = rows[name]
        assert (r["centre"], r["sigma"]) == (pytest.approx(np.mean(y_mc)), pytest.approx(np.std(y_mc, ddof=1)))
        assert stats.ks_2samp(y_mc, y).pvalue > 1e-6, name
    for name in row("Monte Carlo range"):
        assert (rows[name]["low"], rows[name]["high"]) == (np.min(y_mc), np.max(y_mc))
    assert seen == set(rows), f"rows the property test does not know: {set(rows) - seen}"
