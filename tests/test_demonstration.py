"""What a requirement can demonstrate (issue 37): a yield of exactly 1 refused at load, a constant output's Cpk
stated instead of crashing, the n that demonstrates a yield-and-Cpk requirement the larger of the two needs, and a
normal-theory Cpk that a skewed output would pass on normal theory alone.

References are independent of rvtol's code: the success-run formula n = ln(1 − c)/ln(Y), Bissell's bound written
out by hand, scipy.stats' gamma distribution for the skewed output's ppm and percentile Cpk.
"""
import math
import re

import numpy as np
import pytest
from scipy import stats

from rvtol.cli import main
from rvtol.spec import Requirement
from rvtol.verdict import judge

from test_bad_input import REQ, run, setup


# --------------------------------------------------------------------------- min_yield that cannot be demonstrated
@pytest.mark.parametrize("value,reason", [
    ("1.0", "a yield of exactly 1 cannot be demonstrated by any finite sample"),
    ("1", "a yield of exactly 1 cannot be demonstrated by any finite sample"),
    ("1.0000001", "must lie in (0, 1)"),
    ("0.0", "must lie in (0, 1)"),
    ("-0.5", "must lie in (0, 1)"),
    ("nan", "must be a finite number"),
])
def test_a_yield_no_sample_can_demonstrate_is_refused_at_load(tmp_path, capsys, value, reason):
    rc, err, out = run(tmp_path, capsys, setup(tmp_path, req=REQ + f"min_yield = {value}\n"))
    assert rc == 2 and len(err) == 1, err
    m = re.match(r"^rvtol: error: (.+?): (\S+): (.+)$", err[0])
    assert m and m.group(1).endswith("req.toml") and m.group(2) == "requirement[0].min_yield", err[0]
    assert reason in m.group(3), err[0]
    assert not out.exists()


# --------------------------------------------------------------------------- n to demonstrate: the larger need
def _bissell(cpk: float, n: int, c: float = 0.95) -> float:
    return cpk - stats.norm.ppf(c) * math.sqrt(1 / (9 * n) + cpk ** 2 / (2 * (n - 1)))


def _bissell_n(cpk: float, req: float) -> int:
    """The smallest n whose Bissell bound reaches ``req``, by counting up (no root finder)."""
    n = 2
    while _bissell(cpk, n) < req:
        n += 1
    return n


@pytest.mark.parametrize("cpk", [1.37, 1.60])
def test_the_n_that_demonstrates_yield_and_cpk_is_the_larger_need(cpk):
    """Every sample inside (yield 1): the success run needs n = ⌈ln 0.05/ln 0.9973⌉ = 1109; Bissell's bound needs
    ~ 1 780 for Cpk 1.37 and ~ 50 for 1.60 — the requirement is demonstrated at the larger of the two."""
    success_run = math.ceil(math.log(1 - 0.95) / math.log(0.9973))
    assert success_run == 1109
    need_cpk = _bissell_n(cpk, 1.33)
    assert (need_cpk > success_run) == (cpk == 1.37)          # one case each way round
    r = Requirement("y", upper=1.0, min_yield=0.9973, min_cpk=1.33)
    n = 150
    j = judge(r, yield_=1.0, yield_lo=0.05 ** (1 / n), cpk=cpk, cpk_lo=_bissell(cpk, n), n=n)
    assert not j.passed
    assert j.n_to_demonstrate == max(success_run, need_cpk)
    assert any(f"about n = {max(success_run, need_cpk)} samples would demonstrate it" in w for w in j.reasons)
