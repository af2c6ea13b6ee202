"""The plain tier of a first run (rotframe.problem.tiers): the same numbers as the compiled loop, to the bit.

A run whose loop is not compiled yet begins as the loop's plain-Python remake, and compiles the
loop where its first calls project more than `PLAIN_FEVS` right-hand sides. Each case is run three
ways and must agree to the bit in every sample and every event record:

* compiled from the start (this process has the loops, or compiles them);
* in the plain tier from start to end (``loop_is_compiled`` says no, the budget
  never reached);
* in the plain tier for its first calls, then compiled (the budget set low).

The oracle is the compiled loop, which the other tests check against closed forms and other
integrators: these tests say the tier changes nothing, not that the physics is right. A
planted difference between the remake and the loop (a different step control, a dropped term)
fails them: `test_a_planted_difference_is_seen` plants one.
"""

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

import rotframe.forces as rf
from rotframe.problem import engine, tiers
from rotframe.problem.particles import simulate_particles
from rotframe.problem.terms import Force


def spring(t, r, v):
    return -1.3 * r[0], -1.3 * r[1], -1.3 * r[2]


def kick(t, r, v, k):
    return -k * r[0] * abs(r[0]), -k * r[1], -k * math.sin(r[2])


def ground(t, r, v):
    return r[2] + 40.0


ground.terminal = True
ground.direction = -1


def crossing(t, r, v):
    return r[0]


def crossing_k(t, r, v, k):
    return r[0] - 0.01 * k


def omega_of_t(t):
    return np.array([0.01 * math.sin(0.3 * t), 0.0, 0.5 + 0.02 * t])


def inertial_push(t, r, v):
    return 0.05, 0.0, -0.02 * t


R0 = np.array([[1.0, 0.0, 0.5], [0.3, -0.4, 1.0], [-0.2, 0.7, 0.0]])
V0 = np.array([[0.0, 1.0, 0.2], [0.5, 0.1, -0.3], [0.0, -0.2, 0.4]])

CASES = {
    "dop853, user and built-in forces, two events": dict(
        method="dop853", omega=[0.0, 0.1, 0.5], forces=[spring, rf.gravity((0.0, 0.0, -9.81)), rf.drag(linear=0.1, quadratic=0.02)],
        events=[ground, crossing], duration=6.0, samples=40),
    "rk4, user force with params, events": dict(
        method="rk4", omega=[0.0, 0.0, 0.7], forces=[kick, rf.gravity((0.0, -1.0, 0.0))], params=(0.8,), events=[crossing_k],
        duration=4.0, samples=20, step=0.01),
    "rotation-splitting4, user kick and drag's flow": dict(
        method="rotation-splitting4", omega=[0.0, 0.0, 0.9], forces=[spring, rf.drag(linear=0.3)], duration=5.0,
        samples=25, step=0.02),
    "rotation-splitting, user kick, event": dict(
        method="rotation-splitting", omega=[0.1, 0.0, 0.6], forces=[spring, rf.central_gravity(2.0, (0.0, 0.0, -3.0))],
        events=[crossing], duration=4.0, samples=16, step=0.01),
    "dop853, a frame turning by a function, an accelerating origin": dict(
        method="dop853", omega=omega_of_t, forces=[spring], origin_acceleration=lambda t: np.array([0.0, 0.1 * t, 0.0]),
        duration=5.0, samples=30),
    "dop853, a table frame, a force in inertial axes": dict(
        method="dop853", omega=(np.linspace(0.0, 5.0, 11), np.column_stack([np.zeros(11), np.zeros(11),
                                                                            0.4 + 0.05 * np.linspace(0.0, 5.0, 11)])),
        forces=[spring, Force(inertial_push, axes="inertial")], duration=5.0, samples=30),
    # inline=False: the engine's loop by name (the steady loop, rotframe.problem.steady, takes this problem otherwise)
    "dop853, a pendulum and gravity with its potential": dict(
        method="dop853", omega=[0.0, 0.0, 0.3], forces=[rf.pendulum(2.0), rf.gravity((0.0, 0.0, -9.81))], duration=4.0, samples=20,
        r0=np.array([[1.2, 0.0, -1.6]]), v0=np.array([[0.0, 0.3, 0.0]]), inline=False),
    "rk4, altitude gravity and a spring": dict(
        method="rk4", omega=[0.0, 0.0, 0.2], forces=[rf.altitude_gravity(9.81, 100.0), rf.spring(2.0)],
        duration=3.0, samples=12, step=0.01),
}


