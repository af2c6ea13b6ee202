"""Scene parameters as typed, frozen dataclasses (issue 14): names match the scenario files, typos are refused."""

import dataclasses
import tomllib
from pathlib import Path

import pytest

from cli_calls import assert_clean, call
from rotframe import scenes
from rotframe.errors import ScenarioError
from rotframe.scenes.base import scene_parameters

REPO = Path(__file__).resolve().parents[1]
BUILTIN = [name for name, target in scenes.SCENES.items() if isinstance(target, str)]


@pytest.mark.parametrize("name", BUILTIN)
def test_dataclass_fields_are_the_scenario_file_parameters(name):
    """Each built-in scene declares exactly the parameters of its scenario file, no more, no fewer.

    A field the file lacks would fail every run; a file parameter the dataclass lacks would be
    refused: either is a misspelt name, caught here rather than by a user.
    """
    scene = scenes.get(name)
    fields = {f.name for f in dataclasses.fields(scene.PARAMETERS)}
    data = tomllib.loads((REPO / "scenarios" / f"{name}.toml").read_text(encoding="utf-8"))
    assert fields == set(data["parameters"]), name
    assert dataclasses.is_dataclass(scene.PARAMETERS) and scene.PARAMETERS.__dataclass_params__.frozen
    for func in ("simulate", "analyse", "record"):
        assert getattr(getattr(scene, func), "parameters", None) is scene.PARAMETERS, (name, func)


def test_builder_converts_types_and_refuses_unknown_and_missing_keys():
    from rotframe.scenes.dzhanibekov import DzhanibekovParameters
    from rotframe.scenes.foucault import FoucaultParameters

    p = scene_parameters(DzhanibekovParameters, {"i1": 1, "i2": 2.0, "i3": 3.0, "omega": [0.1, 2, 0.0],
                                                 "duration": 5.0, "run": {"method": "exact"}})
    assert p.omega == (0.1, 2.0, 0.0) and isinstance(p.i1, float) and p.i1 == 1.0
    assert scene_parameters(DzhanibekovParameters, p) is p
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.i1 = 2.0
    with pytest.raises(AttributeError):
        p.latitude  # noqa: B018  (a name the scene does not have)
    with pytest.raises(ScenarioError, match="^parameter i4 = 4.0: not a parameter") as info:
        scene_parameters(DzhanibekovParameters, {"i1": 1.0, "i2": 2.0, "i3": 3.0, "i4": 4.0})
    assert "\n" not in str(info.value) and "allowed: i1, i2, i3, omega, duration" in str(info.value)
    with pytest.raises(ScenarioError, match="duration: missing"):
        scene_parameters(DzhanibekovParameters, {"i1": 1.0, "i2": 2.0, "i3": 3.0, "omega": [1, 0, 0]})
    # defaults (the display and model choices that the scene had as fallbacks) fill what is left out
    f = scene_parameters(FoucaultParameters, {"length": 67.0, "latitude": 48.8, "amplitude": 3.0, "duration": 10.0,
                                              "small_angle": False})
    assert f.g_model == "wgs84" and f.record_samples == 20000
    with pytest.raises(ScenarioError, match="small_angle = 'no': expected true or false"):
        scene_parameters(FoucaultParameters, {"length": 67.0, "latitude": 48.8, "amplitude": 3.0,
                                              "duration": 10.0, "small_angle": "no"})


def test_a_scene_still_takes_a_plain_dict():
    """The scene protocol passes a mapping: plugins and scripts that call a scene with a dict keep working."""
    from rotframe.scenes import heavy_top

    inertia, L0, q0 = heavy_top.build({"i1": 1.9e-4, "i3": 2.5e-5, "mass": 0.1, "length": 0.04, "g": 9.81,
                                       "theta0": 20.0, "phidot0": 0.0, "psidot0": 300.0, "wobble": 0.0,
                                       "duration": 1.0})
    assert inertia.tolist() == [1.9e-4, 1.9e-4, 2.5e-5] and L0.shape == (3,) and q0.shape == (4,)


