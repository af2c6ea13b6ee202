"""Compiled fixed-step methods for particles in a rotating frame: the one-step maps.

Methods by code: 0 exact-rotation splitting (order 2), 1 its Yoshida order-4
composition, 2 classical Runge-Kutta (docs/physics/splitting.md). A particle's
state is the tuple ``(x, y, z, vx, vy, vz)``, kept in registers: the step
kernels take and return it and take no array. What a step needs from the
schedule (the rate and its derivative at each stage, the angle turned over each
sub-step and the cosine and sine of the Coriolis rotation) is its plan
(`make_plan`). At a steady rate the plan is the same for every step and
particle, so it is made once per call and the steps between two samples are
one loop (`_free_steps`, for a free particle, is the throughput path); a
varying schedule is read once per step. The drivers that call these maps over
an ensemble are in `rotframe.particles.drivers`; the forces in
`rotframe.particles.forces`.
"""

from __future__ import annotations

import math

from numba import njit

from rotframe.numerics.composition import YOSHIDA4_INNER, YOSHIDA4_OUTER
from rotframe.numerics.rk4 import rk4_particle_step
from rotframe.numerics.rotation import rodrigues_rotate
from rotframe.numerics.sphere import great_circle, kick_across
from rotframe.numerics.step_control import grid_time
from rotframe.particles.forces import (drag_coefficients, drag_flow, position_acceleration, state_acceleration,
                                       string_normal)
from rotframe.particles.packed import NFEV, jit_internal, jit_kernel, unpack

#: a step's body, inlined by numba into each loop that calls it (a call per step would pass the
#: packed model and the plan, some 40 scalars, every step: three times the cost of the step)
_inline = njit(inline="always", error_model="numpy", nogil=True)
#: the force, inlined into the RK4 step (four evaluations a step: four calls passing the packed model)
_acceleration = _inline(state_acceleration.py_func)
_position_acceleration = _inline(position_acceleration.py_func)
from rotframe.particles.schedule import omega_angle, omega_magnitude, omega_rate

#: The integer each fixed-step method is compiled under (this module's loops branch on it). The
#: methods are named everywhere else (`rotframe.method_registry`); `loop_code` turns a name into it.
_LOOP_CODES = {"rotation-splitting": 0, "rotation-splitting4": 1, "rk4": 2}
#: Force evaluations per step of each fixed-step method (the splittings' kicks, RK4's stages).
EVALS_PER_STEP = {"rotation-splitting": 1, "rotation-splitting4": 3, "rk4": 4}


def loop_code(name: str) -> int:
    """The code the compiled loops know the fixed-step method ``name`` by (-1: not one of theirs, dop853)."""
    return _LOOP_CODES.get(name, -1)

__all__ = ["loop_code", "EVALS_PER_STEP", "make_plan", "method_steps", "one_step", "free_step", "sphere_step", "rk4_step", "rk4_step_of", "advance", "step_splitting", "step_sphere", "step_splitting4", "step_rk4",
           "select_step"]

# numba compiles a separate version of a function for every constant it is called with
# (the argument is typed Literal[int](1), not int64), and of everything the constant is
# passed on to: method_steps(method, state, 1, ...) beside method_steps(method, state, n, ...)
# compiled every step kernel twice. So no constant count goes to a compiled function: one
# step is n = int(1) (a call's result is an int64, not a literal), and a method code is
# passed on as the variable it is.

# A compiled function that passes an array on to another one that is not inlined
# increfs and decrefs it at every call (atomic operations, tens of ns in all). So what
# runs for every sub-step or stage passes no array on: the step kernels take none (the
# state is a tuple, the model a PackedModel), the schedule readers below only read theirs,
# and the functions that pass arrays on (make_plan, dop853_step, the drivers) run at most
# once per step.


@jit_internal
def _stage(t, wt, wv):
    """Rotation data of a Runge-Kutta stage at time t, laid out as `_sub`: ``(w, w', 0, 1, 0)``."""
    return omega_magnitude(t, wt, wv), omega_rate(t, wt, wv), 0.0, 1.0, 0.0


@jit_internal
def _lookup(t, h, wt, wv, wint):
    """The schedule over [t, t + h]: w and w' at t + h/2, and the angle turned (the integral of w)."""
    tm = t + 0.5 * h
    return (omega_magnitude(tm, wt, wv), omega_rate(tm, wt, wv),
            omega_angle(t + h, wt, wv, wint) - omega_angle(t, wt, wv, wint))


