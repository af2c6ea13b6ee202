"""Every input of the Python doors that takes a Quantity takes it everywhere (issue 33, class 2).

Tables, origin accelerations, atol and params convert too; a Quantity that reaches the core, or
a function that returns one, is refused in one line; a unit is never dropped. The oracle is the
same problem written by hand in SI (100 ms = 0.1 s, 1 deg/s = pi/180 rad/s), not astropy.
"""

from __future__ import annotations

import math

import astropy.units as u
import numpy as np
import pytest

import rotframe
from rotframe.errors import RotframeError

DEG = math.pi / 180.0


def spring(t, r, v, k):
    return -k * r[0], -k * r[1], -k * r[2]


def push(t, r, v, speed):
    return speed, 0.0, 0.0


def test_an_omega_table_in_ms_and_deg_per_s_is_the_table_in_seconds_and_radians():
    times_ms = np.array([0.0, 500.0, 1000.0, 1500.0, 2000.0])
    rates_deg = np.array([[0, 0, 10], [0, 0, 12], [0, 5, 15], [0, 0, 11], [1, 0, 10.0]])
    base = dict(r0=[1.0, 0, 0], v0=[0, 0.5, 0], duration=2.0, samples=4)
    with_units = rotframe.simulate(omega=(times_ms * u.ms, rates_deg * u.deg / u.s), **base)
    by_hand = rotframe.simulate(omega=(times_ms / 1000.0, rates_deg * DEG), **base)
    np.testing.assert_array_equal(with_units.trajectory.r, by_hand.trajectory.r)
    bare = rotframe.simulate(omega=(times_ms / 1000.0, rates_deg), **base)  # the numbers, unit dropped
    assert not np.allclose(bare.trajectory.r, by_hand.trajectory.r, atol=1e-3)


def test_an_origin_acceleration_table_and_vectors_of_quantities_convert():
    base = dict(omega=[0, 0, 0], duration=1.0, samples=2)
    with_units = rotframe.simulate(r0=[1 * u.km, 0 * u.m, 2 * u.cm], v0=[0, 0, 0] * u.km / u.h,
                                   origin_acceleration=([0, 0.5, 1] * u.s, [[0, 0, 1], [0, 0, 2], [0, 0, 3]] * u.cm
                                                        / u.s ** 2), **base)
    by_hand = rotframe.simulate(r0=[1000.0, 0, 0.02], v0=[0, 0, 0],
                                origin_acceleration=([0, 0.5, 1], [[0, 0, 0.01], [0, 0, 0.02], [0, 0, 0.03]]), **base)
    np.testing.assert_array_equal(with_units.trajectory.r, by_hand.trajectory.r)


def test_params_and_atol_convert_to_si():
    base = dict(omega=[0, 0, 0], r0=[0, 0, 0], v0=[0, 0, 0], duration=1.0, samples=2, forces=[push])
    with_units = rotframe.simulate(params=(36 * u.km / u.h,), atol=[1 * u.mm] * 3 + [1 * u.mm / u.s] * 3, **base)
    by_hand = rotframe.simulate(params=(10.0,), atol=[1e-3] * 6, **base)
    np.testing.assert_array_equal(with_units.trajectory.r, by_hand.trajectory.r)
    assert with_units.trajectory.r[-1, 0, 0] == pytest.approx(5.0, rel=1e-9)  # a = 10 m/s^2 for 1 s


def test_body_inputs_convert():
    with_units = rotframe.simulate_body(inertia=[1, 2, 3] * u.kg * u.cm ** 2, L0=[0, 0, 1] * u.g * u.m ** 2 / u.s,
                                        q0=[0, 0, 0, 1] * u.one, duration=500 * u.ms, samples=2)
    by_hand = rotframe.simulate_body(inertia=[1e-4, 2e-4, 3e-4], L0=[0, 0, 1e-3], q0=[0, 0, 0, 1], duration=0.5,
                                     samples=2)
    np.testing.assert_allclose(with_units.trajectory.q, by_hand.trajectory.q, rtol=1e-13, atol=1e-15)  # cm^2 -> m^2


