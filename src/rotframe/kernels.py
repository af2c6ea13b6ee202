"""Compiled kernels for particles in a rotating frame (numba, cached on disk).

Everything here works on plain float64 arrays in SI units and radians; there is
no I/O and no Python object in a step loop. The Python side
(:mod:`rotframe.integrators`) packs a :class:`rotframe.model.ParticleModel` into
the flat parameter vector ``P`` described below and calls the drivers in
chunks of output samples, so that a progress bar, Ctrl-C and a numerical
failure can be handled between chunks without losing data.

Equation of motion (rotating frame, PHYSICS.md section 1)::

    r'' = g(r) - 2 w(t) x v - w x (w x r) - w'(t) x r - k1 v - k2 |v| v  [+ tension]

with ``w(t) = w_hat * w(t)``, a fixed unit axis times a magnitude that is
piecewise linear in time (a constant is a one-node table). Each term is
switched by a flag in ``P``; a term that is off costs one branch.

Layout of ``P`` (see ``pack`` in :mod:`rotframe.model`)::

    0:3   uniform gravity vector g (m/s^2)          [used when gravity mode == 0]
    3:6   unit rotation axis w_hat
    6     coriolis on (1.0) / off (0.0)
    7     centrifugal on / off
    8     euler term on / off
    9     linear drag k1 (1/s)
    10    quadratic drag k2 (1/m)
    11    gravity mode: -1 none, 0 uniform, 1 altitude (g0 (R/(R+z))^2 down), 2 central
    12    GM (m^3/s^2)            13  R, Earth radius (m); the centre is at (0, 0, -R)
    14    pendulum length L (m), 0 for a free particle
    15:18 pendulum pivot (m)
    18    g0 for the altitude model (m/s^2)
    19    horizontal spring w0^2 (1/s^2): a += -w0^2 (x, y, 0), the small-angle pendulum
    20    density scale height H (m) of the drag: k -> k exp(-z / H); 0 for uniform air

The rotation-rate magnitude table is ``wt`` (node times, increasing) and
``wv`` (values, rad/s); outside the table the end values are held. ``wint``
holds the integral of w from ``wt[0]`` to each node, so the rotation angle
over any interval is exact for the piecewise-linear schedule.
"""

from __future__ import annotations

import numpy as np
from numba import njit

# Parameter-vector indices (kept in one place; model.pack writes them).
I_G, I_AXIS, I_CORIOLIS, I_CENTRIFUGAL, I_EULER = 0, 3, 6, 7, 8
I_KLIN, I_KQUAD, I_GMODE, I_GM, I_R, I_PLEN, I_PIVOT, I_G0, I_SPRING, I_SCALE_H = 9, 10, 11, 12, 13, 14, 15, 18, 19, 20
N_PARAMS = 21

# Event description: (kind, component, value, direction, terminal)
#   kind 0: position component r[c] - value, kind 1: velocity component v[c] - value,
#   kind 2: altitude above the sphere of radius R about (0, 0, -R), minus value (curved ground)
#   direction: +1 rising only, -1 falling only, 0 both. terminal: 1 stops that particle.
N_EVENT_FIELDS = 5


# ---------------------------------------------------------------------------
# rotation-rate schedule
# ---------------------------------------------------------------------------


@njit(cache=True)
def omega_magnitude(t, wt, wv):
    """Magnitude w(t) of the piecewise-linear schedule (rad/s)."""
    n = wt.shape[0]
    if n == 1 or t <= wt[0]:
        return wv[0]
    if t >= wt[n - 1]:
        return wv[n - 1]
    k = np.searchsorted(wt, t) - 1
    s = (t - wt[k]) / (wt[k + 1] - wt[k])
    return wv[k] + s * (wv[k + 1] - wv[k])


@njit(cache=True)
def omega_rate(t, wt, wv):
    """Time derivative w'(t) of the schedule (rad/s^2); zero outside the table."""
    n = wt.shape[0]
    if n == 1 or t < wt[0] or t >= wt[n - 1]:
        return 0.0
    k = np.searchsorted(wt, t, side="right") - 1
    return (wv[k + 1] - wv[k]) / (wt[k + 1] - wt[k])


