"""Source of the compiled particle driver of a user's problem (DOP853 and RK4, events, energy).

`rotframe.problem.codegen` writes a module made of a generated header (the user's
functions bound to names, the frame's evaluators, the state size ``D``, the event count
``NE``) followed by `SOURCE`, and numba compiles it with ``cache=True``. The header
defines, besides ``jit``, ``math``, ``np`` and the DOP853
tableau ``A, B, C, E3, E5`` and error norm ``error_norm``::

    frame_rates(t, F) -> (wx, wy, wz, ex, ey, ez)    omega and omega' in frame axes
    origin_acceleration(t, G) -> (ax, ay, az)        the frame origin's acceleration
    user_acceleration(t, y, P) -> (ax, ay, az)       the sum of the user's forces, frame axes
    constrain(y, ax, ay, az) -> (ax, ay, az)         the total kept on a pendulum's sphere (or as it is)
    event_value(k, t, y, P) -> float                 event k's function
    potential(t, y, P) -> float                      the sum of the forces' potentials

The state ``y`` of one particle is ``(x, y, z, vx, vy, vz)`` in the frame's axes, followed,
when a force is given in inertial axes, by the frame's attitude ``(qx, qy, qz, qw)``
(scalar last, rotating frame components into inertial ones), integrated with the rest:
``q' = q (omega, 0) / 2``.

Equation of motion (docs/physics/rotating-frames.md)::

    r'' = sum f - 2 w x v - w x (w x r) - w' x r - a0(t)   [+ the string's tension]

Each particle is integrated alone (its own steps, its own events), so the samples do not
depend on how many threads share the ensemble (blocks of particles on threads). A call advances
every particle by at most ``budget`` steps and returns, so that Python sees Ctrl-C, SIGTERM
and progress between calls; the state to continue from is kept in the arrays passed in.

Status codes per particle: 0 running, 1 finished, 2 stopped by a terminal event,
3 non-finite state, 4 step size collapsed.
"""

from rotframe.problem.stepping import SOURCE as STEPPING_SOURCE

SOURCE = r'''
# ---- the body shared by every generated particle driver (rotframe.problem.particle_driver) ----

@jit
def rhs(t, y, dy, P, F, G):
    wx, wy, wz, ex, ey, ez = frame_rates(t, F)
    x = y[0]
    yy = y[1]
    z = y[2]
    vx = y[3]
    vy = y[4]
    vz = y[5]
    ax, ay, az = user_acceleration(t, y, P)
    # Coriolis: -2 w x v
    ax -= 2.0 * (wy * vz - wz * vy)
    ay -= 2.0 * (wz * vx - wx * vz)
    az -= 2.0 * (wx * vy - wy * vx)
    # centrifugal: -w x (w x r) = |w|^2 r - (w . r) w
    wr = wx * x + wy * yy + wz * z
    w2 = wx * wx + wy * wy + wz * wz
    ax += w2 * x - wr * wx
    ay += w2 * yy - wr * wy
    az += w2 * z - wr * wz
    # Euler: -w' x r
    ax -= ey * z - ez * yy
    ay -= ez * x - ex * z
    az -= ex * yy - ey * x
    ox, oy, oz = origin_acceleration(t, G)
    ax, ay, az = constrain(y, ax - ox, ay - oy, az - oz)
    dy[0] = vx
    dy[1] = vy
    dy[2] = vz
    dy[3] = ax
    dy[4] = ay
    dy[5] = az
    if D == 10:
        attitude_rate(y, dy, 6, wx, wy, wz)


@jit
def energies(T, OUT, P, F, rotating):
    """Energy (rotating = False) or the Jacobi integral (rotating = True) per sample and particle, per unit mass."""
    n = OUT.shape[0]
    N = OUT.shape[1]
    E = np.empty((n, N))
    for a in range(n):
        wx, wy, wz, ex, ey, ez = frame_rates(T[a], F)
        for i in range(N):
            y = OUT[a, i]
            kin = 0.5 * (y[3] * y[3] + y[4] * y[4] + y[5] * y[5])
            e = kin + potential(T[a], y, P)
            if rotating:
                cx = wy * y[2] - wz * y[1]
                cy = wz * y[0] - wx * y[2]
                cz = wx * y[1] - wy * y[0]
                e -= 0.5 * (cx * cx + cy * cy + cz * cz)
            E[a, i] = e
    return E
'''