@jit_internal
def _sub(looked_up, m):
    """Rotation data ``(w, w', turn, cos, sin)`` of a splitting sub-step from its `_lookup`.

    ``cos`` and ``sin`` are those of the Coriolis rotation angle ``-2 turn`` of
    a free particle (1 and 0 when there is none).
    """
    w, wd, turn = looked_up
    c = 1.0
    s = 0.0
    if m.coriolis and not m.length > 0.0:
        angle = -2.0 * turn
        c = math.cos(angle)
        s = math.sin(angle)
    return w, wd, turn, c, s


@jit_internal
def make_plan(method, t, h, m, wt, wv, wint):
    """The rotation data a step [t, t + h] of ``method`` needs: three tuples laid out as `_sub`.

    Splitting: the step (three times); splitting4: its three sub-steps; rk4:
    the rates at t, t + h/2 and t + h (turn 0, cos 1, sin 0). At a steady
    rate the plan does not depend on t (the angle turned over a sub-step h' is
    w h'), so it is made once per step size and its sines and cosines are reused.
    ``wt = None`` (a steady schedule known at compile time) compiles the steady plan only.
    """
    if wt is None:
        return _steady_plan(method, h, m)
    if m.steady:
        return _steady_plan(method, h, m)
    if method == 1:
        h1, h0 = _sub_steps(method, h)[1][:2]
        return (_sub(_lookup(t, h1, wt, wv, wint), m), _sub(_lookup(t + h1, h0, wt, wv, wint), m),
                _sub(_lookup(t + h1 + h0, h1, wt, wv, wint), m))
    if method == 2:
        return _stage(t, wt, wv), _stage(t + 0.5 * h, wt, wv), _stage(t + h, wt, wv)
    sub = _sub(_lookup(t, h, wt, wv, wint), m)
    return sub, sub, sub


@jit_internal
def _steady_plan(method, h, m):
    """`make_plan` at the steady rate ``m.w``."""
    if method == 1:
        h1, h0 = _sub_steps(method, h)[1][:2]
        outer = _sub((m.w, 0.0, m.w * h1), m)
        return outer, _sub((m.w, 0.0, m.w * h0), m), outer
    if method == 2:
        rates = (m.w, 0.0, 0.0, 1.0, 0.0)
        return rates, rates, rates
    sub = _sub((m.w, 0.0, m.w * h), m)
    return sub, sub, sub


@jit_internal
def _sub_steps(method, h):
    """Number and lengths of the splitting sub-steps of a step h: one of h, or Yoshida's h1, h0, h1."""
    if method == 1:
        h1 = YOSHIDA4_OUTER * h
        return 3, (h1, YOSHIDA4_INNER * h, h1)
    return 1, (h, h, h)


@jit_internal
def _free_steps(state, n, method, h, m, plan):
    """Exact-rotation splitting of a free particle; see `step_splitting`.

    ``n`` steps of `free_step`, which numba inlines here: with nothing but
    scalars in the loop, this is the throughput path of the ensemble driver.
    """
    for _ in range(n):
        state = free_step(state, method, h, m, plan)
    return state


@_inline
def free_step(state, method, h, m, plan):
    """One step of the exact-rotation splitting of a free particle (inlined into its callers).

    Per sub-step: drift r += v h/2; kick v += a_pos(r) h/2 and exact drag;
    rotate v about w_hat by -2 turn (cos and sin from the plan); drag and kick
    again; drift h/2.
    """
    x, y, z, vx, vy, vz = state
    ux, uy, uz = m.axis
    n_sub, lengths = _sub_steps(method, h)
    for i in range(n_sub):
        hh = 0.5 * lengths[i]
        w, wd, turn, c, s = plan[i]
        x += hh * vx
        y += hh * vy
        z += hh * vz
        if m.uniform:
            ax, ay, az = m.g
        else:
            ax, ay, az = _position_acceleration(x, y, z, m, w, wd)
        vx += hh * ax
        vy += hh * ay
        vz += hh * az
        k1 = 0.0
        k2 = 0.0
        if m.drag:
            k1, k2 = drag_coefficients(z, m)
            vx, vy, vz = drag_flow(vx, vy, vz, k1, k2, hh)
        if m.coriolis:
            vx, vy, vz = rodrigues_rotate(vx, vy, vz, ux, uy, uz, c, s)
        if m.drag:
            vx, vy, vz = drag_flow(vx, vy, vz, k1, k2, hh)
        vx += hh * ax
        vy += hh * ay
        vz += hh * az
        x += hh * vx
        y += hh * vy
        z += hh * vz
    return x, y, z, vx, vy, vz


@jit_internal
def _sphere_steps(state, n, method, h, m, plan):
    """Splitting on the sphere |r - pivot| = L; see `step_sphere`."""
    for _ in range(n):
        state = sphere_step(state, method, h, m, plan)
    return state


