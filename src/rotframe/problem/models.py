"""The equations of motion the engine steps: a particle in any rotating frame, a rigid body under a torque.

Compiled once (numba, cached on disk) for every problem: the user's functions arrive as the
addresses of their compiled glue (`rotframe.problem.calls`) and the problem's data in the
`PROBLEM` tuple ``(model, M, p, FK, FT, FC, OK, OT, OC)``.

**A particle** (``model = PARTICLE``), state ``(x, y, z, vx, vy, vz)`` in the frame's axes,
followed, when a force is given in inertial axes, by the frame's attitude ``(qx, qy, qz, qw)``
(scalar last, rotating frame components into inertial ones), ``q' = q (omega, 0) / 2``.
Equation of motion (docs/physics/rotating-frames.md)::

    r'' = sum f - 2 w x v - w x (w x r) - w' x r - a0(t)   [+ the string's tension]

``M = (string, px, py, pz, length, drag, k1, k2, H, coriolis, centrifugal, euler)``: the
pendulum's string (1 or 0, its pivot and length; `rotframe.problem.terms.StringConstraint`),
for the splittings a drag term's exact flow (1 or 0 and ``v' = -(k1 + k2 |v|) exp(-z / H) v``,
``H = 0``: uniform air), and 1 or 0 for each of the frame's terms the run keeps
(`rotframe.problem.terms.FRAME_TERMS`: a term left out is skipped, in the right-hand side, the
splittings' kick and their Coriolis turn alike).

**A rigid body** (``model = BODY``), state ``(L1, L2, L3, qx, qy, qz, qw)``, the angular
momentum in body axes and the attitude (body to space, scalar last)::

    L' = L x omega + tau(t, L, q),   omega = I^-1 L,   q' = q (omega, 0) / 2

``M`` (`body_constants`) = ``I^-1`` by rows (9 numbers), then what the splittings' free step takes
(`rotframe.rigid.kernels.free_step`): the principal inverses and ``1/I_s - 1/I_p`` (4), the symmetry
axis (-1: none), and 1 where torques act (the kicks; 0: none).

**Vectors of time** (`vector_of_time`): omega and omega' of the frame, a0 of its origin, by
kind: ``ZERO``; ``CONSTANT`` (``C[0, 0]``); ``TABLE``, a C2 cubic spline (``T`` the knots,
``C`` (n - 1, 4, 3) its coefficients); ``BODY``, the quintic Hermite interpolant through a
body's omega, omega', omega'' (``T`` its sample times, ``C`` (n, 3, 3)); ``FUNCTION``, the
user's ``omega(t)`` with omega' from the fourth-order central difference of step ``T[0]``
(`rotframe.problem.frame.derivative_step`) or ``FUNCTION_DOT``, with the user's omega'.
The constant kinds are answered in the right-hand side itself; the others by the engine's
evaluator of a varying vector, `rotframe.problem.varying` (called by address, compiled for the
problem's own kinds). The numpy twins used for analysis are in `rotframe.problem.frame`.

**Fixed-step methods of a model's own** (`own_step`, methods ``SPLITTING``, ``SPLITTING4``,
``SPLITTING6``, ``SPLITTING8``): a particle's rotation splitting (docs/physics/splitting.md: drift,
kick, the Coriolis rotation, a drag term's exact flow; with a pendulum's string, the same on the
string's sphere, `sphere_strang`: the great-circle flow for the drift, the Coriolis rotation about
the string) and a body's splitting, the rigid scenes' own step (`rotframe.rigid.kernels.free_step`:
the free flow exactly for a symmetric body, else the Lie-Poisson splitting, McLachlan 1993;
Dullweber, Leimkuhler & McLachlan 1997: exact rotations about the principal axes; the torques a kick
at fixed attitude), each of order 2, Yoshida's triple jump of it, order 4, and Kahan & Li's
compositions of orders 6 and 8 (`rotframe.numerics.composition`).

The string's tension, the air's density and the splitting kick's frame terms (centrifugal, Euler, for
any vector omega) are `rotframe.particles.accelerations`' (each term's arithmetic written once, for
the scenes too); `particle_rhs` writes the frame's terms in place, the same arithmetic (measured:
called, they made a user force's evaluation 4 % slower). The small functions on the hot path (those, `vector_of_time`'s constant kinds,
`attitude_rate`, `rhs`) are inlined into their callers by numba (`rotframe.numerics.compiled.jit_inline`);
the right-hand sides and the splittings' steps, called from every step, are compiled once each and
inlined by LLVM into their callers (`rotframe.numerics.compiled.jit_llvm_inline`: numba's own
inlining of a right-hand side into DOP853's stages took more of a first compile than the stages
themselves, and inlining the large ones that way made the engine's first compile take two
minutes). Called, a splitting's step passed the problem's data through a call at every step:
LLVM-inlined, `rotation-splitting4` on the Foucault model took 39.5 ms against 59 to 70 (the
scene's own kernels: 39), with the same first compile (8.8 and 8.9 s, one pinned core,
2026-11-29). The evaluators of a varying vector and the energy stay compiled apart, without
reference counting (`rotframe.numerics.compiled.jit_uncounted`, see `rotframe.problem.engine`).

A particle's right-hand side is one template (`_particle_rhs`) with two kinds of copy: the
engine's own (`particle_rhs`), which reads each part of the model (the frame's and the origin's
kinds, the frame's terms, the string) from the problem's constants as it runs, and the copy a
loop compiled for one problem takes (`with_parts`, `rotframe.problem.inlined`), which holds
them as constants, so that numba and LLVM drop the parts the problem lacks: the same arithmetic,
in the same order, for the parts it has.

Scratch ``W`` (`SCRATCH` numbers, one per calling block): what a user's function writes (the terms, a
vector of time; ``W[6]`` set where one raised), read into locals at once (no slice of it is
taken: a view costs more than the arithmetic of a term); then what the rotation splitting keeps from
step to step: its Coriolis turns' cosines and sines (`TURN`, `turn_cos_sin`) and a steady frame's
axis (`AXIS`, `turn_axis`).
"""

