"""The built-in terms, as the same kind of object as your own force (``rotframe.forces``).

Each factory returns a [`rotframe.Force`][rotframe.problem.particles.Force] (or, for the
pendulum, the string's constraint) that ``rotframe.simulate`` takes in its ``forces`` list
beside your own::

    import rotframe
    from rotframe import forces

    def wind(t, r, v):                       # your own term: m/s^2 in the frame's axes
        return 0.0, 0.3 * (1.0 - abs(r[2]) / 100.0), 0.0

    res = rotframe.simulate(omega=[0.0, 4.6e-5, 5.7e-5], r0=[0, 0, 50.0], v0=[20.0, 0, 30.0],
                            duration=5.0, forces=[forces.gravity([0, 0, -9.81]),
                                                  forces.drag(quadratic=4e-5), wind])

A built-in term goes the same way into the same compiled driver as your force (its function
is plain arithmetic on ``t, r, v``, compiled with numba like yours), so a built-in term and a
force of yours that does the same arithmetic give the same trajectory to the last bit
(``tests/test_forces.py``). Their arithmetic is the scenes' own: a term's acceleration is
written once, in `rotframe.particles.accelerations`, which both the scenes' compiled kernels
([`rotframe.particles.model.ParticleModel`][rotframe.particles.model.ParticleModel]) and these
functions call; each factory's docstring names the scene term it is. A term's constants are
compiled into its function: a run with other constants compiles its driver once (cached on disk
like any other). A value you vary from run to run is cheaper as a ``params`` entry of a force of
your own. The run's ``params`` go to your forces, not to a built-in term (``Force.takes_params``
False), so it sits beside forces of yours that use them.

The frame's own terms (Coriolis, centrifugal, Euler, the origin's acceleration) are not terms
to add: ``rotframe.simulate`` adds them from ``omega`` and ``origin_acceleration`` (``frame_terms``
chooses which of the frame's act).

The terms linear in ``(r, v)`` with constant coefficients carry their part of
``a = K r + C v + b`` (``Force.linear``): ``gravity``, ``spring``, ``drag`` with ``linear`` alone in
uniform air, and ``lorentz``. A problem of those terms alone, in a steady frame, runs under
``method="exact"``, the exact flow (`rotframe.problem.exact`).

=========================  ===============================  =======================
factory                     acceleration (frame axes)        the scenes' term
=========================  ===============================  =======================
``gravity(g)``              ``g``                            ``gravity``
``altitude_gravity(g0, R)`` ``-g0 (R / (R + z))^2 z_hat``    ``altitude-gravity``
``central_gravity(gm, c)``  ``-GM (r - c) / |r - c|^3``      ``central-gravity``
``drag(linear, quadratic,`` ``-(k1 + k2 |v|) rho(z) v``      ``linear-drag``,
``scale_height)``                                            ``quadratic-drag``
``spring(k, anchor)``       ``-k (r - anchor)``              ``spring`` (horizontal)
``pendulum(length, pivot)`` the string's tension             ``pendulum``
``lorentz(q_over_m, B, E)`` ``(q/m) (E + v x B)``            (none)
=========================  ===============================  =======================
"""

from __future__ import annotations


import numpy as np

from rotframe.errors import ScenarioError
from rotframe.problem.particles import Force, StringConstraint
from rotframe.units import si_number, si_vector

__all__ = ["Force", "gravity", "altitude_gravity", "central_gravity", "drag", "spring", "pendulum", "lorentz"]


#: a 3 x 3 zero, as the rows of a term's linear form (`Force.linear`)
_ZERO3 = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))


def _diagonal(a, b, c):
    """The rows of diag(a, b, c), for a term's linear form (`Force.linear`)."""
    return ((a, 0.0, 0.0), (0.0, b, 0.0), (0.0, 0.0, c))


def _arithmetic():
    """Bind the terms' arithmetic, written once (`rotframe.particles.accelerations`), as this module's globals.

    A factory whose function calls it runs this first. They are module globals, read by name, so
    a GPU compile rebinds them to its own versions, and imported only here because they are
    compiled functions: numba's import (0.1 s) is not paid by a run of uniform gravity alone,
    whose exact flow compiles nothing.
    """
    global _air_density, _altitude_gravity, _central_gravity, _drag_rate, _spring_pull
    from rotframe.particles.accelerations import air_density as _air_density
    from rotframe.particles.accelerations import altitude_gravity as _altitude_gravity
    from rotframe.particles.accelerations import central_gravity as _central_gravity
    from rotframe.particles.accelerations import drag_rate as _drag_rate
    from rotframe.particles.accelerations import spring_pull as _spring_pull