@_inline
def sphere_step(state, method, h, m, plan):
    """One step of the splitting on the sphere (its sub-steps; inlined into its callers)."""
    n_sub, lengths = _sub_steps(method, h)
    for i in range(n_sub):
        state = _sphere_step(state, lengths[i], m, plan[i])
    return state


@jit_internal
def _sphere_step(state, h, m, sub):
    """One sub-step of `_sphere_steps` with the rotation data ``sub``."""
    x, y, z, vx, vy, vz = state
    hh = 0.5 * h
    px, py, pz = m.pivot
    x, y, z, vx, vy, vz = great_circle(x, y, z, vx, vy, vz, hh, px, py, pz, m.length)  # numerics.sphere
    ax, ay, az = position_acceleration(x, y, z, m, sub[0], sub[1])
    nx, ny, nz = string_normal(x, y, z, m)
    ax, ay, az, vx, vy, vz = kick_across(vx, vy, vz, ax, ay, az, nx, ny, nz, hh)
    k1 = 0.0
    k2 = 0.0
    if m.drag:
        k1, k2 = drag_coefficients(z, m)
        vx, vy, vz = drag_flow(vx, vy, vz, k1, k2, hh)
    if m.coriolis:
        if m.steady:  # -2 (w . n) h, the engine's arithmetic (`rotframe.problem.models.sphere_strang`)
            w = sub[0]
            angle = -2.0 * ((m.axis[0] * w) * nx + (m.axis[1] * w) * ny + (m.axis[2] * w) * nz) * h
        else:  # the turn integrated over the sub-step: exact for the schedule's piecewise-linear rate
            wn = m.axis[0] * nx + m.axis[1] * ny + m.axis[2] * nz
            angle = -2.0 * wn * sub[2]
        vx, vy, vz = rodrigues_rotate(vx, vy, vz, nx, ny, nz, math.cos(angle), math.sin(angle))
    if m.drag:
        vx, vy, vz = drag_flow(vx, vy, vz, k1, k2, hh)
    vx += hh * ax
    vy += hh * ay
    vz += hh * az
    return great_circle(x, y, z, vx, vy, vz, hh, px, py, pz, m.length)


@jit_internal
def _rk4_steps(state, n, h, m, plan):
    """Classical Runge-Kutta, the rates at t, t + h/2 and t + h from the plan; see `step_rk4`."""
    for _ in range(n):
        state = rk4_step(state, h, m, plan)
    return state


@_inline
def _stage_acceleration(ctx, t, state):
    """The acceleration at an RK4 stage, ``ctx = (m, w, wd)``: the model and the plan's rates at the stage's time."""
    m, w, wd = ctx
    return _acceleration(state, m, w, wd)


#: the one RK4 step of a particle (`rotframe.numerics.rk4.rk4_particle_step`) with the scenes' acceleration
_rk4_particle_step = rk4_particle_step("scene", _stage_acceleration, _inline)


@_inline
def rk4_step(state, h, m, plan):
    """One classical Runge-Kutta step (inlined into its callers), the rates at t, t + h/2 and t + h from the
    ``plan``: the one RK4 step of a particle (`rotframe.numerics.rk4.rk4_particle_step`); see `step_rk4`."""
    a1 = _acceleration(state, m, plan[0][0], plan[0][1])
    return _rk4_particle_step((m, plan[1][0], plan[1][1]), (m, plan[2][0], plan[2][1]), 0.0, state, h, a1)


@_inline
def rk4_step_of(state, method, h, m, plan):
    """`rk4_step` with the splittings' arguments (``method`` unused), to be passed where they are."""
    return rk4_step(state, h, m, plan)


@jit_internal
def method_steps(method, state, n, h, m, plan, rk4, sphere):
    """``n`` steps of size h of method 0 splitting, 1 splitting4 or 2 rk4, all with the same ``plan``.

    One step for a varying rate (the plan is the step's own); any number at a
    steady rate, where every step has the same plan. ``rk4`` (method 2) and
    ``sphere`` (a pendulum, the splitting on the sphere) are None where the
    caller knows they are false, which numba prunes at compile time (a free
    particle's splitting compiles neither RK4 nor the sphere), or booleans
    read at run time.
    """
    if rk4 is not None:
        if rk4:
            return _rk4_steps(state, n, h, m, plan)
    if sphere is not None:
        if sphere:
            return _sphere_steps(state, n, method, h, m, plan)
    return _free_steps(state, n, method, h, m, plan)


