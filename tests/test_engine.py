"""The one engine of a problem of your own (issue 32): compiled once, a small glue per problem, failures named.

- The glue a problem compiles (`rotframe.problem.glue`) is rendered and linted here: every name it
  reads is bound (the header's imports, the user's functions, its own locals), and it compiles as
  Python for every shape of problem (forces in both axes, potentials, events, a function frame with
  and without omega', an origin function, array parameters of several shapes; a body's torque).
- The engine is compiled once for every problem: two problems of different structure in one
  process leave each entry point with its one signature.
- A user function that raises or gives NaN inside the compiled run is named in one line, with the
  time, the state and the samples up to there: a force, an event, omega(t).
"""

from __future__ import annotations

import ast
import builtins

import os
import subprocess
import sys
import numpy as np
import pytest

import rotframe
from rotframe.errors import IntegrationError, ScenarioError
from rotframe.problem import codegen, glue
from rotframe.problem.terms import Force

R0, V0 = [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]


def spring(t, r, v, k, anchor, table):
    return -k * (r[0] - anchor[0]), -k * (r[1] - anchor[1]), -k * r[2] + 0.0 * table[1, 1]


def spring_potential(t, r, k, anchor, table):
    return 0.5 * k * ((r[0] - anchor[0]) ** 2 + (r[1] - anchor[1]) ** 2 + r[2] ** 2)


def wind(t, r, v, k, anchor, table):
    return 0.1, 0.0, 0.0


def floor(t, r, v, k, anchor, table):
    return r[2] + 10.0


def _undefined_names(source: str, known: set) -> set:
    """Names a module reads that nothing binds (its imports, assignments, defs, arguments, ``known``, builtins)."""
    tree = ast.parse(source)
    bound = set(known) | set(dir(builtins))
    for node in ast.walk(tree):
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            bound |= {(a.asname or a.name).split(".")[0] for a in node.names}
        elif isinstance(node, (ast.FunctionDef, ast.Lambda)):
            bound.add(getattr(node, "name", ""))
            bound |= {a.arg for a in node.args.args}
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            bound.add(node.id)
    return {n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)} - bound


PARAMS = (2.0, np.array([0.5, -0.5, 0.0]), np.arange(6.0).reshape(2, 3))


@pytest.mark.parametrize("splitting", [False, True])
@pytest.mark.parametrize("omega", ["", "function", "function_dot"])
def test_the_particle_glue_renders_and_lints(splitting, omega):
    forces = [Force(spring, potential=spring_potential), Force(wind, axes="inertial")]
    source = glue.particle_source(forces, [floor], PARAMS, splitting=splitting, omega=omega, origin=True)
    bound = {"force_0", "force_1", "potential_0", "event_0", "omega_fn", "omega_dot_fn", "origin_fn"}
    for header in (codegen._HEADER_COMPILED.format(cache=False), codegen._HEADER_PLAIN):
        text = header + source
        compile(text, "<glue>", "exec")
        assert _undefined_names(text, bound) == set()
    assert source.count("\ndef ") == 3 + (omega != "") + 1  # terms, event, potential, omega, origin
    assert "P2 = readonly(p[4:10]).reshape((2, 3))" in source and "P0 = p[0]" in source
    lines = glue.render(source).splitlines()
    assert lines[0].startswith("   1  ") and len(lines) == len(source.splitlines())


@pytest.mark.parametrize("takes_params", [(True,), (False, True, False)])
def test_the_body_glue_renders_and_lints(takes_params):
    source = glue.body_source(takes_params, PARAMS)
    text = codegen._HEADER_COMPILED.format(cache=False) + source
    compile(text, "<glue>", "exec")
    assert _undefined_names(text, {f"torque_{k}" for k in range(len(takes_params))}) == set()
    calls = [line.strip() for line in source.splitlines() if "torque_" in line]
    assert calls == [f"a = torque_{k}(t, L, q{', P0, P1, P2' if takes else ''})" for k, takes in enumerate(takes_params)]


def test_params_flatten_into_one_array_in_order():
    flat = glue.flatten_params(PARAMS)
    assert flat.dtype == np.float64 and flat.flags.c_contiguous
    np.testing.assert_array_equal(flat, np.concatenate([[2.0], PARAMS[1], PARAMS[2].ravel()]))