@njit(cache=True)
def omega_angle(t, wt, wv, wint):
    """Integral of w from ``wt[0]`` to t (rad), exact for the piecewise-linear schedule."""
    n = wt.shape[0]
    if n == 1 or t <= wt[0]:
        return wv[0] * (t - wt[0])
    if t >= wt[n - 1]:
        return wint[n - 1] + wv[n - 1] * (t - wt[n - 1])
    k = np.searchsorted(wt, t) - 1
    dt = t - wt[k]
    slope = (wv[k + 1] - wv[k]) / (wt[k + 1] - wt[k])
    return wint[k] + wv[k] * dt + 0.5 * slope * dt * dt


# ---------------------------------------------------------------------------
# accelerations
# ---------------------------------------------------------------------------


@njit(cache=True)
def _position_acceleration(r, t, P, wt, wv, out):
    """Forces that depend on position and time only: gravity, centrifugal, Euler."""
    mode = P[I_GMODE]
    if mode == 0.0:
        out[0] = P[0]
        out[1] = P[1]
        out[2] = P[2]
    elif mode == 1.0:
        R = P[I_R]
        s = R / (R + r[2])
        out[0] = 0.0
        out[1] = 0.0
        out[2] = -P[I_G0] * s * s
    elif mode == 2.0:
        dx = r[0]
        dy = r[1]
        dz = r[2] + P[I_R]
        d2 = dx * dx + dy * dy + dz * dz
        f = -P[I_GM] / (d2 * np.sqrt(d2))
        out[0] = f * dx
        out[1] = f * dy
        out[2] = f * dz
    else:
        out[0] = 0.0
        out[1] = 0.0
        out[2] = 0.0
    k = P[I_SPRING]
    if k != 0.0:
        out[0] -= k * r[0]
        out[1] -= k * r[1]
    ax = P[3]
    ay = P[4]
    az = P[5]
    if P[I_CENTRIFUGAL] != 0.0:
        # -w x (w x r) = w^2 (r - (w_hat . r) w_hat)
        w = omega_magnitude(t, wt, wv)
        d = ax * r[0] + ay * r[1] + az * r[2]
        w2 = w * w
        out[0] += w2 * (r[0] - d * ax)
        out[1] += w2 * (r[1] - d * ay)
        out[2] += w2 * (r[2] - d * az)
    if P[I_EULER] != 0.0:
        # -w' x r with w' = w'(t) w_hat (fixed axis)
        wd = omega_rate(t, wt, wv)
        out[0] -= wd * (ay * r[2] - az * r[1])
        out[1] -= wd * (az * r[0] - ax * r[2])
        out[2] -= wd * (ax * r[1] - ay * r[0])


@njit(cache=True)
def acceleration(r, v, t, P, wt, wv, out):
    """Total acceleration in the rotating frame (for Runge-Kutta methods).

    For a pendulum (``P[14] > 0``) the string constraint is kept by the
    index-1 form: the normal component of the applied acceleration is removed
    and the centripetal term ``-|v_t|^2 / L n`` added.
    """
    _position_acceleration(r, t, P, wt, wv, out)
    if P[I_CORIOLIS] != 0.0:
        w2 = 2.0 * omega_magnitude(t, wt, wv)
        ax = P[3] * w2
        ay = P[4] * w2
        az = P[5] * w2
        out[0] -= ay * v[2] - az * v[1]
        out[1] -= az * v[0] - ax * v[2]
        out[2] -= ax * v[1] - ay * v[0]
    k1 = P[I_KLIN]
    k2 = P[I_KQUAD]
    if k1 != 0.0 or k2 != 0.0:
        air = _air(r, P)
        k1 *= air
        k2 *= air
        speed = np.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
        k = k1 + k2 * speed
        out[0] -= k * v[0]
        out[1] -= k * v[1]
        out[2] -= k * v[2]
    L = P[I_PLEN]
    if L > 0.0:
        nx = (r[0] - P[15]) / L
        ny = (r[1] - P[16]) / L
        nz = (r[2] - P[17]) / L
        an = out[0] * nx + out[1] * ny + out[2] * nz
        vn = v[0] * nx + v[1] * ny + v[2] * nz
        v2t = v[0] * v[0] + v[1] * v[1] + v[2] * v[2] - vn * vn
        c = an + v2t / L
        out[0] -= c * nx
        out[1] -= c * ny
        out[2] -= c * nz


# ---------------------------------------------------------------------------
# small vector helpers
# ---------------------------------------------------------------------------