@_inline
def one_step(method, state, h, m, plan, rk4, sphere):
    """One step of `method_steps`, the family chosen at run time (the GPU kernel's step, `rotframe.particles.gpu`).

    The CPU drivers choose the family where numba prunes it and pass `free_step`,
    `sphere_step` or `rk4_step_of` alone: inlined, this function brings all three.
    """
    if rk4 is not None:
        if rk4:
            return rk4_step(state, h, m, plan)
    if sphere is not None:
        if sphere:
            return sphere_step(state, method, h, m, plan)
    return free_step(state, method, h, m, plan)


@jit_internal
def advance(method, state, times, s, k0, n, h, m, wt, wv, wint, plan, rk4, sphere):
    """Steps k0 .. k0 + n - 1 of size h of sample interval ``s`` of the sample ``times`` (step k starts at
    ``times[s] + k h``, `rotframe.numerics.step_control.grid_time`).

    ``plan`` is the `make_plan` of every step when the rate is steady; a
    varying schedule is sampled here, once per step, so that the step
    kernels take no array. ``wt = None`` is a steady schedule known at compile time;
    ``rk4`` and ``sphere`` as in `method_steps`.
    """
    if wt is None:
        return method_steps(method, state, n, h, m, plan, rk4, sphere)
    if m.steady:
        return method_steps(method, state, n, h, m, plan, rk4, sphere)
    for k in range(k0, k0 + n):
        state = method_steps(method, state, int(1), h, m, make_plan(method, grid_time(times, s, k, h), h, m, wt,
                                                                    wv, wint), rk4, sphere)
    return state


@jit_internal
def _step_in_place(method, r, v, t, h, P, wt, wv, wint):
    """One step [t, t + h] on the state arrays r, v (updated in place); returns the force evaluations."""
    m = unpack(P, wt, wv)
    state = method_steps(method, (r[0], r[1], r[2], v[0], v[1], v[2]), 1, h, m, make_plan(method, t, h, m, wt, wv, wint),
                         method == 2, m.length > 0.0)
    r[0], r[1], r[2], v[0], v[1], v[2] = state
    return NFEV[method]


@jit_kernel
def step_splitting(r, v, t, h, P, wt, wv, wint, a):
    """Exact-rotation splitting, order 2 (drift, kick, rotate, kick, drift).

    Strang composition of exact sub-flows (docs/physics/splitting.md): drift
    r += v h/2; kick v += a_pos(r, t + h/2) h/2 and exact drag; rotate v about
    w_hat by -2 * integral of w over the step (the exact Coriolis flow, no
    tan() as in Boris); drag and kick again; drift h/2. Explicit, symmetric
    (time-reversible), volume-preserving; one force evaluation per step.
    For a pendulum the constrained version `step_sphere` is used.

    ``r`` and ``v`` (3,) are updated in place; ``a`` (3,) is unused (the
    kernels keep their scratch in registers). Returns the force evaluations.
    """
    return _step_in_place(0, r, v, t, h, P, wt, wv, wint)


@jit_kernel
def step_sphere(r, v, t, h, P, wt, wv, wint, a):
    """Splitting on the sphere |r - pivot| = L (spherical pendulum), order 2.

    Sub-flows, each exact on the constraint manifold T S^2:
    A: free motion on the sphere (a great circle at constant speed);
    B: applied forces at fixed r, projected on the tangent plane (the string
       takes the normal part); drag exact;
    C: Coriolis at fixed r: its tangential part rotates v about the normal n by
       -2 (w . n) times the elapsed angle (the normal part is taken by the string).
    Composition A(h/2) B(h/2) C(h) B(h/2) A(h/2): symmetric, second order, the
    constraint kept to round-off (n is renormalised after every great-circle move).
    Arguments and result as `step_splitting`.
    """
    m = unpack(P, wt, wv)
    state = _sphere_step((r[0], r[1], r[2], v[0], v[1], v[2]), h, m, make_plan(0, t, h, m, wt, wv, wint)[0])
    r[0], r[1], r[2], v[0], v[1], v[2] = state
    return 1


@jit_kernel
def step_splitting4(r, v, t, h, P, wt, wv, wint, a):
    """Fourth-order symmetric composition (Yoshida 1990) of `step_splitting`."""
    return _step_in_place(1, r, v, t, h, P, wt, wv, wint)


@jit_kernel
def step_rk4(r, v, t, h, P, wt, wv, wint, a):
    """Classical Runge-Kutta, order 4, four force evaluations; conserves nothing exactly."""
    return _step_in_place(2, r, v, t, h, P, wt, wv, wint)


@jit_kernel
def select_step(method, r, v, t, h, P, wt, wv, wint, a):
    """Dispatch on the method code: 0 splitting, 1 splitting4, 2 rk4."""
    return _step_in_place(method, r, v, t, h, P, wt, wv, wint)
