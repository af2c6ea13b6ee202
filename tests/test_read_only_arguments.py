"""A user function cannot write into the integrator's state (issue 33, class 3).

``r``, ``v``, ``L``, ``q`` and array parameters reach a user function read-only: compiled, numba
refuses a function that writes into one, and the refusal names it; in plain Python the write raises
and is named the same way. The oracle for "the state was not touched" is the free fall's closed
form z(t) = z0 - g t^2 / 2.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

import rotframe
from rotframe.errors import RotframeError

BASE = dict(omega=[0, 0, 0], r0=[0, 0, 10.0], v0=[0, 0, 0], duration=1.0, samples=4)


def pins_z(t, r, v):
    r[2] = 0.0
    return 0.0, 0.0, -9.81


def pins_z_late(t, r, v):
    if t > 0.5:
        r[2] = 0.0
    return 0.0, 0.0, -9.81


def zeroes_v(t, r, v):
    v[:] = 0.0
    return 0.0, 0.0, -9.81


def height_event(t, r, v):
    v[0] = 1.0
    return r[2]


def scales_param(t, r, v, gains):
    gains[0] = 2.0 * gains[0]
    return 0.0, 0.0, -gains[0]


@pytest.mark.parametrize("jit", [True, False], ids=["compiled", "plain"])
@pytest.mark.parametrize("changes, role", [
    (dict(forces=[pins_z]), "forces[0] (pins_z)"),
    (dict(forces=[pins_z_late]), "forces[0] (pins_z_late)"),
    (dict(forces=[zeroes_v]), "forces[0] (zeroes_v)"),
    (dict(forces=[lambda t, r, v: (0.0, 0.0, -9.81)], events=[height_event]), "events[0] (height_event)"),
    (dict(forces=[scales_param], params=(np.array([9.81]),)), "forces[0] (scales_param)"),
], ids=["r at once", "r later", "v", "event", "param array"])
def test_a_write_into_an_argument_is_refused_by_name(changes, role, jit):
    with pytest.raises(RotframeError) as info:
        rotframe.simulate(**{**BASE, **changes}, jit=jit)
    message = str(info.value)
    name, function = role.split(" (")
    assert re.search(re.escape(name) + r" \((\w+\.)?" + re.escape(function), message), message
    assert "writes into" in message, message
    assert "\n" not in message


def test_a_parameter_array_of_the_user_is_not_touched():
    gains = np.array([9.81])

    def fall(t, r, v, g):
        return 0.0, 0.0, -g[0]

    res = rotframe.simulate(**BASE, forces=[fall], params=(gains,))
    assert gains.flags.writeable  # the user's own array: no flag changed, a copy went in
    z = res.trajectory.r[:, 0, 2]
    np.testing.assert_allclose(z, 10.0 - 0.5 * 9.81 * res.trajectory.times ** 2, rtol=1e-12, atol=1e-12)


def test_a_torque_writing_into_its_momentum_is_refused_by_name():
    def damps(t, L, q):
        L[0] = 0.0
        return 0.0, 0.0, 0.0

    for jit in (True, False):
        with pytest.raises(RotframeError, match=r"torque \(.*damps\) writes into"):
            rotframe.simulate_body(inertia=[1, 2, 3], L0=[1, 0, 0], q0=[0, 0, 0, 1], duration=1.0, torque=damps,
                                   samples=2, jit=jit)


def test_reading_functions_still_compile_on_read_only_arrays():
    def many_reads(t, r, v):
        n = np.linalg.norm(r) + np.dot(r, v) + np.cross(r, v)[0] + np.sum(r * r) + (r @ v)
        w = r.copy()
        w[2] = 0.0  # a copy is the function's own
        return 0.0 * n, 0.0 * w[0], -9.81

    res = rotframe.simulate(**BASE, forces=[many_reads])
    z = res.trajectory.r[:, 0, 2]
    np.testing.assert_allclose(z, 10.0 - 0.5 * 9.81 * res.trajectory.times ** 2, rtol=1e-12, atol=1e-12)
