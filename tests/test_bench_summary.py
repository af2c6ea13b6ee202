"""The bench's summary per problem and error level, and its peers' right-hand sides (no timing asserted).

The summary is checked on hand-made rows (what it must pick is known); the peers'
right-hand sides, and rotframe's own heavy-top right-hand side, against the heavy top's and the
particle's equations written out here with np.cross and scipy's Rotation (a third, plain writing
of the same formulas).
"""

import math

import numpy as np
import pytest

from rotframe.rigid import dynamics as rigid
from rotframe.app.bench import level_summary, peers


def _row(method, wall, error, family, scenario="p", horizon="h"):
    return {"scenario": scenario, "method": method, "setting": 1e-6, "wall_s": wall, "error": error,
            "error_kind": "k", "nfev": 1, "horizon": horizon, "family": family}


def test_summary_picks_the_fastest_run_at_each_level():
    rows = [_row("dop853", 1e-4, 5e-4, "rotframe"), _row("dop853", 3e-4, 5e-7, "rotframe"),
            _row("rk4", 2e-4, 2e-10, "rotframe"),
            _row("diffrax-Tsit5", 2e-3, 8e-4, "peer"), _row("scipy-DOP853", 1e-3, 9e-7, "peer"),
            _row("diffrax-Dopri8", 5e-3, 1e-8, "peer")]
    rows[-1]["compile_s"] = 2.5
    summ = {r["level"]: r for r in level_summary(rows)}
    assert summ[1e-3]["rotframe_method"] == "dop853" and summ[1e-3]["wall_s"] == 1e-4
    assert summ[1e-3]["peer"] == "scipy-DOP853" and summ[1e-3]["ratio"] == pytest.approx(10.0)
    assert summ[1e-6]["wall_s"] == 2e-4 and summ[1e-6]["ratio"] == pytest.approx(5.0)  # rk4 is faster there
    assert "below the 10x goal by a factor 2.0" in summ[1e-6]["note"]
    assert summ[1e-9]["peer"] is None and summ[1e-9]["ratio"] is None
    assert "no peer run reached this error (smallest 1.0e-08)" in summ[1e-9]["note"]
    for r in summ.values():  # the row contract of bench --json
        assert {"scenario", "method", "setting", "wall_s", "error", "error_kind", "nfev"} <= set(r)


def test_summary_ignores_zero_error_except_for_exact():
    rows = [_row("splitting", 1e-6, 0.0, "rotframe"), _row("exact", 1e-3, 0.0, "rotframe"),
            _row("scipy-RK45", 1e-2, 1e-10, "peer")]
    summ = level_summary(rows)
    assert all(r["rotframe_method"] == "exact" for r in summ)


def test_peer_rigid_rhs_match_rotframe():
    rng = np.random.default_rng(0)
    inertia = np.array([1.9e-4, 1.9e-4, 2.5e-5])
    spec = {"kind": "rigid", "inertia": tuple(inertia), "mgl": 0.04}
    f, g = peers.python_rhs(spec), peers.numba_rhs(spec)
    for _ in range(5):
        y = rng.normal(size=7)
        ref = _heavy_top_equations(y, inertia, 0.04)
        assert np.allclose(rigid.rigid_rhs(0.0, y, inertia, mgl=0.04), ref, rtol=1e-13,
                           atol=1e-13 * np.abs(ref).max())
        assert np.allclose(f(0.0, y), ref, rtol=1e-13, atol=1e-13 * np.abs(ref).max())
        assert np.allclose(g(0.0, y), ref, rtol=1e-13, atol=1e-13 * np.abs(ref).max())


def _heavy_top_equations(y, inertia, mgl):
    """Euler's equations with the gravity torque and the quaternion kinematics, written out here:
    dL/dt = L x w + mgl z_b x e3 (z_b the space vertical in body axes, from scipy's Rotation),
    dq/dt = q (x) (w, 0) / 2 in scalar-last form (vector qs w + qv x w, scalar -qv . w)."""
    from scipy.spatial.transform import Rotation

    L, q = y[:3], y[3:]
    w = L / inertia
    e3 = np.array([0.0, 0.0, 1.0])
    z_b = Rotation.from_quat(q).inv().apply(e3)  # body -> space is R(q); its inverse takes space z to body axes
    dL = np.cross(L, w) + mgl * np.cross(z_b, e3)
    qv, qs = q[:3], q[3]
    return np.concatenate([dL, 0.5 * (qs * w + np.cross(qv, w)), [-0.5 * qv @ w]])


