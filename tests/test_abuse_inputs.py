"""Abuse of the command line, in process: whatever the input, exit 0, 2 or 3, one line, no traceback.

A hypothesis test feeds generated ``--set`` values, scenario files and sweep specs
to :func:`rotframe.app.cli.main`; the examples are kept small (``--max-steps`` and
``--max-samples`` bound each run's work) so that the whole file runs in well
under a minute. The named cases below are the ones found by hand (issue 12).
"""

import json

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings, strategies as st  # noqa: E402


BOUNDS = ["--max-steps", "2e5", "--max-samples", "2e4"]


from cli_calls import assert_clean, call  # noqa: E402


# ---------------------------------------------------------------------------
# generated input
# ---------------------------------------------------------------------------

NUMBERS = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-10**30, 10**30))
TEXTS = st.one_of(
    NUMBERS.map(repr),
    st.sampled_from(["", " ", "abc", "nan", "-inf", "1e400", "3 ft", "3 s", "48d50m N", "1,2,3", "1,2", "0x10",
                     "None", "true", "1e-320", "10 lightyear", "5 kg", "1/0", "1 m m", "😀", "\x00", "1e12",
                     "lie-poisson", "splitting", "exact"]),
    st.text(max_size=12),
)
RUN_KEYS = ["duration", "latitude", "height", "length", "amplitude", "speed", "samples", "step", "rtol", "method",
            "small_angle", "g_model", "drag", "omega0", "i1", "i3", "theta0", "nosuch", "record_samples"]


@settings(max_examples=25, deadline=None, suppress_health_check=list(HealthCheck))
@given(name=st.sampled_from(["tower-drop", "foucault", "free-top", "turntable", "inertial-oscillation"]),
       sets=st.lists(st.tuples(st.sampled_from(RUN_KEYS), TEXTS), max_size=3),
       json_flag=st.booleans())
def test_generated_sets_never_traceback(capsys, name, sets, json_flag):
    argv = ["run", name, "--no-record", "--set", "duration=0.5"]
    for key, value in sets:
        argv += ["--set", f"{key}={value}"]
    code, out, err = call(capsys, *argv, *BOUNDS, *(["--json"] if json_flag else []))
    assert_clean(code, out, err)
    if json_flag and code == 0:
        json.loads(out)  # stdout is exactly one JSON document


TOML_VALUES = st.sampled_from(['"zero"', "5", "-1", "1e400", "[1, 2]", "true", '"3 ft"', "{ a = 1 }", "[]", '""',
                               '"x"', "0", "1.5", '"../../x"', '"/tmp/abs"'])


@settings(max_examples=25, deadline=None, suppress_health_check=list(HealthCheck))
@given(top=st.lists(st.tuples(st.sampled_from(["name", "title", "description", "model", "optional_terms",
                                               "parameters", "bogus"]), TOML_VALUES), max_size=2, unique_by=lambda t: t[0]),
       scene=st.sampled_from(['"foucault"', '"free-top"', '"tower-drop"', '"nosuch"', "5"]),
       params=st.lists(st.tuples(st.sampled_from(["length", "latitude", "duration", "height", "i1", "new"]),
                                 st.sampled_from(["default", "min", "max", "unit", "shape", "type", "doc",
                                                  "choices", "exclusive_min"]),
                                 TOML_VALUES), max_size=3),
       run=st.lists(st.tuples(st.sampled_from(["method", "step", "samples", "rtol", "nope"]), TOML_VALUES),
                    max_size=2, unique_by=lambda t: t[0]))
def test_generated_scenario_files_never_traceback(tmp_path_factory, capsys, top, scene, params, run):
    folder = tmp_path_factory.mktemp("toml")
    lines = [f"{k} = {v}" for k, v in top] + [f"scene = {scene}"]
    tables = {}
    for pname, key, value in params:
        tables.setdefault(pname, {})[key] = value
    for pname, kv in tables.items():
        lines.append(f"[parameters.{pname}]")
        lines += [f"{k} = {v}" for k, v in kv.items()]
    if run:
        lines.append("[run]")
        lines += [f"{k} = {v}" for k, v in run]
    path = folder / "gen.toml"
    path.write_text("\n".join(lines) + "\n")
    for command in (["show", str(path)], ["run", str(path), "--no-record", "--set", "duration=0.2", *BOUNDS]):
        code, out, err = call(capsys, *command)
        assert_clean(code, out, err)


