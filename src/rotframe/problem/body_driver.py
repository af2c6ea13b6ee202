"""Source of the compiled rigid-body driver of a user's problem: Euler's equations with a torque.

State ``y = (L1, L2, L3, qx, qy, qz, qw)``: the angular momentum in body axes (kg m^2/s) and
the attitude, a scalar-last quaternion rotating body components into space components (the
convention of ``rotframe.rigid`` and scipy's ``Rotation.from_quat``). With ``omega = I^-1 L``
(any symmetric inertia tensor, in the body axes the user chose)::

    L' = L x omega + tau(t, L, q)          (Euler's equations in body axes)
    q' = q (omega, 0) / 2

``F = (I^-1,)``. The stepping (DOP853, RK4) is `rotframe.problem.stepping`'s; a body
has no events (``NE = 0``). Its own fixed-step methods (``own_step``) are the Lie-Poisson
splittings of the free body in principal axes (McLachlan 1993; Dullweber, Leimkuhler &
McLachlan 1997: the exact rotations about each body axis, composed symmetrically) with the
torque as a kick at fixed attitude, exact for a torque of ``(t, q)`` alone: order 2
(``lie-poisson``) and Yoshida's fourth-order triple jump of it (``lie-poisson4``).
"""

from rotframe.problem.stepping import SOURCE as STEPPING_SOURCE

SOURCE = r'''
# ---- the body of every generated rigid-body driver (rotframe.problem.body_driver) ----

@jit
def rhs(t, y, dy, P, F, G):
    Iinv = F[0]
    L1 = y[0]
    L2 = y[1]
    L3 = y[2]
    w1 = Iinv[0, 0] * L1 + Iinv[0, 1] * L2 + Iinv[0, 2] * L3
    w2 = Iinv[1, 0] * L1 + Iinv[1, 1] * L2 + Iinv[1, 2] * L3
    w3 = Iinv[2, 0] * L1 + Iinv[2, 1] * L2 + Iinv[2, 2] * L3
    tx, ty, tz = user_torque(t, y, P)
    dy[0] = L2 * w3 - L3 * w2 + tx
    dy[1] = L3 * w1 - L1 * w3 + ty
    dy[2] = L1 * w2 - L2 * w1 + tz
    attitude_rate(y, dy, 3, w1, w2, w3)


@jit
def event_value(k, t, y, P):
    return 0.0


@jit
def turn_about_axis(k, a, yn):
    """The exact flow of H_k = L_k^2 / (2 I_k) for an angle a = h L_k / I_k: L turns by -a about body
    axis k, the attitude by +a about it (q <- q (e_k sin(a/2), cos(a/2)))."""
    c = math.cos(a)
    s = math.sin(a)
    i = (k + 1) % 3
    j = (k + 2) % 3
    li = yn[i]
    lj = yn[j]
    yn[i] = c * li + s * lj
    yn[j] = -s * li + c * lj
    hc = math.cos(0.5 * a)
    hs = math.sin(0.5 * a)
    qx = yn[3]
    qy = yn[4]
    qz = yn[5]
    qw = yn[6]
    ex = hs if k == 0 else 0.0
    ey = hs if k == 1 else 0.0
    ez = hs if k == 2 else 0.0
    yn[3] = qw * ex + hc * qx + (qy * ez - qz * ey)
    yn[4] = qw * ey + hc * qy + (qz * ex - qx * ez)
    yn[5] = qw * ez + hc * qz + (qx * ey - qy * ex)
    yn[6] = qw * hc - (qx * ex + qy * ey + qz * ez)


@jit
def strang(t, h, yn, P, F):
    """Kick(h/2) . R1(h/2) R2(h/2) R3(h) R2(h/2) R1(h/2) . kick(h/2): second order, symplectic on the
    Lie-Poisson manifold; the kick L += h tau(t, q) is exact for a torque of (t, q) alone."""
    Iinv = F[0]
    tx, ty, tz = user_torque(t, yn, P)
    yn[0] += 0.5 * h * tx
    yn[1] += 0.5 * h * ty
    yn[2] += 0.5 * h * tz
    turn_about_axis(0, 0.5 * h * yn[0] * Iinv[0, 0], yn)
    turn_about_axis(1, 0.5 * h * yn[1] * Iinv[1, 1], yn)
    turn_about_axis(2, h * yn[2] * Iinv[2, 2], yn)
    turn_about_axis(1, 0.5 * h * yn[1] * Iinv[1, 1], yn)
    turn_about_axis(0, 0.5 * h * yn[0] * Iinv[0, 0], yn)
    tx, ty, tz = user_torque(t + h, yn, P)
    yn[0] += 0.5 * h * tx
    yn[1] += 0.5 * h * ty
    yn[2] += 0.5 * h * tz


@jit
def own_step(method, t, y, h, yn, P, F, G):
    """Method 2: the Strang splitting (order 2); method 3: Yoshida's triple jump of it (order 4)."""
    for j in range(D):
        yn[j] = y[j]
    if method == 2:
        strang(t, h, yn, P, F)
    else:
        w1 = YOSHIDA4_OUTER  # Yoshida's triple jump (rotframe.numerics.composition)
        w0 = YOSHIDA4_INNER
        strang(t, w1 * h, yn, P, F)
        strang(t + w1 * h, w0 * h, yn, P, F)
        strang(t + (w1 + w0) * h, w1 * h, yn, P, F)
'''

SOURCE = SOURCE + STEPPING_SOURCE
