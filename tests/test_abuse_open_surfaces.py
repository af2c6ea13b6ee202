"""The open surfaces abused as a careless or hostile user would (issue 33's catalogue).

`rotframe.simulate`, `rotframe.simulate_body` and `rotframe.sweep` with arguments of every wrong
kind, user functions that misbehave, a damaged driver cache, work over the limits, a closed
cluster client and signals inside compiled calls. Each case must end in one line that names what
is wrong (a `RotframeError`), a note, or a kept partial: never a raw exception of numpy's,
numba's or pickle's, never a silent number. The classes, not the issue's examples: each case
below is a different value of a class.
"""

from __future__ import annotations

import ast
import functools
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import astropy.units as u
import numpy as np
import pytest

import rotframe
from rotframe.errors import RotframeError

REPO = Path(__file__).resolve().parents[1]


def fall(t, r, v):
    return 0.0, 0.0, -9.81


def spring(t, r, v, k):
    return -k * r[0], -k * r[1], -k * r[2]


def height(t, r, v):
    return r[2]


class CallableObject:
    def __call__(self, t, r, v):
        return 0.0, 0.0, -9.81

    def method(self, t, r, v):
        return 0.0, 0.0, -9.81


def with_attrs(f, **attrs):
    def g(t, r, v):
        return r[2]

    for key, value in attrs.items():
        setattr(g, key, value)
    return g


BASE = dict(omega=[0, 0, 0], r0=[0, 0, 10], v0=[0, 0, 0], duration=1.0, samples=2, forces=[fall])