def test_the_engine_compiles_once_for_every_problem(monkeypatch):
    from rotframe.problem import engine, tiers

    monkeypatch.setattr(tiers, "PLAIN_PARTICLES", 0)  # compiled from the start, whatever the caches hold

    def pull(t, r, v, c):
        return -c * r[0], -c * r[1], -c * r[2]

    def ground(t, r, v):
        return r[2] + 1.0

    rotframe.simulate(omega=[0.0, 0.0, 0.5], r0=R0, v0=V0, duration=1.0, forces=[pull], params=(1.0,), samples=4)
    rotframe.simulate(omega=lambda t: np.array([0.0, 0.1 * t, 0.5]), r0=R0, v0=V0, duration=1.0, events=[ground],
                      forces=[Force(lambda t, r, v: (0.0, 0.0, -1.0), axes="inertial")], method="rk4", step=0.01,
                      samples=4)
    rotframe.simulate_body(inertia=[1.0, 2.0, 3.0], L0=[0.1, 1.0, 0.1], q0=[0, 0, 0, 1], duration=1.0, samples=4)
    from rotframe.problem.signatures import BODY, PARTICLE

    # each variant of the loop (model, method, events) compiled once, for its one signature, whatever the problem
    used = [engine.variant(PARTICLE, "dop853", False), engine.variant(PARTICLE, "rk4", True),
            engine.variant(BODY, "dop853", False)]
    for kernel in used + [engine.start_events]:
        assert len(kernel.signatures) == 1, kernel.signatures
    assert len({id(k) for k in used}) == 3
    with pytest.raises(TypeError):  # closed to new compiles: a problem's functions arrive as addresses
        used[0](*[None] * 31)


