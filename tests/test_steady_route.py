"""The engine's steady specialisation (`rotframe.problem.steady`) is the engine's loop, to the bit, and is chosen only
where the terms allow it.

``inline=False`` asks for the engine's general loop by name, so it is the oracle here: the same problem, the same
method and tolerances, run by the loop whose physics the rest of the suite checks against closed forms and
conserved quantities. The steady loop must give its very steps and numbers (a planted change of a term's sign, of
the tolerance rule or of the sample times fails these tests).
"""

from __future__ import annotations

import numpy as np
import pytest

from rotframe import forces
from rotframe.particles.threads import BLOCK
from rotframe.problem.particles import simulate_particles
from rotframe.problem.steady import FIXED_STEADY

STEADY_NOTE = "steady loop"
FIXED_NOTE = "fixed-step drivers"


def _on_string(rng, L, pivot, n):
    """n start states on the sphere of radius L about pivot, below it, moving across the string."""
    r, v = [], []
    for _ in range(n):
        d = rng.normal(size=3)
        d[2] = -abs(d[2]) - 1.0
        d /= np.linalg.norm(d)
        r.append(pivot + L * d)
        u = np.cross(d, rng.normal(size=3))
        v.append(0.3 * u)
    return np.array(r), np.array(v)


def _random_problem(seed):
    rng = np.random.default_rng(seed)
    w = rng.normal(size=3) * 10.0 ** rng.uniform(-5, -0.5)
    g = np.array([0.0, 0.0, -9.81]) + rng.normal(size=3) * 0.1
    frame_terms = tuple(t for t in ("coriolis", "centrifugal", "euler") if rng.random() < 0.7)
    n = int(rng.integers(1, 4))
    terms = [forces.gravity(g)] if rng.random() < 0.8 else []
    if rng.random() < 0.6:
        L = float(rng.uniform(0.5, 70.0))
        pivot = rng.normal(size=3)
        terms.append(forces.pendulum(L, pivot))
        r0, v0 = _on_string(rng, L, pivot, n)
    else:
        r0, v0 = rng.normal(size=(n, 3)) * 10.0, rng.normal(size=(n, 3))
    rng.shuffle(terms)
    atol = None if rng.random() < 0.6 else float(10.0 ** rng.uniform(-12, -7))
    rtol = float(10.0 ** rng.uniform(-12, -5))
    kw = dict(omega=w, r0=r0, v0=v0, duration=float(rng.uniform(1.0, 40.0)), samples=int(rng.integers(1, 30)),
              forces=terms, frame_terms=frame_terms, rtol=rtol, atol=atol)
    if seed >= 8:  # a built-in crossing of a coordinate of r or v, zero at no start: crossed by some, terminal or not
        from rotframe.events import crossing

        c, of = int(rng.integers(0, 3)), (r0, v0)[int(rng.integers(0, 2))]
        level = float(np.mean(of[:, c]) + 0.3 * rng.normal() * (1.0 + np.std(of[:, c])))
        kw["events"] = [crossing(c, level, of="r" if of is r0 else "v", direction=int(rng.integers(-1, 2)),
                                 terminal=bool(rng.random() < 0.5), name="level")]
        kw["max_events"] = int(rng.integers(1, 4))  # some crossings not kept: the same warning
    return kw


@pytest.mark.parametrize("seed", range(20))
def test_the_steady_loop_is_the_engines_loop_to_the_bit(seed):
    kw = _random_problem(seed)
    steady = simulate_particles(**kw)
    general = simulate_particles(**kw, inline=False)
    assert any(STEADY_NOTE in n for n in steady.notes), steady.notes
    assert not any(STEADY_NOTE in n for n in general.notes)
    a, b = steady.trajectory, general.trajectory
    # both count the most any particle took; the engine's loop evaluates f again at the start of each of its calls
    assert a.steps == b.steps > 0 and 0 < a.nfev <= b.nfev
    assert np.array_equal(a.times, b.times)
    assert np.array_equal(a.r, b.r) and np.array_equal(a.v, b.v)
    assert a.event_times.keys() == b.event_times.keys()
    for name in a.event_times:  # each crossing located on the same re-steps: times and states to the bit
        for x, y in zip(a.event_times[name], b.event_times[name]):
            assert np.array_equal(x, y)
        for x, y in zip(a.event_states[name], b.event_states[name]):
            assert np.array_equal(x, y)
    assert np.array_equal(a.extras["status"], b.extras["status"]) and steady.warnings == general.warnings
    # the tolerances each records (for Result.sol's restarts): the calls' driver's rows and the rows the engine's
    # loop filled in place, the same
    assert a.extras["atol"].shape == (a.r.shape[1], 6) and np.array_equal(a.extras["atol"], b.extras["atol"])
    assert steady.diagnostics.keys() == general.diagnostics.keys()
    for key in steady.diagnostics:
        assert steady.diagnostics[key] == general.diagnostics[key]


