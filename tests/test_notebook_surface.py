"""What a notebook user meets: warnings as Python warnings, short reprs and tables, quantities,
method names in scipy's spelling, a figure that is not drawn through pyplot, a missing extra
named in one line."""

from __future__ import annotations

import subprocess
import sys
import warnings

import numpy as np
import pytest

import rotframe
from rotframe.errors import MissingExtraError, RotframeWarning, ScenarioError


def test_rotframe_warning_is_exported_user_warning():
    assert rotframe.RotframeWarning is RotframeWarning
    assert issubclass(RotframeWarning, UserWarning)


def test_each_result_warning_is_also_a_python_warning():
    # a falling sleeping top under dop853 (the default, top-splitting8, gets it right): DOP853 does not keep
    # the invariants past the upright position, and its nutation period is far from the theory
    with pytest.warns(RotframeWarning) as caught:
        r = rotframe.run("heavy-top", method="dop853", theta0=0, psidot0=150, wobble=1e-4)
    assert r.warnings, "the run should warn"
    assert [str(w.message) for w in caught if w.category is RotframeWarning] == r.warnings
    assert all(w.filename == __file__ for w in caught)  # they point at the caller's line


def test_a_clean_run_warns_nothing():
    with warnings.catch_warnings():
        warnings.simplefilter("error", RotframeWarning)
        r = rotframe.run("tower-drop")
    assert r.warnings == []


def test_scenario_repr_is_short_and_tables_list_parameters():
    scn = rotframe.load("foucault")
    text = repr(scn)
    assert text.startswith("<rotframe.Scenario foucault") and len(text) < 120 and "\n" not in text
    md, html = scn._repr_markdown_(), scn._repr_html_()
    for name, p in scn.parameters.items():
        assert f"| {name} |" in md and f"<td style='text-align:left'>{name}</td>" in html
    assert "| parameter | default | unit | allowed | meaning |" in md


def test_result_tables_show_metrics_beside_theory_and_warnings():
    r = rotframe.run("tower-drop")
    md = r._repr_markdown_()
    assert "| metric | measured | theory | unit |" in md
    assert f"| east_deflection_m | {r.metrics['east_deflection_m']:.6g} | {r.theory['east_deflection_m']:.6g} | m |" in md
    assert "<table>" in r._repr_html_()
    with pytest.warns(RotframeWarning):
        top = rotframe.run("heavy-top", method="dop853", theta0=0, psidot0=150, wobble=1e-4)
    assert "warning:" in top._repr_markdown_() and "warning:" in top._repr_html_()


def test_quantities_carry_the_units_of_the_names():
    u = pytest.importorskip("astropy.units")
    r = rotframe.run("tower-drop")
    q = r.quantities()
    east = q["metrics"]["east_deflection_m"]
    assert east.unit == u.m and east.value == r.metrics["east_deflection_m"]
    assert q["theory"]["fall_time_s"].unit == u.s
    assert q["diagnostics"]["energy_rel_drift"].unit == u.dimensionless_unscaled
    assert isinstance(r.metrics["east_deflection_m"], float)  # plain floats stay the default
    top = rotframe.run("free-top", duration="30 d")
    assert top.quantities()["metrics"]["space_precession_rate_rad_s"].unit == u.rad / u.s


@pytest.mark.parametrize("spelling", ["DOP853", "Dop853", "dop853"])
def test_method_names_in_any_case(spelling):
    r = rotframe.run("tower-drop", spelling)
    assert r.method == "dop853"


def test_method_names_in_any_case_everywhere():
    from rotframe.particles.integrators import canonical_method
    from rotframe.scenes.rigid_base import FREE_METHODS, HEAVY_METHODS

    assert canonical_method("ROTATION-SPLITTING4") == "rotation-splitting4"
    assert canonical_method("Splitting") == "rotation-splitting"
    assert "LIE-POISSON" in FREE_METHODS and FREE_METHODS.canonical("Exact") == "exact"
    assert HEAVY_METHODS.canonical("SPLITTING4") == "top-splitting4"
    assert rotframe.run("dzhanibekov", "Lie-Poisson4", duration=2).method == "lie-poisson4"
    with pytest.raises(ScenarioError, match="not one of"):
        rotframe.run("tower-drop", "DOP54")