def test_a_variant_compiles_only_its_own_model_method_and_events(tmp_path):
    """A first DOP853 particle problem without events, in a steady frame, compiles no body, no splitting, no RK4, no
    event locator and no evaluator of a varying frame; a body then compiles its own variant and no particle's."""
    script = tmp_path / "first.py"
    script.write_text(_FIRST_PROBLEM)
    env = dict(os.environ, ROTFRAME_CACHE_DIR=str(tmp_path / "problems"), NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    proc = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, env=env, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    lines = proc.stdout.strip().splitlines()[-3:]
    particle, body = set(lines[0].split()), set(lines[2].split())
    # the one DOP853 loop of rotframe (numerics.dop853_loop), compiled for the engine's particle
    # (its whole loop: a loop over the particles that calls the trajectory, compiled apart, at its address)
    assert {"advance_particle6_dop853_at", "particle_rhs", "dop853_stages_engine_particle6",
            "dop853_trajectory_engine_particle6_by_address_entry"} <= particle, particle
    # the right-hand side is compiled once, marked for LLVM to inline, and no DOP853 stage calls it any more
    assert lines[1] == "inline True, calls left 0", lines[1]
    assert not particle & {"body_rhs", "own_step", "particle_strang", "body_split", "rotation_strang",
                           "rk4_step_engine_particle", "kick_acceleration",
                           "lie_poisson_strang",
                           "sphere_strang", "varying_into", "varying_vector", "hermite"}, particle
    # then a body: its own variant and right-hand side, no particle's
    assert {"advance_body7_dop853_at", "body_rhs", "dop853_stages_engine_body7"} <= body, body
    assert "particle_rhs" not in body, body


_FIRST_PROBLEM = """
from numba.core import event
import rotframe

names = []
compiled = {}


class Listener(event.Listener):
    def on_start(self, ev):
        names.append(ev.data["dispatcher"].py_func.__name__)
        compiled[names[-1]] = ev.data["dispatcher"]

    def on_end(self, ev):
        pass


event.register("numba:compile", Listener())
import rotframe.problem.tiers
rotframe.problem.tiers.PLAIN_PARTICLES = 0  # what a run compiles is inspected here: no first run in the plain tier
import rotframe.numerics.compile_apart
rotframe.numerics.compile_apart.spare_core = lambda: False  # and every compile in this process, where it is seen
rotframe.simulate(omega=[0.0, 0.0, 0.5], r0=[1.0, 0.0, 0.0], v0=[0.0, 1.0, 0.0], duration=1.0,
                  forces=[lambda t, r, v: (-r[0], -r[1], -r[2])], samples=4)
print(" ".join(names))
from rotframe.problem import engine, models
ir = next(iter(compiled["dop853_stages_engine_particle6"].overloads.values())).library.get_llvm_str()
calls = [line for line in ir.splitlines() if " call " in line and "particle_rhs" in line]
print(f"inline {next(iter(models.particle_rhs.overloads.values())).fndesc.inline}, calls left {len(calls)}")
names.clear()
rotframe.simulate_body(inertia=[1.0, 2.0, 3.0], L0=[0.1, 1.0, 0.1], q0=[0, 0, 0, 1], duration=1.0, samples=4)
print(" ".join(names))
"""


def force_raises_after(t, r, v):
    if t > 0.5:
        raise ValueError("sensor lost")
    return -r[0], -r[1], -r[2]


def event_nan_after(t, r, v):
    return r[2] - 5.0 if t < 0.5 else np.nan


def event_raises_after(t, r, v):
    if t > 0.5:
        raise RuntimeError("event broke")
    return r[2] - 5.0


def omega_raises_after(t):
    if t > 0.5:
        raise ZeroDivisionError("no rate")
    return np.array([0.0, 0.0, 1.0])


@pytest.mark.parametrize("method", ["dop853", "rk4"])
def test_a_force_that_raises_mid_run_is_named_with_time_state_and_samples(method):
    with pytest.raises(ScenarioError) as info:
        rotframe.simulate(omega=[0, 0, 1.0], r0=R0, v0=V0, duration=2.0, forces=[force_raises_after], samples=20,
                          method=method, step=0.01)
    msg = str(info.value)
    assert "\n" not in msg and "force_raises_after" in msg and "ValueError: sensor lost" in msg
    assert "r = [" in msg and "v = [" in msg
    part = info.value.partial.trajectory
    assert 0.4 <= part.times[-1] <= 0.5 and np.all(np.isfinite(part.r))


@pytest.mark.parametrize("method", ["dop853", "rk4", "rotation-splitting"])
def test_an_event_that_gives_nan_mid_run_is_named(method):
    with pytest.raises(IntegrationError) as info:
        rotframe.simulate(omega=[0, 0, 1.0], r0=R0, v0=V0, duration=2.0, events=[event_nan_after], samples=20,
                          method=method, step=0.01)
    msg = str(info.value)
    assert "event_nan_after" in msg and "non-finite" in msg and "nan" in msg


@pytest.mark.parametrize("method", ["dop853", "rk4", "rotation-splitting"])
def test_an_event_that_raises_mid_run_is_named(method):
    with pytest.raises(ScenarioError) as info:
        rotframe.simulate(omega=[0, 0, 1.0], r0=R0, v0=V0, duration=2.0, events=[event_raises_after], samples=20,
                          method=method, step=0.01)
    msg = str(info.value)
    assert "event_raises_after" in msg and "RuntimeError: event broke" in msg


def test_an_omega_function_that_raises_mid_run_is_named():
    with pytest.raises(ScenarioError) as info:
        rotframe.simulate(omega=omega_raises_after, r0=R0, v0=V0, duration=2.0, samples=20)
    msg = str(info.value)
    assert "omega_raises_after" in msg and "ZeroDivisionError: no rate" in msg


@pytest.mark.parametrize("step, per_sample", [(1e-3, 1), (2.5e-4, 2), (1e-4, 5)])
def test_a_fixed_step_takes_its_count_of_steps_however_far_the_run_goes(step, per_sample):
    """Each sample interval takes exactly its substeps: the interval's rounding (ulps of t, 2e-12 of a 5e-4 s
    interval at t = 4 s) once made a step short of a sample and a sliver to it."""
    n = 20000
    particle = rotframe.simulate(omega=[0.0, 0.0, 0.5], r0=R0, v0=V0, duration=10.0, method="rk4", step=step,
                                 samples=n)
    body = rotframe.simulate_body(inertia=[1.0, 2.0, 3.0], L0=[0.1, 1.0, 0.1], q0=[0, 0, 0, 1], duration=10.0,
                                  method="lie-poisson", step=step, samples=n)
    assert particle.to_dict()["steps"] == body.to_dict()["steps"] == n * per_sample