from __future__ import annotations

import math

from rotframe.numerics.compiled import bound, jit_inline, jit_llvm_inline, jit_uncounted
from rotframe.numerics.composition import YOSHIDA4_INNER, YOSHIDA4_OUTER, composition_weights
from rotframe.numerics.rotation import rodrigues_rotate
from rotframe.numerics.sphere import great_circle, kick_across
from rotframe.particles.accelerations import air_density, centrifugal, euler, string_tension
from rotframe.particles.forces import drag_flow
from rotframe.rigid.kernels import free_step
from rotframe.problem.calls import call_potential, call_terms, call_varying
from rotframe.problem.loop_state import store_state

__all__ = ["ZERO", "CONSTANT", "TABLE", "BODY_FRAME", "FUNCTION", "FUNCTION_DOT", "DOP853", "RK4", "SPLITTING",
           "SPLITTING4", "SPLITTING6", "SPLITTING8", "EVALUATIONS_PER_STEP", "SCRATCH", "BODY_CONSTANTS", "body_constants", "inverse_inertia", "vector_of_time", "rhs", "own_step", "particle_energy"]

#: kinds of a vector of time
ZERO, CONSTANT, TABLE, BODY_FRAME, FUNCTION, FUNCTION_DOT = range(6)
#: method codes of the compiled loop (the names are `rotframe.method_registry`'s; no code leaves this package)
DOP853, RK4, SPLITTING, SPLITTING4, SPLITTING6, SPLITTING8 = range(6)
#: a fixed step's right-hand sides (``NFEV``) by method code: RK4's stages after the first (f at the step's end is the
#: next one's first); a splitting's two kicks times its composition's stages (1, 3, 9, 17)
EVALUATIONS_PER_STEP = (0, 3, 2, 6, 18, 34)
#: Kahan & Li's fractions of the order-2 step in the compositions of orders 6 and 8 (`rotframe.numerics.composition`,
#: the scenes' own), constants of the compiled step
KAHAN_LI6_STEPS = tuple(float(w) for w in composition_weights(6))
KAHAN_LI8_STEPS = tuple(float(w) for w in composition_weights(8))
#: the slots of the scratch ``W`` that keep the Coriolis turn's last two angles, each with its cosine and sine
#: (`turn_cos_sin`), after `rotframe.problem.calls.RAISED`
TURN = 7
#: the slots that keep a steady frame's |w| and its unit axis (`turn_axis`)
AXIS = TURN + 6
#: the length of the scratch ``W``
SCRATCH = AXIS + 4