def _tiers(m, tier_mode, budget):
    """``tier_mode`` set on ``tiers`` with the monkeypatch context ``m`` (`_run`)."""
    if tier_mode == "compiled":  # never the plain tier, whether or not this process has compiled the loop yet
        m.setattr(tiers, "PLAIN_PARTICLES", 0)
    elif tier_mode == "trajectory":  # the whole loop cold, DOP853's trajectory tier made: the run begins there
        m.setattr(tiers, "loop_is_compiled", lambda variant: len(variant) == 5 and variant[4] == engine.TRAJECTORY_TIER)
    else:
        m.setattr(tiers, "loop_is_compiled", lambda variant: False)
        m.setattr(tiers, "PLAIN_FEVS", 10**12 if tier_mode == "plain" else budget)
        if tier_mode == "switch-whole":  # DOP853 too switches to the whole loop, not to its trajectory tier
            m.setattr(tiers, "TRAJECTORY_CALLS", 0)


def _run(case, tier_mode, monkeypatch, budget=None):
    """The case's run: ``compiled`` (the loop as this process has it), ``plain`` (the plain tier throughout),
    ``switch`` (the plain tier for its first calls, then compiled: DOP853's trajectory tier, the whole loop for the
    others), ``switch-whole`` (the same, the whole loop for DOP853 too), ``trajectory`` (DOP853's trajectory tier
    throughout)."""
    kw = dict(case)
    kw.setdefault("r0", R0)
    kw.setdefault("v0", V0)
    with monkeypatch.context() as m:
        _tiers(m, tier_mode, budget)
        return simulate_particles(**kw)


def _record_trajectory_tiers(monkeypatch):
    """A list that receives "trajectory" each time a run's driver is made the trajectory tier's
    (`rotframe.problem.codegen.Driver.trajectory_tier`)."""
    from rotframe.problem.codegen import Driver

    chosen = []
    made = Driver.trajectory_tier

    def recorded(self):
        chosen.append("trajectory")
        return made(self)

    monkeypatch.setattr(Driver, "trajectory_tier", recorded)
    return chosen


def _same(a, b):
    ta, tb = a.trajectory, b.trajectory
    np.testing.assert_array_equal(ta.times, tb.times)
    np.testing.assert_array_equal(ta.r, tb.r)
    np.testing.assert_array_equal(ta.v, tb.v)
    assert ta.event_times.keys() == tb.event_times.keys()
    for name in ta.event_times:
        for x, y in zip(ta.event_times[name], tb.event_times[name]):
            np.testing.assert_array_equal(x, y)
        for x, y in zip(ta.event_states[name], tb.event_states[name]):
            np.testing.assert_array_equal(x, y)
    assert ta.steps == tb.steps  # not nfev: each call begins with f at its start, and the tiers cut calls apart
    assert a.diagnostics.keys() == b.diagnostics.keys()
    for key in a.diagnostics:
        assert a.diagnostics[key] == b.diagnostics[key], key