def _foucault_like():
    L = 10.0
    pivot = np.array([0.0, 0.0, L])
    a = 0.5
    return dict(omega=[0.0, 4e-5, 5e-5], r0=[a, 0.0, L - np.sqrt(L * L - a * a)], v0=[0.0, 0.0, 0.0], duration=5.0,
                samples=5, forces=[forces.gravity([0.0, 0.0, -9.81]), forces.pendulum(L, pivot)])


def _steady(**kw):
    return any(STEADY_NOTE in n for n in simulate_particles(**kw).notes)


def test_the_foucault_model_runs_the_steady_loop():
    assert _steady(**_foucault_like())


@pytest.mark.parametrize("n_small", [1, BLOCK])
def test_the_steady_loop_counts_the_costliest_particle_wherever_it_is(n_small):
    # a hanging bob that hardly swings beside a wide swing: the wide one takes more steps, whatever its place (with
    # BLOCK small ones, in another block than the first on every core)
    kw = _foucault_like()
    L, wide = 10.0, 8.0
    small, large = kw["r0"], [wide, 0.0, L - np.sqrt(L * L - wide * wide)]
    alone = simulate_particles(**dict(kw, r0=large)).trajectory.steps
    assert alone > simulate_particles(**kw).trajectory.steps
    for r0 in ([small] * n_small + [large], [large] + [small] * n_small):
        run = simulate_particles(**dict(kw, r0=r0, v0=np.zeros((len(r0), 3))))
        assert any(STEADY_NOTE in n for n in run.notes)
        assert run.trajectory.steps == alone


@pytest.mark.parametrize("change", [
    {"method": "rk4", "step": 0.01, "inline": True},
    {"inline": True},
    {"events": [lambda t, r, v: r[0] - 10.0]},
    {"omega": lambda t: (0.0, 4e-5, 5e-5 * (1.0 + 0.01 * t))},
    {"origin_acceleration": [0.0, 0.0, 0.1]},
    {"forces": [forces.gravity([0.0, 0.0, -9.81]), forces.drag(linear=0.01)]},
    {"forces": [forces.gravity([0.0, 0.0, -9.81]), forces.spring(1.0)]},
    {"forces": [forces.gravity([0.0, 0.0, -9.81]), forces.gravity([0.0, 0.1, 0.0])]},
    {"forces": [lambda t, r, v: (0.0, 0.0, -9.81)]},
])
def test_other_runs_take_the_engines_loop(change):
    kw = dict(_foucault_like(), **change)
    if "forces" in change:  # no string: any start
        kw["r0"] = [1.0, 2.0, 3.0]
    assert not _steady(**kw)


def _random_fixed_problem(seed):
    """A steady problem of uniform gravity and the Coriolis term (the tower drop's class), the centrifugal term too
    in half of them, air drag in some, under RK4 or the splitting, with one built-in crossing or none."""
    from rotframe.events import crossing

    rng = np.random.default_rng(1000 + seed)
    n = int(rng.integers(1, 5))
    w = rng.normal(size=3) * 10.0 ** rng.uniform(-5, -1) if rng.random() < 0.9 else np.zeros(3)
    terms = [forces.gravity(np.array([0.0, 0.0, -9.81]) + rng.normal(size=3) * 0.1)] if rng.random() < 0.85 else []
    r0, v0 = rng.normal(size=(n, 3)) * 10.0, rng.normal(size=(n, 3)) * 3.0
    duration = float(rng.uniform(0.5, 6.0))
    samples = int(rng.integers(1, 30))
    kw = dict(omega=w, r0=r0, v0=v0, duration=duration, samples=samples, forces=terms,
              frame_terms=("coriolis", "euler") if rng.random() < 0.5 else ("coriolis",),
              method=str(rng.choice(FIXED_STEADY)), step=duration / samples / rng.uniform(1.0, 60.0))
    if rng.random() < 0.3:  # air drag, its own exact flow under the splitting
        linear = float(rng.choice([0.0, rng.uniform(0.01, 0.5)]))
        terms.append(forces.drag(linear=linear, quadratic=float(rng.uniform(1e-4, 0.05)) if linear == 0.0 or
                                 rng.random() < 0.6 else 0.0,
                                 scale_height=float(rng.choice([0.0, rng.uniform(5.0, 50.0)]))))
        rng.shuffle(terms)
    if rng.random() < 0.5:  # every frame term, as simulate's default
        kw["frame_terms"] = ("coriolis", "centrifugal", "euler")
    if rng.random() < 0.8:
        of = "v" if rng.random() < 0.3 else "r"
        k = int(rng.integers(0, 3))
        value = float(np.mean((r0 if of == "r" else v0)[:, k]) + rng.normal() * 0.3)  # some particles cross it
        kw["events"] = [crossing(k, value, of=of, direction=int(rng.integers(-1, 2)), terminal=bool(rng.random() < 0.6),
                                 name="level")]
    return kw