@jit_inline
def vector_of_time(kind, T, C, fn, varying, t, W):
    """The vector of the kind (module docstring) and its derivative at ``t``: ``(x, y, z, dx, dy, dz)``.

    ``W`` (6,) receives what a user's function writes (``FUNCTION``, ``FUNCTION_DOT``). The
    constant kinds are answered here (small enough for the compiler to inline into the
    right-hand side), the others by `rotframe.problem.varying.varying_into_for`'s copy, called at its address ``varying``
    (`rotframe.problem.calls`): it is compiled only for a problem whose frame or origin varies,
    not with the engine (`rotframe.problem.varying.needs_varying`).
    """
    if kind == CONSTANT:
        return C[0, 0, 0], C[0, 0, 1], C[0, 0, 2], 0.0, 0.0, 0.0
    if kind == ZERO:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    call_varying(varying, kind, T, C, fn, t, W)
    return W[0], W[1], W[2], W[3], W[4], W[5]


@jit_inline
def attitude_rate(y, dy, k, wx, wy, wz):
    """q' = q (w, 0) / 2 for the scalar-last quaternion y[k:k + 4] (w in the rotating axes), into dy."""
    qx = y[k]
    qy = y[k + 1]
    qz = y[k + 2]
    qw = y[k + 3]
    dy[k] = 0.5 * (qw * wx + qy * wz - qz * wy)
    dy[k + 1] = 0.5 * (qw * wy + qz * wx - qx * wz)
    dy[k + 2] = 0.5 * (qw * wz + qx * wy - qy * wx)
    dy[k + 3] = -0.5 * (qx * wx + qy * wy + qz * wz)


#: a part of a particle's model read from its constants as the run goes (the engine's own loop, one for every problem),
#: where a loop compiled for one problem holds it as a constant (`with_parts`)
AT_RUN_TIME = -1
# the template's names of the model's parts (`_particle_rhs`): read at run time in the engine's own copy
FRAME_KIND = ORIGIN_KIND = CORIOLIS = CENTRIFUGAL = EULER = STRING = AT_RUN_TIME


def _particle_rhs(t, y, dy, prob, fns, W):
    """The template of a particle's right-hand side (`particle_rhs`, `with_parts`).

    Each part of the model (the frame's and the origin's kinds, the frame's terms, the string) is
    read from ``prob`` where its name in capitals is `AT_RUN_TIME`, else it is that constant.
    """
    M = prob[1]
    fk = prob[3] if FRAME_KIND == AT_RUN_TIME else FRAME_KIND
    wx, wy, wz, ex, ey, ez = vector_of_time(fk, prob[4], prob[5], fns[2], fns[4], t, W)
    x = y[0]
    yy = y[1]
    z = y[2]
    vx = y[3]
    vy = y[4]
    vz = y[5]
    call_terms(fns[0], t, y, prob[2], W)
    ax = W[0]
    ay = W[1]
    az = W[2]
    # the frame's terms in place, the arithmetic of accelerations.coriolis, centrifugal and euler: called
    # (inlined), they made a user force's evaluation 4 % slower (bench user-force, 2026-11-29);
    # each where the run keeps it (M[9:12], `rotframe.problem.terms.check_frame_terms`)
    if (M[9] != 0.0) if CORIOLIS == AT_RUN_TIME else CORIOLIS:
        ax -= 2.0 * (wy * vz - wz * vy)  # Coriolis: -2 w x v
        ay -= 2.0 * (wz * vx - wx * vz)
        az -= 2.0 * (wx * vy - wy * vx)
    if (M[10] != 0.0) if CENTRIFUGAL == AT_RUN_TIME else CENTRIFUGAL:
        wr = wx * x + wy * yy + wz * z  # centrifugal: -w x (w x r) = |w|^2 r - (w . r) w
        w2 = wx * wx + wy * wy + wz * wz
        ax += w2 * x - wr * wx
        ay += w2 * yy - wr * wy
        az += w2 * z - wr * wz
    if (M[11] != 0.0) if EULER == AT_RUN_TIME else EULER:
        ax -= ey * z - ez * yy  # Euler: -w' x r
        ay -= ez * x - ex * z
        az -= ex * yy - ey * x
    ok = prob[6] if ORIGIN_KIND == AT_RUN_TIME else ORIGIN_KIND
    ox, oy, oz, _, _, _ = vector_of_time(ok, prob[7], prob[8], fns[3], fns[4], t, W)
    ax -= ox
    ay -= oy
    az -= oz
    if (M[0] != 0.0) if STRING == AT_RUN_TIME else STRING:
        ax, ay, az = string_tension(ax, ay, az, x, yy, z, vx, vy, vz, M[1], M[2], M[3], M[4])
    dy[0] = vx
    dy[1] = vy
    dy[2] = vz
    dy[3] = ax
    dy[4] = ay
    dy[5] = az
    if y.shape[0] == 10:
        attitude_rate(y, dy, 6, wx, wy, wz)