def test_method_in_a_scenario_file_in_any_case(tmp_path):
    src = rotframe.load("dzhanibekov").path.read_text()
    assert 'method = "exact"' in src
    path = tmp_path / "flip.toml"
    path.write_text(src.replace('name = "dzhanibekov"', 'name = "flip-upper"').replace('method = "exact"',
                                                                                      'method = "Lie-Poisson4"'))
    scn = rotframe.load(path)
    assert scn.run["method"] == "lie-poisson4"


def test_plot_does_not_touch_pyplot(tmp_path):
    """The figure is built without pyplot: Jupyter shows it once (as the cell's value), no window opens."""
    code = ("import sys, rotframe\n"
            "r = rotframe.run('tower-drop')\n"
            f"fig = r.plot({str(tmp_path / 'p.png')!r})\n"
            "from matplotlib.figure import Figure\n"
            "assert isinstance(fig, Figure)\n"
            "assert 'matplotlib.pyplot' not in sys.modules, 'pyplot was imported'\n")
    subprocess.run([sys.executable, "-c", code], check=True, timeout=600)
    assert (tmp_path / "p.png").stat().st_size > 10_000


def test_missing_matplotlib_is_one_line_naming_the_extra(tmp_path, monkeypatch):
    import importlib.util

    from rotframe.app import plot

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "matplotlib" else real(name, *a))
    with pytest.raises(MissingExtraError, match=r"rotframe\[plot\]"):
        plot.require_matplotlib()
    from rotframe.app import cli

    code = cli.main(["run", "tower-drop", "--no-record", "--png", str(tmp_path / "x.png")])
    assert code == 2 and not (tmp_path / "x.png").exists()


def test_progress_true_without_tqdm_draws_the_text_bar(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)  # as if tqdm were not installed
    rotframe.run("heavy-top", duration=0.5, progress=True)
    assert "100.0%" in capsys.readouterr().err


def test_progress_true_with_tqdm_uses_its_bar(capsys):
    pytest.importorskip("tqdm")
    rotframe.run("heavy-top", duration=0.5, progress=True)
    err = capsys.readouterr().err
    assert "100.0%" in err and "run" in err


def test_foucault_picture_shows_the_swing_plane_angle(tmp_path):
    pytest.importorskip("matplotlib")
    r = rotframe.run("foucault", duration=1800)
    fig = r.plot()
    ax = fig.axes[1]
    assert "swing-plane angle" in ax.get_ylabel()
    measured, theory = (line.get_ydata() for line in ax.get_lines()[:2])
    # the measured angle follows the theory line (an independent closed form) to 1% of the turn
    assert np.max(np.abs(measured - theory)) < 0.01 * abs(theory[-1] - theory[0]) + 0.05


def test_projectile_picture_ends_at_the_landing(tmp_path):
    pytest.importorskip("matplotlib")
    r = rotframe.run("projectile")
    fig = r.plot()
    deflection, flight = fig.axes[0], fig.axes[1]
    assert flight.get_xlim()[1] == pytest.approx(r.metrics["flight_time_s"], rel=1e-9)
    y = deflection.get_lines()[0].get_ydata()
    assert y[-1] == pytest.approx(r.metrics["lateral_deflection_m"], rel=1e-9)


def test_heavy_top_picture_shows_the_tilt_between_the_turning_points():
    pytest.importorskip("matplotlib")
    r = rotframe.run("heavy-top", duration=2)
    ax = r.plot().axes[0]
    theta = ax.get_lines()[0].get_ydata()
    # the simulated tilt stays between the turning points of Goldstein's cubic (an independent closed form)
    assert theta.min() >= r.theory["theta_min_deg"] - 1e-3 and theta.max() <= r.theory["theta_max_deg"] + 1e-3
    assert theta.max() - theta.min() > 0.9 * (r.theory["theta_max_deg"] - r.theory["theta_min_deg"])