@pytest.mark.parametrize("name", list(CASES))
def test_plain_tier_and_the_switch_give_the_compiled_numbers(name, monkeypatch):
    case = CASES[name]
    monkeypatch.setattr(tiers, "TRAJECTORY_CALLS", 10**6)  # every DOP853 case fits the trajectory tier (its limit: below)
    tiers_chosen = _record_trajectory_tiers(monkeypatch)
    compiled = _run(case, "compiled", monkeypatch)
    assert not any("plain-Python remake" in n for n in compiled.notes)
    assert np.all(compiled.trajectory.extras["status"] >= 1)
    plain = _run(case, "plain", monkeypatch)
    assert any("short enough for its plain-Python remake" in n for n in plain.notes), plain.notes
    _same(plain, compiled)
    # switched after the first plain call (the budget a single right-hand side): the rest compiled
    switched = _run(case, "switch", monkeypatch, budget=1)
    assert any("remake ran the first" in n and "then the loop compiled" in n for n in switched.notes), switched.notes
    stepped = case["method"] == "dop853"  # DOP853 switches to its trajectory tier: its trajectories compiled alone
    assert any("its trajectories alone" in n for n in switched.notes) == stepped, switched.notes
    assert tiers_chosen == (["trajectory"] if stepped else []), tiers_chosen
    assert 0 < switched.trajectory.steps
    _same(switched, compiled)
    if stepped:
        tiers_chosen.clear()
        whole = _run(case, "switch-whole", monkeypatch, budget=1)
        assert any("then the loop compiled (" in n for n in whole.notes), whole.notes
        assert tiers_chosen == [], tiers_chosen
        _same(whole, compiled)
        trajectory = _run(case, "trajectory", monkeypatch)
        assert not any("plain-Python" in n for n in trajectory.notes), trajectory.notes
        assert tiers_chosen == ["trajectory"], tiers_chosen  # begun there, not in the whole loop
        _same(trajectory, compiled)


def _torque(t, L, q, c):
    return -c * L[0], c * q[2], 0.1 * math.sin(t)


def _gravity_torque(t, L, q, c):  # of the attitude alone: the splittings' kick
    return c * q[0] * q[3], -c * q[1], 0.0


from rotframe.problem.body import Torque  # noqa: E402 -- the body cases' marker, beside them

BODIES = {
    "a free body, dop853": dict(method="dop853", duration=300.0),
    "a torque, dop853": dict(method="dop853", torque=_torque, params=(0.2,)),
    "a torque, rk4": dict(method="rk4", torque=_torque, params=(0.2,), step=0.005),
    "a torque of the attitude, lie-poisson4": dict(method="lie-poisson4", torque=Torque(_gravity_torque,
                                                                                       attitude_only=True),
                                                   params=(0.3,), step=0.01),
    # the compositions of orders 6 and 8 call their step at its address (rotframe.problem.body_split_step)
    "a torque of the attitude, lie-poisson8": dict(method="lie-poisson8", torque=Torque(_gravity_torque,
                                                                                       attitude_only=True),
                                                   params=(0.3,), step=0.02, duration=3.0),
    "a symmetric body, lie-poisson6": dict(method="lie-poisson6", inertia=[2.0, 2.0, 3.0], step=0.02, duration=3.0),
}


def _body(case, tier_mode, monkeypatch, budget=None):
    from rotframe.problem.body import simulate_rigid_body

    kw = dict(dict(inertia=[1.0, 2.0, 3.0], L0=[0.1, 1.0, 0.2], q0=[0.0, 0.0, 0.0, 1.0], duration=6.0, samples=24),
              **case)
    with monkeypatch.context() as m:
        _tiers(m, tier_mode, budget)
        return simulate_rigid_body(**kw)