def _random_pendulum(seed):
    """A pendulum (a string from a random pivot, gravity, air drag in some) in a steady frame under RK4 or the
    splitting, started on the string's sphere with a velocity along it, some with a built-in crossing."""
    from rotframe.events import crossing

    rng = np.random.default_rng(5000 + seed)
    n = int(rng.integers(1, 4))
    L, pivot = float(rng.uniform(1.0, 70.0)), rng.normal(size=3) * 2.0
    amp, phi = rng.uniform(0.01, 1.2, n), rng.uniform(0.0, 2.0 * np.pi, n)
    out = np.stack([np.sin(amp) * np.cos(phi), np.sin(amp) * np.sin(phi), -np.cos(amp)], axis=1)  # pivot -> bob
    along = np.cross(out, rng.normal(size=(n, 3)))
    v0 = along / np.linalg.norm(along, axis=1)[:, None] * rng.uniform(0.0, 2.0, (n, 1)) * float(rng.random() < 0.5)
    terms = [forces.gravity(np.array([0.0, 0.0, -9.81]) + rng.normal(size=3) * 0.1), forces.pendulum(L, pivot)]
    if rng.random() < 0.3:
        terms.insert(1, forces.drag(linear=float(rng.uniform(0.001, 0.1))))
    duration, samples = float(rng.uniform(1.0, 10.0)), int(rng.integers(1, 20))
    kw = dict(omega=rng.normal(size=3) * 10.0 ** rng.uniform(-5, -1), r0=pivot + L * out, v0=v0, duration=duration,
              samples=samples, forces=terms, method=str(rng.choice(FIXED_STEADY)),
              frame_terms=tuple(t for t in ("coriolis", "centrifugal", "euler") if rng.random() < 0.7) or ("coriolis",),
              step=duration / samples / rng.uniform(1.0, 40.0))
    if rng.random() < 0.5:
        level = float(np.mean(kw["r0"][:, 0]) + 0.1 * L * rng.normal())  # zero at no start: some cross it
        kw["events"] = [crossing(0, level, direction=int(rng.integers(-1, 2)),
                                 terminal=bool(rng.random() < 0.5), name="level")]
    return kw


@pytest.mark.parametrize("seed", range(32))
def test_the_fixed_step_drivers_are_the_engines_loop_to_the_bit(seed):
    # a steady problem of uniform gravity and the frame's terms under RK4 or the rotation splitting runs on the
    # scenes' fixed-step drivers (chosen from the terms, `rotframe.problem.steady`) where their model keeps the
    # frame's omega to the bit: the engine's loop (inline=False) is the oracle, sample by sample, event by event,
    # with its counts and statuses
    from rotframe.problem.steady import omega_kept

    kw = _random_fixed_problem(seed) if seed < 20 else _random_pendulum(seed)
    fixed = simulate_particles(**kw)
    general = simulate_particles(**kw, inline=False)
    routed = any(FIXED_NOTE in n for n in fixed.notes)
    assert routed == (not np.any(kw["omega"]) or omega_kept(kw["omega"])), fixed.notes
    assert not any(FIXED_NOTE in n for n in general.notes)
    a, b = fixed.trajectory, general.trajectory
    assert np.array_equal(a.times, b.times)
    assert np.array_equal(a.r, b.r) and np.array_equal(a.v, b.v)
    assert a.event_times.keys() == b.event_times.keys()
    for name in a.event_times:
        for x, y in zip(a.event_times[name], b.event_times[name]):
            assert np.array_equal(x, y)
        for x, y in zip(a.event_states[name], b.event_states[name]):
            assert np.array_equal(x, y)
    assert np.array_equal(a.extras["status"], b.extras["status"])
    assert a.steps == b.steps > 0 and a.extras["step"] == b.extras["step"]
    assert fixed.diagnostics == general.diagnostics and fixed.warnings == general.warnings