@settings(max_examples=20, deadline=None, suppress_health_check=list(HealthCheck))
@given(axis=st.tuples(st.sampled_from(["latitude", "height", "drag", "nosuch", "latitude[0]", ""]), TEXTS, TEXTS,
                      st.sampled_from(["0", "1", "3", "-2", "1e9", "x", "2.5", ""])),
       mode=st.sampled_from(["grid", "log-grid", "vary"]),
       seed=st.sampled_from(["0", "-1", "abc", "99999999999999999999999"]))
def test_generated_sweep_specs_never_traceback(tmp_path, capsys, monkeypatch, axis, mode, seed):
    monkeypatch.chdir(tmp_path)
    key, a, b, n = axis
    if mode == "vary":
        spec = ["--samples", n or "3", "--vary", f"{key}=uniform({a},{b})", "--seed", seed]
    else:
        spec = [f"--{mode}", f"{key}={a}:{b}:{n}"]
    code, out, err = call(capsys, "sweep", "tower-drop", *spec, "--max-rows", "4", *BOUNDS, "--out",
                          str(tmp_path / "s.parquet"), "--json")
    assert_clean(code, out, err)


# ---------------------------------------------------------------------------
# the cases of issue 12, one by one
# ---------------------------------------------------------------------------

FILES = {
    "binary.toml": b"\x89PNG\r\n\x1a\n\x00\xff\xfe",
    "min.toml": b'scene = "foucault"\n[parameters.length]\ndefault = 10.0\nmin = "zero"\n',
    "shape.toml": b'scene = "foucault"\n[parameters.length]\ndefault = 10.0\nshape = "three"\n',
    "params.toml": b'scene = "foucault"\nparameters = "x"\n',
    "desc.toml": b'scene = "foucault"\ndescription = 5\n',
    "slug.toml": b'name = "../../x"\nscene = "foucault"\n',
    "abs.toml": b'name = "/tmp/evil"\nscene = "foucault"\n',
    "unknown.toml": b'scene = "nosuch"\n',
    "method.toml": b'scene = "foucault"\n[run]\nmethod = "lie-poisson"\n',
}


@pytest.mark.parametrize("fname", sorted(FILES))
@pytest.mark.parametrize("command", ["run", "show"])
def test_bad_scenario_files_are_one_line(tmp_path, capsys, fname, command):
    path = tmp_path / fname
    path.write_bytes(FILES[fname])
    code, out, err = call(capsys, command, str(path), *(["--no-record"] if command == "run" else []))
    assert code == 2, (out, err)
    assert_clean(code, out, err)
    assert fname in err


def test_partial_file_takes_missing_parameters_from_the_builtin_scene(tmp_path, capsys):
    path = tmp_path / "mine.toml"
    path.write_text('scene = "foucault"\n[parameters.length]\ndefault = 10.0\nunit = "m"\n'
                    '[parameters.latitude]\ndefault = 45.0\nunit = "deg"\n')
    code, out, err = call(capsys, "run", str(path), "--no-record", "--json", "--set", "duration=60")
    assert code == 0, err
    summary = json.loads(out)
    assert summary["params"]["length"] == 10.0 and summary["params"]["latitude"] == 45.0
    assert "amplitude" in summary["params"]  # from scenarios/foucault.toml
    assert summary["model"] == ["gravity", "coriolis", "pendulum"]


def test_rigid_method_from_file_or_set_is_accepted(tmp_path, capsys):
    path = tmp_path / "top.toml"
    path.write_text('scene = "free-top"\n[run]\nmethod = "lie-poisson"\nsamples = 100\n')
    code, out, err = call(capsys, "run", str(path), "--no-record", "--json", "--set", "duration=1000", "--set",
                          "step=10")
    assert code == 0, err
    assert json.loads(out)["method"] == "lie-poisson"
    code, out, err = call(capsys, "run", "free-top", "--no-record", "--json", "--set", "method=lie-poisson",
                          "--set", "duration=1000", "--set", "step=10", "--set", "samples=100")
    assert code == 0, err
    assert json.loads(out)["method"] == "lie-poisson"


def test_scenario_methods_match_the_scene_modules():
    from rotframe import scenes
    from rotframe.app import scenario
    from rotframe.particles.integrators import METHOD_NAMES

    for name in scenes.SCENES:
        assert set(scenario.methods_for(name)) == set(getattr(scenes.get(name), "METHODS", METHOD_NAMES)), name