def gravity(g) -> Force:
    """Uniform gravity: ``a = g`` (m/s^2, the frame's axes); ``U = -g . r``. The scenes' term ``gravity``.

    Examples
    --------
    >>> gravity([0.0, 0.0, -9.81]).accel(0.0, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    (0.0, 0.0, -9.81)
    """
    gx, gy, gz = si_vector("gravity", "g", g, "m/s^2")

    def gravity(t, r, v):
        return gx, gy, gz

    def potential(t, r):
        return -(gx * r[0] + gy * r[1] + gz * r[2])

    return Force(gravity, potential=potential, name="gravity", takes_params=False, array_potential=True,
                 linear=(_ZERO3, _ZERO3, (gx, gy, gz)))


def altitude_gravity(g0, radius) -> Force:
    """Gravity falling off with height z above a flat ground: ``a_z = -g0 (R / (R + z))^2``.

    ``U = -g0 R^2 / (R + z)``. The scenes' term ``altitude-gravity`` (g0 in m/s^2, R in m).
    """
    _arithmetic()
    g0, R = si_number("altitude_gravity", "g0", g0, "m/s^2"), si_number("altitude_gravity", "radius", radius, "m")
    if not R > 0:
        raise ScenarioError(f"altitude_gravity: radius={R!r} must be > 0 (m)")

    def gravity(t, r, v):
        return 0.0, 0.0, _altitude_gravity(r[2], g0, R)

    def potential(t, r):
        return -g0 * R * R / (R + r[2])

    return Force(gravity, potential=potential, name="altitude-gravity", takes_params=False, array_potential=True,
                 scene=("altitude-gravity", g0, R))


def central_gravity(gm, centre) -> Force:
    """Gravity of a point mass at ``centre``: ``a = -GM (r - c) / |r - c|^3``; ``U = -GM / |r - c|``.

    The scenes' term ``central-gravity`` is this one with ``c = (0, 0, -R)``, Earth's centre
    below a local frame on its surface (GM in m^3/s^2, c in m).
    """
    _arithmetic()
    GM = si_number("central_gravity", "gm", gm, "m^3/s^2")
    cx, cy, cz = si_vector("central_gravity", "centre", centre, "m")

    def gravity(t, r, v):
        return _central_gravity(r[0] - cx, r[1] - cy, r[2] - cz, GM)

    def potential(t, r):
        dx = r[0] - cx
        dy = r[1] - cy
        dz = r[2] - cz
        return -GM / np.sqrt(dx * dx + dy * dy + dz * dz)  # numpy's: r may be (3, M) arrays (array_potential)

    return Force(gravity, potential=potential, name="central-gravity", takes_params=False, array_potential=True)


def drag(*, linear=0.0, quadratic=0.0, scale_height=0.0) -> Force:
    """Air drag: ``a = -(k1 + k2 |v|) rho(z) v`` with ``rho = exp(-z / H)`` (1 for ``H = 0``).

    The scenes' terms ``linear-drag`` (``linear`` = k1, 1/s) and ``quadratic-drag``
    (``quadratic`` = k2, 1/m), over an exponential atmosphere of scale height ``H`` (m).
    ``v`` is the velocity relative to the frame: still air turning with it. Under the rotation
    splittings it runs as its exact flow at fixed position (the direction of ``v`` kept, its speed
    decaying in closed form), as the scenes' drag does, not as a kick.

    Examples
    --------
    >>> ax, ay, az = drag(quadratic=0.01).accel(0.0, [0.0, 0.0, 0.0], [3.0, 4.0, 0.0])
    >>> round(ax, 12), round(ay, 12)                    # -k2 |v| v with |v| = 5 m/s
    (-0.15, -0.2)
    """
    _arithmetic()
    k1, k2, H = (si_number("drag", "linear", linear, "1/s"), si_number("drag", "quadratic", quadratic, "1/m"),
                 si_number("drag", "scale_height", scale_height, "m"))
    if k1 < 0 or k2 < 0 or H < 0:
        raise ScenarioError(f"drag: linear={k1!r}, quadratic={k2!r}, scale_height={H!r}; each must be >= 0")
    if k1 == 0.0 and k2 == 0.0:
        raise ScenarioError("drag: give linear=k1 (1/s) or quadratic=k2 (1/m), or both")
    name = "linear-drag" if k2 == 0.0 else "quadratic-drag" if k1 == 0.0 else "linear-drag, quadratic-drag"

    def drag(t, r, v):
        air = _air_density(r[2], H)
        c = _drag_rate(v[0], v[1], v[2], k1 * air, k2 * air)
        return -c * v[0], -c * v[1], -c * v[2]

    # linear in v with a constant coefficient only without the quadratic part, in uniform air
    linear = (_ZERO3, _diagonal(-k1, -k1, -k1), (0.0, 0.0, 0.0)) if k2 == 0.0 and H == 0.0 else ()
    return Force(drag, name=name, flow=("drag", k1, k2, H), takes_params=False, linear=linear)


