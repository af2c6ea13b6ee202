"""rotframe.simulate and simulate_body under careless input: refused in one line, or taken as meant."""

from __future__ import annotations

import astropy.units as u
import numpy as np
import pytest

import rotframe
from rotframe.errors import RotframeError


def grav(t, r, v):
    return 0.0, 0.0, -9.81


BASE = dict(omega=[0, 0, 0], r0=[0, 0, 10], v0=[0, 0, 0], duration=1.0, samples=2)

REFUSED = {
    "rtol text": (dict(rtol="abc"), "rtol"),
    "duration text": (dict(duration="x"), "duration"),
    "duration negative": (dict(duration=-1.0), "duration"),
    "duration infinite": (dict(duration=np.inf), "duration"),
    "omega of two": (dict(omega=[0, 0]), "omega"),
    "omega not finite": (dict(omega=[0, np.nan, 0]), "omega"),
    "omega table decreasing": (dict(omega=([0.0, 2.0, 1.0], np.zeros((3, 3)))), "increase"),
    "omega table too short": (dict(omega=([0.0, 0.5], np.zeros((2, 3)))), "omega"),
    "r0 text": (dict(r0="abc"), "r0"),
    "r0 shape": (dict(r0=[[0, 0, 1, 2]]), "r0"),
    "forces a number": (dict(forces=3), "forces"),
    "force not callable": (dict(forces=[3]), "forces[0]"),
    "duration in metres": (dict(duration=1 * u.m), "duration"),
    "method unknown": (dict(method="rk45"), "method"),
    "samples zero": (dict(samples=0), "samples"),
    "samples fractional": (dict(samples=2.5), "samples"),
    "params text": (dict(params=("a",)), "params[0]"),
    "step zero for rk4": (dict(method="rk4", step=0.0), "step"),
    "force wrong shape": (dict(forces=[lambda t, r, v: (0.0, 0.0)]), "forces[0]"),
    "event wrong shape": (dict(events=[lambda t, r, v: (0.0, 1.0)]), "events[0]"),
    "force raises": (dict(forces=[lambda t, r, v: 1 / 0]), "ZeroDivisionError"),
    "origin table decreasing": (dict(origin_acceleration=([1.0, 0.0], np.zeros((2, 3)))), "origin_acceleration"),
    "axes unknown": (dict(forces=[rotframe.Force(grav, axes="body")]), "axes"),
    "omega_dot without callable": (dict(omega_dot=lambda t: (0.0, 0.0, 0.0)), "omega_dot"),
}


@pytest.mark.parametrize("case", sorted(REFUSED))
def test_simulate_refuses_in_one_line(case):
    changes, needle = REFUSED[case]
    with pytest.raises(RotframeError) as info:
        rotframe.simulate(**{**BASE, **changes})
    message = str(info.value)
    assert needle in message
    assert "\n" not in message and len(message) < 600


TAKEN = {
    "a single force, not a list": dict(forces=grav),
    "quantities": dict(omega=[0, 0, 1] * u.deg / u.s, r0=[0, 0, 10] * u.km, v0=[0, 0, 0] * u.m / u.s,
                       duration=1 * u.min, forces=[grav]),
    "one start, two velocities": dict(v0=[[0, 0, 0], [1, 0, 0]], forces=[grav]),
    "method in capitals": dict(method="DOP853", forces=[grav]),
}


@pytest.mark.parametrize("case", sorted(TAKEN))
def test_simulate_takes_what_is_meant(case):
    res = rotframe.simulate(**{**BASE, **TAKEN[case]})
    assert res.trajectory.r.shape[0] == 3 and np.all(np.isfinite(res.trajectory.r))


def test_quantities_are_converted_to_si():
    res = rotframe.simulate(**{**BASE, "r0": [0, 0, 1] * u.km, "duration": 2 * u.s, "forces": [grav]})
    assert res.trajectory.times[-1] == 2.0
    assert res.trajectory.r[0, 0, 2] == 1000.0


BODY = dict(inertia=[1, 2, 3], L0=[1, 0, 0], q0=[0, 0, 0, 1], duration=1.0, samples=2)
BODY_REFUSED = {
    "inertia text": (dict(inertia="x"), "inertia"),
    "inertia negative": (dict(inertia=[1, -2, 3]), "inertia"),
    "inertia not a body": (dict(inertia=[1, 1, 5]), "triangle"),
    "inertia not symmetric": (dict(inertia=[[1, 0.1, 0], [0, 2, 0], [0, 0, 2.5]]), "symmetric"),
    "q0 not unit": (dict(q0=[0, 0, 0, 2]), "q0"),
    "L0 shape": (dict(L0=[1, 0]), "L0"),
    "torque not callable": (dict(torque="x"), "torque"),
    "torque wrong shape": (dict(torque=lambda t, L, q: (0.0,)), "torque"),
    "splitting with a torque": (dict(torque=lambda t, L, q: (0.0, 0.0, 0.0), method="Lie-Poisson"), "Lie-Poisson"),
    "exact with a torque": (dict(torque=lambda t, L, q: (0.0, 0.0, 0.0), method="exact"), "exact"),
    "method unknown": (dict(method="verlet"), "method"),
}


@pytest.mark.parametrize("case", sorted(BODY_REFUSED))
def test_simulate_body_refuses_in_one_line(case):
    changes, needle = BODY_REFUSED[case]
    with pytest.raises(RotframeError) as info:
        rotframe.simulate_body(**{**BODY, **changes})
    assert needle in str(info.value) and "\n" not in str(info.value)