def test_file_recording_goes_under_recordings(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "elsewhere" / "spin.toml"
    path.parent.mkdir()
    path.write_text('name = "spin"\nscene = "turntable"\n')
    code, out, err = call(capsys, "run", str(path), "--set", "duration=0.5", "--set", "samples=50")
    assert code == 0, err
    assert (tmp_path / "recordings" / "spin.rrd").is_file()


@pytest.mark.parametrize("argv,fragment", [
    (["run", "foucault", "--set", "samples=1e12"], "--max-"),
    (["run", "foucault", "--set", "duration=100 yr"], "--max-steps"),
    # foucault's default (dop853) chooses its own steps: a fixed step is a fixed-step method's setting
    (["run", "foucault", "--method", "splitting", "--set", "step=1e-12"], "--max-steps"),
    (["run", "free-top", "--set", "samples=1e12"], "--max-samples"),
    # a fixed step far below what the work limit allows
    (["run", "heavy-top", "--method", "top-splitting", "--set", "step=1e-12"], "--max-steps"),
    (["run", "heavy-top", "--set", "duration=1e9"], "--max-steps"),
    (["sweep", "tower-drop", "--grid", "latitude=0:90:1000000000"], "--max-rows"),
    (["sweep", "tower-drop", "--samples", "1000000000", "--vary", "latitude=uniform(0,90)"], "--max-rows"),
    (["sweep", "tower-drop", "--grid", "latitude=0:90:2000", "--grid", "height=1:100:2000"], "--max-rows"),
])
def test_work_over_the_limits_is_refused_with_the_estimate(tmp_path, capsys, monkeypatch, argv, fragment):
    monkeypatch.chdir(tmp_path)
    code, out, err = call(capsys, *argv, *(["--no-record"] if argv[0] == "run" else []))
    assert code == 2, err
    assert_clean(code, out, err)
    assert fragment in err and "limit" in err
    assert not list(tmp_path.rglob("*.rrd")) and not list(tmp_path.rglob("*.parquet"))


def test_the_limit_flags_raise_the_limits(capsys):
    code, _, err = call(capsys, "run", "tower-drop", "--method", "splitting", "--set", "step=1e-4", "--no-record",
                        "--max-steps", "10")
    assert code == 2 and "limit of 10" in err
    code, _, err = call(capsys, "run", "tower-drop", "--method", "splitting", "--set", "step=1e-4", "--no-record",
                        "--max-steps", "1e6")
    assert code == 0, err


@pytest.mark.parametrize("argv,fragment", [
    (["sweep", "tower-drop", "--samples", "3", "--vary", "latitude=uniform(0,90)", "--seed", "-1"], "seed"),
    (["run", "foucault", "--bogus"], "unrecognized arguments"),
    (["run"], "required"),
    (["sweep", "tower-drop", "--samples", "x"], "--samples"),
    (["nosuchcommand"], "invalid choice"),
])
def test_usage_errors_are_one_line(capsys, argv, fragment):
    code, out, err = call(capsys, *argv)
    assert code == 2
    assert_clean(code, out, err)
    assert fragment in err


def test_an_example_value_is_a_real_value(tmp_path, capsys):
    path = tmp_path / "ex.toml"
    path.write_text('scene = "foucault"\n[parameters.length]\ndefault = "long"\nunit = "m"\n')
    code, _, err = call(capsys, "run", str(path), "--no-record")
    assert code == 2 and "None" not in err and "e.g. '1 m'" in err
    code, _, err = call(capsys, "run", "foucault", "--no-record", "--set", "step=fast")
    assert code == 2 and "None" not in err


def test_a_sweep_whose_every_row_is_invalid_is_an_input_error(tmp_path, capsys):
    # amplitude must stay below length: every row of this grid is refused by the scene's own check
    code, out, err = call(capsys, "sweep", "foucault", "--set", "length=1", "--grid", "amplitude=2:3:2",
                          "--set", "duration=10", "--out", str(tmp_path / "f.parquet"))
    assert code == 2, err
    assert_clean(code, out, err)
    assert "invalid" in err


@pytest.mark.parametrize("argv,fragment", [
    (["section", "rectangle", "--set", "width=1e200", "--set", "height=1e200"], "width"),
    (["section", "rectangle", "--set", "width=1e-200", "--set", "height=1"], "width"),
    (["section", "polygon", "--set", "vertices=0,0;1,0;1,1;0,1", "--set", "holes=0.2,0.2;0.8,0.2;0.8,0.8;0.2,0.8|"
      "0.3,0.3;0.7,0.3;0.7,0.7;0.3,0.7"], "polygon"),
])
def test_section_errors_keep_the_prefix_and_plain_numbers(recwarn, capsys, argv, fragment):
    code, out, err = call(capsys, *argv)
    assert code == 2
    assert err.startswith("rotframe section: ") and err.count("\n") == 1, err
    assert "np.float64" not in err and fragment in err
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]