#: case -> (changes to BASE, a word the one line must hold)
SIMULATE = {
    "params a float": (dict(params=4.0), "params"),
    "params a string": (dict(params="4.0"), "params"),
    "params a dict": (dict(params={"k": 4.0}), "params"),
    "params holding complex": (dict(params=(1 + 2j,), forces=[spring]), "params[0]"),
    "params holding a dict": (dict(params=({"a": 1},), forces=[spring]), "params[0]"),
    "params holding a ragged list": (dict(params=([1.0, [2.0, 3.0]],), forces=[spring]), "params[0]"),
    "params holding NaN": (dict(params=(np.nan,), forces=[spring]), "params[0]"),
    "params holding an empty array": (dict(params=(np.array([]),), forces=[spring]), "params[0]"),
    "params holding text": (dict(params=("k",), forces=[spring]), "params[0]"),
    "omega text": (dict(omega="0,0,1"), "omega"),
    "omega complex": (dict(omega=[0, 0, 1j]), "omega"),
    "omega a ragged table": (dict(omega=([0, 1, 2], [[0, 0, 1], [0, 0], [0, 0, 1]])), "omega"),
    "omega a ragged vector": (dict(omega=[0, [0, 1]]), "omega"),
    "omega a table interpolated by a number": (dict(omega=([0, 1, 2], np.zeros((3, 3)), 3)), "omega"),
    "omega a table interpolated by name unknown": (dict(omega=([0, 1, 2], np.zeros((3, 3)), "spline")), "omega"),
    "origin_acceleration a ragged vector": (dict(origin_acceleration=[[0], 0, 1]), "origin_acceleration"),
    "duration a 2-D array (its repr spans lines)": (dict(duration=np.zeros((2, 2))), "duration"),
    "rtol a 2-D array (its repr spans lines)": (dict(rtol=np.zeros((2, 2))), "rtol"),
    "device an array": (dict(device=np.zeros(2)), "device"),
    "frame_attitude all zero, where no force reads it": (dict(frame_attitude=[0, 0, 0, 0]), "frame_attitude"),
    "frame_attitude ragged, where no force reads it": (dict(frame_attitude=[0, [0], 0, 1]), "frame_attitude"),
    "device an empty array": (dict(device=np.array([])), "device"),
    "omega a table with NaN": (dict(omega=([0, 1, 2], [[0, 0, 1], [0, np.nan, 0], [0, 0, 1]])), "omega"),
    "omega a table of text": (dict(omega=(["a", "b"], [[0, 0, 1], [0, 0, 1]])), "omega"),
    "omega a table too short in time": (dict(omega=([0.0, 0.5], [[0, 0, 1], [0, 0, 1]])), "omega"),
    "omega a table in metres": (dict(omega=([0, 1, 2] * u.m, np.zeros((3, 3)))), "omega"),
    "omega_dot not callable": (dict(omega=lambda t: (0.0, 0.0, 1.0), omega_dot=[0, 0, 0], jit=False), "omega_dot"),
    "omega returning two": (dict(omega=lambda t: (0.0, 1.0), jit=False), "omega"),
    "atol text": (dict(atol="tight"), "atol"),
    "atol negative": (dict(atol=-1e-9), "atol"),
    "atol of four": (dict(atol=[1e-9] * 4), "atol"),
    "atol one Quantity": (dict(atol=1 * u.mm), "atol"),
    "atol mixed units wrong": (dict(atol=[1 * u.s] * 6), "atol"),
    "r0 ragged": (dict(r0=[[0, 0, 1], [0, 1]]), "r0"),
    "r0 complex": (dict(r0=[0, 0, 1j]), "r0"),
    "r0 of four": (dict(r0=[0, 0, 1, 2]), "r0"),
    "v0 in kilograms": (dict(v0=[0, 0, 1] * u.kg), "v0"),
    "duration NaN": (dict(duration=np.nan), "duration"),
    "duration a Quantity in metres": (dict(duration=3 * u.m), "duration"),
    "samples a float": (dict(samples=2.5), "samples"),
    "samples True": (dict(samples=True), "samples"),
    "method a number": (dict(method=3), "method"),
    "jit a string": (dict(jit="no"), "jit"),
    "jit None": (dict(jit=None), "jit"),
    "force a partial": (dict(forces=[functools.partial(spring, k=1.0)]), "forces[0]"),
    "force a callable object": (dict(forces=[CallableObject()]), "forces[0]"),
    "force a bound method": (dict(forces=[CallableObject().method]), "forces[0]"),
    "force returning text": (dict(forces=[lambda t, r, v: ("a", "b", "c")]), "forces[0]"),
    "force returning NaN": (dict(forces=[lambda t, r, v: (np.nan, 0.0, 0.0)]), "forces[0]"),
    "force returning a Quantity": (dict(forces=[lambda t, r, v: [0, 0, -9.81] * u.m / u.s ** 2], jit=False),
                                   "forces[0]"),
    "force taking too few arguments": (dict(forces=[lambda t, r: (0.0, 0.0, 0.0)]), "forces[0]"),
    "event direction text": (dict(events=[with_attrs(height, direction="up")]), "events[0].direction"),
    "event direction NaN": (dict(events=[with_attrs(height, direction=np.nan)]), "events[0].direction"),
    "event terminal text": (dict(events=[with_attrs(height, terminal="yes")]), "events[0].terminal"),
    "event not callable": (dict(events=[3.0]), "events[0]"),
    "frame_attitude of three": (dict(frame_attitude=[0, 0, 1], forces=[rotframe.Force(fall, axes="inertial")]),
                                "frame_attitude"),
    "frame_attitude zero": (dict(frame_attitude=[0, 0, 0, 0], forces=[rotframe.Force(fall, axes="inertial")]),
                            "frame_attitude"),
    "origin_acceleration text": (dict(origin_acceleration="up"), "origin_acceleration"),
}


def refused_in_one_line(call, kwargs, needle):
    """``call(**kwargs)`` raises a RotframeError of one line that holds ``needle``."""
    with pytest.raises(RotframeError) as info:
        call(**kwargs)
    message = str(info.value)
    assert needle in message, message
    assert "\n" not in message and len(message) < 700


@pytest.mark.parametrize("case", sorted(SIMULATE))
def test_simulate_refuses_in_one_line(case):
    changes, needle = SIMULATE[case]
    refused_in_one_line(rotframe.simulate, {**BASE, **changes}, needle)


def torque_free(t, L, q):
    return 0.0, 0.0, 0.0