#: a particle's right-hand side in the engine's own loop: every part of the model read from ``prob``
particle_rhs = jit_llvm_inline(bound(_particle_rhs, "particle_rhs"))


def model_parts(prob) -> dict:
    """The parts of the particle model ``prob`` (`rotframe.problem.signatures.PROBLEM`), by the template's names."""
    M = prob[1]
    return {"FRAME_KIND": int(prob[3]), "ORIGIN_KIND": int(prob[6]), "CORIOLIS": int(M[9] != 0.0),
            "CENTRIFUGAL": int(M[10] != 0.0), "EULER": int(M[11] != 0.0), "STRING": int(M[0] != 0.0)}


@jit_llvm_inline
def body_rhs(t, y, dy, prob, fns, W):
    M = prob[1]
    L1 = y[0]
    L2 = y[1]
    L3 = y[2]
    w1 = M[0] * L1 + M[1] * L2 + M[2] * L3
    w2 = M[3] * L1 + M[4] * L2 + M[5] * L3
    w3 = M[6] * L1 + M[7] * L2 + M[8] * L3
    tx = ty = tz = 0.0
    if M[14] != 0.0:  # torques act (`body_constants`); a free body calls none
        call_terms(fns[0], t, y, prob[2], W)
        tx = W[0]
        ty = W[1]
        tz = W[2]
    dy[0] = L2 * w3 - L3 * w2 + tx
    dy[1] = L3 * w1 - L1 * w3 + ty
    dy[2] = L1 * w2 - L2 * w1 + tz
    attitude_rate(y, dy, 3, w1, w2, w3)


@jit_inline
def rhs(body, t, y, dy, prob, fns, W):
    """y' = f(t, y) into ``dy``: a particle's where ``body`` is None, else a rigid body's.

    ``body`` is a constant of the compiled caller (None, or the literal True): numba prunes the
    other model's branch before typing, so a particle's loop never compiles a body, nor a body's
    a particle (`rotframe.problem.engine.variant`).
    """
    if body is None:
        particle_rhs(t, y, dy, prob, fns, W)
    else:
        body_rhs(t, y, dy, prob, fns, W)


