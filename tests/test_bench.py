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