@pytest.mark.parametrize("name", list(BODIES))
def test_a_body_in_the_plain_tier_and_switched_gives_the_compiled_numbers(name, monkeypatch):
    compiled = _body(BODIES[name], "compiled", monkeypatch)
    plain = _body(BODIES[name], "plain", monkeypatch)
    switched = _body(BODIES[name], "switch", monkeypatch, budget=1)
    assert not any("plain-Python remake" in n for n in compiled.notes)
    assert any("short enough for its plain-Python remake" in n for n in plain.notes), plain.notes
    assert any("then the loop compiled" in n for n in switched.notes), switched.notes
    stepped = BODIES[name]["method"] == "dop853"
    assert any("its trajectories alone" in n for n in switched.notes) == stepped, switched.notes
    runs = [plain, switched]
    if stepped:
        runs += [_body(BODIES[name], "switch-whole", monkeypatch, budget=1),
                 _body(BODIES[name], "trajectory", monkeypatch)]
    for run in runs:
        np.testing.assert_array_equal(run.trajectory.L, compiled.trajectory.L)
        np.testing.assert_array_equal(run.trajectory.q, compiled.trajectory.q)
        assert run.diagnostics == compiled.diagnostics


@pytest.fixture(autouse=True)
def _fresh_ledger(monkeypatch):
    """Each test begins with no plain-tier work spent in the process (`tiers.plain_fevs_spent`)."""
    monkeypatch.setattr(tiers, "_SPENT", {})


def test_short_runs_of_one_loop_compile_it_once_they_have_spent_the_budget(monkeypatch):
    """A run that ends plain leaves its loop cold, but its right-hand sides count: the runs after it begin plain
    until the loop's runs together would pass PLAIN_FEVS, and that run compiles the loop; the numbers are the
    same in every run."""
    case = dict(CASES["rk4, user force with params, events"], r0=R0[0], v0=V0[0])
    compiled = _run(case, "compiled", monkeypatch)
    fevs = compiled.trajectory.nfev
    with monkeypatch.context() as m:
        m.setattr(tiers, "loop_is_compiled", lambda variant: False)
        m.setattr(tiers, "PLAIN_FEVS", int(3.5 * fevs))  # three runs fit, the fourth would pass it
        runs = [simulate_particles(**case) for _ in range(4)]
    for run in runs[:3]:
        assert any("short enough for its plain-Python remake" in n for n in run.notes), run.notes
    assert any("then the loop compiled" in n for n in runs[3].notes), runs[3].notes
    for run in runs:
        _same(run, compiled)


def test_a_planted_difference_is_seen(monkeypatch):
    """The comparison above sees a remake that differs from the loop: Hairer's safety factor planted 1 % smaller in
    the plain tier alone changes its steps and numbers."""
    from rotframe.numerics import plain as plain_module, step_control

    case = CASES["dop853, user and built-in forces, two events"]
    compiled = _run(case, "compiled", monkeypatch)
    with monkeypatch.context() as m:
        m.setattr(plain_module, "_PLAIN", {})  # the remakes made anew, reading the planted constant
        m.setattr(plain_module, "_SPACES", {})
        m.setattr(engine, "_VARIANTS", {key: k for key, k in engine._VARIANTS.items() if key[-1]})
        m.setattr(step_control, "SAFE", step_control.SAFE * 0.99)  # read by the plain remake, frozen in the loop
        plain = _run(case, "plain", monkeypatch)
    with pytest.raises(AssertionError):
        _same(plain, compiled)


def test_large_ensembles_and_inline_runs_begin_compiled(monkeypatch):
    """More particles than PLAIN_PARTICLES, or inline=True, never begin in the plain tier."""
    case = dict(CASES["rk4, user force with params, events"])
    with monkeypatch.context() as m:
        m.setattr(tiers, "loop_is_compiled", lambda variant: False)
        n = tiers.PLAIN_PARTICLES + 1
        many = simulate_particles(**dict(case, r0=np.tile(R0[0], (n, 1)), v0=np.tile(V0[0], (n, 1))))
        assert not any("plain-Python" in note for note in many.notes)
        inlined = simulate_particles(**dict(case, r0=R0, v0=V0, inline=True))
        assert not any("plain-Python" in note for note in inlined.notes)