def spring(k, anchor=(0.0, 0.0, 0.0), *, horizontal=False) -> Force:
    """A linear spring (per unit mass): ``a = -k (r - anchor)``; ``U = k |r - anchor|^2 / 2``.

    ``k`` in 1/s^2 (the spring constant over the mass: the square of the angular frequency).
    With ``horizontal=True`` only x and y are pulled back, ``a = -k (x - x_a, y - y_a, 0)``:
    the scenes' term ``spring``, the small-angle pendulum (``k = g / L``).
    """
    _arithmetic()
    k = si_number("spring", "k", k, "1/s^2")
    ax_, ay_, az_ = si_vector("spring", "anchor", anchor, "m")
    vertical = 0.0 if horizontal else 1.0

    def spring(t, r, v):
        return _spring_pull(r[0] - ax_, r[1] - ay_, vertical * (r[2] - az_), k)

    def potential(t, r):
        dx = r[0] - ax_
        dy = r[1] - ay_
        dz = r[2] - az_
        return 0.5 * k * (dx * dx + dy * dy + vertical * dz * dz)

    return Force(spring, potential=potential, name="spring", takes_params=False, array_potential=True,
                 linear=(_diagonal(-k, -k, -vertical * k), _ZERO3, (k * ax_, k * ay_, vertical * k * az_)))


def pendulum(length, pivot=(0.0, 0.0, 0.0)) -> StringConstraint:
    """The pendulum's string: the particle stays at ``length`` (m) from ``pivot`` (m, frame axes).

    Not a force but a constraint: its tension is whatever keeps the particle on the sphere
    under every other term, the frame's included. The scenes' term ``pendulum``. Start the
    particle on the sphere, with no velocity along the string; add gravity yourself.

    Examples
    --------
    A Foucault pendulum 67 m long at 49 degrees north (ENU axes, the pivot above the origin)::

        lat = np.radians(49.0)
        w = 7.292115e-5 * np.array([0.0, np.cos(lat), np.sin(lat)])
        res = rotframe.simulate(omega=w, r0=[1.0, 0.0, 67.0 - np.sqrt(67.0**2 - 1.0)], v0=[0, 0, 0],
                                duration=600.0, forces=[forces.gravity([0, 0, -9.81]),
                                                        forces.pendulum(67.0, pivot=[0, 0, 67.0])],
                                frame_terms=("coriolis",))  # the local g holds the centrifugal term
    """
    L = si_number("pendulum", "length", length, "m")
    if not L > 0:
        raise ScenarioError(f"pendulum: length={L!r} must be > 0 (m)")
    return StringConstraint(L, si_vector("pendulum", "pivot", pivot, "m"))


def lorentz(q_over_m, B, E=(0.0, 0.0, 0.0)) -> Force:
    """The Lorentz force per unit mass, ``a = (q/m) (E + v x B)``, in uniform fields (the frame's axes).

    ``v`` is relative to the frame: these are the fields of a co-rotating plasma, where the
    corotation electric field cancels ``omega x r``. q/m in C/kg, B in T, E in V/m.
    """
    qm = si_number("lorentz", "q_over_m", q_over_m, "C/kg")
    bx, by, bz = si_vector("lorentz", "B", B, "T")
    ex, ey, ez = si_vector("lorentz", "E", E, "V/m")

    def force(t, r, v):
        return (qm * (ex + v[1] * bz - v[2] * by), qm * (ey + v[2] * bx - v[0] * bz),
                qm * (ez + v[0] * by - v[1] * bx))

    # v x B = C v with C = [[0, bz, -by], [-bz, 0, bx], [by, -bx, 0]]
    C = ((0.0, qm * bz, -qm * by), (-qm * bz, 0.0, qm * bx), (qm * by, -qm * bx, 0.0))
    return Force(force, name="Lorentz force", takes_params=False, linear=(_ZERO3, C, (qm * ex, qm * ey, qm * ez)))