@pytest.mark.parametrize("spec", [
    {"kind": "particle", "w": (0.0, 4.6e-5, 5.7e-5), "g": (0.0, 0.0, -9.81), "ramp": None, "pendulum": None},
    {"kind": "particle", "w": (0.0, 4.6e-5, 5.7e-5), "g": (0.0, 0.0, -9.81), "ramp": None,
     "pendulum": (67.0, (0.0, 0.0, 67.0))},
    {"kind": "particle", "w": (0.0, 0.0, 0.0), "g": (0.0, 0.0, 0.0), "ramp": (1.0, 0.2), "pendulum": None}])
def test_peer_particle_rhs_match_the_equations(spec):
    rng = np.random.default_rng(1)
    f, g = peers.python_rhs(spec), peers.numba_rhs(spec)
    for _ in range(5):
        t, y = rng.uniform(0, 4), rng.normal(size=6) * 10
        r, v = y[:3], y[3:]
        if spec["ramp"]:
            w = np.array([0.0, 0.0, spec["ramp"][0] + spec["ramp"][1] * t])
            wd = np.array([0.0, 0.0, spec["ramp"][1]])
            a = -2 * np.cross(w, v) - np.cross(w, np.cross(w, r)) - np.cross(wd, r)
        else:
            a = np.array(spec["g"]) - 2 * np.cross(spec["w"], v)
            if spec["pendulum"]:
                L, pivot = spec["pendulum"]
                n = (r - np.array(pivot)) / L
                a = a - (a @ n + v @ v / L) * n
        ref = np.concatenate([v, a])
        assert np.allclose(f(t, y), ref, rtol=1e-13, atol=1e-12)
        assert np.allclose(g(t, y), ref, rtol=1e-13, atol=1e-12)


def test_diffrax_peer_solves_a_rotation_when_installed():
    ok, why = peers.diffrax_available()
    if not ok:
        pytest.skip(why)
    # pure Coriolis, no gravity: the velocity turns at 2|w| exactly, |v| is constant
    spec = {"kind": "particle", "w": (0.0, 0.0, 0.5), "g": (0.0, 0.0, 0.0), "ramp": None, "pendulum": None}
    y0 = np.array([0.0, 0.0, 0.0, 1.0, 0.0, 0.0])
    run, _ = peers.diffrax_solver(spec, "Dopri8", 2.0, y0, peers.atol_scale(spec, y0))
    y, nfev = run(1e-12)
    angle = -2 * 0.5 * 2.0
    assert np.allclose(y[3:5], [math.cos(angle), math.sin(angle)], atol=1e-9) and nfev > 0


def test_levels_below_the_reference_accuracy_are_not_claimed():
    rows = [_row("dop853", 1e-3, 1e-10, "rotframe"), _row("diffrax-Dopri8", 1e-1, 1e-10, "peer")]
    for r in rows:
        r["reference_error"] = 3e-9
    summ = {r["level"]: r for r in level_summary(rows)}
    assert summ[1e-6]["ratio"] == pytest.approx(100.0)
    assert summ[1e-9]["ratio"] is None and "not measurable" in summ[1e-9]["note"]