SOURCE = SOURCE + STEPPING_SOURCE

#: ``own_step`` of a driver run by DOP853 or RK4: never called, and nothing to compile (the method is
#: an argument of the compiled loop, so every branch of ``take_step`` is compiled: a driver for those
#: two methods leaves the splittings out of its source, and its first run compiles in seconds less)
PLAIN_OWN_STEP = r'''
@jit
def own_step(method, t, y, h, yn, P, F, G):
    """DOP853 and RK4 need no step of the driver's own (never called)."""
    for j in range(D):
        yn[j] = y[j]
'''

#: ``own_step`` of a driver run by a rotation splitting (methods 2 and 3), with what it kicks with
SPLITTING_OWN_STEP = r'''
@jit
def kick_acceleration(t, y, P, F, G):
    """What the splittings kick with: the forces (of t and r alone) and the frame's terms of position,
    centrifugal, Euler and the origin's, with omega at t (returned too, for the Coriolis turn)."""
    wx, wy, wz, ex, ey, ez = frame_rates(t, F)
    x = y[0]
    yy = y[1]
    z = y[2]
    ax, ay, az = user_acceleration(t, y, P)
    wr = wx * x + wy * yy + wz * z
    w2 = wx * wx + wy * wy + wz * wz
    ox, oy, oz = origin_acceleration(t, G)
    ax += w2 * x - wr * wx - (ey * z - ez * yy) - ox
    ay += w2 * yy - wr * wy - (ez * x - ex * z) - oy
    az += w2 * z - wr * wz - (ex * yy - ey * x) - oz
    return ax, ay, az, wx, wy, wz


@jit
def rotation_strang(t, h, yn, P, F, G):
    """One step of the rotation splitting (docs/physics/splitting.md), as the scenes' particle kernels:
    drift h/2, kick h/2, a drag term's exact flow h/2, the Coriolis flow v' = -2 w x v (v turned by
    -2 |w| h about w, with w at the step's middle: exact for a constant omega, symmetric always),
    the drag flow h/2, kick h/2, drift h/2."""
    hh = 0.5 * h
    for j in range(3):
        yn[j] += hh * yn[j + 3]
    ax, ay, az, wx, wy, wz = kick_acceleration(t + hh, yn, P, F, G)
    vx = yn[3] + hh * ax
    vy = yn[4] + hh * ay
    vz = yn[5] + hh * az
    k1, k2 = drag_rates(yn)  # a drag term's exact flow, h/2 on each side of the turn (none: the identity)
    vx, vy, vz = drag_flow(vx, vy, vz, k1, k2, hh)
    w = math.sqrt(wx * wx + wy * wy + wz * wz)
    if w > 0.0:
        angle = -2.0 * w * h
        vx, vy, vz = rodrigues_rotate(vx, vy, vz, wx / w, wy / w, wz / w, math.cos(angle), math.sin(angle))
    vx, vy, vz = drag_flow(vx, vy, vz, k1, k2, hh)
    yn[3] = vx + hh * ax
    yn[4] = vy + hh * ay
    yn[5] = vz + hh * az
    for j in range(3):
        yn[j] += hh * yn[j + 3]


@jit
def own_step(method, t, y, h, yn, P, F, G):
    """Method 2: the rotation splitting (order 2); method 3: Yoshida's triple jump of it (order 4)."""
    for j in range(D):
        yn[j] = y[j]
    if method == 2:
        rotation_strang(t, h, yn, P, F, G)
    else:
        w1 = YOSHIDA4_OUTER  # Yoshida's triple jump (rotframe.numerics.composition)
        w0 = YOSHIDA4_INNER
        rotation_strang(t, w1 * h, yn, P, F, G)
        rotation_strang(t + w1 * h, w0 * h, yn, P, F, G)
        rotation_strang(t + (w1 + w0) * h, w1 * h, yn, P, F, G)
'''

