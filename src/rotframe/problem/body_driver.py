"""Source of the compiled rigid-body driver of a user's problem: Euler's equations with a torque.

State ``y = (L1, L2, L3, qx, qy, qz, qw)``: the angular momentum in body axes (kg m^2/s) and
the attitude, a scalar-last quaternion rotating body components into space components (the
convention of ``rotframe.rigid`` and scipy's ``Rotation.from_quat``). With ``omega = I^-1 L``
(any symmetric inertia tensor, in the body axes the user chose)::

    L' = L x omega + tau(t, L, q)          (Euler's equations in body axes)
    q' = q (omega, 0) / 2

``F = (I^-1,)``. The stepping (DOP853, RK4) is `rotframe.problem.stepping`'s; a body
has no events (``NE = 0``).
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
    qx = y[3]
    qy = y[4]
    qz = y[5]
    qw = y[6]
    dy[3] = 0.5 * (qw * w1 + qy * w3 - qz * w2)
    dy[4] = 0.5 * (qw * w2 + qz * w1 - qx * w3)
    dy[5] = 0.5 * (qw * w3 + qx * w2 - qy * w1)
    dy[6] = -0.5 * (qx * w1 + qy * w2 + qz * w3)


@jit
def event_value(k, t, y, P):
    return 0.0
'''

SOURCE = SOURCE + STEPPING_SOURCE
