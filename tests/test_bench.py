"""`rotframe bench`: the JSON contract and the scipy baselines (a smoke test; speed lives in the bench)."""

import json
import math
import subprocess
import sys

from rotframe.app.bench import speedups


def test_bench_quick_json_rows_follow_the_contract(tmp_path):
    res = subprocess.run([sys.executable, "-m", "rotframe", "bench", "tower-drop", "--quick", "--json"],
                         capture_output=True, text=True, cwd=tmp_path, timeout=600)
    assert res.returncode == 0, res.stderr
    rows = json.loads(res.stdout)
    for row in rows:
        assert {"scenario", "method", "setting", "wall_s", "error", "error_kind", "nfev"} <= set(row)
    methods = {r["method"] for r in rows}
    assert {"scipy-RK45", "scipy-DOP853", "scipy-Radau", "scipy-LSODA"} <= methods
    assert {"exact", "rotation-splitting", "rk4", "dop853"} <= methods
    exact = [r for r in rows if r["method"] == "exact"][0]
    assert exact["error"] < 1e-9 and exact["error_kind"].startswith("analytic")
    timed = [r for r in rows if r.get("kind") is None]
    assert all(r["wall_s"] > 0 for r in timed)
    # one summary row per error level, with the fastest peer and the ratio
    summary = [r for r in rows if r.get("kind") == "summary"]
    assert [r["level"] for r in summary] == [1e-3, 1e-6, 1e-9]
    assert all(r["peer"].startswith("scipy") and r["ratio"] > 0 for r in summary)
    assert any(r.get("kind") == "environment" for r in rows)
    speed = speedups(rows)
    assert all(math.isfinite(s["speedup"]) for s in speed.values())


def test_bench_unknown_name_exits_2(tmp_path):
    res = subprocess.run([sys.executable, "-m", "rotframe", "bench", "nosuch"], capture_output=True, text=True,
                         cwd=tmp_path)
    assert res.returncode == 2
    assert "available" in res.stderr


def test_free_top_problem_runs_against_the_closed_form():
    # the Earth over two Euler periods (616 turns): exact is the reference itself (error 0); dop853 at
    # rtol 1e-8 must stay within the scenes' bound 10 n rtol of the closed form (n = nfev / 12 steps;
    # measured 1.2e-5 for ~34000 evaluations: bound 2.8e-4); lie-poisson's sub-flows are exact for a
    # symmetric body, so its error is round-off at any step: at most eps (2.2e-16) times the 3900 rad
    # turned times sqrt(530 steps), 2e-11, bounded here by 1e-10 (measured 3e-13)
    from rotframe.app.bench.problems import problems

    (p,) = problems(["free-top"], quick=True)
    assert p.scenario == "free-top" and set(p.runs) == {"exact", "dop853", "lie-poisson", "rk4"}
    y, _, _ = p.run("exact", None)
    assert p.error(y) == 0.0
    y, nfev, _ = p.run("dop853", 1e-8)
    assert 0 < p.error(y) < 10 * 1e-8 * nfev / 12
    y, _, _ = p.run("lie-poisson", 1e5)
    assert p.error(y) < 1e-10