def _kick_acceleration(t, y, prob, fns, W):
    """The template of what the rotation splittings kick with (`kick_acceleration`, `with_parts`): the
    forces (of t and r alone) and the frame's terms of position, centrifugal and Euler (where the run keeps them,
    ``M[10:12]``) and the origin's, with omega at t (returned too, for the Coriolis turn). Each part of the model is
    read from ``prob`` where its name in capitals is `AT_RUN_TIME`, else it is that constant (`_particle_rhs`)."""
    fk = prob[3] if FRAME_KIND == AT_RUN_TIME else FRAME_KIND
    wx, wy, wz, ex, ey, ez = vector_of_time(fk, prob[4], prob[5], fns[2], fns[4], t, W)
    M = prob[1]
    x = y[0]
    yy = y[1]
    z = y[2]
    call_terms(fns[0], t, y, prob[2], W)
    ax = W[0]
    ay = W[1]
    az = W[2]
    ok = prob[6] if ORIGIN_KIND == AT_RUN_TIME else ORIGIN_KIND
    ox, oy, oz, _, _, _ = vector_of_time(ok, prob[7], prob[8], fns[3], fns[4], t, W)
    keep = (M[10] != 0.0) if CENTRIFUGAL == AT_RUN_TIME else CENTRIFUGAL
    cx, cy, cz = centrifugal(x, yy, z, wx, wy, wz) if keep else (0.0, 0.0, 0.0)
    keep = (M[11] != 0.0) if EULER == AT_RUN_TIME else EULER
    qx, qy, qz = euler(x, yy, z, ex, ey, ez) if keep else (0.0, 0.0, 0.0)
    ax += cx - qx - ox
    ay += cy - qy - oy
    az += cz - qz - oz
    return ax, ay, az, wx, wy, wz


#: what the engine's own splittings kick with: every part of the model read from ``prob``
kick_acceleration = jit_llvm_inline(bound(_kick_acceleration, "kick_acceleration"))


def with_parts(parts) -> dict:
    """The functions of a particle's model that read its parts, each -> its copy with the model's ``parts`` as
    constants, as Python: what a loop compiled for one problem takes in their place (`rotframe.problem.inlined` on
    the CPU, `rotframe.problem.gpu`), so that the parts the problem lacks are pruned from every method's step."""
    tag = "_".join(str(parts[k]) for k in sorted(parts))
    return {particle_rhs: bound(_particle_rhs, f"particle_rhs_{tag}", **parts),
            kick_acceleration: bound(_kick_acceleration, f"kick_acceleration_{tag}", **parts)}


@jit_inline
def drag_rates(M, y):
    """The drag term's coefficients at the particle's height, for its exact flow (zero without one)."""
    if M[5] == 0.0:
        return 0.0, 0.0
    air = air_density(y[2], M[8])
    return M[6] * air, M[7] * air


@jit_inline
def turn_cos_sin(angle, W):
    """``cos(angle), sin(angle)`` of the Coriolis turn, kept in ``W[TURN:TURN + 6]`` for the last two angles.

    A fixed step in a steady frame turns the velocity by the same angle at every step (by two, in
    turn, under Yoshida's composition), and its cosine and sine cost as much as the rest of the
    splitting's step. A kept pair is the one computed for that very angle, so the step's numbers are
    those of computing it anew. A slot whose cosine is 0 is empty (``W`` starts as zeros, and no
    float's cosine is 0); a zero angle (either sign) is never kept, as the two zeros compare equal."""
    if angle == 0.0:
        return 1.0, angle  # cos(+-0) = 1, sin(+-0) = +-0
    if angle == W[TURN] and W[TURN + 1] != 0.0:
        return W[TURN + 1], W[TURN + 2]
    if angle == W[TURN + 3] and W[TURN + 4] != 0.0:
        return W[TURN + 4], W[TURN + 5]
    c = math.cos(angle)
    s = math.sin(angle)
    W[TURN + 3] = W[TURN]
    W[TURN + 4] = W[TURN + 1]
    W[TURN + 5] = W[TURN + 2]
    W[TURN] = angle
    W[TURN + 1] = c
    W[TURN + 2] = s
    return c, s


@jit_inline
def turn_axis(steady, wx, wy, wz, W):
    """``|w|`` and the unit axis ``w / |w|`` of the Coriolis turn (zeros where ``|w|`` is 0); in a ``steady`` frame,
    kept in ``W[AXIS:AXIS + 4]`` from the first step on.

    A steady frame's omega is the same at every step of a problem, and its norm and the three
    quotients cost as much as the rest of the splitting's step. The kept values are those computed
    from that omega, so the step's numbers are those of computing them anew. ``W`` is the work array
    of one problem (`rotframe.problem.engine.scratch`, made per run or per prepared problem; a GPU
    thread's own): it never meets another omega. A slot holding 0 is empty (a kept ``|w|`` is > 0)."""
    if steady and W[AXIS] > 0.0:
        return W[AXIS], W[AXIS + 1], W[AXIS + 2], W[AXIS + 3]
    w = math.sqrt(wx * wx + wy * wy + wz * wz)
    if not w > 0.0:
        return w, 0.0, 0.0, 0.0
    ux = wx / w
    uy = wy / w
    uz = wz / w
    if steady:
        W[AXIS] = w
        W[AXIS + 1] = ux
        W[AXIS + 2] = uy
        W[AXIS + 3] = uz
    return w, ux, uy, uz


