"""Held-out abuse (issue 12 follow-up): classes of bad input found after the issue's own catalogue.

Every case must end with exit 0, 2 or 3, ONE line on stderr when non-zero and no
traceback; a run that fails must not print a NaN as if it were a result.
Each case is a single short run (tower-drop with the exact propagator, or a
refusal before any integration), so the file runs in a few seconds.
"""

import json

import pytest



from cli_calls import assert_clean, call  # noqa: E402


def scenario_file(tmp_path, parameters: str) -> str:
    path = tmp_path / "s.toml"
    path.write_text('scene = "tower-drop"\nname = "s"\n' + parameters)
    return str(path)


@pytest.mark.parametrize("parameters", [
    # a bare value overrides only the default: the built-in bounds (height > 0) still hold
    "[parameters]\nheight = -1\n",
    # a list where the scene takes a number: refused, not a TypeError deep in the scene
    "[parameters]\nheight = []\n",
    "[parameters.latitude]\ndefault = []\n",
    "[parameters.drag]\ndefault = [1, 2]\n",
    # a string parameter given a list or a table
    "[parameters.g_model]\ndefault = [\"wgs84\"]\n",
])
def test_file_overrides_keep_the_scenes_kind_and_bounds(tmp_path, capsys, parameters):
    code, out, err = call(capsys, "run", scenario_file(tmp_path, parameters), "--no-record", "--json")
    assert_clean(code, out, err, allowed=(2,))
    assert "parameters" in err or "height" in err or "latitude" in err or "drag" in err or "g_model" in err


@pytest.mark.parametrize("parameters", [
    "[parameters.height]\ndefault = 1e308\n",  # the fall time overflows to inf
    "[parameters]\nheight = 1e308\n",
])
def test_overflowing_duration_is_refused_in_one_line(tmp_path, capsys, parameters):
    code, out, err = call(capsys, "run", scenario_file(tmp_path, parameters), "--no-record", "--json")
    assert_clean(code, out, err, allowed=(2, 3))
    assert "RuntimeWarning" not in err
    assert "nan" not in err.lower().replace("finite", "")


def test_empty_vector_is_refused():
    from rotframe.errors import ScenarioError
    from rotframe.app.scenario import Parameter, parse_value

    p = Parameter(name="v", default=[0.0, 0.0, 0.0], unit="m", type="vector")
    with pytest.raises(ScenarioError, match="one or more"):
        parse_value(p, [])
    with pytest.raises(ScenarioError):
        parse_value(p, "")


def test_api_refuses_a_non_finite_duration_or_state():
    import numpy as np

    from rotframe.errors import ScenarioError
    from rotframe.particles.integrators import integrate_particles
    from rotframe.particles.model import ParticleModel

    model = ParticleModel(terms=("gravity",), g=np.array([0.0, 0.0, -9.8]))
    for duration in (float("inf"), float("nan"), -1.0, 0.0):
        with pytest.raises(ScenarioError, match="duration"):
            integrate_particles(model, [0, 0, 1], [0, 0, 0], duration, method="exact")
    with pytest.raises(ScenarioError, match="non-finite"):
        integrate_particles(model, [0, 0, float("inf")], [0, 0, 0], 1.0, method="exact")


def test_an_interrupt_swallowed_in_a_destructor_is_delivered_again(capsys):
    """Python swallows (and prints) an exception raised in ``__del__`` or a weakref callback.

    A Ctrl-C whose handler ran there was lost and printed a traceback; the scope keeps it
    quiet and delivers the signal again, so the work still stops.
    """
    import time

    from rotframe.app.signals import InterruptScope

    class Dies:
        def __del__(self):
            raise KeyboardInterrupt()

    with pytest.raises(KeyboardInterrupt):
        with InterruptScope():
            Dies()
            time.sleep(5)  # the signal delivered again interrupts this within 0.1 s
    err = capsys.readouterr().err
    assert "Exception ignored" not in err and "Traceback" not in err


@pytest.mark.parametrize("call_it", [
    # an integer too large for a float: OverflowError, an ArithmeticError, not a ValueError
    lambda: __import__("rotframe").frames.euler_to_dcm([10**400, 0, 0], "zyx"),
    lambda: __import__("rotframe").inertia.solid_sphere(10**400, 1.0),
    # object input whose arithmetic divides by zero
    lambda: __import__("rotframe.rigid.dynamics").rigid.dynamics.rigid_rhs(__import__("numpy").array([1, 2, 3], dtype=object),
                                                   [0.0, 0.0, 1.0]),
])
def test_arithmetic_errors_from_junk_input_are_rotframe_errors(call_it):
    from rotframe.errors import RotframeError

    with pytest.raises(RotframeError):
        call_it()