REFUSED = {
    "table times in metres": dict(omega=([0, 1, 2] * u.m, np.zeros((3, 3)))),
    "table rates in kg": dict(omega=([0, 1, 2], np.ones((3, 3)) * u.kg)),
    "one atol Quantity": dict(atol=1 * u.mm),
    "params in kelvin per metre mixed with rates": dict(params=(1 * u.K,), forces=[spring], omega=[0, 0, 1 * u.kg]),
}


@pytest.mark.parametrize("case", sorted(REFUSED))
def test_a_quantity_that_cannot_convert_is_refused_in_one_line(case):
    args = dict(omega=[0, 0, 0], r0=[1, 0, 0], v0=[0, 0, 0], duration=1.0, samples=2)
    args.update(REFUSED[case])
    with pytest.raises(RotframeError) as info:
        rotframe.simulate(**args)
    assert "\n" not in str(info.value) and len(str(info.value)) < 400


def test_the_core_refuses_a_quantity_it_would_strip():
    from rotframe.problem.particles import simulate_particles

    with pytest.raises(RotframeError, match="Quantity"):
        simulate_particles(omega=([0, 100, 200] * u.ms, np.zeros((3, 3))), r0=[1, 0, 0], v0=[0, 0, 0], duration=0.1)
    with pytest.raises(RotframeError, match="Quantity"):
        simulate_particles(omega=[0, 0, 0], r0=[1, 0, 0] * u.km, v0=[0, 0, 0], duration=0.1)


def test_a_function_returning_a_quantity_is_refused_by_name():
    def omega(t):
        return [0, 0, 1] * u.deg / u.s

    with pytest.raises(RotframeError, match=r"omega .*Quantity"):
        rotframe.simulate(omega=omega, r0=[1, 0, 0], v0=[0, 0, 0], duration=1.0, samples=2, jit=False)


# the built-in terms' and torques' factories: (factory, its Quantity arguments, the same in SI by hand, a point to
# evaluate at (t, r, v) or (t, L, q))
_R, _V = np.array([1.0, 2.0, 3.0]), np.array([0.1, 0.2, 0.3])
_L, _Q = np.array([1.0, 0.0, 0.0]), np.array([0.3, 0.1, 0.2, math.sqrt(1 - 0.14)])
FACTORIES = [
    ("gravity", lambda: rotframe.forces.gravity([0, 0, -980] * u.cm / u.s**2),
     lambda: rotframe.forces.gravity([0.0, 0.0, -9.8])),
    ("altitude_gravity", lambda: rotframe.forces.altitude_gravity(980 * u.cm / u.s**2, 6371 * u.km),
     lambda: rotframe.forces.altitude_gravity(9.8, 6.371e6)),
    ("central_gravity", lambda: rotframe.forces.central_gravity(3.986e5 * u.km**3 / u.s**2, [0, 0, -6371] * u.km),
     lambda: rotframe.forces.central_gravity(3.986e14, [0.0, 0.0, -6.371e6])),
    ("drag", lambda: rotframe.forces.drag(linear=6 / u.min, quadratic=0.02 / u.km, scale_height=8 * u.km),
     lambda: rotframe.forces.drag(linear=0.1, quadratic=2e-5, scale_height=8000.0)),
    ("spring", lambda: rotframe.forces.spring(4 * u.Hz**2, [100, 0, 0] * u.cm),
     lambda: rotframe.forces.spring(4.0, [1.0, 0.0, 0.0])),
    ("lorentz", lambda: rotframe.forces.lorentz(1 * u.mC / u.g, [0, 0, 1000] * u.mT, [0, 1, 0] * u.kV / u.km),
     lambda: rotframe.forces.lorentz(1.0, [0.0, 0.0, 1.0], [0.0, 1.0, 0.0])),
    ("torques.gravity", lambda: rotframe.torques.gravity(2000 * u.g, 3 * u.cm, 980 * u.cm / u.s**2),
     lambda: rotframe.torques.gravity(2.0, 0.03, 9.8)),
    ("torques.body_fixed", lambda: rotframe.torques.body_fixed([1, 2, 3] * u.mN * u.m),
     lambda: rotframe.torques.body_fixed([1e-3, 2e-3, 3e-3])),
    ("torques.space_fixed", lambda: rotframe.torques.space_fixed([1, 2, 3] * u.mN * u.m),
     lambda: rotframe.torques.space_fixed([1e-3, 2e-3, 3e-3])),
]