@njit(cache=True)
def _rotate(v, ax, ay, az, c, s):
    """Rotate v in place about the unit axis (ax, ay, az) by the angle with cos c, sin s."""
    d = ax * v[0] + ay * v[1] + az * v[2]
    cx = ay * v[2] - az * v[1]
    cy = az * v[0] - ax * v[2]
    cz = ax * v[1] - ay * v[0]
    one_c = 1.0 - c
    v0 = v[0] * c + cx * s + ax * d * one_c
    v1 = v[1] * c + cy * s + ay * d * one_c
    v2 = v[2] * c + cz * s + az * d * one_c
    v[0] = v0
    v[1] = v1
    v[2] = v2


@njit(cache=True)
def _air(r, P):
    """Relative air density exp(-z / H) at r, or 1 for uniform air (H = 0)."""
    H = P[I_SCALE_H]
    if H > 0.0:
        return np.exp(-r[2] / H)
    return 1.0


@njit(cache=True)
def _drag_flow(v, k1, k2, h):
    """Exact flow of v' = -(k1 + k2 |v|) v over h at fixed position (direction kept, speed decays)."""
    if k1 == 0.0 and k2 == 0.0:
        return
    speed = np.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    if speed == 0.0:
        return
    if k1 == 0.0:
        new = speed / (1.0 + k2 * speed * h)
    else:
        e = np.exp(-k1 * h)
        new = k1 * speed * e / (k1 + k2 * speed * (1.0 - e))
    f = new / speed
    v[0] *= f
    v[1] *= f
    v[2] *= f


# ---------------------------------------------------------------------------
# one-step methods (state r, v updated in place; return force evaluations)
# ---------------------------------------------------------------------------


@njit(cache=True)
def step_splitting(r, v, t, h, P, wt, wv, wint, a):
    """Exact-rotation splitting, order 2 (drift, kick, rotate, kick, drift).

    Strang composition of exact sub-flows (PHYSICS.md section 3): drift
    r += v h/2; kick v += a_pos(r, t + h/2) h/2 and exact drag; rotate v about
    w_hat by -2 * integral of w over the step (the exact Coriolis flow, no
    tan() as in Boris); drag and kick again; drift h/2. Explicit, symmetric
    (time-reversible), volume-preserving; one force evaluation per step.
    For a pendulum the constrained version :func:`step_sphere` is used.
    """
    if P[I_PLEN] > 0.0:
        return step_sphere(r, v, t, h, P, wt, wv, wint, a)
    hh = 0.5 * h
    for i in range(3):
        r[i] += hh * v[i]
    _position_acceleration(r, t + hh, P, wt, wv, a)
    air = _air(r, P)
    k1 = P[I_KLIN] * air
    k2 = P[I_KQUAD] * air
    for i in range(3):
        v[i] += hh * a[i]
    _drag_flow(v, k1, k2, hh)
    if P[I_CORIOLIS] != 0.0:
        angle = -2.0 * (omega_angle(t + h, wt, wv, wint) - omega_angle(t, wt, wv, wint))
        _rotate(v, P[3], P[4], P[5], np.cos(angle), np.sin(angle))
    _drag_flow(v, k1, k2, hh)
    for i in range(3):
        v[i] += hh * a[i]
    for i in range(3):
        r[i] += hh * v[i]
    return 1