def test_a_level_below_the_goal_says_by_how_much_and_why():
    # hand-made rows: at 1e-3 the peer does half the work (1000 vs 2000 nfev) in 4x our time -> ratio 4,
    # and the reason is the work; at 1e-6 both do 2000 evaluations and the peer's cost 5x ours -> ratio 5,
    # the reason is the cost per evaluation
    rows = [dict(_row("dop853", 1e-4, 5e-4, "rotframe"), nfev=2000),
            dict(_row("diffrax-Tsit5", 4e-4, 8e-4, "peer"), nfev=1000),
            dict(_row("dop853", 2e-4, 5e-7, "rotframe"), nfev=2000),
            dict(_row("diffrax-Dopri8", 1e-3, 9e-7, "peer"), nfev=2000)]
    summ = {r["level"]: r for r in level_summary(rows)}
    assert summ[1e-3]["ratio"] == pytest.approx(4.0) and summ[1e-3]["shortfall"] == pytest.approx(2.5)
    assert "needs 2x less work (1000 vs 2000 nfev" in summ[1e-3]["reason"]
    assert summ[1e-3]["note"].startswith("below the 10x goal by a factor 2.5: ")
    assert summ[1e-6]["ratio"] == pytest.approx(5.0) and summ[1e-6]["shortfall"] == pytest.approx(2.0)
    assert "evaluation costs only 5x ours (also compiled" in summ[1e-6]["reason"]
    assert "it does 1x our work (2000 vs 2000 nfev)" in summ[1e-6]["reason"]
    # at the goal: no shortfall, no reason (the Tsit5 row made slower, Dopri8's 1e-3 s is the fastest peer)
    rows[1]["wall_s"] = 2e-3
    summ = {r["level"]: r for r in level_summary(rows)}
    assert summ[1e-3]["ratio"] == pytest.approx(10.0) and "reason" not in summ[1e-3] and "note" not in summ[1e-3]


def test_the_larger_shortfall_names_the_reason():
    """The peer does 5% less work but each of its evaluations costs 7x ours: ratio 6.7, and the
    shortfall is the cost per evaluation (10/7 = 1.4), not the work (1/0.95 = 1.05)."""
    from rotframe.app.bench.summary import shortfall_reason

    mine = {"nfev": 1000, "wall_s": 1.0, "method": "dop853"}
    peer = {"nfev": 950, "wall_s": 950 * 7.0 / 1000, "method": "diffrax-Dopri8", "setting": 1e-9}
    assert shortfall_reason(mine, peer).startswith("the peer's evaluation costs only 7x ours")
    peer_less_work = {"nfev": 200, "wall_s": 200 * 8.0 / 1000, "method": "scipy-LSODA", "setting": 1e-6}
    assert shortfall_reason(mine, peer_less_work).startswith("the peer needs 5x less work")


def test_readme_table_lists_first_runs_against_their_goals():
    # tools/bench_table.py turns the startup rows into the README's first-run table
    import importlib.util
    from pathlib import Path

    spec = importlib.util.spec_from_file_location("bench_table", Path(__file__).resolve().parents[1] / "tools" /
                                                  "bench_table.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    rows = [{"scenario": "startup", "method": "rotframe run foucault --no-record", "setting": setting,
             "wall_s": wall, "import_s": 0.5, "beyond_imports_s": wall - 0.5, "goal_s": goal, "goal_met": met}
            for setting, wall, goal, met in (("warm compile cache", 1.4, 1.0, False),
                                             ("first-ever run (empty compile cache)", 3.2, 3.0, True))]
    text = mod.table(rows)
    line = next(x for x in text.splitlines() if "rotframe run foucault" in x)
    assert "1.40 s (imports 0.50, beyond them 0.90): not met" in line
    assert "3.20 s (imports 0.50, beyond them 2.70): met" in line


def test_a_run_s_imports_are_read_from_its_own_importtime_report():
    # the startup rows count each run's own imports (python -X importtime), so a scene that
    # imports less than the CLI's usual set is not credited with a negative time beyond them
    import subprocess
    import sys

    from rotframe.app.bench.throughput import import_seconds

    log = ("import time: self [us] | cumulative | imported package\n"
           "import time:       100 |        100 |   _io\n"
           "import time:       200 |        300 | encodings\n"
           "import time:        50 |         50 |     codecs\n"
           "import time:       400 |       1450 | json\n")
    assert import_seconds(log) == (300 + 1450) / 1e6
    res = subprocess.run([sys.executable, "-X", "importtime", "-c", "import json, fractions"], capture_output=True,
                         text=True, check=True)
    seconds = import_seconds(res.stderr)
    top = [ln for ln in res.stderr.splitlines() if ln.endswith("| json") or ln.endswith("| fractions")]
    assert len(top) == 2 and seconds >= sum(int(ln.split("|")[1]) for ln in top) / 1e6 > 0