@jit_llvm_inline
def rotation_strang(t, h, s, yt, prob, fns, W):
    """One step of the rotation splitting (docs/physics/splitting.md), as the scenes' particle kernels:
    drift h/2, kick h/2, a drag term's exact flow h/2, the Coriolis flow v' = -2 w x v (v turned by
    -2 |w| h about w, with w at the step's middle: exact for a constant omega, symmetric always),
    the drag flow h/2, kick h/2, drift h/2. The state ``s`` is a particle's six numbers, and so is
    the result: it stays in registers from step to step (`particle_split`); the kick reads it from ``yt``,
    after the drift (the velocity still the step's first)."""
    x, y, z, vx, vy, vz = s
    hh = 0.5 * h
    x = x + hh * vx
    y = y + hh * vy
    z = z + hh * vz
    store_state(yt, (x, y, z, vx, vy, vz))  # what the kick's forces read (they are functions of arrays)
    ax, ay, az, wx, wy, wz = kick_acceleration(t + hh, yt, prob, fns, W)
    vx = vx + hh * ax
    vy = vy + hh * ay
    vz = vz + hh * az
    k1, k2 = drag_rates(prob[1], yt)  # a drag term's exact flow, h/2 on each side of the turn (none: the identity)
    vx, vy, vz = drag_flow(vx, vy, vz, k1, k2, hh)
    if prob[1][9] != 0.0:  # the Coriolis flow, where the run keeps the term (and w is not 0)
        w, ux, uy, uz = turn_axis(prob[3] == CONSTANT, wx, wy, wz, W)
        if w > 0.0:
            cos_turn, sin_turn = turn_cos_sin(-2.0 * w * h, W)
            vx, vy, vz = rodrigues_rotate(vx, vy, vz, ux, uy, uz, cos_turn, sin_turn)
    vx, vy, vz = drag_flow(vx, vy, vz, k1, k2, hh)
    vx = vx + hh * ax
    vy = vy + hh * ay
    vz = vz + hh * az
    return x + hh * vx, y + hh * vy, z + hh * vz, vx, vy, vz


@jit_llvm_inline
def sphere_strang(t, h, s, yt, prob, fns, W):
    """One step of the rotation splitting on the string's sphere, as the scenes' pendulum splitting
    (`rotframe.particles.kernels`; docs/physics/splitting.md): the great-circle flow h/2
    (`rotframe.numerics.sphere`), the kick's part across the string h/2, a drag term's exact flow h/2,
    the Coriolis flow across the string (v turned about the string's direction n by -2 (w . n) h, w at
    the step's middle), the drag flow h/2, the kick h/2, the great-circle flow h/2. The string's
    tension is the part of every force along n, which the flows on the sphere take exactly. The state
    as `rotation_strang`'s; the kick reads the position after the first flow, the velocity the step's first."""
    M = prob[1]
    px = M[1]
    py = M[2]
    pz = M[3]
    L = M[4]
    hh = 0.5 * h
    x, y, z, vx, vy, vz = great_circle(s[0], s[1], s[2], s[3], s[4], s[5], hh, px, py, pz, L)
    store_state(yt, (x, y, z, s[3], s[4], s[5]))
    ax, ay, az, wx, wy, wz = kick_acceleration(t + hh, yt, prob, fns, W)
    nx = (x - px) / L
    ny = (y - py) / L
    nz = (z - pz) / L
    ax, ay, az, vx, vy, vz = kick_across(vx, vy, vz, ax, ay, az, nx, ny, nz, hh)
    k1, k2 = drag_rates(M, yt)
    vx, vy, vz = drag_flow(vx, vy, vz, k1, k2, hh)
    if M[9] != 0.0:  # the Coriolis flow, where the run keeps the term
        angle = -2.0 * (wx * nx + wy * ny + wz * nz) * h
        vx, vy, vz = rodrigues_rotate(vx, vy, vz, nx, ny, nz, math.cos(angle), math.sin(angle))
    vx, vy, vz = drag_flow(vx, vy, vz, k1, k2, hh)
    vx += hh * ax
    vy += hh * ay
    vz += hh * az
    return great_circle(x, y, z, vx, vy, vz, hh, px, py, pz, L)


