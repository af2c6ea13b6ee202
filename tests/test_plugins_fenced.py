"""Door 3 (issue 27): plugins are fenced by rotframe.scenes.register / _import_plugin.

A plugin that is missing, raises on import, has a syntax error, is not a scene, or brings a
scenario file that is not TOML gives exit 2 and one line naming it (a ScenarioError from
Python); a built-in name is refused unless ``override=True``; a plugin's prints at import
go to stderr, so ``--json`` stays one document on stdout.
"""

import json

import pytest

import rotframe
from cli_calls import assert_clean, call
from rotframe import scenes
from rotframe.errors import ScenarioError


@pytest.fixture(autouse=True)
def clean_registry(monkeypatch):
    saved = dict(scenes.SCENES), dict(scenes.SCENARIO_FILES), set(scenes._PLUGINS_LOADED)
    monkeypatch.delenv("ROTFRAME_PLUGINS", raising=False)
    yield
    scenes.SCENES.clear()
    scenes.SCENES.update(saved[0])
    scenes.SCENARIO_FILES.clear()
    scenes.SCENARIO_FILES.update(saved[1])
    scenes._PLUGINS_LOADED.clear()
    scenes._PLUGINS_LOADED.update(saved[2])


PLUGINS = {
    "raises": "raise RuntimeError('the plugin is broken')\n",
    "syntax": "def f(:\n    pass\n",
    "imports-missing": "import no_such_module_rotframe_test\n",
    "exits": "import sys\nsys.exit(3)\n",
    "registers-builtin": "import rotframe, rotframe.scenes.turntable as t\nrotframe.register_scene('turntable', t)\n",
    "registers-non-scene": "import rotframe, json\nrotframe.register_scene('mine', json)\n",
}


@pytest.mark.parametrize("kind", list(PLUGINS))
def test_a_faulty_plugin_is_exit_2_and_one_line_naming_it(tmp_path, monkeypatch, capsys, kind):
    plugin = tmp_path / f"plugin_{kind.replace('-', '_')}.py"
    plugin.write_text(PLUGINS[kind], encoding="utf-8")
    monkeypatch.setenv("ROTFRAME_PLUGINS", str(plugin))
    code, out, err = call(capsys, "run", "turntable", "--no-record")
    assert_clean(code, out, err, allowed=(2,))
    assert plugin.name in err, err


def test_a_missing_plugin_module_is_exit_2(monkeypatch, capsys):
    monkeypatch.setenv("ROTFRAME_PLUGINS", "no_such_plugin_module_x")
    code, out, err = call(capsys, "run", "turntable", "--no-record")
    assert_clean(code, out, err, allowed=(2,))
    assert "no_such_plugin_module_x" in err


@pytest.mark.parametrize("content", ["this is = not [toml", "\xff\xfe", "[parameters\n"])
def test_register_scene_with_a_scenario_that_is_not_toml_names_the_file(tmp_path, content):
    path = tmp_path / "bad.toml"
    path.write_bytes(content.encode("latin-1"))
    with pytest.raises(ScenarioError, match="bad.toml") as info:
        rotframe.register_scene("mine", scenes.get("turntable"), scenario=path)
    assert "\n" not in str(info.value)
    assert "mine" not in scenes.SCENES


@pytest.mark.parametrize("module", ["no.such.module", "json", "rotframe.errors"])
def test_register_scene_of_a_missing_or_non_scene_module_is_refused(module):
    with pytest.raises(ScenarioError, match="register_scene") as info:
        rotframe.register_scene("mine", module)
    assert module in str(info.value) and "\n" not in str(info.value)
    assert "mine" not in scenes.SCENES


def test_a_builtin_name_is_refused_unless_overridden(tmp_path):
    scene = scenes.get("tower-drop")
    with pytest.raises(ScenarioError, match="built-in"):
        rotframe.register_scene("turntable", scene)
    assert scenes.SCENES["turntable"] == "rotframe.scenes.turntable"
    toml = tmp_path / "turntable.toml"
    toml.write_text('scene = "mine"\n[parameters.x]\ndefault = 1.0\n', encoding="utf-8")
    with pytest.raises(ScenarioError, match="built-in scenario"):
        rotframe.register_scene("mine", scene, scenario=toml)
    rotframe.register_scene("turntable", scene, override=True)
    assert scenes.SCENES["turntable"] is scene


def test_a_plugin_that_prints_at_import_leaves_json_one_document(tmp_path, monkeypatch, capsys):
    plugin = tmp_path / "chatty.py"
    plugin.write_text("print('hello from the plugin')\n", encoding="utf-8")
    monkeypatch.setenv("ROTFRAME_PLUGINS", str(plugin))
    code, out, err = call(capsys, "run", "turntable", "--no-record", "--json", "--set", "duration=0.2")
    assert code == 0, err
    assert json.loads(out)["scenario"] == "turntable"
    assert "hello from the plugin" in err
