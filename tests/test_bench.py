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


def test_an_unstable_setting_is_a_failed_row_not_the_end_of_the_bench():
    """A ladder step that raises IntegrationError (RK4 past its stability limit) gives a row with
    infinite error and a note; the next settings still run (the full bench stopped there once)."""
    import math
    from types import SimpleNamespace

    import numpy as np

    from rotframe.app.bench.measure import Plan, run_problem
    from rotframe.errors import IntegrationError

    def run(method, step):
        if step > 0.01:
            raise IntegrationError(f"unstable step: grew by t = 4 s (method {method}, step {step} s)")
        return np.zeros(2), 10, 0.0

    p = SimpleNamespace(scenario="fake", horizon="1 s", runs={"rk4": [0.04, 0.001]}, run=run,
                        error=lambda y: 1e-6, error_kind="test", ref_error=0.0, spec=None, rhs=None,
                        y0=np.zeros(2), scipy_rtols=(), atol=1e-12, scipy_budget_s=1.0)
    rows = run_problem(p, plan=Plan(quick=False))  # no scipy tolerances, no spec: no peers
    ours = [r for r in rows if r["method"] == "rk4"]
    assert [r["setting"] for r in ours] == [0.04, 0.001]
    assert math.isinf(ours[0]["error"]) and ours[0]["note"].startswith("failed: unstable step")
    assert ours[1]["error"] == 1e-6 and ours[1]["compile_s"] >= 0


def test_a_prepared_run_is_timed_alone_and_gives_the_same_result():
    """The bench times a prepared run's call alone (the final state is picked out after the timing,
    as a peer's conversion to numpy is); ``finish`` gives bitwise what ``run`` gives."""
    import numpy as np

    from rotframe.app.bench.measure import timed_call
    from rotframe.app.bench.problems import PREPARED, problems

    for name, method, setting in (("tower-drop", "exact", None), ("heavy-top", "top-splitting8", 2e-2)):
        p = problems([name], quick=True)[0]
        call, finish = timed_call(p, method + PREPARED, setting)
        raw = call()
        # the prepared run's samples, nothing more: the scenes' PreparedRun's (r, v), or the engine's Trajectory
        assert isinstance(raw, tuple) and len(raw) == 2 or type(raw).__name__ == "Trajectory"
        y, nfev, inv = finish(raw)
        y_run, nfev_run, inv_run = p.run(method + PREPARED, setting)
        np.testing.assert_array_equal(y, y_run)
        assert nfev == nfev_run and inv() == inv_run()
    # a method that is not prepared times run itself
    call, finish = timed_call(p, "dop853", 1e-8)
    np.testing.assert_array_equal(finish(call())[0], p.run("dop853", 1e-8)[0])


def test_bench_help_names_every_benchmark_that_is_not_a_problem():
    from rotframe.app.bench import EXTRAS

    out = subprocess.run([sys.executable, "-m", "rotframe", "bench", "--help"], capture_output=True, text=True,
                         timeout=120).stdout
    words = " ".join(out.split())  # argparse wraps the help text (user- force)
    assert all(name in words.replace("- ", "-") for name in EXTRAS), words


def test_bare_quick_is_a_smoke_test_of_each_problems_default_method(monkeypatch):
    # `rotframe bench --quick` with no names: each problem's scene default only (a first run compiles
    # little), plain scipy beside it, and no ensemble or user-force rows; named problems keep every method
    import rotframe.app.bench as bench
    from rotframe.app.bench.problems import problems

    (tower,) = problems(["tower-drop"], quick=True)
    assert {"exact", "rotation-splitting", "rk4", "dop853"} <= set(tower.runs)
    assert bench.smoke_runs(tower) == {"exact": tower.runs["exact"]}
    (foucault,) = problems(["foucault"], quick=True)
    assert list(bench.smoke_runs(foucault)) == ["dop853"]  # "dop853 for the full pendulum; ..."
    monkeypatch.setattr(bench, "problems", lambda names, quick: [tower])
    monkeypatch.setattr(bench, "record_rows", lambda n: [])
    rows = bench.run_bench(quick=True)
    methods = {r["method"] for r in rows if r.get("kind") is None}
    assert methods == {"exact", "scipy-RK45", "scipy-DOP853", "scipy-Radau", "scipy-LSODA"}
    assert not any(r["scenario"] in ("ensemble", "user-force") for r in rows)
    assert any("smoke test" in r.get("note", "") for r in rows)