@jit_llvm_inline
def torque_kick(t, h, yn, prob, fns, W):
    """L += h tau(t, L, q): exact for a torque of (t, q) alone (the only torques the splittings take)."""
    call_terms(fns[0], t, yn, prob[2], W)
    yn[0] += h * W[0]
    yn[1] += h * W[1]
    yn[2] += h * W[2]


#: a body's constants in ``M`` (`body_constants`): I^-1 by rows (9), then the free step's (`free_step`): the
#: principal inverses and 1/I_s - 1/I_p (4), the symmetry axis (-1: none), and 1 where torques act (0: no kick)
BODY_CONSTANTS = 15


def inverse_inertia(I):
    """I^-1 of the inertia tensor ``I`` (3, 3); of principal moments with a zero one (a thin rod), 1/I_i and 0 for
    the zero one (no spin along it: no angular momentum there)."""
    import numpy as np

    if np.all(I == np.diag(np.diag(I))):
        d = np.diag(I)
        return np.diag(np.divide(1.0, d, out=np.zeros(3), where=d > 0.0))
    return np.linalg.inv(I)


def body_constants(inertia, inv_principal, symmetry, kicks):
    """``M`` of a body (`BODY_CONSTANTS` numbers): ``inertia``'s inverse by rows (`inverse_inertia`), ``inv_principal`` (4, as
    `rotframe.rigid.checks.check_inertia` gives it, zeros off principal axes), the ``symmetry`` axis (-1: none)
    and ``kicks`` (whether torques act)."""
    import numpy as np

    return np.ascontiguousarray(np.concatenate([inverse_inertia(inertia).ravel(), inv_principal,
                                                [float(symmetry), 1.0 if kicks else 0.0]]))


@jit_llvm_inline
def lie_poisson_strang(t, h, yn, prob, fns, W):
    """Kick(h/2) . free(h) . kick(h/2), the rigid scenes' own step (`rotframe.rigid.kernels.free_step`, written once):
    the free flow exactly for a symmetric body (turning about L and about its symmetry axis), else the
    1,2,3,2,1 Lie-Poisson splitting (McLachlan 1993); second order, symplectic on the Lie-Poisson manifold
    (principal axes). The kicks are skipped where no torque acts."""
    M = prob[1]
    if M[14] != 0.0:
        torque_kick(t, 0.5 * h, yn, prob, fns, W)
    free_step(yn[0:3], yn[3:7], h, M[9:13], int(M[13]))
    if M[14] != 0.0:
        torque_kick(t + h, 0.5 * h, yn, prob, fns, W)


@jit_llvm_inline
def particle_strang(t, h, s, yt, prob, fns, W):
    """A particle's splitting, order 2: on the string's sphere where it has one, else the rotation splitting."""
    if prob[1][0] != 0.0:
        return sphere_strang(t, h, s, yt, prob, fns, W)
    return rotation_strang(t, h, s, yt, prob, fns, W)


@jit_inline
def particle_split(method, t, s, h, yt, prob, fns, W):
    """A particle's step of the splitting ``method`` (`own_step`) from its state ``s`` at t, six numbers in and out:
    the loops carry it in registers from step to step (`rotframe.problem.fixed_step`); ``yt`` (6,) is the scratch
    its kicks read the state from."""
    if method == SPLITTING:
        return particle_strang(t, h, s, yt, prob, fns, W)
    if method == SPLITTING4:
        w1 = YOSHIDA4_OUTER
        w0 = YOSHIDA4_INNER
        s = particle_strang(t, w1 * h, s, yt, prob, fns, W)
        s = particle_strang(t + w1 * h, w0 * h, s, yt, prob, fns, W)
        return particle_strang(t + (w1 + w0) * h, w1 * h, s, yt, prob, fns, W)
    if method == SPLITTING6:
        return _particle_composed(KAHAN_LI6_STEPS, t, s, h, yt, prob, fns, W)
    return _particle_composed(KAHAN_LI8_STEPS, t, s, h, yt, prob, fns, W)


