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


def test_simulate_and_simulate_body_flag_what_nothing_reads_and_it_changes_nothing():
    """The API's own runs: an unread setting of the method, and params that no function of the caller's takes
    (the built-in terms' constants are their own); each flagged once, and two values give the same numbers."""
    import math

    from rotframe import forces, torques

    body = dict(inertia=[0.02, 0.02, 0.01], L0=[0.0, 0.0, 0.4], q0=[0.1, 0.0, 0.0, math.sqrt(0.99)], duration=0.5)
    runs = [rotframe.simulate_body(method="lie-poisson", step=0.01, rtol=rtol, params=(k,),
                                   torque=torques.gravity(0.5, 0.04, 9.81), **body) for rtol, k in ((1e-3, 1.0),
                                                                                                     (1e-9, 2.0))]
    for run in runs:
        assert sum(w.startswith("rtol = ") and "lie-poisson" in w for w in run.warnings) == 1, run.warnings
        assert sum(w.startswith("params = ") and "no torque of yours" in w for w in run.warnings) == 1
    assert np.array_equal(runs[0].trajectory.q, runs[1].trajectory.q)
    particle = dict(omega=[0.0, 0.0, 1.0], r0=[1.0, 0.0, 0.0], v0=[0.0, 0.0, 0.0], duration=1.0)
    runs = [rotframe.simulate(forces=[forces.spring(4.0)], params=(k,), **particle) for k in (1.0, 2.0)]
    for run in runs:
        assert sum(w.startswith("params = ") and "no force or event of yours" in w for w in run.warnings) == 1
    assert np.array_equal(runs[0].trajectory.r, runs[1].trajectory.r)
    # read: a force of yours that takes them, or a torque; nothing flagged
    read = rotframe.simulate(forces=[lambda t, r, v, k: (-k * r[0], -k * r[1], -k * r[2])], params=(4.0,), **particle)
    assert not any("is not used" in w for w in read.warnings)
    read = rotframe.simulate_body(torque=lambda t, L, q, c: (-c * L[0], -c * L[1], -c * L[2]), params=(0.1,),
                                  method="dop853", rtol=1e-8, **body)
    assert not any("is not used" in w for w in read.warnings)