def test_a_user_function_that_raises_in_the_plain_tier_is_named(monkeypatch):
    from rotframe.problem.callables import UserFunctionError

    def breaks(t, r, v):
        if t > 1.0:
            raise ValueError("broken at t > 1")
        return -r[0], -r[1], -r[2]

    with monkeypatch.context() as m:
        m.setattr(tiers, "loop_is_compiled", lambda variant: False)
        with pytest.raises(UserFunctionError) as info:
            simulate_particles(omega=[0.0, 0.0, 0.5], r0=R0[:1], v0=V0[:1], duration=3.0, forces=[breaks], samples=30,
                               method="rk4", step=0.01)
    assert "broken at t > 1" in str(info.value) and "particle 0" in str(info.value)
    assert info.value.partial is not None and 0.9 <= info.value.t_reached <= 1.0 + 1e-9


_CHILD = r"""
import json, sys
from rotframe.numerics import compile_apart
from rotframe.problem import engine
from rotframe.problem.particles import simulate_particles

made, load = [], compile_apart.CompiledApart.load_all  # how each second process of a compile was made
compile_apart.CompiledApart.load_all = lambda self, *args: made.append(self.how) or load(self, *args)
begun, begin = [], compile_apart.begin  # the kernels begun ahead of a run's functions' compile
compile_apart.begin = lambda module, function, *args: begun.append(function) or begin(module, function, *args)

def spring(t, r, v):
    return -1.7 * r[0], -1.7 * r[1], -1.7 * r[2]

def spring_run():
    T = float(sys.argv[1])
    # a frame given as a table (argv[2] "table"; the same steady rate) has an evaluator of its own to compile
    omega = ([0.0, T / 2, T], [[0.0, 0.0, 0.5]] * 3) if sys.argv[2:] == ["table"] else [0.0, 0.0, 0.5]
    return simulate_particles(omega=omega, r0=[1.0, 0.0, 0.0], v0=[0.0, 1.0, 0.0], duration=T, forces=[spring],
                              samples=10)


run = spring_run()
begun_first, unused_first = list(begun), len(compile_apart._BEGUN)  # the first run's, and those it left running
from numba.core import caching  # then what a second run loads from numba's disk cache: nothing
reloaded, looked, load_overload = [], [], caching.Cache.load_overload


def counted(self, *args):
    found = load_overload(self, *args)
    looked.append(self._name)
    if found is not None:
        reloaded.append(found.fndesc.qualname)
    return found


caching.Cache.load_overload = counted
spring_run()
print(json.dumps({"notes": run.notes, "r": run.trajectory.r[-1, 0].tolist(),
                  "compiled": engine.variant(0, "dop853", False, load_only=True) is not None,
                  "trajectory": engine.variant(0, "dop853", False, "trajectory", load_only=True) is not None,
                  "apart": made, "reloaded": reloaded, "begun": begun_first, "unused": unused_first,
                  "looked": looked}))
"""