BODY = dict(inertia=[1, 2, 3], L0=[0, 0, 1], q0=[0, 0, 0, 1], duration=1.0, samples=2)
SIMULATE_BODY = {
    "inertia text": (dict(inertia="1,2,3"), "inertia"),
    "inertia two by two": (dict(inertia=[[1, 0], [0, 1]]), "inertia"),
    "inertia negative": (dict(inertia=[1, -2, 3]), "inertia"),
    "inertia not symmetric": (dict(inertia=[[1, 0.5, 0], [0, 2, 0], [0, 0, 3]]), "inertia"),
    "inertia in metres": (dict(inertia=[1, 2, 3] * u.m), "inertia"),
    "L0 of two": (dict(L0=[0, 1]), "L0"),
    "q0 not a unit quaternion": (dict(q0=[0, 0, 0, 2]), "q0"),
    "torque a partial": (dict(torque=functools.partial(lambda t, L, q, k: (0.0, 0.0, k), k=1.0)), "torque"),
    "torque returning two": (dict(torque=lambda t, L, q: (0.0, 0.0)), "torque"),
    "torque writing into L": (dict(torque=lambda t, L, q: L.__setitem__(0, 0.0) or (0.0, 0.0, 0.0)), "torque"),
    "jit text": (dict(jit="yes"), "jit"),
    "params a float": (dict(torque=torque_free, params=2.0), "params"),
    "method unknown": (dict(method="verlet"), "method"),
}


@pytest.mark.parametrize("case", sorted(SIMULATE_BODY))
def test_simulate_body_refuses_in_one_line(case):
    changes, needle = SIMULATE_BODY[case]
    refused_in_one_line(rotframe.simulate_body, {**BODY, **changes}, needle)


SWEEP = {
    "seed text": (dict(grid={"height": [50, 100]}, seed="abc"), "seed"),
    "seed negative": (dict(grid={"height": [50, 100]}, seed=-1), "seed"),
    "seed True": (dict(grid={"height": [50, 100]}, seed=True), "seed"),
    "samples text": (dict(vary={"height": "normal(100,5)"}, samples="10"), "samples"),
    "grid value text": (dict(grid={"height": "100"}), "grid"),
    "grid value a number": (dict(grid={"height": 100}), "grid"),
    "grid a list": (dict(grid=["height", 100]), "grid"),
    "grid in seconds": (dict(grid={"height": [1, 2] * u.s}), "grid"),
    "vary not text": (dict(vary={"height": 100}, samples=4), "vary"),
    "points text": (dict(points="height=1,2"), "points"),
    "client text": (dict(grid={"height": [50, 100]}, client="tcp://127.0.0.1:1"), "client"),
}


@pytest.mark.parametrize("case", sorted(SWEEP))
def test_sweep_refuses_in_one_line(case):
    kwargs, needle = SWEEP[case]
    refused_in_one_line(functools.partial(rotframe.sweep, "tower-drop"), kwargs, needle)


def test_sweep_refuses_a_closed_client():
    distributed = pytest.importorskip("distributed")
    client = distributed.Client(processes=False, dashboard_address=None)
    client.close()
    with pytest.raises(RotframeError, match="client"):
        rotframe.sweep("tower-drop", grid={"height": [50, 100]}, client=client)


# --- user functions that misbehave during the run -------------------------------------------


def nan_later(t, r, v):
    return 0.0, 0.0, -9.81 if t < 0.5 else np.nan


def raises_later(t, r, v):
    if t > 0.5:
        raise RuntimeError("sensor offline")
    return 0.0, 0.0, -9.81


class Config:
    K = 2.0


CONFIG = Config()


def reads_an_object(t, r, v):
    return 0.0, 0.0, -CONFIG.K


@pytest.mark.parametrize("force, kind, needle", [
    (nan_later, "IntegrationError", "nan_later"),
    (raises_later, "UserFunctionError", "sensor offline"),
    (reads_an_object, "UserFunctionError", "Cannot determine Numba type"),
], ids=["NaN later", "raises later", "numba's reason"])
def test_a_function_failing_during_the_run_is_named_with_its_reason(force, kind, needle):
    with pytest.raises(RotframeError) as info:
        rotframe.simulate(**{**BASE, "forces": [force], "samples": 10})
    assert type(info.value).__name__ == kind
    assert needle in str(info.value) and "\n" not in str(info.value)
    partial = getattr(info.value, "partial", None)
    if kind != "UserFunctionError" or needle != "Cannot determine Numba type":
        assert partial is not None  # the samples before the failure are kept


# --- work over the limits: refused at once, not after minutes -------------------------------