@njit(cache=True)
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
    """
    L = P[I_PLEN]
    hh = 0.5 * h
    _great_circle(r, v, hh, P, L)
    _position_acceleration(r, t + hh, P, wt, wv, a)
    nx = (r[0] - P[15]) / L
    ny = (r[1] - P[16]) / L
    nz = (r[2] - P[17]) / L
    an = a[0] * nx + a[1] * ny + a[2] * nz
    a[0] -= an * nx
    a[1] -= an * ny
    a[2] -= an * nz
    air = _air(r, P)
    k1 = P[I_KLIN] * air
    k2 = P[I_KQUAD] * air
    for i in range(3):
        v[i] += hh * a[i]
    _drag_flow(v, k1, k2, hh)
    if P[I_CORIOLIS] != 0.0:
        wn = P[3] * nx + P[4] * ny + P[5] * nz
        angle = -2.0 * wn * (omega_angle(t + h, wt, wv, wint) - omega_angle(t, wt, wv, wint))
        _rotate(v, nx, ny, nz, np.cos(angle), np.sin(angle))
    _drag_flow(v, k1, k2, hh)
    for i in range(3):
        v[i] += hh * a[i]
    _great_circle(r, v, hh, P, L)
    return 1


@njit(cache=True)
def _great_circle(r, v, tau, P, L):
    """Exact geodesic flow on the sphere of radius L about the pivot, for time tau."""
    nx = (r[0] - P[15]) / L
    ny = (r[1] - P[16]) / L
    nz = (r[2] - P[17]) / L
    vn = v[0] * nx + v[1] * ny + v[2] * nz
    vx = v[0] - vn * nx
    vy = v[1] - vn * ny
    vz = v[2] - vn * nz
    speed = np.sqrt(vx * vx + vy * vy + vz * vz)
    if speed > 0.0:
        ux = vx / speed
        uy = vy / speed
        uz = vz / speed
        phi = speed * tau / L
        c = np.cos(phi)
        s = np.sin(phi)
        mx = nx * c + ux * s
        my = ny * c + uy * s
        mz = nz * c + uz * s
        vx = speed * (ux * c - nx * s)
        vy = speed * (uy * c - ny * s)
        vz = speed * (uz * c - nz * s)
        nx, ny, nz = mx, my, mz
    norm = np.sqrt(nx * nx + ny * ny + nz * nz)
    nx /= norm
    ny /= norm
    nz /= norm
    vn = vx * nx + vy * ny + vz * nz
    r[0] = P[15] + L * nx
    r[1] = P[16] + L * ny
    r[2] = P[17] + L * nz
    v[0] = vx - vn * nx
    v[1] = vy - vn * ny
    v[2] = vz - vn * nz


# Yoshida (1990) triple jump: w1 = 1 / (2 - 2^(1/3)), w0 = 1 - 2 w1.
_YOSHIDA_W1 = 1.0 / (2.0 - 2.0 ** (1.0 / 3.0))
_YOSHIDA_W0 = 1.0 - 2.0 * _YOSHIDA_W1


@njit(cache=True)
def step_splitting4(r, v, t, h, P, wt, wv, wint, a):
    """Fourth-order symmetric composition (Yoshida 1990) of :func:`step_splitting`."""
    h1 = _YOSHIDA_W1 * h
    h0 = _YOSHIDA_W0 * h
    step_splitting(r, v, t, h1, P, wt, wv, wint, a)
    step_splitting(r, v, t + h1, h0, P, wt, wv, wint, a)
    step_splitting(r, v, t + h1 + h0, h1, P, wt, wv, wint, a)
    return 3


@njit(cache=True)
def step_rk4(r, v, t, h, P, wt, wv, wint, a):
    """Classical Runge-Kutta, order 4, four force evaluations; conserves nothing exactly."""
    k1r = v.copy()
    k1v = np.empty(3)
    acceleration(r, v, t, P, wt, wv, k1v)
    r2 = r + 0.5 * h * k1r
    v2 = v + 0.5 * h * k1v
    k2v = np.empty(3)
    acceleration(r2, v2, t + 0.5 * h, P, wt, wv, k2v)
    r3 = r + 0.5 * h * v2
    v3 = v + 0.5 * h * k2v
    k3v = np.empty(3)
    acceleration(r3, v3, t + 0.5 * h, P, wt, wv, k3v)
    r4 = r + h * v3
    v4 = v + h * k3v
    k4v = np.empty(3)
    acceleration(r4, v4, t + h, P, wt, wv, k4v)
    for i in range(3):
        r[i] += h / 6.0 * (k1r[i] + 2.0 * v2[i] + 2.0 * v3[i] + v4[i])
        v[i] += h / 6.0 * (k1v[i] + 2.0 * k2v[i] + 2.0 * k3v[i] + k4v[i])
    return 4


@njit(cache=True)
def select_step(method, r, v, t, h, P, wt, wv, wint, a):
    """Dispatch on the method code: 0 splitting, 1 splitting4, 2 rk4."""
    if method == 0:
        return step_splitting(r, v, t, h, P, wt, wv, wint, a)
    elif method == 1:
        return step_splitting4(r, v, t, h, P, wt, wv, wint, a)
    else:
        return step_rk4(r, v, t, h, P, wt, wv, wint, a)


# ---------------------------------------------------------------------------
# events
# ---------------------------------------------------------------------------


@njit(cache=True)
def _event_value(ev, r, v, P):
    c = int(ev[1])
    if ev[0] == 0.0:
        return r[c] - ev[2]
    if ev[0] == 1.0:
        return v[c] - ev[2]
    R = P[I_R]
    dz = r[2] + R
    return np.sqrt(r[0] * r[0] + r[1] * r[1] + dz * dz) - R - ev[2]


@njit(cache=True)
def _crossed(ev, g0, g1):
    direction = ev[3]
    if direction > 0.0:
        return g0 < 0.0 and g1 >= 0.0
    if direction < 0.0:
        return g0 > 0.0 and g1 <= 0.0
    return (g0 < 0.0 and g1 >= 0.0) or (g0 > 0.0 and g1 <= 0.0)


# ---------------------------------------------------------------------------
# fixed-step driver
# ---------------------------------------------------------------------------


@njit(cache=True)
def run_fixed(method, r, v, alive, t0, h, steps_per_sample, n_samples, P, wt, wv, wint,
              events, out_r, out_v, ev_t, ev_r, ev_v, ev_count, ev_which, max_events):
    """Advance an ensemble with a fixed-step method and store samples.

    Parameters
    ----------
    method : int
        0 splitting, 1 splitting4, 2 rk4.
    r, v : (N, 3) arrays
        State at ``t0`` (rotating frame, m and m/s); updated in place.
    alive : (N,) bool array
        Particles still moving; a terminal event clears the flag (in place).
    h : float
        Step (s). Samples are stored every ``steps_per_sample`` steps.
    events : (E, 5) array
        Event table (see module docstring). Crossings are located by
        re-stepping from the last state before the crossing with a shorter step
        (bisection to round-off), so an event time is exact for the method's own
        discrete trajectory.
    out_r, out_v : (n_samples, N, 3) arrays
        Filled with the state after each sample interval; a stopped particle
        keeps its state at the terminal event.
    ev_t, ev_r, ev_v, ev_count, ev_which : event records per particle (time, state, event index).

    Returns
    -------
    n_done : int
        Samples completed (``n_samples`` unless a state became non-finite).
    bad : int
        Index of the first particle with a non-finite state, or -1.
    nfev : int
        Force evaluations of particle 0 (the cost of one trajectory).
    """
    n = r.shape[0]
    n_ev = events.shape[0]
    a = np.empty(3)
    rs = np.empty(3)
    vs = np.empty(3)
    rt = np.empty(3)
    vt = np.empty(3)
    g_old = np.empty(n_ev)
    nfev0 = 0
    n_done = n_samples
    bad = -1
    for p in range(n):
        ri = r[p].copy()
        vi = v[p].copy()
        is_alive = alive[p]
        t = t0
        k_step = 0
        for e in range(n_ev):
            g_old[e] = _event_value(events[e], ri, vi, P)
        for s in range(n_samples):
            if is_alive:
                for _ in range(steps_per_sample):
                    rs[:] = ri
                    vs[:] = vi
                    nf = select_step(method, ri, vi, t, h, P, wt, wv, wint, a)
                    if p == 0:
                        nfev0 += nf
                    k_step += 1
                    t_new = t0 + k_step * h
                    stop = False
                    for e in range(n_ev):
                        g_new = _event_value(events[e], ri, vi, P)
                        if _crossed(events[e], g_old[e], g_new):
                            tau = _locate(method, events[e], rs, vs, t, h, P, wt, wv, wint, a, rt, vt)
                            k = ev_count[p]
                            if k < max_events:
                                ev_t[p, k] = t + tau
                                ev_r[p, k] = rt
                                ev_v[p, k] = vt
                                ev_which[p, k] = e
                            ev_count[p] = k + 1
                            if events[e, 4] != 0.0:
                                stop = True
                                ri[:] = rt
                                vi[:] = vt
                                t_new = t + tau
                        g_old[e] = g_new
                    t = t_new
                    if stop:
                        is_alive = False
                        break
                finite = True
                for i in range(3):
                    if not (np.isfinite(ri[i]) and np.isfinite(vi[i])):
                        finite = False
                if not finite:
                    if s < n_done:
                        n_done = s
                    if bad < 0:
                        bad = p
                    break
            out_r[s, p] = ri
            out_v[s, p] = vi
        r[p] = ri
        v[p] = vi
        alive[p] = is_alive
    return n_done, bad, nfev0


@njit(cache=True)
def _locate(method, ev, rs, vs, t, h, P, wt, wv, wint, a, rt, vt):
    """Sub-step tau in (0, h] at which the event function of the one-step map vanishes.

    Bisection on tau of g(step(state, tau)), 60 halvings: the bracket shrinks to
    round-off. The state at the event is left in ``rt``, ``vt``.
    """
    lo = 0.0
    hi = h
    g_lo = _event_value(ev, rs, vs, P)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        rt[:] = rs
        vt[:] = vs
        select_step(method, rt, vt, t, mid, P, wt, wv, wint, a)
        g_mid = _event_value(ev, rt, vt, P)
        if (g_lo < 0.0) == (g_mid < 0.0) and g_mid != 0.0:
            lo = mid
            g_lo = g_mid
        else:
            hi = mid
    rt[:] = rs
    vt[:] = vs
    select_step(method, rt, vt, t, hi, P, wt, wv, wint, a)
    return hi


# ---------------------------------------------------------------------------
# adaptive Dormand-Prince 8(5,3)
# ---------------------------------------------------------------------------


@njit(cache=True)
def _deriv(t, y, P, wt, wv, out):
    out[0] = y[3]
    out[1] = y[4]
    out[2] = y[5]
    acceleration(y[0:3], y[3:6], t, P, wt, wv, out[3:6])


@njit(cache=True)
def _dop853_step(t, y, f0, h, P, wt, wv, A, B, C, K, y_new):
    """One DOP853 step from (t, y) with f0 = f(t, y); K (13, 6) receives the stages."""
    K[0] = f0
    tmp = np.empty(6)
    for s in range(1, 12):
        for j in range(6):
            acc = 0.0
            for m in range(s):
                acc += A[s, m] * K[m, j]
            tmp[j] = y[j] + h * acc
        _deriv(t + C[s] * h, tmp, P, wt, wv, K[s])
    for j in range(6):
        acc = 0.0
        for m in range(12):
            acc += B[m] * K[m, j]
        y_new[j] = y[j] + h * acc
    _deriv(t + h, y_new, P, wt, wv, K[12])


@njit(cache=True)
def _dop853_error(K, h, y, y_new, rtol, atol, E3, E5):
    e5 = 0.0
    e3 = 0.0
    for j in range(6):
        sc = atol + rtol * max(abs(y[j]), abs(y_new[j]))
        s5 = 0.0
        s3 = 0.0
        for m in range(13):
            s5 += E5[m] * K[m, j]
            s3 += E3[m] * K[m, j]
        e5 += (s5 / sc) ** 2
        e3 += (s3 / sc) ** 2
    if e5 == 0.0 and e3 == 0.0:
        return 0.0
    return abs(h) * e5 / np.sqrt((e5 + 0.01 * e3) * 6.0)


@njit(cache=True)
def run_dop853(r, v, alive, t0, sample_times, P, wt, wv, rtol, atol, h0, A, B, C, E3, E5,
               events, out_r, out_v, ev_t, ev_r, ev_v, ev_count, ev_which, max_events, h_state):
    """Adaptive Dormand-Prince 8(5,3) (Hairer, Norsett & Wanner, II.10) for an ensemble.

    Error control as in Hairer's DOP853 (5th- and 3rd-order estimates combined).
    Output at ``sample_times``: the state at a sample time inside an accepted
    step is computed by one extra DOP853 step of the right length from the
    step's start (an interpolant of the same order as the method). Events are
    located the same way, by bisection on the length of that extra step.
    ``h_state`` (N,) carries each particle's step size between calls.

    Returns (n_done, bad, nfev, steps) like :func:`run_fixed` (cost of particle 0).
    """
    n = r.shape[0]
    n_out = sample_times.shape[0]
    n_ev = events.shape[0]
    K = np.empty((13, 6))
    Kt = np.empty((13, 6))
    y = np.empty(6)
    y_new = np.empty(6)
    yt = np.empty(6)
    f0 = np.empty(6)
    g_old = np.empty(n_ev)
    nfev0 = 0
    steps0 = 0
    n_done = n_out
    bad = -1
    t_end = sample_times[n_out - 1]
    for p in range(n):
        y[0:3] = r[p]
        y[3:6] = v[p]
        t = t0
        h = h_state[p]
        if h <= 0.0:
            h = h0
        is_alive = alive[p]
        _deriv(t, y, P, wt, wv, f0)
        nf = 1
        for e in range(n_ev):
            g_old[e] = _event_value(events[e], y[0:3], y[3:6], P)
        k_out = 0
        while k_out < n_out and sample_times[k_out] <= t:
            out_r[k_out, p] = y[0:3]
            out_v[k_out, p] = y[3:6]
            k_out += 1
        failed = False
        while is_alive and t < t_end:
            # one accepted step
            accepted = False
            while not accepted:
                if t + h > t_end:
                    h = t_end - t
                min_h = 10.0 * abs(np.nextafter(t, np.inf) - t)
                if h < min_h:
                    failed = True
                    break
                _dop853_step(t, y, f0, h, P, wt, wv, A, B, C, K, y_new)
                nf += 12
                err = _dop853_error(K, h, y, y_new, rtol, atol, E3, E5)
                if not np.isfinite(err):
                    h *= 0.2
                    continue
                if err < 1.0:
                    fac = 10.0 if err == 0.0 else min(10.0, 0.9 * err ** (-1.0 / 8.0))
                    accepted = True
                else:
                    fac = max(0.2, 0.9 * err ** (-1.0 / 8.0))
                h_used = h
                h = h * fac
            if failed:
                break
            t_new = t + h_used
            if p == 0:
                steps0 += 1
            # events inside (t, t_new]
            stop = False
            t_stop = t_new
            for e in range(n_ev):
                g_new = _event_value(events[e], y_new[0:3], y_new[3:6], P)
                if _crossed(events[e], g_old[e], g_new):
                    lo = 0.0
                    hi = h_used
                    g_lo = g_old[e]
                    for _ in range(60):
                        mid = 0.5 * (lo + hi)
                        if mid <= lo or mid >= hi:
                            break
                        _dop853_step(t, y, f0, mid, P, wt, wv, A, B, C, Kt, yt)
                        g_mid = _event_value(events[e], yt[0:3], yt[3:6], P)
                        if (g_lo < 0.0) == (g_mid < 0.0) and g_mid != 0.0:
                            lo = mid
                            g_lo = g_mid
                        else:
                            hi = mid
                    _dop853_step(t, y, f0, hi, P, wt, wv, A, B, C, Kt, yt)
                    k = ev_count[p]
                    if k < max_events:
                        ev_t[p, k] = t + hi
                        ev_r[p, k] = yt[0:3]
                        ev_v[p, k] = yt[3:6]
                        ev_which[p, k] = e
                    ev_count[p] = k + 1
                    if events[e, 4] != 0.0 and t + hi <= t_stop:
                        stop = True
                        t_stop = t + hi
                g_old[e] = g_new
            # samples inside (t, t_stop]
            while k_out < n_out and sample_times[k_out] <= t_stop:
                ts = sample_times[k_out]
                if ts == t_new:
                    yt[:] = y_new
                else:
                    _dop853_step(t, y, f0, ts - t, P, wt, wv, A, B, C, Kt, yt)
                    nf += 12
                out_r[k_out, p] = yt[0:3]
                out_v[k_out, p] = yt[3:6]
                k_out += 1
            if stop:
                _dop853_step(t, y, f0, t_stop - t, P, wt, wv, A, B, C, Kt, yt)
                y[:] = yt
                t = t_stop
                is_alive = False
                break
            y[:] = y_new
            f0[:] = K[12]
            t = t_new
            finite = True
            for j in range(6):
                if not np.isfinite(y[j]):
                    finite = False
            if not finite:
                failed = True
                break
        if failed:
            if bad < 0:
                bad = p
            if k_out < n_done:
                n_done = k_out
        # a stopped particle keeps its final state in the remaining samples
        while k_out < n_out:
            out_r[k_out, p] = y[0:3]
            out_v[k_out, p] = y[3:6]
            k_out += 1
        r[p] = y[0:3]
        v[p] = y[3:6]
        alive[p] = is_alive
        h_state[p] = h
        if p == 0:
            nfev0 = nf
    return n_done, bad, nfev0, steps0