def test_a_first_run_in_a_fresh_install_begins_in_the_plain_tier(tmp_path):
    """In a new process with every cache empty, a short run is answered by the plain tier and compiles no loop; a long
    one switches and compiles DOP853's trajectory tier, not the whole loop, its trajectory and stages in forked
    processes where there are two cores (`rotframe.numerics.compile_apart`); the next short one, in another process,
    finds the tier in the cache and runs there, compiling nothing. The final states agree to the bit. A steady frame
    begins nothing ahead: the run's own compile is short, and a short run would pay for processes it never uses."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"), ROTFRAME_CACHE_DIR=str(tmp_path / "drivers"))

    def child(duration, *frame):
        out = subprocess.run([sys.executable, "-c", _CHILD, repr(duration), *frame], env=env, capture_output=True,
                             text=True, timeout=600)
        assert out.returncode == 0, out.stderr[-2000:]
        return json.loads(out.stdout.strip().splitlines()[-1])

    short = child(10.0)
    assert any("short enough for its plain-Python remake" in n for n in short["notes"]), short["notes"]
    assert not short["compiled"] and not short["trajectory"]
    long = child(400.0)
    assert any("then the loop compiled, its trajectories alone" in n for n in long["notes"]), long["notes"]
    assert long["trajectory"] and not long["compiled"]
    two = len(os.sched_getaffinity(0)) >= 2 and sys.platform.startswith("linux")
    # the trajectory forked, the stages compiled here meanwhile (nothing begun ahead: the frame is steady)
    assert long["apart"] == (["fork"] if two else [None]) and short["apart"] == []
    assert short["begun"] == long["begun"] == [] and short["unused"] == long["unused"] == 0
    again = child(10.0)
    assert not any("plain-Python" in n for n in again["notes"]), again["notes"]
    assert again["trajectory"] and not again["compiled"] and again["apart"] == []
    assert again["r"] == short["r"]
    # a run in the tier asks whether the whole loop is made: the tier's kernels, once made, are not loaded again, and
    # the whole loop, once not found in numba's cache, is not looked for there again (`engine._NOT_CACHED`)
    assert long["reloaded"] == again["reloaded"] == [], (long["reloaded"], again["reloaded"])
    assert long["looked"] == again["looked"] == [], (long["looked"], again["looked"])


def test_a_first_run_of_a_varying_frame_begins_the_tier_ahead_of_its_own_compile(tmp_path):
    """A frame given as a table compiles its evaluator before the run's first plain call: the trajectory tier's two
    parts are begun in second processes before it (`rotframe.problem.tiers.begin_ahead`), a long run adopts both and
    compiles the tier, not the whole loop; a short one leaves them running, stopped at its process's exit."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"), ROTFRAME_CACHE_DIR=str(tmp_path / "drivers"))
    two = len(os.sched_getaffinity(0)) >= 2 and sys.platform.startswith("linux")
    ahead = ["compile_tier_trajectory", "compile_tier_stages"]
    runs = {}
    for name, duration in (("short", 10.0), ("long", 400.0)):  # the long one in caches of its own: nothing made
        own = dict(env, NUMBA_CACHE_DIR=str(tmp_path / name))
        out = subprocess.run([sys.executable, "-c", _CHILD, repr(duration), "table"], env=own, capture_output=True,
                             text=True, timeout=600)
        assert out.returncode == 0, out.stderr[-2000:]
        runs[name] = json.loads(out.stdout.strip().splitlines()[-1])
    short, long = runs["short"], runs["long"]
    assert any("short enough for its plain-Python remake" in n for n in short["notes"]), short["notes"]
    assert short["begun"] == long["begun"] == ahead and short["unused"] == (2 if two else 0)
    assert long["unused"] == 0 and long["trajectory"] and not long["compiled"]  # the long run adopted both
    assert long["apart"] == (["fork", "fork"] if two else [None, None]) and short["apart"] == []


def _blows_up(t, r, v):
    return -r[0], -r[1], 1.0 / (r[2] - r[2]) if t > 0.5 else 0.0  # Python raises; compiled, an inf


def test_a_run_that_fails_in_the_plain_tier_fails_as_compiled(monkeypatch):
    """Python raises ZeroDivisionError where the compiled loop goes on with inf: the plain tier hands the failing run
    to the compiled loop from its start, so the error and its samples are the compiled run's."""
    from rotframe.errors import RotframeError

    kw = dict(omega=[0.0, 0.0, 0.5], r0=R0[:1], v0=V0[:1], duration=2.0, forces=[_blows_up], samples=20)
    errors = {}
    for mode in ("compiled", "plain"):
        with monkeypatch.context() as m:
            if mode == "compiled":
                m.setattr(tiers, "PLAIN_PARTICLES", 0)
            else:
                m.setattr(tiers, "loop_is_compiled", lambda variant: False)
            with pytest.raises(RotframeError) as info:
                simulate_particles(**kw)
            errors[mode] = info.value
    assert type(errors["plain"]) is type(errors["compiled"])
    assert str(errors["plain"]) == str(errors["compiled"])
    assert "ZeroDivisionError" not in str(errors["plain"])
    np.testing.assert_array_equal(errors["plain"].partial.r, errors["compiled"].partial.r)