def _rounded_omega():
    """An omega (rad/s) that the scenes' model does not keep to the bit on this machine (`omega_kept` False)."""
    from rotframe.problem.steady import omega_kept

    rng = np.random.default_rng(7)
    for _ in range(1000):
        w = rng.uniform(-1e-3, 1e-3, 3)
        if not omega_kept(w):
            return w.tolist()
    pytest.skip("every omega drawn is kept to the bit on this machine")


@pytest.mark.parametrize("change", [{"omega": "rounded"}, {"forces": [forces.spring(1.0)]}])
def test_fixed_step_runs_outside_the_drivers_arithmetic_take_the_engines_loop(change):
    # an omega the drivers' model rounds (its axis times its rate is not omega again), and a term they do not take
    # from the engine (a spring: the scenes' is horizontal, a linear form not constant)
    from rotframe.events import crossing
    from rotframe.problem.steady import omega_kept

    kw = dict(omega=[0.0, 4.6e-5, 5.7e-5], r0=[[0.0, 0.0, 5.0]], v0=[[0.0, 0.0, 0.0]], duration=2.0,
              forces=[forces.gravity([0.0, 0.0, -9.81])], frame_terms=("coriolis",), method="rotation-splitting",
              step=1e-3, events=[crossing(2, 0.0, direction=-1, terminal=True, name="ground")])
    assert any(FIXED_NOTE in n for n in simulate_particles(**kw).notes)  # the tower drop's problem: the drivers
    kw.update(change)
    if change.get("omega") == "rounded":  # numpy's norm rounds by the machine's vector unit: found, not assumed
        kw["omega"] = _rounded_omega()
    assert "omega" not in change or not omega_kept(np.array(kw["omega"]))
    assert not any(FIXED_NOTE in n for n in simulate_particles(**kw).notes)


def test_a_run_whose_event_is_zero_at_a_start_takes_the_engines_loop():
    # the drivers take the sign just after a zero start from derivatives, the engine from re-steps: not the same rule
    from rotframe.events import crossing

    kw = dict(omega=[0.0, 4e-5, 5e-5], r0=[[0.0, 0.0, 0.0], [0.0, 0.0, 5.0]], v0=[[1.0, 0.0, 3.0], [0.0, 0.0, 0.0]],
              duration=2.0, forces=[forces.gravity([0.0, 0.0, -9.81])], method="rk4", step=1e-3,
              frame_terms=("coriolis",), events=[crossing(2, 0.0, direction=-1, terminal=True, name="ground")])
    run = simulate_particles(**kw)
    assert not any(FIXED_NOTE in n for n in run.notes)
    assert any(FIXED_NOTE in n for n in simulate_particles(**dict(kw, r0=[[0.0, 0.0, 1e-9], [0.0, 0.0, 5.0]])).notes)


def test_a_failure_on_the_steady_loop_is_met_and_named_by_the_engines_loop():
    # a rate so large that the centrifugal term overflows once the particle moves (its work estimate is over the
    # limit: raised so that it runs to the failure); the steady loop fails, and the run is made again on the engine's
    # loop, which names the cause, as a run with inline=False does
    from rotframe import limits
    from rotframe.errors import IntegrationError

    kw = dict(omega=[0.0, 0.0, 1e150], r0=[1e-160, 0.0, 0.0], v0=[0.0, 0.0, 0.0], duration=1.0, samples=4,
              frame_terms=("centrifugal",))
    with limits.applied(limits.current().with_overrides(max_steps=1e300)):
        with pytest.raises(IntegrationError) as steady:
            simulate_particles(**kw)
        with pytest.raises(IntegrationError) as general:
            simulate_particles(**kw, inline=False)
    assert str(steady.value) == str(general.value)
    assert "step size collapsed" in str(steady.value)
    assert steady.value.t_reached == general.value.t_reached
    assert np.array_equal(steady.value.partial.r, general.value.partial.r)


