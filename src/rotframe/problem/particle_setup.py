"""A particle problem checked and built: what `rotframe.problem.particles.simulate_particles` does before its first step.

`set_up` checks every argument (each bad one a one-line ScenarioError naming it), calls each
of the user's functions once at the start, builds (or finds in the cache) the problem's glue
(`rotframe.problem.codegen`) and the engine's data (`rotframe.problem.signatures.PROBLEM`), and
returns it all as a `SetUp`. `start_states` and `run_state` make a run's arrays from it. A
`simulate_particles` call sets up and runs once; a `rotframe.problem.prepared.PreparedProblem`
sets up once and runs many times.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rotframe import method_registry as registry
from rotframe.errors import ScenarioError
from rotframe.limits import check_memory, check_run
from rotframe.problem import callables as uf
from rotframe.problem.arguments import (array_of, check_event, check_flag, check_inline, check_params, run_grid,
                                        sequence_of_callables)
from rotframe.problem.codegen import Driver, build_module
from rotframe.problem.frame import frame_spec, origin_spec, stop_times
from rotframe.problem.glue import flatten_params, particle_source
from rotframe.problem.steady import steady_model
from rotframe.problem.terms import Force, as_term, check_frame_terms, check_splitting, model_constants, one_constraint

__all__ = ["SetUp", "set_up", "checked_states", "plain_states", "checked_atol", "checked_attitude", "check_arrays", "start_states",
           "fill_states", "run_state", "problem_tuple", "function_roles"]


#: float64, the dtype a run's arrays have (numpy keeps one object for it: compared by identity, in 30 ns)
_F64 = np.dtype(np.float64)


def plain_states(r0, v0) -> bool:
    """Whether ``r0``, ``v0`` are already what a run takes: float64 arrays of one shape, (3,) or (N, 3), C-ordered
    (what a prepared run's caller passes; their checks then take a microsecond, not five)."""
    return (type(r0) is np.ndarray and type(v0) is np.ndarray and r0.dtype is _F64 and v0.dtype is _F64
            and r0.shape == v0.shape and r0.shape[-1:] == (3,) and r0.ndim <= 2 and r0.flags.c_contiguous
            and v0.flags.c_contiguous)


def checked_states(r0, v0):
    """The start states ``r0``, ``v0`` as (N, 3) arrays: one of them may be a single state for all N; finite."""
    if plain_states(r0, v0):
        r, v = r0.reshape(-1, 3), v0.reshape(-1, 3)
        if not (all(map(math.isfinite, r0.tolist() + v0.tolist())) if r0.ndim == 1 else
                np.isfinite(r).all() and np.isfinite(v).all()):
            raise ScenarioError("r0, v0: not finite")
        return r, v
    r = np.atleast_2d(array_of(r0, "r0"))
    v = np.atleast_2d(array_of(v0, "v0"))
    if (r.ndim == 2 and v.ndim == 2 and r.shape[1] == 3 and v.shape[1] == 3 and r.shape[0] != v.shape[0]
            and 1 in (r.shape[0], v.shape[0])):
        n = max(r.shape[0], v.shape[0])  # one start position with N velocities, or the other way round
        r, v = np.repeat(r, n // r.shape[0], axis=0), np.repeat(v, n // v.shape[0], axis=0)
    if r.ndim != 2 or r.shape[1] != 3 or v.shape != r.shape:
        raise ScenarioError(f"r0, v0: shapes {np.shape(r0)} and {np.shape(v0)}; expected both (3,) or both (N, 3)")
    if not (np.isfinite(r).all() and np.isfinite(v).all()):  # array methods: a prepared run checks at every run
        raise ScenarioError("r0, v0: not finite")
    return np.ascontiguousarray(r), np.ascontiguousarray(v)  # one layout for the string's compiled check


def problem_tuple(M, p, frame, origin):
    """The engine's `rotframe.problem.signatures.PROBLEM` tuple of a particle problem."""
    from rotframe.problem.signatures import PARTICLE  # numba's types: imported by the runs that compile

    return (PARTICLE, M, p, *frame.packed(), *origin.packed(derivative=False))


def _functions(frame, origin, forces, events, labels):
    """The user's functions of a problem as ``(glue name, role, function)``: the name the glue binds it to
    (`rotframe.problem.glue.particle_source`) and the role its errors name it by, in the roles' order."""
    found = []
    if frame.kind == "function":
        found.append(("omega_fn", "omega", frame.funcs[0]))
        if len(frame.funcs) > 1:
            found.append(("omega_dot_fn", "omega_dot", frame.funcs[1]))
    if origin.kind == "function":
        found.append(("origin_fn", "origin_acceleration", origin.funcs[0]))
    found += [(f"force_{k}", labels[k], f.accel) for k, f in enumerate(forces)]
    found += [(f"potential_{k}", f"{labels[k]}.potential", f.potential) for k, f in enumerate(forces)
              if f.potential is not None]
    found += [(f"event_{k}", f"events[{k}]", g) for k, g in enumerate(events)]
    return found


def _bind(frame, origin, forces, events, labels, compiled):
    """The glue's names bound to the user's functions, compiled for it (or as plain Python)."""
    prep = uf.compiled_for_glue if compiled else uf.plain_function
    return {name: prep(f) for name, _, f in _functions(frame, origin, forces, events, labels)}


def function_roles(frame, origin, forces, events, labels):
    """The user's functions of a problem as ``(role, function)`` pairs, named as its errors name them."""
    return [(role, f) for _, role, f in _functions(frame, origin, forces, events, labels)]


def _check_functions(forces, events, params, r, v, t0, labels):
    """Each force, potential and event once, in plain Python, at the start: shape, finiteness, raises."""
    when = f"at t = {t0:g} s, r = {r.tolist()}, v = {v.tolist()}"
    for k, f in enumerate(forces):
        uf.check_call(labels[k], f.accel, (t0, r.copy(), v.copy(), *f.params_for(params)), (3,), when=when)
        if f.potential is not None:
            uf.check_call(f"{labels[k]}.potential", f.potential, (t0, r.copy(), *f.params_for(params)), (), when=when)
        if f.potential is not None and f.array_potential:  # numpy's energies will call it on every sample at once
            uf.check_call(f"{labels[k]}.potential (array_potential=True: r as (3, 2), t as (2,))", f.potential,
                          (np.full(2, t0), np.stack([r, r], axis=1), *f.params_for(params)), (2,), when=when)
    for k, g in enumerate(events):
        uf.check_call(f"events[{k}]", g, (t0, r.copy(), v.copy(), *params), (), when=when)


def checked_attitude(frame_attitude) -> np.ndarray:
    """``frame_attitude=`` as four numbers (a scalar-last quaternion, x, y, z, w), finite and not all 0; a one-line
    ScenarioError otherwise. Checked wherever it is given, read only where a force acts in inertial axes."""
    q0 = array_of(frame_attitude, "frame_attitude")
    if q0.shape != (4,) or not np.all(np.isfinite(q0)) or not np.any(q0):
        raise ScenarioError(f"frame_attitude: {q0.tolist()}; a scalar-last quaternion (x, y, z, w), 4 finite "
                            "numbers, not all 0")
    return q0


def checked_atol(atol) -> np.ndarray | None:
    """``atol=`` as `tolerance_rows` takes it: six positive numbers (r then v; one number for all six), or None for the
    default (each particle's own scales); a one-line ScenarioError otherwise. A prepared run checks it once."""
    if atol is None:
        return None
    a = array_of(atol, "atol")
    if a.ndim == 0:
        a = np.full(6, float(a))
    if a.shape != (6,) or not np.all(a > 0):
        raise ScenarioError(f"atol={atol!r}: a positive number or 6 positive numbers (r then v)")
    return a


def tolerance_rows(N, D, rtol, atol):
    """Absolute tolerances, one row per particle ((N, D)): ``atol`` (`checked_atol`) for r and v and ``rtol`` for the
    rest of the state where given, else rows of NaN, which the engine's DOP853 loop fills with each particle's own
    (`rotframe.numerics.step_control.own_tolerances`, from its start state: its steps, and its numbers, do not depend on the
    other particles of the ensemble). The rule is compiled into the loop, not made here at every run: a prepared run
    spent 6 us of numpy on it, where the whole of its own cost is some 20 us."""
    if atol is None:
        return np.full((N, D), np.nan)
    out = np.full((N, D), rtol)
    out[:, :6] = atol
    return out


@dataclass
class SetUp:
    """A particle problem made ready to run (`set_up`): its checked settings, terms and events, the engine's driver,
    the problem's data (`rotframe.problem.signatures.PROBLEM`) and its functions' addresses."""

    #: the start states checked (N, 3)
    r: np.ndarray
    v: np.ndarray
    method: str
    duration: float
    times: np.ndarray
    rtol: float
    hfix: float
    D: int
    frame: object
    origin: object
    terms: list
    forces: list
    labels: list
    events: list
    params: tuple
    frame_terms: tuple
    on_gpu: bool
    #: what runs it (None for method exact, which compiles nothing)
    driver: object = None
    prob: tuple = None
    fns: tuple = None
    slots: int = 1
    stops: np.ndarray = None
    EDIR: np.ndarray = None
    ETERM: np.ndarray = None
    cache_notes: list = None
    #: when the driver's build began (`time.perf_counter`): compile time counts from there
    t0: float = 0.0
    #: makes the same problem's driver as plain Python (`rotframe.problem.tiers`); None for a plain run
    plain_driver: object = None
    #: the `rotframe.problem.steady.SteadyProblem` of a run that a steady loop runs; None for the engine's loop
    steady: object = None


def set_up(r0, v0, *, omega, duration, forces, params, origin_acceleration, events, method, rtol, step, samples,
           omega_dot, jit, max_events, device, frame_terms, inline=None, steady=True, fixed_steady=True, ahead=False):
    """Check a particle problem and build what runs it, from the start states ``r0``, ``v0``: a `SetUp`.

    Every argument as `simulate_particles` takes it, checked in its order; the start states are
    checked too (the string's sphere, each function called once at particle 0's), and their
    number sizes the work limits. For method ``exact`` nothing is built: the set-up is returned
    checked, its driver None (the flow is the caller's, `rotframe.problem.exact`). Nor for a run
    that a steady loop runs (``steady``, `rotframe.problem.steady`): its ``steady`` is that loop's problem
    (``fixed_steady`` False: DOP853's alone, not the scenes' fixed-step drivers). With ``ahead`` (the run may begin
    in the plain tier) and a varying frame or origin, whose evaluator compiles first, a loop the run will compile if
    it is long begins to compile in second processes before the problem's functions compile
    (`rotframe.problem.tiers.begin_ahead`): a steady frame's own compile is too short for the overlap to pay for the
    processes a short run never uses (`tools/startup_side_by_side.py`, 2026-12-02).
    """
    import time

    check_flag(jit, "jit")
    check_inline(inline, jit)
    on_gpu = _check_device(device, method, jit)
    method = registry.check(method, "particles", default="dop853", gpu=on_gpu)
    if isinstance(max_events, bool) or not isinstance(max_events, (int, np.integer)) or max_events < 1:
        raise ScenarioError(f"max_events={max_events!r}: a whole number >= 1 (event crossings kept per particle)")
    frame_terms = check_frame_terms(frame_terms)
    r, v = checked_states(r0, v0)
    N = r.shape[0]
    fixed = method not in ("dop853", "exact")
    duration, samples, times, rtol, hfix = run_grid(duration, samples, rtol, step, fixed=fixed,
                                                    what=f"method {method}", particles=N)
    frame = frame_spec(omega, omega_dot)
    origin = origin_spec(origin_acceleration)
    for spec, what in ((frame, "omega"), (origin, "origin_acceleration")):
        if spec.t_range[1] < duration or spec.t_range[0] > 0.0:
            raise ScenarioError(f"{what}: defined for t in [{spec.t_range[0]:g}, {spec.t_range[1]:g}] s, "
                                f"not over the run's [0, {duration:g}] s")
    terms = [as_term(f, k) for k, f in enumerate(sequence_of_callables(forces, "forces"))]
    forces = [f for f in terms if isinstance(f, Force)]
    labels = [f"forces[{k}]" for k, f in enumerate(terms) if isinstance(f, Force)]  # as the user numbered them
    constraint = one_constraint(terms, r, v)
    events = sequence_of_callables(events, "events")
    for k, g in enumerate(events):
        if not callable(g):
            raise ScenarioError(f"events[{k}]: {g!r} is not callable (a function g(t, r, v, *params) -> float)")
    params = check_params(params)
    if method.startswith("rotation-splitting"):
        check_splitting(method, forces, labels)
    if method == "exact":  # the exact flow of a linear problem (the caller's): chosen from the terms, nothing compiled
        return SetUp(r, v, method, duration, times, rtol, hfix, 6, frame, origin, terms, forces, labels, events, params,
                     frame_terms, on_gpu)
    inertial = any(f.axes == "inertial" for f in forces)
    D = 10 if inertial else 6
    _check_functions(forces, events, params, r[0], v[0], 0.0, labels)
    settings = [check_event(g, k) for k, g in enumerate(events)]  # (direction, terminal) of each
    slots = event_slots([terminal for _, terminal in settings], max_events)
    steady = steady_model(method, on_gpu, jit, inline, frame, origin, terms, events, frame_terms, r, v,
                          uf.event_names(events), fixed_steady, samples) if steady else None
    if steady is not None:  # the steady loop, compiled once for every such problem: nothing of this one is built
        return SetUp(r, v, method, duration, times, rtol, hfix, D, frame, origin, terms, forces, labels, events, params,
                     frame_terms, on_gpu, slots=slots, steady=steady)
    if frame.kind == "function":
        frame.vector_at([0.0])  # checked in frame_spec; the derivative's form too
    roles = function_roles(frame, origin, forces, events, labels)
    for role, f in roles:
        uf.check_compilable(role, f, jit)
    splitting = method.startswith("rotation-splitting")
    glue = particle_source(forces, events, params, splitting=splitting, origin=origin.kind == "function",
                           omega=("function_dot" if len(frame.funcs) > 1 else "function") if frame.kind == "function"
                           else "")
    key, cache_note = uf.cache_key(roles, f"|{[f.axes for f in forces]}")
    cache_notes = [cache_note] if cache_note and jit else []
    t0 = time.perf_counter()
    if ahead and jit and not on_gpu and inline is not True:
        from rotframe.problem.signatures import PARTICLE
        from rotframe.problem.tiers import begin_ahead

        begin_ahead((PARTICLE, method, bool(events), D), N, frame.kind != "constant" or origin.kind != "zero")
    try:
        driver = Driver(build_module("particle", key, lambda: _bind(frame, origin, forces, events, labels, jit), glue,
                                     compiled=jit, notes=cache_notes), compiled=jit)
    except Exception as exc:
        import numba

        if isinstance(exc, numba.core.errors.NumbaError):
            _compile_failure(exc, roles, params, r[0], v[0], frame,
                             {labels[k] for k, f in enumerate(forces) if not f.takes_params})
        raise
    prob = problem_tuple(model_constants(constraint, next((f for f in forces if f.flow), None) if splitting else None,
                                         frame_terms), flatten_params(params), frame, origin)
    stops = stop_times((frame, origin), duration)
    check_arrays(N, times.size, D, slots, stops.size)
    EDIR = np.array([float(d) for d, _ in settings], dtype=float)
    ETERM = np.array([bool(t) for _, t in settings], dtype=bool)

    def plain_driver():  # the same problem as plain Python, for a first run whose loop is not compiled yet
        return Driver(build_module("particle", key, lambda: _bind(frame, origin, forces, events, labels, False), glue,
                                   compiled=False), compiled=False)

    return SetUp(r, v, method, duration, times, rtol, hfix, D, frame, origin, terms, forces, labels, events, params,
                 frame_terms, on_gpu, driver, prob, driver.functions(prob), slots, stops, EDIR, ETERM, cache_notes, t0,
                 plain_driver if jit else None)


def event_slots(terminal, max_events) -> int:
    """The event records kept per particle, from the events' ``terminal`` flags.

    One where there are no events (the arrays' shapes). One per event where every event is terminal: a particle's
    first crossing ends it, and the step that ends it records each event at most once before the records after the
    earliest terminal crossing are dropped, so an ensemble to the ground keeps N records, not N times ``max_events``
    (at 20,000 particles its arrays took a tenth of `simulate`'s time). Else ``max_events``. Never more than
    ``max_events``."""
    if not terminal:
        return 1
    return min(max_events, len(terminal)) if all(terminal) else max_events


def check_arrays(N, n, D, slots, knots):
    """Refuse a run of N particles, n samples, states of D numbers and ``slots`` event records each whose arrays
    exceed the memory limit, or whose frame's ``knots`` (each ends a step) or samples exceed the work limits
    (`rotframe.limits`)."""
    check_memory("simulate", {"samples (r, v and state at each sample)": 8.0 * n * N * D,
                              "event slots": 8.0 * N * slots * (D + 2), "per-particle state": 8.0 * N * (3 * D + 16)})
    check_run(steps=knots, samples=n, particles=N, what="simulate (the frame's knots each end a step)")


def start_states(s, r, v, atol, attitude, omega):
    """The engine's states ``y`` (N, D) of the set-up ``s`` from ``r``, ``v`` (N, 3) (`fill_states`), and the
    absolute tolerances (N, D) (`tolerance_rows`; ``atol`` as `checked_atol` gives it)."""
    y = np.zeros((r.shape[0], s.D))
    fill_states(s, r, v, attitude, omega, y)
    return y, tolerance_rows(r.shape[0], s.D, s.rtol, atol)


def fill_states(s, r, v, attitude, omega, y):
    """The engine's states of the set-up ``s`` from ``r``, ``v`` (N, 3) into ``y`` (N, D): with the frame's attitude
    where a force acts in inertial axes (``attitude`` as `checked_attitude` gives it; None: the identity, or a body
    frame's first)."""
    y[:, :3] = r
    y[:, 3:6] = v
    if s.D == 10:
        q0 = np.array([0.0, 0.0, 0.0, 1.0]) if attitude is None else attitude
        if attitude is None and s.frame.kind == "body":
            q0 = np.asarray(omega.trajectory.q[0], dtype=float)
        y[:, 6:] = q0 / np.linalg.norm(q0)


def run_state(N, D, slots, n_events):
    """The engine's per-particle arrays of a run (`rotframe.problem.engine.advance`), by name, at the start."""
    return dict(TC=np.zeros(N), H=np.zeros(N), IDX=np.zeros(N, np.int64), SUB=np.zeros(N, np.int64),
                ST=np.zeros(N, np.int64), EVT=np.full((N, slots), np.nan), EVY=np.zeros((N, slots, D)),
                EVK=np.zeros((N, slots), np.int64), EVN=np.zeros(N, np.int64),
                GPREV=np.zeros((N, max(n_events, 1))), NSTEP=np.zeros(N, np.int64), NFEV=np.zeros(N, np.int64))


def _check_device(device, method, jit) -> bool:
    """Whether the run is on the GPU (``device="gpu"``, `rotframe.problem.gpu`): checked, in one line each."""
    from rotframe.particles.threads import check_device

    if check_device(device, "device") != "gpu":
        return False
    if method is None:
        raise ScenarioError(f"method: none given; device='gpu' runs {', '.join(registry.names('particles', gpu=True))} "
                            "(the default, dop853, runs on the CPU)")
    if not jit:
        raise ScenarioError("jit=False: plain Python runs on the CPU; device='gpu' compiles the forces for the GPU")
    return True


def _compile_failure(exc, roles, params, r, v, frame, without_params=()):
    """Name the function numba could not compile (``without_params``: the roles of the built-in terms, which take
    no ``params``)."""
    def sample_args(role):
        own = () if role.split(".")[0] in without_params else params
        if role.startswith("forces") and role.endswith("potential"):
            return (0.0, r.copy(), *own)
        if role.startswith(("forces", "events")):
            return (0.0, r.copy(), v.copy(), *own)
        return (0.0,)

    found = uf.diagnose_compile(roles, sample_args)
    reason = found or f"numba cannot compile the problem: {uf.numba_reason(exc)}"
    raise uf.UserFunctionError(f"simulate: {reason}; pass jit=False to run it in plain Python (slow)") from None