def test_section_far_from_the_origin_keeps_its_area(capsys):
    # a valid 1 mm x 2 mm rectangle 3e6 m from the origin: area 2e-6 m^2 (cancellation-free on centred coordinates)
    code, out, err = call(capsys, "section", "polygon", "--json", "--set",
                          "vertices=3e6,0;3000000.001,0;3000000.001,0.002;3e6,0.002")
    assert code == 0, err
    area = json.loads(out)["properties"]["area"]
    # the coordinates themselves are rounded to ulp(3e6) = 4.7e-10 m: 1e-6 relative on a 1 mm side
    assert area == pytest.approx(2e-6, rel=2e-6)


def test_a_tiny_hole_far_away_is_subtracted():
    from rotframe.rigid.sections import polygon

    o = 3e6
    sq = [[o, o], [o + 1, o], [o + 1, o + 1], [o, o + 1]]
    hole = [[o + 0.5, o + 0.5], [o + 0.5001, o + 0.5], [o + 0.5001, o + 0.5001], [o + 0.5, o + 0.5001]]
    # exact net area 1 - 1e-8 m^2; coordinates near 3e6 m carry ulp 4.7e-10 m, so 1e-9 relative is the resolution
    assert polygon(sq, [hole]).area == pytest.approx(1 - 1e-8, rel=1e-9)
    assert polygon(sq, [hole[::-1]]).area < 1.0


def test_python_api_junk_is_a_rotframe_error():
    import numpy as np

    from rotframe import frames

    from rotframe.rigid import mass_properties as inertia

    from rotframe.rigid import dynamics as rigid
    from rotframe.errors import NotARotationError, RotframeError

    junk = ["abc", 1 + 2j, object(), None, [["a"] * 3] * 3, np.eye(3) * (1 + 1j)]
    for mod in (frames, inertia, rigid):
        for name in mod.__all__:
            func = getattr(mod, name)
            if not callable(func) or isinstance(func, type):
                continue
            for value in junk:
                try:
                    func(value)
                except RotframeError as exc:
                    assert isinstance(exc, ValueError)
                except TypeError as exc:  # a missing required argument, not bad data
                    assert "required positional" in str(exc) or "missing" in str(exc), (name, exc)
    rot = np.eye(3).astype(complex)
    rot[0, 1] = 1e-3j
    with pytest.raises(NotARotationError):
        frames.check_rotation(rot)


@settings(max_examples=40, deadline=None)
@given(st.one_of(st.text(max_size=5), st.complex_numbers(), st.lists(st.complex_numbers(), min_size=3, max_size=3),
                 st.lists(st.text(max_size=2), min_size=3, max_size=3), st.none(), st.dictionaries(st.text(), st.text())))
def test_hypothesis_junk_to_the_python_api(value):
    from rotframe import frames
    from rotframe.rigid import mass_properties as inertia
    from rotframe.rigid import dynamics as rigid
    from rotframe.errors import RotframeError

    calls = [lambda: frames.euler_to_dcm(value, "ZXZ"), lambda: frames.check_rotation(value),
             lambda: frames.elemental("x", value), lambda: inertia.check_tensor(value),
             lambda: inertia.principal_moments(value), lambda: inertia.solid_sphere(value, 1.0),
             lambda: rigid.energy(value, [1.0, 2.0, 3.0]), lambda: rigid.omega_body([1.0, 2.0, 3.0], value)]
    for c in calls:
        try:
            c()
        except RotframeError as exc:
            assert isinstance(exc, ValueError)


@pytest.mark.parametrize("value", ["INF", float("inf"), [0.0, float("-inf"), 1.0]])
def test_an_infinite_angle_is_refused_in_one_line_even_with_warnings_as_errors(value):
    """numpy's warning of cos(inf) is not the answer: the guard's one-line NaN refusal is, also where the caller's
    filters turn warnings into errors (a test suite, ``python -W error``)."""
    import warnings

    from rotframe import frames
    from rotframe.errors import RotframeError

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for call in (lambda: frames.elemental("x", value), lambda: frames.euler_to_dcm(
                np.broadcast_to(np.asarray(value if not isinstance(value, str) else np.inf, float), (3,)), "ZXZ")):
            with pytest.raises(RotframeError) as err:
                call()
            assert isinstance(err.value, ValueError) and "\n" not in str(err.value)