def test_the_work_bound_is_the_fewest_evaluations_at_the_level_times_our_cost():
    """Power-law ladders, where interpolating log work in log error is exact: an 8th-order method
    (error c n^-8, ours, 50 ns an evaluation) and a 4th-order peer (error d n^-4, 2 ns: cheap enough to be under the goal), whose
    constants put the level 1e-3 at n = 63,000 and 1,300,000 evaluations, between their rungs."""
    from rotframe.app.bench.summary import GOAL, at_level, work_bound

    def ladder(method, family, c, p, cost, ns):
        return [dict(_row(method, cost * n, c * n ** -p, family), nfev=n) for n in ns]

    level, n_ours, n_peer = 1e-3, 63_000.0, 1_300_000.0
    ours = ladder("dop853", "rotframe", level * n_ours ** 8, 8, 50e-9, [50_000, 70_000, 100_000])
    peer = ladder("diffrax-Tsit5", "peer", level * n_peer ** 4, 4, 2e-9, [500_000, 1_000_000, 2_000_000])
    got = at_level(ours, level)
    assert got[0] == pytest.approx(n_ours, rel=1e-12) and got[1] == pytest.approx(50e-9 * n_ours, rel=1e-12)
    assert at_level(peer, level)[0] == pytest.approx(n_peer, rel=1e-12)
    assert at_level(ours, 1e-12) is None  # no row reaches it
    best = min((r for r in ours if r["error"] <= level), key=lambda r: r["wall_s"])
    b = work_bound(ours + peer, level, best)
    assert b["fewest_nfev"] == pytest.approx(n_ours, rel=1e-12) and b["fewest_nfev_method"] == "dop853"
    assert b["peer_wall_at_level"] == pytest.approx(2e-9 * n_peer, rel=1e-12)
    assert b["bound_ratio"] == pytest.approx(2e-9 * n_peer / (n_ours * 50e-9), rel=1e-12)
    assert b["needed_s_per_eval"] == pytest.approx(2e-9 * n_peer / (GOAL * n_ours), rel=1e-12)
    # in the summary, a level under the goal carries the bound and says it
    summ = {r["level"]: r for r in level_summary(ours + peer)}
    row = summ[level]
    assert row["bound_ratio"] == pytest.approx(b["bound_ratio"]) and "the bound is x" in row["note"]


def test_the_problem_start_up_rows_time_four_runs_against_their_goals(monkeypatch):
    """The first problem ever (both caches empty) short and long, a new problem and a changed force, each against its
    goal; the note says which tier ran each."""
    from rotframe.app.bench import problem_startup

    calls = []
    plain = "... short enough for its plain-Python remake ..."
    switched = "... remake ran the first 8 steps, then the loop compiled ..."

    def child(env, runs):
        calls.append((env["NUMBA_CACHE_DIR"], env["ROTFRAME_CACHE_DIR"], runs))
        answers = {1: [{"wall": 0.4, "tier": plain}], 2: [{"wall": 4.5, "tier": switched}],
                   3: [{"wall": 0.3, "tier": ""}, {"wall": 0.25, "tier": ""}]}
        return answers[len(calls)]

    monkeypatch.setattr(problem_startup, "_child", child)
    peer = [{"run": "diffrax", "setting": "first solve in a process"}]
    monkeypatch.setattr(problem_startup, "diffrax_startup_rows", lambda constants: peer)
    rows = problem_startup.problem_startup_rows()
    assert rows[4:] == peer  # diffrax's rows follow rotframe's (tests/test_bench_diffrax_startup.py)
    rows = rows[:4]
    assert [r["setting"] for r in rows] == ["first problem ever", "first problem ever, long", "new problem",
                                            "changed force"]
    assert [r["wall_s"] for r in rows] == [0.4, 4.5, 0.3, 0.25]
    assert [r["goal_met"] for r in rows] == [True, False, True, True]
    assert "plain-Python remake" in rows[0]["note"] and "compiled" in rows[1]["note"]
    assert "loaded from numba's cache" in rows[2]["note"]
    assert calls[0][:2] != calls[1][:2]  # both first runs find every cache empty
    assert calls[1][:2] == calls[2][:2]  # the new problem finds what the long first run cached
    assert [span for call in calls for _, span in call[2]] == [problem_startup.SHORT_S, problem_startup.LONG_S,
                                                               problem_startup.SHORT_S, problem_startup.SHORT_S]
    assert len({k for call in calls for k, _ in call[2]}) == 4  # a new force every time: nothing found by chance