def test_an_endless_run_is_refused_within_seconds():
    t0 = time.perf_counter()
    with pytest.raises(rotframe.limits.LimitError, match="integration steps"):
        rotframe.simulate(omega=[0, 0, 0], r0=[1, 0, 0], v0=[0, 1, 0], duration=1e12, forces=[spring], params=(1.0,))
    assert time.perf_counter() - t0 < 60


def test_a_huge_duration_is_refused_not_called_non_finite():
    with pytest.raises(rotframe.limits.LimitError):
        rotframe.simulate(omega=[0, 0, 0], r0=[1, 0, 0], v0=[0, 1, 0], duration=1e300, forces=[spring], params=(1.0,))


@pytest.mark.parametrize("inline", [None, False])  # the steady loop (rotframe.problem.steady) and the engine's
@pytest.mark.parametrize("max_steps", [None, 1000])  # its bound from the motion's rate, and its projected pace
def test_an_adaptive_run_over_the_limit_is_told_what_helps_it(inline, max_steps):
    """An adaptive method has no step to enlarge: the refusal asks for a shorter run (and, where the count comes from
    the run's own pace at its tolerance, a looser rtol), whichever loop runs it."""
    from rotframe import forces, limits

    L = 10.0
    kw = dict(omega=[0.0, 4e-5, 5e-5], r0=[0.5, 0.0, L - np.sqrt(L * L - 0.25)], v0=[0.0, 0.0, 0.0],
              duration=1e12 if max_steps is None else 3600.0, rtol=1e-10,
              forces=[forces.gravity([0.0, 0.0, -9.81]), forces.pendulum(L, [0.0, 0.0, L])], inline=inline)
    overrides = {} if max_steps is None else {"max_steps": max_steps}
    with limits.applied(limits.current().with_overrides(**overrides)):
        with pytest.raises(limits.LimitError) as err:
            rotframe.simulate(**kw)
    text = str(err.value)
    assert "shorten" in text and "enlarge step" not in text and "smaller step" not in text, text
    if max_steps is not None:
        assert "rtol" in text, text


def test_event_slots_count_in_the_memory_limit():
    from rotframe import limits

    with limits.applied(limits.current().with_overrides(max_memory=1e6)):
        with pytest.raises(limits.LimitError, match="event slots"):
            rotframe.simulate(**{**BASE, "r0": np.zeros((2000, 3)) + [0, 0, 10], "events": [height]})


def test_a_table_with_more_knots_than_steps_allowed_is_refused_up_front():
    from rotframe import limits

    t = np.linspace(0, 1, 5001)
    with limits.applied(limits.current().with_overrides(max_steps=1000)):
        with pytest.raises(limits.LimitError, match="knots"):
            rotframe.simulate(**{**BASE, "omega": (t, np.zeros((t.size, 3)))})


def test_a_body_run_over_the_step_limit_is_refused():
    with pytest.raises(rotframe.limits.LimitError):
        rotframe.simulate_body(**{**BODY, "duration": 1e15, "L0": [0.3, 2.0, 0.4]})


# --- the driver cache, damaged ---------------------------------------------------------------

CACHE_RUN = textwrap.dedent('''
    import rotframe
    def spring(t, r, v):
        return -r[0], -r[1], -r[2]
    res = rotframe.simulate(omega=[0, 0, 1], r0=[1, 0, 0], v0=[0, 1, 0], duration=1.0, forces=[spring], samples=2)
    print(repr(float(res.trajectory.r[-1, 0, 0])))
    print(res.notes)
''')


def _cache_run(tmp_path, cache, **env):
    environ = dict(os.environ, PYTHONPATH=str(REPO / "src"), ROTFRAME_CACHE_DIR=str(cache), **env)
    environ.pop("NUMBA_CACHE_DIR", None)  # numba's files beside the driver's source, where the tests damage them
    return subprocess.run([sys.executable, "-c", CACHE_RUN], capture_output=True, text=True, timeout=300,
                          env=environ, cwd=tmp_path)


def _garbage_index(pycache):
    for f in pycache.glob("*.nbi"):
        f.write_bytes(f.read_bytes()[:20])


def _garbage_data(pycache):
    for f in pycache.glob("*.nbc"):
        f.write_bytes(b"not a pickle")


