"""``--threads N`` (run, sweep, bench) and ``rotframe.run(threads=N)``: set for the command only, checked, and
without effect on any number.

Equality is exact (no tolerance): the ensemble is cut into fixed blocks whatever the
thread count and each particle is integrated on its own
(:mod:`rotframe.particles.ensemble`), so a thread count that changed a result
would be a bug, not round-off.
"""

import json
import math
import os

import numpy as np
import pytest

from rotframe.app import cli
from rotframe.errors import ScenarioError
from rotframe.particles import ensemble, threads

pq = pytest.importorskip("pyarrow.parquet")


@pytest.fixture
def spy(monkeypatch):
    """Records the thread count each ensemble resolved (small blocks, so that 300 particles make 5 of them)."""
    seen = []
    real = ensemble.resolve_threads

    def resolving(threads=None):
        n = real(threads)
        seen.append(n)
        return n

    monkeypatch.setattr(ensemble, "resolve_threads", resolving)
    monkeypatch.setattr(threads, "BLOCK", 64)
    return seen


def _sweep(tmp_path, capsys, threads):
    out = tmp_path / f"t{threads}.parquet"
    code = cli.main(["sweep", "tower-drop", "--grid", "height=10:300:300", "--out", str(out), "--json",
                     "--threads", str(threads)])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert json.loads(captured.out)["path"] == "ensemble"
    return pq.read_table(out).to_pydict()


def test_sweep_threads_option_reaches_the_ensemble_and_changes_no_number(tmp_path, capsys, spy):
    one = _sweep(tmp_path, capsys, 1)
    assert spy and set(spy) == {1}
    spy.clear()
    two = _sweep(tmp_path, capsys, 2)
    # the option reaches the sweep's ensemble work: 2 threads at the batch (its chunks may then run one
    # thread each, side by side), never more than asked
    assert spy and max(spy) == 2
    assert ensemble.threads_in_force() is None  # the option did not outlive the command
    for key in ("east_deflection_m", "north_deflection_m", "fall_time_s"):
        a, b = np.array(one[key], dtype=float), np.array(two[key], dtype=float)
        assert np.isfinite(a).all() and np.array_equal(a, b), key


@pytest.mark.parametrize("command", [["run", "foucault", "--no-record"], ["sweep", "foucault", "--grid",
                                                                          "latitude=0:10:2"], ["bench", "ensemble"]])
@pytest.mark.parametrize("value", ["0", "-2", "1.5", "many", "nan", "inf"])
def test_bad_threads_exit_2_with_one_line(tmp_path, capsys, command, value):
    code = cli.main([*command, "--threads", value])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1 and "--threads" in err and repr(value) in err and ">= 1" in err


def test_api_threads_is_for_the_run_only(monkeypatch):
    import rotframe
    from rotframe.app import runner

    seen = []
    real = runner.simulate

    def simulate(*args, **kwargs):
        seen.append(ensemble.threads_in_force())
        return real(*args, **kwargs)

    monkeypatch.setattr(runner, "simulate", simulate)
    rotframe.run("tower-drop", threads=3)
    rotframe.run("tower-drop")
    assert seen == [3, None]
    assert ensemble.threads_in_force() is None
    for bad in (0, -1, 2.5, "x"):
        with pytest.raises(ScenarioError, match="threads"):
            rotframe.run("tower-drop", threads=bad)


def test_sweep_batches_share_the_cores():
    from rotframe.app.sweep.execute import batch_threads

    cores = os.cpu_count() or 1
    assert batch_threads(here=True) == cores  # in this process: every core
    assert batch_threads(local_workers=2) == max(1, cores // 2)  # a LocalCluster shares them
    assert batch_threads() is None  # an existing scheduler: each worker's own cores
    with ensemble.threads_scope(3):  # --threads wins wherever the batch runs
        assert batch_threads(here=True) == batch_threads(local_workers=2) == batch_threads() == 3


def _drops(n, steps, h, seed=4):
    from rotframe.particles.integrators import Event
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    w = np.array([0.0, 4.6e-5, 5.7e-5])
    g = np.array([0.0, 0.0, -9.81])
    model = ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.constant(w), g=g)
    rng = np.random.default_rng(seed)
    r0 = rng.normal(size=(n, 3)) + [0, 0, 1000]
    v0 = rng.normal(size=(n, 3))
    ground = Event("ground", "r", 2, 0.0, -1, True)
    ours = ensemble.integrate_ensemble(model, r0, v0, steps * h, ground, method="rotation-splitting",
                                       run={"step": h, "samples": 1}, threads=1)
    return ours, r0, v0, w, g


def test_benchsame_work_check_accepts_the_ceiling_and_rejects_other_physics():
    """The check that ``bench ensemble``'s ceiling does our work would catch a ceiling doing other work.

    The ceiling with Coriolis matches to round-off; without Coriolis (rotation by 0)
    it differs by about 1e-6 of |v|, far above the check's 1e-12; one step fewer also fails.
    """
    from rotframe.app.bench import ceiling
    from rotframe.app.bench.throughput import same_work

    n, steps, h = 300, 48, 1e-3  # 16 samples of 3 steps (an ensemble this small samples 16 times)
    ours, r0, v0, w, g = _drops(n, steps, h)
    angle = -2 * np.linalg.norm(w) * h

    def hand(c, s, k=steps):
        r, v = r0.copy(), v0.copy()
        ceiling.serial(r, v, g, w, c, s, h, k, False, True)  # the splitting, watching the ground
        return r, v

    same, rel, note = same_work(ours, hand(math.cos(angle), math.sin(angle)), n, steps, h)
    assert same and rel <= 1e-12 and note.startswith("same")
    same, rel, note = same_work(ours, hand(1.0, 0.0), n, steps, h)
    assert not same and rel > 1e-9 and note.startswith("NOT")
    assert not same_work(ours, hand(math.cos(angle), math.sin(angle), steps - 1), n, steps, h)[0]


def test_bench_ensemble_honours_threads_and_reports_the_ceiling(capsys):
    code = cli.main(["bench", "ensemble", "--quick", "--json", "--threads", "1"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    rows = [r for r in json.loads(captured.out) if r["scenario"] == "ensemble"]
    # 3 methods x (event, none) x 4 rows, and the engine's door (the sweeps') beside the two fixed-step event cases
    assert len(rows) == 28 and {r["threads"] for r in rows} == {1}
    assert sum(r["method"].startswith("rotframe simulate (N, 3)") for r in rows) == 4
    assert {(r["integrator"], r["event"]) for r in rows} == {(m, e) for m in ("rotation-splitting", "rk4", "dop853")
                                                             for e in (True, False)}
    for r in rows:
        assert r["same_work"] is True and r["same_steps"] is True, r["method"]
    allcore = rows[1]
    assert allcore["bitwise_identical_to_1_thread"] is True
    assert allcore["same_work"] is True and allcore["same_work_max_rel"] <= 1e-12
    for key in ("parallel_efficiency", "goal_ratio", "scaling_vs_ceiling", "of_ceiling", "particle_steps_per_s"):
        assert math.isfinite(allcore[key]) and allcore[key] > 0
    assert "prange" in rows[3]["method"]
