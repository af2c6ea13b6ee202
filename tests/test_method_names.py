"""Method names (issue 14): one source per kind, canonical names reported, old names still accepted."""

import pytest

from cli_calls import assert_clean, call
from rotframe import scenes
from rotframe.particles import integrators
from rotframe.scenes.base import MethodNames, particle_methods

PARTICLE_SCENES = ("turntable", "tower-drop", "foucault", "inertial-oscillation", "projectile")


def test_particle_scenes_take_their_methods_from_the_registry():
    for name in PARTICLE_SCENES:
        assert tuple(scenes.get(name).METHODS) == tuple(integrators.METHODS), name


def test_heavy_top_methods_are_renamed_and_the_old_names_are_aliases():
    from rotframe.scenes import heavy_top

    assert tuple(heavy_top.METHODS) == ("top-splitting", "top-splitting4", "top-splitting6", "top-splitting8",
                                        "rk4", "dop853")
    for old, new in (("splitting", "top-splitting"), ("splitting4", "top-splitting4"),
                     ("splitting6", "top-splitting6")):
        assert old in heavy_top.METHODS and heavy_top.METHODS.canonical(old) == new
    assert "lie-poisson" not in heavy_top.METHODS and "exact" not in heavy_top.METHODS


@pytest.mark.parametrize("old,new", [("splitting", "top-splitting"), ("splitting4", "top-splitting4")])
def test_an_old_heavy_top_name_runs_the_same_method_and_reports_the_new_name(old, new):
    """The alias is resolved before the run: the same kernel, so the same numbers to the last bit."""
    s_old = rotframe_run("heavy-top", old)
    s_new = rotframe_run("heavy-top", new)
    assert s_old["method"] == s_new["method"] == new
    assert s_old["metrics"] == s_new["metrics"] and s_old["steps"] == s_new["steps"]


def rotframe_run(name, method):
    from rotframe.app import runner

    summary, _ = runner.run(name, {"duration": "0.5"}, method=method)
    return summary


def test_heavy_top_default_is_the_canonical_name(capsys):
    import json

    code, out, err = call(capsys, "run", "heavy-top", "--set", "duration=0.2", "--no-record", "--json")
    assert_clean(code, out, err, allowed=(0,))
    assert json.loads(out)["method"] == "top-splitting8"  # the scenario's default since issue 27
    code, out, err = call(capsys, "run", "heavy-top", "--method", "splitting", "--set", "duration=0.2",
                          "--no-record", "--json")
    assert_clean(code, out, err, allowed=(0,))
    assert json.loads(out)["method"] == "top-splitting"


def test_a_scenario_file_may_name_an_old_method(tmp_path, capsys):
    import json

    path = tmp_path / "top.toml"
    path.write_text('scene = "heavy-top"\n[run]\nmethod = "splitting4"\nstep = 1e-4\n', encoding="utf-8")
    code, out, err = call(capsys, "run", path, "--set", "duration=0.2", "--no-record", "--json")
    assert_clean(code, out, err, allowed=(0,))
    assert json.loads(out)["method"] == "top-splitting4"
    path.write_text('scene = "heavy-top"\n[run]\nmethod = "lie-poisson"\n', encoding="utf-8")
    code, out, err = call(capsys, "run", path, "--no-record")
    assert_clean(code, out, err, allowed=(2,))
    assert "top-splitting" in err


def test_method_names_tuple_lists_canonical_names_only():
    names = MethodNames(("a", "b"), {"old-a": "a"})
    assert list(names) == ["a", "b"] and len(names) == 2 and ", ".join(names) == "a, b"
    assert "old-a" in names and "c" not in names and ["a"] not in names
    assert names.canonical("old-a") == "a" and names.canonical("b") == "b" and names.canonical(None) is None
    with pytest.raises(ValueError):
        MethodNames(("a",), {"x": "nowhere"})


def test_particle_aliases_run_and_report_the_canonical_name():
    methods = particle_methods()
    for old, new in integrators.ALIASES.items():
        assert old in methods and methods.canonical(old) == new
        summary = rotframe_run_particle("turntable", old)
        assert summary["method"] == new


def rotframe_run_particle(name, method):
    from rotframe.app import runner

    summary, _ = runner.run(name, {"duration": "0.2"}, method=method)
    return summary