def _well(t, r, k):
    """A potential of the user's own (not numpy's arrays): the energy diagnostic reads it state by state."""
    return 0.5 * k * (r[0] * r[0] + r[1] * r[1]) + k * math.cosh(0.1 * r[2])


def _well_force(t, r, v, k):
    return -k * r[0], -k * r[1], -0.1 * k * math.sinh(0.1 * r[2])


def test_a_first_runs_energy_of_a_few_states_is_the_plain_remakes_and_the_compiled_ones_to_the_bit(monkeypatch):
    # the compiled `energies` neither made nor cached (a fresh dispatcher, the cache said empty): a run whose states
    # are few evaluates its diagnostic by the plain remake, compiles nothing for it, and gives the compiled numbers
    from numba import njit

    import rotframe.numerics.compiled as compiled

    kw = dict(omega=[0.0, 0.2, 0.9], r0=[[1.0, 0.5, 0.2], [0.3, -0.2, 1.0]], v0=[[0.0, 0.4, 0.1], [0.2, 0.0, 0.0]],
              duration=30.0, forces=[Force(_well_force, potential=_well)], params=(1.7,), samples=400,
              plain_tier=False)
    compiled_run = simulate_particles(**kw)
    real = engine.energies
    fresh = njit(cache=False, error_model="numpy", nogil=True, no_cfunc_wrapper=True)(real.py_func)
    monkeypatch.setattr(engine, "energies", fresh)
    monkeypatch.setitem(engine.SIGNATURES, fresh, engine.SIGNATURES[real])
    monkeypatch.setattr(compiled, "load_cached", lambda kernel, signature: False)
    first = simulate_particles(**dict(kw, plain_tier=True))
    assert not fresh.signatures  # nothing compiled for the diagnostic
    assert first.diagnostics["jacobi_rel_drift"] == compiled_run.diagnostics["jacobi_rel_drift"] > 0.0
    assert np.array_equal(first.trajectory.extras["energy"], compiled_run.trajectory.extras["energy"])
    many = simulate_particles(**dict(kw, plain_tier=True, samples=tiers.PLAIN_ENERGIES))  # more states: compiled
    assert fresh.signatures and np.isfinite(many.diagnostics["jacobi_rel_drift"])


def test_more_particles_than_trajectory_calls_compile_the_whole_loop(monkeypatch):
    """A first run of more particles than TRAJECTORY_CALLS (a call of the trajectory loop each) compiles the whole
    loop instead, where the loop over them is compiled too; one of as many fits the trajectory tier, however many knots
    its frame's table has (the trajectory runs through the stops itself). The numbers are the same in each."""
    table = CASES["dop853, a table frame, a force in inertial axes"]  # 3 particles, a table's knots
    compiled = _run(table, "compiled", monkeypatch)
    with monkeypatch.context() as m:
        m.setattr(tiers, "TRAJECTORY_CALLS", 2)
        switched = _run(table, "switch", monkeypatch, budget=1)
        assert any("then the loop compiled (" in n for n in switched.notes), switched.notes
        assert not tiers.trajectory_tier_fits("dop853", 3)
    with monkeypatch.context() as m:
        m.setattr(tiers, "TRAJECTORY_CALLS", 3)
        stepped = _run(table, "switch", monkeypatch, budget=1)
        assert any("its trajectories alone" in n for n in stepped.notes), stepped.notes
        assert tiers.trajectory_tier_fits("dop853", 3)
    _same(switched, compiled)
    _same(stepped, compiled)
    assert not tiers.trajectory_tier_fits("rk4", 1)

