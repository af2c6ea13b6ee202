"""A run setting the caller gives and the method does not read is flagged, and is truly unread.

``step`` means nothing to ``dop853`` (adaptive) or ``exact``; ``rtol`` nothing to the fixed-step
methods or ``exact``. The summary warns about each one the caller set (not about the scenario
file's defaults), and each warning is checked against the runs themselves: two values of the
unread setting give bitwise the same result.
"""

import numpy as np
import pytest

import rotframe
from rotframe.app import runner
from rotframe.particles.integrators import METHODS


@pytest.mark.parametrize("name, method, key, values", [
    ("foucault", "dop853", "step", ("0.5", "0.01")),
    ("foucault", "rk4", "rtol", ("1e-6", "1e-12")),
    ("tower-drop", "exact", "step", ("0.01", "1e-5")),
    ("tower-drop", "exact", "rtol", ("1e-3", "1e-12")),
    ("heavy-top", "dop853", "step", ("1e-3", "1e-5")),
    ("heavy-top", "top-splitting", "rtol", ("1e-3", "1e-12")),
])
def test_an_unread_setting_is_flagged_and_changes_nothing(name, method, key, values):
    short = {} if name == "tower-drop" else {"duration": "0.5"}  # the drop has no duration: it ends on the ground
    runs = [runner.run(name, {key: v, **short}, method=method) for v in values]
    for (summary, _), value in zip(runs, values):
        flagged = [w for w in summary["warnings"] if w.startswith(f"{key} = ") and "is not used" in w]
        assert len(flagged) == 1 and method in flagged[0], summary["warnings"]
    (_, first), (_, second) = runs
    for field in ("r", "v", "L", "q"):  # particle (r, v) or rigid body (L, q) states
        if hasattr(first.trajectory, field):
            assert np.array_equal(getattr(first.trajectory, field), getattr(second.trajectory, field)), field


def test_a_read_setting_and_the_file_defaults_are_not_flagged():
    summary, _ = runner.run("foucault", {"duration": "0.5", "rtol": "1e-8"}, method="dop853")
    assert not any("is not used" in w for w in summary["warnings"])
    summary, _ = runner.run("heavy-top", {"duration": "0.5", "step": "1e-4"}, method="top-splitting")
    assert not any("is not used" in w for w in summary["warnings"])
    # heavy-top.toml sets both step and rtol; the default top-splitting8 run reads step only, and says nothing
    summary, _ = runner.run("heavy-top", {"duration": "0.5"})
    assert not any("is not used" in w for w in summary["warnings"])


def test_the_python_api_flags_the_same():
    result = rotframe.run("foucault", method="rk4", duration=0.5, rtol=1e-6)
    assert any(w.startswith("rtol = ") and "rk4" in w for w in result.warnings)


def test_the_kind_rule_matches_the_particle_registry():
    # unused_settings tells the kinds apart by name (exact, dop853, the rest fixed): so does the registry
    for name, info in METHODS.items():
        expected = "exact" if name == "exact" else "adaptive" if name == "dop853" else "fixed"
        assert info.kind == expected, (name, info.kind)