def test_an_unknown_parameter_in_a_scenario_file_is_refused_with_exit_2(tmp_path, capsys):
    """A file that adds a parameter its scene does not have (a typo, or a key meant for another scene)."""
    path = tmp_path / "drop.toml"
    path.write_text('scene = "tower-drop"\n[parameters.hieght]\ndefault = 20.0\nunit = "m"\n', encoding="utf-8")
    code, out, err = call(capsys, "run", path, "--no-record")
    assert_clean(code, out, err, allowed=(2,))
    assert "hieght" in err and "not a parameter" in err and "height" in err


def _normal_gravity(lat_rad):  # WGS84 normal gravity (Somigliana), written out here as the oracle
    import math
    s2 = math.sin(lat_rad) ** 2
    return 9.7803253359 * (1 + 0.00193185265241 * s2) / math.sqrt(1 - 0.00669437999013 * s2)


def test_a_file_that_redeclares_a_parameter_in_another_unit_is_converted_to_the_scenes_unit(tmp_path, capsys):
    """height in km in a user file runs as the same height in metres (issue 27): the fall time is the
    one of 158.5 m, to round-off, and agrees with sqrt(2 h / g) (g: normal gravity at the latitude)."""
    import json
    import math

    km = tmp_path / "km.toml"
    km.write_text('scene = "tower-drop"\n[parameters.height]\ndefault = 0.1585\nunit = "km"\nmin = 0.0\n',
                  encoding="utf-8")
    code, out, err = call(capsys, "run", km, "--no-record", "--json")
    assert_clean(code, out, err, allowed=(0,))
    got = json.loads(out)
    assert got["params"]["height"] == pytest.approx(158.5, rel=1e-15)
    code, out, err = call(capsys, "run", "tower-drop", "--no-record", "--json")
    ref = json.loads(out)
    assert got["metrics"]["fall_time_s"] == pytest.approx(ref["metrics"]["fall_time_s"], rel=1e-13)
    lat = math.radians(50 + 53 / 60)
    closed = math.sqrt(2 * 158.5 / _normal_gravity(lat))
    assert abs(got["metrics"]["fall_time_s"] - closed) < 1e-6  # Coriolis changes the fall time by ~1e-7 s
    # the bounds a file gives in its own unit are converted too: 0.2 km is above a max of 0.19 km
    km.write_text('scene = "tower-drop"\n[parameters.height]\ndefault = 0.2\nunit = "km"\nmax = 0.19\n',
                  encoding="utf-8")
    code, out, err = call(capsys, "run", km, "--no-record")
    assert_clean(code, out, err, allowed=(2,))
    assert "height" in err and "190" in err


@pytest.mark.parametrize("unit", ["s", "kg", "furlong/fortnight", "not-a-unit"])
def test_a_redeclared_unit_of_another_dimension_is_refused_naming_file_key_and_units(tmp_path, capsys, unit):
    path = tmp_path / "odd.toml"
    path.write_text(f'scene = "tower-drop"\n[parameters.height]\ndefault = 0.1585\nunit = "{unit}"\n',
                    encoding="utf-8")
    code, out, err = call(capsys, "run", path, "--no-record")
    assert_clean(code, out, err, allowed=(2,))
    assert "odd.toml" in err and "height" in err and repr(unit) in err and "'m'" in err
    with pytest.raises(ScenarioError, match="height"):
        import rotframe
        rotframe.run(str(path))


def test_a_redeclared_angle_in_radians_is_converted_to_degrees(tmp_path):
    import math

    from rotframe.app import scenario as sc

    path = tmp_path / "rad.toml"
    path.write_text('scene = "tower-drop"\n[parameters.latitude]\ndefault = 0.5\nunit = "rad"\n', encoding="utf-8")
    p = sc.load(str(path)).parameters["latitude"]
    assert p.unit == "deg" and p.default == pytest.approx(math.degrees(0.5), rel=1e-15)
    assert (p.min, p.max) == (-90, 90)
