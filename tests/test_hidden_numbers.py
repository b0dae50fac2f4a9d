"""Numbers users cannot check themselves, pinned to independent references (issue 27, item 9)."""
import math

import numpy as np
import pytest

from rvtol.ci import differences as df
from rvtol.ci.compare import Change


def _paired(n11, n12, n21, n22):
    """The paired 2×2 table as two flag vectors: x (rows) and y (columns)."""
    x = np.r_[np.ones(n11 + n12), np.zeros(n21 + n22)].astype(bool)
    y = np.r_[np.ones(n11), np.zeros(n12), np.ones(n21), np.zeros(n22)].astype(bool)
    return x, y


def test_paired_ppm_interval_reproduces_the_published_newcombe_interval():
    """Newcombe's square-and-add interval for paired proportions (Newcombe 1998, Stat. Med. 17:2635, method 10),
    as published for Cavo et al. (2012), complete response before/after consolidation, table [[59, 6], [16, 80]]:
    estimate −0.0621, 95 % CI −0.1186 to −0.0046 (Fagerland, Lydersen & Laake, Statistical Analysis of
    Contingency Tables, CRC 2017, chapter 8).  p_rows − p_cols = b − a in rvtol's terms."""
    x, y = _paired(59, 6, 16, 80)
    d, lo, hi = df.proportion_change(y, x, paired=True)
    assert d == pytest.approx(-10 / 161)
    assert lo == pytest.approx(-0.1186, abs=5e-5) and hi == pytest.approx(-0.0046, abs=5e-5)


def test_no_infinite_gain_when_nothing_changed():
    c = Change("mean", 1.0, 1.0, 0.0, (0.0, 0.0), (-0.1, 0.1))
    assert c.gain is None and c.to_dict()["gain"] is None
    assert Change("mean", 1.0, 1.1, 0.1, (0.05, 0.15), (-0.1, 0.3)).gain == pytest.approx(4.0)


def test_markdown_escapes_raw_html_from_the_study():
    from rvtol.ci.markdown import render_markdown

    summary = {"verdict": "PASS", "study": "s`x", "title": "<img src=x onerror=alert(1)>", "n": 10, "method": "lhs",
               "seed": 1, "rvtol_version": "0", "outputs": {"y": {"requirements": [{
                   "requirement": "<script>alert(1)</script>", "min_yield": 0.9, "basis": "estimate",
                   "confidence": 0.95, "yield": 1.0, "yield_ci": [0.7, 1.0], "yield_bound": 1.0, "ppm": 0.0,
                   "passed": True, "reasons": []}]}}}
    md = render_markdown(summary)
    assert "<script>" not in md and "<img" not in md
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in md and "`s'x`" in md
