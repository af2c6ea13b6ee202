"""The built-in events, as the same kind of object as your own (``rotframe.events``).

An event of ``rotframe.simulate`` is a function ``g(t, r, v, *params) -> float`` whose zero
crossings are located (``terminal`` and ``direction`` attributes as in
``scipy.integrate.solve_ivp``). A factory here returns such a function, compiled and located
like yours by every method, that also says what it is, as a built-in force carries its linear
form (`rotframe.forces`): the exact flow of a linear problem (``method="exact"``) locates it on
the flow itself, by the scenes' Newton iteration on ``exp(M t)`` (`rotframe.particles.linear`),
where it locates no function of your own::

    import rotframe
    from rotframe import events, forces

    ground = events.crossing(2, 0.0, direction=-1, terminal=True, name="ground")
    res = rotframe.simulate(omega=[0.0, 4.6e-5, 5.7e-5], r0=[0, 0, 100.0], v0=[0, 0, 0], duration=6.0,
                            forces=[forces.gravity([0, 0, -9.81])], events=[ground], method="exact")
    res.trajectory.event_times["ground"]         # the landing, to round-off

=============================================  =====================================
factory                                        the event function
=============================================  =====================================
``crossing(component, value, of="r")``         ``r[component] - value`` (``of="v"``: ``v[component] - value``)
``altitude(radius, value)``                    ``|r - c| - radius - value``, ``c = (0, 0, -radius)``
=============================================  =====================================

The scenes' ground is ``crossing(2, 0.0, direction=-1, terminal=True, name="ground")`` on flat
ground (``tower-drop``, ``projectile``), ``altitude(R, 0.0, direction=-1, terminal=True,
name="ground")`` on the curved Earth (``projectile`` with its ``curvature`` term), whose surface
is a nonlinear function of the state: the exact flow takes no problem with it.
"""

from __future__ import annotations

import math

from rotframe.errors import ScenarioError
from rotframe.units import si_number

__all__ = ["crossing", "altitude"]


def crossing(component, value=0.0, *, of="r", direction=0, terminal=False, name=None):
    """An event where one coordinate of the state crosses ``value``: ``g = r[component] - value``.

    Parameters
    ----------
    component : int
        0, 1 or 2: the axis of the frame (x, y, z).
    value : float
        The level crossed (m for ``of="r"``, m/s for ``of="v"``).
    of : {"r", "v"}
        The position's coordinate, or the velocity's (``v[component] - value``: an apex where ``v_z``
        crosses 0).
    direction : {-1, 0, 1}
        Falling crossings only, both, or rising only.
    terminal : bool
        The particle stops at its first crossing (samples after it keep the state there).
    name : str, optional
        The event's name in ``Result.trajectory.event_times`` (default ``"x_crossing"``, ``"vz_crossing"``...).

    Returns
    -------
    function
        ``g(t, r, v)`` with the attributes ``terminal``, ``direction`` and ``crossing``, the triple
        ``(of, component, value)`` the exact flow reads.

    Examples
    --------
    >>> ground = crossing(2, 0.0, direction=-1, terminal=True, name="ground")
    >>> ground(0.0, [0.0, 0.0, 3.5], [0.0, 0.0, -1.0]), ground.__name__, ground.crossing
    (3.5, 'ground', ('r', 2, 0.0))
    """
    _check_kind("crossing", direction, terminal, name)
    if isinstance(component, bool) or component not in (0, 1, 2):
        raise ScenarioError(f"crossing: component={component!r}; allowed 0, 1, 2 (x, y, z of the frame)")
    if of not in ("r", "v"):
        raise ScenarioError(f"crossing: of={of!r}; allowed 'r' (a position's coordinate) or 'v' (a velocity's)")
    k, c = int(component), si_number("crossing", "value", value, "m" if of == "r" else "m/s")
    if of == "r":
        def event(t, r, v):
            return r[k] - c
    else:
        def event(t, r, v):
            return v[k] - c
    event.__name__ = event.__qualname__ = name or f"{'' if of == 'r' else 'v'}{'xyz'[k]}_crossing"
    event.terminal = terminal
    event.direction = int(direction)
    event.crossing = (of, k, c)
    return event


def altitude(radius, value=0.0, *, direction=0, terminal=False, name=None):
    """An event where the height above a sphere crosses ``value``: ``g = |r - c| - radius - value``.

    The sphere of ``radius`` R centred at ``c = (0, 0, -R)`` touches the frame's origin: the ground
    of a local frame on a round Earth (the scenes' event kind ``altitude``, the same arithmetic:
    `rotframe.particles.events`). Its value is a nonlinear function of the state, so the exact flow
    takes no problem with it; every other method locates it as an event of yours.

    Parameters
    ----------
    radius : float
        R (m), > 0.
    value : float
        The height crossed (m).
    direction, terminal, name
        As for `crossing` (default name ``"altitude"``).

    Returns
    -------
    function
        ``g(t, r, v)`` with the attributes ``terminal`` and ``direction``.

    Examples
    --------
    >>> ground = altitude(6.371e6, direction=-1, terminal=True, name="ground")
    >>> round(ground(0.0, [0.0, 0.0, 100.0], [0.0, 0.0, 0.0]), 9), ground.__name__
    (100.0, 'ground')
    """
    _check_kind("altitude", direction, terminal, name)
    R, c = si_number("altitude", "radius", radius, "m"), si_number("altitude", "value", value, "m")
    if not R > 0:
        raise ScenarioError(f"altitude: radius={radius!r}; must be > 0 (m)")

    def event(t, r, v):
        dz = r[2] + R
        return math.sqrt(r[0] * r[0] + r[1] * r[1] + dz * dz) - R - c

    event.__name__ = event.__qualname__ = name or "altitude"
    event.terminal = terminal
    event.direction = int(direction)
    return event


def _check_kind(factory, direction, terminal, name):
    """One-line errors for an event's ``direction``, ``terminal`` and ``name``, naming the ``factory``."""
    if isinstance(direction, bool) or direction not in (-1, 0, 1):
        raise ScenarioError(f"{factory}: direction={direction!r}; allowed -1 (falling), 0 (both), 1 (rising)")
    if not isinstance(terminal, bool):
        raise ScenarioError(f"{factory}: terminal={terminal!r}; True or False")
    if name is not None and not (isinstance(name, str) and name.isidentifier()):
        raise ScenarioError(f"{factory}: name={name!r}; a name of letters, digits and _ (not starting with a digit)")