def _not_utf8(pycache):
    for f in pycache.parent.glob("*.py"):
        f.write_bytes(b"\xff\xfe\x00 not utf-8")


def _folder_in_place(pycache):
    for f in pycache.parent.glob("*.py"):
        f.unlink()
        f.mkdir()


@pytest.mark.parametrize("damage", [_garbage_index, _garbage_data, _not_utf8, _folder_in_place],
                         ids=["truncated index", "garbage data", "source not UTF-8", "a folder in its place"])
def test_a_damaged_cache_entry_is_dropped_and_rebuilt(tmp_path, damage):
    cache = tmp_path / "cache"
    first = _cache_run(tmp_path, cache)
    assert first.returncode == 0, first.stderr
    damage(cache / "__pycache__")
    again = _cache_run(tmp_path, cache)
    assert again.returncode == 0, again.stderr
    value, notes = again.stdout.splitlines()[:2]
    assert value == first.stdout.splitlines()[0]
    assert "damaged" in notes and "rebuilt" in notes
    third = _cache_run(tmp_path, cache)  # and the rebuilt entry serves the next run, without a note
    assert third.returncode == 0
    # but the plain tier's, where no test before it made the engine's loop (the order of the suite's tests)
    notes = ast.literal_eval(third.stdout.splitlines()[1])
    assert all("plain-Python remake" in note for note in notes), notes


def test_an_unwritable_cache_compiles_in_memory_with_a_note(tmp_path):
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    temp = tmp_path / "tmp"
    temp.mkdir()
    (temp / f"rotframe-problems-{os.getuid() if hasattr(os, 'getuid') else 0}").write_text("")  # fallback blocked
    res = _cache_run(tmp_path, blocker / "cache", TMPDIR=str(temp))
    assert res.returncode == 0, res.stderr
    assert "cannot be written" in res.stdout.splitlines()[1]


# --- signals inside compiled calls -------------------------------------------------------------

SLOW = textwrap.dedent('''
    import sys, time, rotframe
    from rotframe.particles.trajectory import RunInterrupted
    def slow(t, r, v):
        acc = 0.0
        for k in range(100000):  # about 0.1 ms an evaluation
            acc += 1e-12 * k
        return -r[0] + 0.0 * acc, -r[1], -r[2]
    said = []
    def progress(fraction):  # called between compiled calls: the run is compiled and going
        if not said:
            said.append(True)
            print("running", flush=True)
    try:
        rotframe.simulate(omega=[0, 0, 1], r0=[1, 0, 0], v0=[0, 1, 0], duration=1e5, forces=[slow], samples=100,
                          progress=progress)
        print("finished")
    except RunInterrupted as exc:
        print("interrupted", exc.partial is not None)
''')


@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM"])
def test_a_signal_inside_a_slow_compiled_call_is_answered_in_a_second(tmp_path, sig):
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"), ROTFRAME_CACHE_DIR=str(tmp_path / "cache"))
    proc = subprocess.Popen([sys.executable, "-c", SLOW], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=env, cwd=tmp_path)
    try:
        assert proc.stdout.readline().strip() == "running"  # compiled, and inside its calls
        time.sleep(1.0)
        sent = time.perf_counter()
        proc.send_signal(getattr(signal, sig))
        out, err = proc.communicate(timeout=30)
        answered = time.perf_counter() - sent
    finally:
        if proc.poll() is None:
            proc.kill()
    assert out.startswith("interrupted True"), (out, err)  # the first line was read above
    assert answered < 3.0


def test_a_frame_attitude_nothing_reads_is_flagged():
    """``frame_attitude`` is read only where a force acts in inertial axes: given without one, the run says so."""
    unread = rotframe.simulate(**{**BASE, "frame_attitude": [0.0, 0.0, 0.0, 1.0]})
    assert any(w.startswith("frame_attitude is not used") for w in unread.warnings), unread.warnings

    def push(t, r, v):
        return 0.1, 0.0, 0.0

    read = rotframe.simulate(**{**BASE, "frame_attitude": [0.0, 0.0, 0.0, 1.0],
                                "forces": [rotframe.Force(push, axes="inertial")]})
    assert not any("frame_attitude" in w for w in read.warnings), read.warnings
