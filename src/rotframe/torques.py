"""The built-in torques on a rigid body, as the same kind of object as your own (``rotframe.torques``).

Each factory returns a [`rotframe.Torque`][rotframe.problem.body.Torque] that
``rotframe.simulate_body`` takes as its ``torque``, alone or in a list beside torques of your own
(summed in order)::

    import rotframe
    from rotframe import torques

    def damper(t, L, q):                        # your own torque: N m in body axes
        return -0.01 * L[0], -0.01 * L[1], -0.01 * L[2]

    res = rotframe.simulate_body(inertia=[0.02, 0.02, 0.01], L0=[0.0, 0.0, 0.5],
                                 q0=[0.2588190451, 0.0, 0.0, 0.9659258263], duration=2.0,
                                 torque=[torques.gravity(mass=0.5, length=0.04, g=9.81), damper])

A built-in torque goes the same way into the same compiled driver as yours (its function is
plain arithmetic on ``t, L, q``, compiled with numba like yours), so a built-in torque and a
torque of yours that does the same arithmetic give the same motion to the last bit
(``tests/test_torques.py``). The arithmetic is the scenes' own: the rigid-body scenes' torque,
`rotframe.rigid.kernels.body_torque`, written once, which these functions call. A torque's
constants are compiled into its function (a run with other constants compiles its glue once,
cached on disk); the run's ``params`` go to your torques, not to a built-in one
(``Torque.takes_params`` False).

Every built-in torque depends on the attitude ``q`` alone (``Torque.attitude_only``), so the
Lie-Poisson splittings take it as a kick.

=============================  ===========================================  ======================
factory                         torque (body axes)                           the scenes' term
=============================  ===========================================  ======================
``gravity(mass, length, g)``    ``m g l (z_b[1], -z_b[0], 0)``               the heavy top's gravity
``body_fixed(tau)``             ``tau``                                      ``torque_body``
``space_fixed(tau)``            ``R(q)^T tau``                               ``torque_space``
=============================  ===========================================  ======================

``z_b = R(q)^T (0, 0, 1)`` is space's vertical in body axes and ``R(q)`` turns body components
into space components (``q`` scalar last, normalised where it is read). The conventions and the
heavy top's equations: docs/physics/rigid-bodies.md.
"""

from __future__ import annotations

from rotframe.errors import ScenarioError
from rotframe.problem.terms import Torque
from rotframe.units import si_number, si_vector

__all__ = ["Torque", "gravity", "body_fixed", "space_fixed"]


def _arithmetic():
    """Bind the torques' arithmetic, written once (`rotframe.rigid.kernels.body_torque`), as this module's global.

    Imported where a factory is called, not with the module: it is a compiled function, and numba's
    import is paid by the runs that need it.
    """
    global _body_torque
    from rotframe.rigid.kernels import body_torque as _body_torque


def gravity(mass, length, g) -> Torque:
    """Gravity on a heavy symmetric top: its centre of mass on body axis 3 at ``length`` from the fixed point.

    ``tau = l e3 x (-m g z_b) = m g l (z_b[1], -z_b[0], 0)`` in body axes, with ``z_b`` space's
    vertical (gravity along -z of space). ``mass`` in kg, ``length`` in m (negative: the centre of
    mass below the pivot), ``g`` in m/s^2 (>= 0; 0: no torque). The heavy-top scene's torque, with ``m g l``
    multiplied as its splitting does (`rotframe.rigid.checks.heavy_top_mgl`: ``mass * g * length``).

    Examples
    --------
    A top tilted by 90 degrees about body x (its axis horizontal, along -y of space) feels a torque about x:

    >>> import math
    >>> tau = gravity(mass=2.0, length=0.5, g=10.0)
    >>> s = math.sqrt(0.5)
    >>> [round(c, 12) + 0.0 for c in tau(0.0, [0.0, 0.0, 1.0], [s, 0.0, 0.0, s])]
    [10.0, 0.0, 0.0]
    """
    _arithmetic()
    m, l, gv = (si_number("gravity", "mass", mass, "kg"), si_number("gravity", "length", length, "m"),
                si_number("gravity", "g", g, "m/s^2"))
    if not m > 0:
        raise ScenarioError(f"gravity: mass={mass!r} must be > 0 (kg)")
    if not gv >= 0:
        raise ScenarioError(f"gravity: g={g!r} must be >= 0 (m/s^2, along -z of space)")
    mgl = m * gv * l

    def gravity(t, L, q):
        return _body_torque(q[0], q[1], q[2], q[3], mgl, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)

    return Torque(gravity, attitude_only=True, name="gravity", takes_params=False)


def body_fixed(tau) -> Torque:
    """A torque fixed in the body, ``tau`` (N m, body axes): a thruster's couple.

    Examples
    --------
    >>> body_fixed([0.0, 0.0, 0.1])(0.0, [1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0])
    (0.0, 0.0, 0.1)
    """
    _arithmetic()
    nx, ny, nz = si_vector("body_fixed", "tau", tau, "N m")

    def body_fixed(t, L, q):
        return _body_torque(q[0], q[1], q[2], q[3], 0.0, nx, ny, nz, 0.0, 0.0, 0.0)

    return Torque(body_fixed, attitude_only=True, name="torque fixed in the body", takes_params=False)


def space_fixed(tau) -> Torque:
    """A torque fixed in space, ``tau`` (N m, space axes), felt in body axes as ``R(q)^T tau``.

    Then ``dL/dt = tau`` in space: the angular momentum in space grows linearly, whatever the body.
    """
    _arithmetic()
    sx, sy, sz = si_vector("space_fixed", "tau", tau, "N m")

    def space_fixed(t, L, q):
        return _body_torque(q[0], q[1], q[2], q[3], 0.0, 0.0, 0.0, 0.0, sx, sy, sz)

    return Torque(space_fixed, attitude_only=True, name="torque fixed in space", takes_params=False)
