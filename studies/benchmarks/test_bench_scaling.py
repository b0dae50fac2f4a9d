"""The scaling benchmark's Amdahl fit against Amdahl's law itself (no timing: made-up times).  Beside the benchmark
it tests: pytest puts this folder on ``sys.path``, so the script imports as a module."""
import pytest

from bench_scaling import amdahl


@pytest.mark.parametrize("s", [0.0, 0.1, 0.3, 1.0])
def test_amdahl_fit_recovers_the_serial_share_of_exact_times(s):
    w = [1, 2, 4, 16]
    t = [100.0 * (s + (1 - s) / k) for k in w]
    assert amdahl(w, t) == pytest.approx(s, abs=1e-12)


def test_amdahl_two_points_by_hand_and_one_point_none():
    # T(2)/T(1) = 1/1.8: s = 2 r - 1 = 0.111...
    assert amdahl([1, 2], [180.0, 100.0]) == pytest.approx(2 * 100 / 180 - 1)
    assert amdahl([1], [5.0]) is None


def _run(phases: dict, run: float) -> dict:
    return {"process": run + 5.0, "run": run, "main_cpu": 1.0, "load": 1.0,
            "phases": {k: {"wall": v, "parallel": v} for k, v in phases.items()}}


def test_a_phase_absent_at_one_worker_has_no_speed_up_and_no_fit(capsys):
    """The figures: one worker renders each figure inside the phase that makes it, so the phase reads 0 s there —
    no ratio against 0 ("0.00×") and no Amdahl fit on it; the phase present everywhere keeps both."""
    from bench_scaling import report

    runs = {("c", "signoff", "process 1"): [_run({"mc": 100.0, "figures": 0.0}, 100.0)],
            ("c", "signoff", "process 2"): [_run({"mc": 50.0, "figures": 2.0}, 52.0)]}
    report(runs, ["c"], ["signoff"], [1, 2], {"signoff": 300})
    lines = {ln.split()[0]: ln for ln in capsys.readouterr().out.splitlines() if ln.strip()}
    assert "0.00×" not in lines["figures"] and "Amdahl" not in lines["figures"]
    assert "none at process 1" in lines["figures"]
    assert "2.00×" in lines["mc"] and "Amdahl s = 0%" in lines["mc"]


def test_the_projection_table_puts_the_measured_run_beside_its_projection_and_the_speed_up_against_it(capsys):
    """Made-up projections: at 2 workers 40 s projected (42 s measured), at 16 workers 10 s — 4.00× against the
    2-worker projection, per phase and for the whole run."""
    from bench_scaling import report_projections

    def proj(run, phases):
        return {**_run(phases, run), "projected": {"run_s": run - 2.0, "phases_s": {k: v - 1.0 for k, v in phases.items()}}}

    by_w = {2: proj(42.0, {"mc": 41.0}), 16: proj(12.0, {"mc": 11.0})}
    report_projections({("c", "signoff"): by_w}, {("c", "signoff", "process 2"): [_run({"mc": 41.0}, 42.0)]},
                       {"signoff": 300})
    lines = {ln.split()[0]: ln for ln in capsys.readouterr().out.splitlines() if ln.strip()}
    assert "41.0 s" in lines["mc"] and "40.0 s" in lines["mc"] and "10.0 s (4.00×)" in lines["mc"]
    assert lines["whole"].split()[2:] == ["42.0", "s", "40.0", "s", "10.0", "s", "(4.00×)"]