def test_tower_drop_picture_ends_at_the_landing():
    pytest.importorskip("matplotlib")
    r = rotframe.run("tower-drop")
    ax = r.plot().axes[1]
    assert ax.get_xlim()[1] <= r.metrics["fall_time_s"] * 1.01


def test_sol_of_a_dop853_run_between_samples_against_the_closed_form():
    """Dense output: between samples, sol(t) follows the closed-form motion under gravity and Coriolis."""
    from rotframe.analytic import coriolis_uniform_gravity

    r = rotframe.run("tower-drop", "DOP853", samples=20)
    model = r._scene_result.extras["model"]
    w, g = model.omega.vector(), model.g
    times = r.trajectory.times
    t_land = float(r.trajectory.event_times["ground"][0][0])
    queries = np.array([0.37, 1.234, 3.3, 0.5 * (times[5] + times[6]), t_land - 1e-3])
    pos, vel = r.sol(queries)
    for t, p, q in zip(queries, pos, vel):
        ref_r, ref_v = coriolis_uniform_gravity(w, g, r.trajectory.r[0, 0], r.trajectory.v[0, 0], t)
        assert np.allclose(p[0], ref_r, rtol=0, atol=1e-9), t
        assert np.allclose(q[0], ref_v, rtol=0, atol=1e-9), t
    k = 7
    assert np.array_equal(r.sol(times[k])[0], r.trajectory.r[k])  # a sample time gives the sample
    after = r.sol(times[-1])[0]
    assert np.array_equal(after, r.trajectory.r[-1])  # after the landing: the landing state
    with pytest.raises(ScenarioError, match="allowed: 0 <= t"):
        r.sol(times[-1] + 1)


def test_sol_refuses_other_methods():
    r = rotframe.run("tower-drop")  # exact
    with pytest.raises(ScenarioError, match="allowed: a dop853 run"):
        r.sol(1.0)


def test_sol_restarts_with_the_tolerances_the_run_took(monkeypatch):
    """Dense output restarts each particle with the absolute tolerances its run took (the engine's own rule for the
    tower drop: its scale in r and another in v; the scene's for foucault), and gives the run restarted from the
    sample on the engine, to round-off."""
    from rotframe.particles import integrators
    from rotframe.problem.particles import simulate_particles
    from rotframe.scenes.base import engine_terms

    taken = []
    real = integrators.integrate_particles

    def spy(*args, **kwargs):
        taken.append(kwargs["atol"])
        return real(*args, **kwargs)

    for name, kw in (("tower-drop", {"samples": 20, "rtol": 1e-6}), ("foucault", {"duration": 60.0, "rtol": 1e-6})):
        r = rotframe.run(name, "DOP853", **kw)
        traj = r._scene_result.trajectory
        rows = traj.extras["atol"]
        assert rows.shape == (1, 6)
        if name == "tower-drop":  # the engine's own rule: not one number for r and v
            assert rows[0, 0] != rows[0, 3]
        k = 3
        t = 0.5 * (traj.times[k] + traj.times[k + 1])
        with monkeypatch.context() as m:
            m.setattr(integrators, "integrate_particles", spy)
            pos, vel = r.sol(t)
        assert taken[-1] == tuple(rows[0])
        omega, forces, frame_terms = engine_terms(r._scene_result.extras["model"])
        again = simulate_particles(omega=omega, forces=forces, frame_terms=frame_terms, r0=traj.r[k, 0],
                                   v0=traj.v[k, 0], duration=t - traj.times[k], method="dop853", rtol=kw["rtol"],
                                   atol=rows[0], samples=1).trajectory
        scale = np.max(np.abs(traj.r[k, 0])) + 1.0
        assert np.allclose(pos[0], again.r[-1, 0], rtol=0, atol=1e-12 * scale), name
        assert np.allclose(vel[0], again.v[-1, 0], rtol=0, atol=1e-12 * scale), name