@pytest.mark.parametrize("name, with_units, by_hand", FACTORIES, ids=[f[0] for f in FACTORIES])
def test_the_factories_convert_quantities(name, with_units, by_hand):
    a, b = with_units(), by_hand()
    point = (0.0, _L, _Q) if name.startswith("torques") else (0.0, _R, _V)
    np.testing.assert_allclose(np.array(a(*point), dtype=float), np.array(b(*point), dtype=float), rtol=1e-12,
                               atol=1e-300)


def test_the_pendulums_length_and_pivot_convert():
    c = rotframe.forces.pendulum(6700 * u.cm, [0, 0, 0.067] * u.km)
    assert c.length == pytest.approx(67.0, rel=1e-15) and np.allclose(c.pivot, [0.0, 0.0, 67.0], rtol=1e-15)


@pytest.mark.parametrize("call, key", [
    (lambda: rotframe.forces.gravity([0, 0, -9.8] * u.km), "gravity: g: km cannot be converted to m/s^2"),
    (lambda: rotframe.forces.spring(4 * u.m), "spring: k: m cannot be converted to 1/s^2"),
    (lambda: rotframe.forces.pendulum(67 * u.s), "pendulum: length: s cannot be converted to m"),
    (lambda: rotframe.torques.body_fixed([1, 2, 3] * u.m), "body_fixed: tau: m cannot be converted to N m"),
    (lambda: rotframe.torques.gravity(2 * u.m, 0.03, 9.8), "gravity: mass: m cannot be converted to kg"),
    (lambda: rotframe.forces.spring("4"), "spring: k='4' is not a number"),
    (lambda: rotframe.forces.pendulum(True), "pendulum: length=True is not a number"),
    (lambda: rotframe.torques.gravity([1, 2] * u.kg, 0.03, 9.8), "gravity: mass=<Quantity [1., 2.] kg> is not a"),
    (lambda: rotframe.forces.drag(linear=1 + 2j), "drag: linear=(1+2j) is not a number"),
    (lambda: rotframe.forces.central_gravity(float("inf"), [0, 0, 0]), "central_gravity: gm=inf is not finite"),
])
def test_a_factory_refuses_a_wrong_unit_a_string_or_a_bool_in_one_line(call, key):
    with pytest.raises(RotframeError) as err:
        call()
    assert str(err.value).startswith(key) and "\n" not in str(err.value), str(err.value)


def test_the_built_in_events_convert_quantities():
    """`rotframe.events`' values and radius: a Quantity is converted (cm, km/h, km), a wrong unit refused."""
    r, v = np.array([0.3, 0.2, 2.0]), np.array([0.0, 0.0, 2.0])
    assert rotframe.events.crossing(2, 100 * u.cm)(0.0, r, v) == rotframe.events.crossing(2, 1.0)(0.0, r, v)
    assert (rotframe.events.crossing(2, 7.2 * u.km / u.h, of="v")(0.0, r, v)
            == rotframe.events.crossing(2, 2.0, of="v")(0.0, r, v))
    assert (rotframe.events.altitude(6371 * u.km, 100 * u.cm)(0.0, r, v)
            == rotframe.events.altitude(6.371e6, 1.0)(0.0, r, v))
    with pytest.raises(RotframeError, match=r"^crossing: value: s cannot be converted to m/s"):
        rotframe.events.crossing(2, 1 * u.s, of="v")
