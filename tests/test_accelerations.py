"""Each built-in term's arithmetic (`rotframe.particles.accelerations`) against an independent formula.

The scenes' kernels and the built-in terms of your own problems (`rotframe.forces`) both call these
functions, so the tests that compare those two routes no longer check a term's formula: these do.
The oracles are numpy's vector algebra (``np.cross``, ``np.linalg.norm``) and mpmath at 50 digits,
written from the physics (docs/physics/rotating-frames.md), not from the functions' own algebra:

- the gravities: the inverse-square law, ``-GM d / |d|^3`` and ``-g0 R^2 / (R + z)^2``;
- drag: ``-(k1 + k2 |v|) exp(-z / H) v``;
- the frame's terms, about a fixed axis (``w = w u``) and for any vector omega: ``-w x (w x r)``,
  ``-2 w x v`` and ``-w' x r``;
- a spring: ``-k (r - anchor)``;
- the pendulum's tension: what the constraint ``|r - p| = L`` demands of the constrained
  acceleration ``a'``: its part along the string is the centripetal ``-|v_t|^2 / L``, its part across
  the string is that of ``a``.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from rotframe.particles import accelerations as acc

mpmath.mp.dps = 50

# zero or of physical size: squares of 1e-266 underflow in the oracles' norms, not in the physics
finite = st.one_of(st.just(0.0), st.floats(1e-6, 1e3), st.floats(-1e3, -1e-6))
vec = st.tuples(finite, finite, finite)
positive = st.floats(1e-3, 1e3)


def _close(a, b, rel=1e-13):
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    scale = max(float(np.max(np.abs(b))), 1e-300)
    return float(np.max(np.abs(a - b))) <= rel * scale


@given(z=st.floats(-1e5, 1e6), g0=positive, R=st.floats(6e5, 1e7))
@settings(max_examples=60, deadline=None)
def test_altitude_gravity_is_the_inverse_square_law_along_the_vertical(z, g0, R):
    exact = -mpmath.mpf(g0) * mpmath.mpf(R) ** 2 / (mpmath.mpf(R) + mpmath.mpf(z)) ** 2
    assert math.isclose(acc.altitude_gravity(z, g0, R), float(exact), rel_tol=1e-14)


@given(d=vec, gm=st.floats(1.0, 4e14))
@settings(max_examples=60, deadline=None)
def test_central_gravity_pulls_towards_the_mass_as_the_inverse_square(d, gm):
    d = np.array(d)
    r = np.linalg.norm(d)
    if r < 1e-3:
        return
    got = np.array(acc.central_gravity(d[0], d[1], d[2], gm))
    assert _close(got, -gm * d / r**3)
    assert math.isclose(np.linalg.norm(got), gm / r**2, rel_tol=1e-13)  # |a| = GM / r^2
    assert float(np.dot(got, d)) < 0.0  # towards the mass


@given(z=st.floats(-1e4, 1e5), H=st.floats(0.0, 1e4))
@settings(max_examples=40, deadline=None)
def test_air_density_is_the_exponential_atmosphere(z, H):
    expected = 1.0 if H == 0.0 else float(mpmath.exp(-mpmath.mpf(z) / mpmath.mpf(H)))
    # the rounding of z / H, times its size: exp's condition number
    assert math.isclose(acc.air_density(z, H), expected, rel_tol=1e-14 * (1.0 + (abs(z / H) if H else 0.0)))


@given(v=vec, k1=st.floats(0.0, 1.0), k2=st.floats(0.0, 1.0), z=st.floats(0.0, 2e4), H=st.floats(0.0, 1e4))
@settings(max_examples=60, deadline=None)
def test_drag_opposes_the_velocity_with_the_linear_and_quadratic_laws(v, k1, k2, z, H):
    v = np.array(v)
    air = math.exp(-z / H) if H > 0 else 1.0
    rate = acc.drag_rate(v[0], v[1], v[2], k1 * acc.air_density(z, H), k2 * acc.air_density(z, H))
    expected = (k1 + k2 * np.linalg.norm(v)) * air
    assert math.isclose(rate, expected, rel_tol=1e-13, abs_tol=1e-300)
    assert rate >= 0.0  # -rate v opposes v


@given(r=vec, axis=vec, w=st.floats(-1e-2, 1e-2))
@settings(max_examples=60, deadline=None)
def test_the_coriolis_term_about_a_fixed_axis_is_the_cross_product(r, axis, w):
    u = np.array(axis)
    n = np.linalg.norm(u)
    if n < 1e-3:
        return
    u = u / n
    r = np.array(r)
    omega = w * u
    v = r[::-1].copy()  # any velocity
    coriolis = np.array(acc.coriolis_about_axis(v[0], v[1], v[2], u[0], u[1], u[2], w))
    expected = 2.0 * np.cross(omega, v)  # the Coriolis acceleration is minus this
    assert np.max(np.abs(coriolis - expected)) <= 1e-13 * abs(w) * max(np.linalg.norm(v), 1e-300) + 1e-300


@given(r=vec, w=vec, wd=vec)
@settings(max_examples=60, deadline=None)
def test_the_frame_terms_for_any_omega_are_the_cross_products(r, w, wd):
    r, w, wd = np.array(r), np.array(w) * 1e-3, np.array(wd) * 1e-6
    tol = 1e-13 * (1.0 + np.linalg.norm(w)) ** 2 * max(np.linalg.norm(r), 1e-300) + 1e-300
    assert np.max(np.abs(np.array(acc.centrifugal(*r, *w)) + np.cross(w, np.cross(w, r)))) <= tol
    assert np.max(np.abs(np.array(acc.euler(*r, *wd)) - np.cross(wd, r))) <= tol
    v = r[::-1].copy()  # any velocity; the Coriolis acceleration is minus this
    assert np.max(np.abs(np.array(acc.coriolis(*v, *w)) - 2.0 * np.cross(w, v))) <= tol


@given(r=vec, axis=vec, wd=st.floats(-1e-3, 1e-3), k=st.floats(0.0, 1e2))
@settings(max_examples=40, deadline=None)
def test_the_euler_term_about_an_axis_and_the_spring(r, axis, wd, k):
    u = np.array(axis)
    if np.linalg.norm(u) < 1e-3:
        return
    u = u / np.linalg.norm(u)
    r = np.array(r)
    got = np.array(acc.euler_about_axis(*r, *u, wd))
    assert np.max(np.abs(got - np.cross(wd * u, r))) <= 1e-13 * abs(wd) * max(np.linalg.norm(r), 1e-300) + 1e-300
    assert np.array_equal(np.array(acc.spring_pull(*r, k)), -k * r)  # one product each: exact to the bit


@given(a=vec, direction=vec, v_seed=vec, pivot=vec, L=st.floats(0.1, 100.0))
@settings(max_examples=80, deadline=None)
def test_the_string_tension_keeps_the_particle_on_its_sphere(a, direction, v_seed, pivot, L):
    n = np.array(direction)
    if np.linalg.norm(n) < 1e-3:
        return
    n = n / np.linalg.norm(n)
    p = np.array(pivot)
    r = p + L * n
    v = np.array(v_seed)
    v = v - np.dot(v, n) * n  # a state on the sphere moves across the string
    a = np.array(a)
    got = np.array(acc.string_tension(a[0], a[1], a[2], r[0], r[1], r[2], v[0], v[1], v[2], p[0], p[1], p[2], L))
    n_exact = (r - p) / L  # as the function forms it: |n_exact| = 1 to the round-off of r - p, eps |p| / L
    scale = max(np.linalg.norm(a), np.dot(v, v) / L, 1e-300) * (1.0 + np.linalg.norm(p) / L)
    # along the string: the centripetal acceleration of a circle of radius L (d2/dt2 |r - p|^2 = 0), from the
    # velocity across the string (v's own, but for what round-off left along it)
    v_across = v - np.dot(v, n_exact) * n_exact
    assert abs(np.dot(got, n_exact) + np.dot(v_across, v_across) / L) <= 1e-12 * scale
    # across it: what the other forces give
    across = got - np.dot(got, n_exact) * n_exact
    assert np.max(np.abs(across - (a - np.dot(a, n_exact) * n_exact))) <= 1e-12 * scale