@jit_llvm_inline
def _particle_composed(weights, t, s, h, yt, prob, fns, W):
    """`particle_strang` composed with the fractions ``weights`` of the step (Kahan & Li's)."""
    done = 0.0
    for w in weights:
        s = particle_strang(t + done * h, w * h, s, yt, prob, fns, W)
        done += w
    return s


@jit_llvm_inline
def _body_composed(weights, t, h, yn, prob, fns, W):
    """`lie_poisson_strang` composed in place with the fractions ``weights`` of the step (Kahan & Li's)."""
    done = 0.0
    for w in weights:
        lie_poisson_strang(t + done * h, w * h, yn, prob, fns, W)
        done += w


@jit_inline
def body_split(method, t, y, h, yn, prob, fns, W):
    """A rigid body's step of the splitting ``method`` (`own_step`), in place in ``yn``: its splitting
    (`lie_poisson_strang`) composed as a particle's (`particle_split`), the attitude normalised after the step.
    Inlined by numba, as `particle_split`: a variant compiles its own composition alone."""
    for j in range(y.shape[0]):
        yn[j] = y[j]
    if method == SPLITTING:
        lie_poisson_strang(t, h, yn, prob, fns, W)
    elif method == SPLITTING4:
        w1 = YOSHIDA4_OUTER
        w0 = YOSHIDA4_INNER
        lie_poisson_strang(t, w1 * h, yn, prob, fns, W)
        lie_poisson_strang(t + w1 * h, w0 * h, yn, prob, fns, W)
        lie_poisson_strang(t + (w1 + w0) * h, w1 * h, yn, prob, fns, W)
    elif method == SPLITTING6:
        _body_composed(KAHAN_LI6_STEPS, t, h, yn, prob, fns, W)
    else:
        _body_composed(KAHAN_LI8_STEPS, t, h, yn, prob, fns, W)
    norm_q = math.sqrt(yn[3] * yn[3] + yn[4] * yn[4] + yn[5] * yn[5] + yn[6] * yn[6])
    for j in range(3, 7):
        yn[j] /= norm_q


@jit_inline
def own_step(body, method, t, y, h, yn, prob, fns, W):
    """``SPLITTING``: the model's splitting (order 2); ``SPLITTING4``: Yoshida's triple jump of it (order 4);
    ``SPLITTING6``, ``SPLITTING8``: Kahan & Li's compositions of it (orders 6 and 8). From (t, y) into ``yn``: a
    particle's by `particle_split` (``yn`` the kicks' scratch until the step is done), a body's by `body_split`.

    Inlined by numba into the variant's loop, whose ``method`` is a constant: the other methods' steps are pruned
    before anything is compiled (each its own function, compiled once and inlined by LLVM)."""
    if body is None:
        yn[0], yn[1], yn[2], yn[3], yn[4], yn[5] = particle_split(method, t, (y[0], y[1], y[2], y[3], y[4], y[5]), h,
                                                                  yn, prob, fns, W)
    else:
        body_split(method, t, y, h, yn, prob, fns, W)


@jit_uncounted
def particle_energy(t, y, prob, fns, potential, rotating, W):
    """Energy per unit mass (``rotating`` False) or the Jacobi integral (True) of one particle's state."""
    wx, wy, wz, _, _, _ = vector_of_time(prob[3], prob[4], prob[5], fns[2], fns[4], t, W)
    kin = 0.5 * (y[3] * y[3] + y[4] * y[4] + y[5] * y[5])
    e = kin + call_potential(potential, t, y, prob[2])
    if rotating:
        cx = wy * y[2] - wz * y[1]
        cy = wz * y[0] - wx * y[2]
        cz = wx * y[1] - wy * y[0]
        e -= 0.5 * (cx * cx + cy * cy + cz * cz)
    return e

