"""The application layer's shared helpers (choices, options, quantities, messages) and its import rules."""

import ast
import math
from pathlib import Path

import numpy as np
import pytest

from rotframe.app.choices import did_you_mean
from rotframe.app.options import jsonable, parse_sets, split_set
from rotframe.app.quantities import NotAQuantity, WrongDimension, value_in
from rotframe.errors import ScenarioError

APP = Path(__file__).resolve().parents[1] / "src" / "rotframe" / "app"


def test_did_you_mean_names_the_closest_option_or_nothing():
    assert did_you_mean("latitud", ["latitude", "height"]) == " (did you mean 'latitude'?)"
    assert did_you_mean("zzz", ["latitude", "height"]) == ""
    # the cutoff is difflib's ratio 2M/T: 'ang' inside 'rectangle' is M = 3 of T = 12 letters, 0.5 exactly
    assert did_you_mean("ang", ["rectangle"], cutoff=0.5) == " (did you mean 'rectangle'?)"
    assert did_you_mean("ang", ["rectangle"], cutoff=0.6) == ""


def test_set_pairs_split_at_the_first_equals_sign_and_the_last_key_wins():
    assert split_set(" omega = 0,1,0 ") == ("omega", "0,1,0")
    assert split_set("expr=a=b") == ("expr", "a=b")
    assert split_set("novalue") is None
    assert parse_sets(["a=1", "b= 2 ", "a=3"]) == {"a": "3", "b": "2"}
    with pytest.raises(ScenarioError, match=r"--set 'oops': expected KEY=VALUE"):
        parse_sets(["oops"])


def test_jsonable_gives_null_for_every_non_finite_number_and_plain_python_types():
    out = jsonable({"p": np.float64(math.inf), 3: [np.int64(2), (np.nan, 1.5)], "path": Path("a/b.rrd")})
    assert out == {"p": None, "3": [2, [None, 1.5]], "path": str(Path("a/b.rrd"))}
    assert type(out["3"][0]) is int


def test_value_in_converts_quantities_and_keeps_plain_numbers():
    # the international foot is 0.3048 m exactly (1959 agreement), independent of astropy
    assert value_in("520 ft", "m") == pytest.approx(520 * 0.3048, rel=1e-15)
    assert value_in("4 inch", "mm") == pytest.approx(4 * 25.4, rel=1e-15)
    assert value_in("158.5", "m") == 158.5  # a number is already in the unit: no conversion at all
    with pytest.raises(WrongDimension) as info:
        value_in("3 s", "m")
    assert info.value.unit.physical_type == "time"
    with pytest.raises(NotAQuantity):
        value_in("abc", "m")


def _imports(path):
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module:
            yield node.module, [a.name for a in node.names]
        elif isinstance(node, ast.Import):
            for a in node.names:
                yield a.name, []


@pytest.mark.parametrize("package", ["sweep", "bench"])
def test_sweep_and_bench_never_import_the_command_line(package):
    """cli imports sweep and bench; they never import cli (the three formed a cycle once)."""
    for path in sorted((APP / package).glob("*.py")):
        for module, names in _imports(path):
            assert module != "rotframe.app.cli", path
            assert not (module == "rotframe.app" and "cli" in names), path


def test_no_module_of_the_application_layer_imports_a_private_name():
    for path in sorted(APP.rglob("*.py")):
        for module, names in _imports(path):
            if module.startswith("rotframe"):
                private = [n for n in names if n.startswith("_") and not n.startswith("__")]
                assert not private, (path, module, private)