def test_a_prepared_steady_problem_is_simulate_to_the_bit_and_fails_as_it_does():
    from rotframe import limits
    from rotframe.errors import IntegrationError
    from rotframe.problem.prepared import PreparedProblem

    kw = _random_problem(5)
    r0, v0 = kw.pop("r0"), kw.pop("v0")
    prepared = PreparedProblem(r0=r0, v0=v0, **kw)
    assert any(STEADY_NOTE in n for n in prepared.notes)
    for scale in (1.0, 1.5):  # a second start (off the string's sphere where there is one: scaled about it)
        if any(isinstance(f, forces.pendulum(1.0).__class__) for f in kw["forces"]) and scale != 1.0:
            continue
        a = prepared.run(r0 * scale, v0)
        b = simulate_particles(r0=r0 * scale, v0=v0, **kw).trajectory
        assert np.array_equal(a.r, b.r) and np.array_equal(a.v, b.v) and np.array_equal(a.times, b.times)
    bad = dict(omega=[0.0, 0.0, 1e150], duration=1.0, samples=4, frame_terms=("centrifugal",))
    start = ([1e-160, 0.0, 0.0], [0.0, 0.0, 0.0])
    with limits.applied(limits.current().with_overrides(max_steps=1e300)):
        with pytest.raises(IntegrationError) as from_prepared:
            PreparedProblem(r0=start[0], v0=start[1], **bad).run(*start)
        with pytest.raises(IntegrationError) as from_simulate:
            simulate_particles(r0=start[0], v0=start[1], **bad)
    assert str(from_prepared.value) == str(from_simulate.value)


def test_an_ensemble_beyond_the_python_rule_takes_the_compiled_tolerances_to_the_bit():
    # more than 256 particles: their own tolerances are made by the compiled rule (rotframe.particles.chunked), a few
    # by the same function run as Python; both are the engine's loop's, particle by particle
    rng = np.random.default_rng(4)
    n = 300
    kw = dict(omega=[0.0, 1e-3, 2e-3], r0=rng.normal(size=(n, 3)) * 10.0 ** rng.uniform(-3, 3, size=(n, 1)),
              v0=rng.normal(size=(n, 3)), duration=2.0, samples=2, forces=[forces.gravity([0.0, 0.0, -9.81])],
              rtol=1e-8)
    steady = simulate_particles(**kw)
    assert any(STEADY_NOTE in note for note in steady.notes)
    general = simulate_particles(**kw, inline=False)
    assert np.array_equal(steady.trajectory.r, general.trajectory.r)
    assert np.array_equal(steady.trajectory.v, general.trajectory.v)
    few = simulate_particles(**dict(kw, r0=kw["r0"][:5], v0=kw["v0"][:5]))  # the Python rule: the same rows
    assert np.array_equal(few.trajectory.r, steady.trajectory.r[:, :5])


@pytest.mark.parametrize("samples", [1, 100])
def test_a_run_longer_than_one_call_runs_on_the_engines_loop(samples):
    # the calls' driver ends each call with a step cut to land on its last sample (and cuts a long sample interval
    # into pieces), where the engine's loop only samples inside its steps: a run of more than one call (here some
    # 5e5 steps) goes to the engine's loop, so the steps, and the numbers, are the engine's whatever the run's length
    L = 1.0
    kw = dict(omega=[0.0, 4e-5, 5e-5], r0=[0.5, 0.0, L - np.sqrt(L * L - 0.25)], v0=[0.0, 0.0, 0.0],
              duration=3e4, samples=samples,
              forces=[forces.gravity([0.0, 0.0, -9.81]), forces.pendulum(L, [0.0, 0.0, L])])
    long_run = simulate_particles(**kw)
    assert not any(STEADY_NOTE in n for n in long_run.notes)
    assert long_run.trajectory.steps > 2e5
    assert np.array_equal(long_run.trajectory.r, simulate_particles(**kw, inline=False).trajectory.r)
    short = dict(kw, duration=3e3)  # some 5e4 steps: one call, the steady loop, the same bits
    assert any(STEADY_NOTE in n for n in simulate_particles(**short).notes)
    assert np.array_equal(simulate_particles(**short).trajectory.r,
                          simulate_particles(**short, inline=False).trajectory.r)