@pytest.mark.parametrize("call_it", [
    lambda: __import__("rotframe").frames.euler_to_dcm([float("nan"), 0, 0], "zyx"),
    lambda: __import__("rotframe").frames.space_derivative([0, 0, 1.0], [float("nan"), 0, 0], [0, 0, 0]),
    lambda: __import__("rotframe").inertia.point_masses([1e308, 1e308], [[1e200, 0, 0], [-1e200, 0, 0]]),
])
@pytest.mark.filterwarnings("ignore::RuntimeWarning")  # numpy's overflow warning comes before the refusal
def test_a_nan_result_is_refused_not_returned(call_it):
    """NaN in, or an overflow inside, must not come back as a silent NaN."""
    from rotframe.errors import RotframeError

    with pytest.raises(RotframeError, match="NaN"):
        call_it()


@pytest.mark.parametrize("kw", [{"height": 10**400}, {"samples": 10**400}])
def test_api_integers_beyond_a_float_are_refused(kw):
    import rotframe
    from rotframe.errors import RotframeError

    with pytest.raises(RotframeError, match="finite"):
        rotframe.run("tower-drop", **kw)


@pytest.mark.parametrize("name", ["a" * 5000 + ".toml", "a" * 5000, "x\x00.toml"])
def test_scenario_names_the_system_cannot_open_are_refused(capsys, name):
    import rotframe
    from rotframe.errors import RotframeError

    with pytest.raises(RotframeError):
        rotframe.load(name)
    code, out, err = call(capsys, "show", name)
    assert_clean(code, out, err, allowed=(2,))


def test_a_toml_file_nested_thousands_deep_is_refused(tmp_path, capsys):
    path = tmp_path / "deep.toml"
    path.write_text("a = " + "[" * 5000 + "]" * 5000 + "\n")
    code, out, err = call(capsys, "show", str(path))
    assert_clean(code, out, err, allowed=(2,))
    assert "nested too deeply" in err


def test_more_periods_than_a_float_counts_are_unresolved_not_an_overflow():
    from rotframe.scenes.base import samples_for

    assert samples_for(1e308, 1e-10, 2000) == (2000, False)


def test_the_command_line_prints_no_numpy_warnings():
    """An overflow inside the analysis is handled (null metric, note); numpy's warning lines stay off stderr."""
    import os
    import subprocess
    import sys

    # issue 27: a rate whose energy overflows a float64 (1e200) is now refused up front, in one line; one just
    # below it (1e153: energy 1.5e306) runs, with its analysis near float64's end
    proc = subprocess.run([sys.executable, "-m", "rotframe", "run", "dzhanibekov", "--no-record", "--json",
                           "--set", "omega=1e153,1e153,1e153"], capture_output=True, text=True, timeout=120,
                          env={**os.environ, "PYTHONWARNINGS": ""})
    assert proc.returncode == 0, proc.stderr
    assert "RuntimeWarning" not in proc.stderr
    json.loads(proc.stdout)
    proc = subprocess.run([sys.executable, "-m", "rotframe", "run", "dzhanibekov", "--no-record", "--json",
                           "--set", "omega=1e200,1e200,1e200"], capture_output=True, text=True, timeout=120,
                          env={**os.environ, "PYTHONWARNINGS": ""})
    assert proc.returncode == 2 and "RuntimeWarning" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1 and "omega" in proc.stderr


@pytest.mark.parametrize("sig,code", [("SIGINT", 130), ("SIGTERM", 143)])
def test_a_signal_while_starting_is_one_line_and_the_shells_code(sig, code):
    """The entry point handles signals before importing the command line (no import traceback)."""
    import subprocess
    import sys

    script = ("import os, signal, time, rotframe.app.console\n"
              f"os.kill(os.getpid(), signal.{sig})\n"
              "time.sleep(10)\n")
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
    assert proc.returncode == code
    assert proc.stderr.strip().splitlines() == [proc.stderr.strip()] and "while starting" in proc.stderr
    assert "Traceback" not in proc.stderr
