"""The cr3bp scene against independent references: Lagrange points, Jacobi constant, Routh's criterion.

Oracles written here, apart from the scene's code: the collinear points by mpmath's root finder on
the effective potential's gradient at 30 digits; L4 from the equilateral triangle; the Jacobi
constant C = 2 Omega - v^2 evaluated on the samples; the linear stability of L4 from the
eigenvalues of the linearised equations (the characteristic polynomial
lambda^4 + lambda^2 + 27 mu (1 - mu) / 4 = 0, Szebehely 1967, section 5.5).
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest

import rotframe

MU_EARTH_MOON = 0.01215058560962404


def _collinear_mpmath(mu):
    mpmath.mp.dps = 30
    m = mpmath.mpf(mu)

    def dOmega(x):  # d/dx of (x^2)/2 + (1-mu)/|x+mu| + mu/|x-1+mu| on the axis
        return x - (1 - m) * (x + m) / abs(x + m) ** 3 - m * (x - 1 + m) / abs(x - 1 + m) ** 3

    L1 = mpmath.findroot(dOmega, (-m + mpmath.mpf("1e-6"), 1 - m - mpmath.mpf("1e-6")), solver="anderson")
    L2 = mpmath.findroot(dOmega, (1 - m + mpmath.mpf("1e-6"), 2), solver="anderson")
    L3 = mpmath.findroot(dOmega, (-2, -m - mpmath.mpf("1e-6")), solver="anderson")
    mpmath.mp.dps = 15
    return float(L1), float(L2), float(L3)


@pytest.mark.parametrize("mu", [MU_EARTH_MOON, 0.001, 0.3])
def test_lagrange_points_match_mpmath(mu):
    from rotframe.scenes.cr3bp import lagrange_points

    pts = lagrange_points(mu)
    ref = _collinear_mpmath(mu)
    for k in range(3):
        assert abs(pts[k, 0] - ref[k]) < 1e-13
    assert np.allclose(pts[3], [0.5 - mu, math.sqrt(3) / 2, 0.0], rtol=0, atol=1e-15)
    # L4 is equidistant (distance 1) from both primaries
    assert abs(np.linalg.norm(pts[3] - [-mu, 0, 0]) - 1) < 1e-15
    assert abs(np.linalg.norm(pts[3] - [1 - mu, 0, 0]) - 1) < 1e-15


def _jacobi(r, v, mu):
    x, y, z = r[:, 0], r[:, 1], r[:, 2]
    r1 = np.sqrt((x + mu) ** 2 + y ** 2 + z ** 2)
    r2 = np.sqrt((x - 1 + mu) ** 2 + y ** 2 + z ** 2)
    return (x * x + y * y) + 2 * (1 - mu) / r1 + 2 * mu / r2 - np.sum(v * v, axis=1)


def test_default_run_conserves_the_jacobi_constant_to_1e_12_over_100_periods():
    res = rotframe.run("cr3bp")
    assert res.params["periods"] == 100
    assert res.diagnostics["jacobi_rel_drift"] <= 1e-12
    C = _jacobi(res.trajectory.r[:, 0], res.trajectory.v[:, 0], res.params["mu"])
    assert np.max(np.abs(C - C[0])) / abs(C[0]) <= 1e-12
    assert abs(res.diagnostics["jacobi_constant"] - C[0]) < 1e-14 * abs(C[0])
    assert not res.warnings
    for k in ("L1_x", "L2_x", "L3_x"):
        assert abs(res.metrics[k] - res.theory[k]) < 1e-12


def _l4_linearly_stable(mu):
    # lambda^2 = s solves s^2 + s + 27 mu (1 - mu) / 4 = 0: stable when both roots are real and negative
    disc = 1 - 27 * mu * (1 - mu)
    return disc >= 0


@pytest.mark.parametrize("mu", [0.01, 0.03, 0.045, 0.1])
def test_tadpole_near_L4_follows_routh(mu):
    routh = 0.5 * (1 - math.sqrt(23 / 27))
    assert _l4_linearly_stable(mu) == (mu < routh)
    res = rotframe.run("cr3bp", mu=mu, offset="0.005,0,0", periods=60, samples=1500)
    L4 = np.array([0.5 - mu, math.sqrt(3) / 2, 0.0])
    far = np.max(np.linalg.norm(res.trajectory.r[:, 0] - L4, axis=1))
    if mu < routh:
        assert far < 0.3, f"mu={mu}: the orbit went {far:.3g} from L4 although Routh says stable"
    else:
        assert far > 0.5, f"mu={mu}: the orbit stayed within {far:.3g} of L4 although Routh says unstable"
    assert res.metrics["left_L4"] == (0.0 if mu < routh else 1.0)


def test_zero_velocity_curve_lies_on_the_jacobi_level():
    from rotframe.scenes.cr3bp import zero_velocity_curve

    mu, C = MU_EARTH_MOON, 3.1
    segs = zero_velocity_curve(mu, C, extent=1.5, n=301)
    assert len(segs) > 100
    pts = segs.reshape(-1, 3)
    v0 = np.zeros_like(pts)
    # linear interpolation on a grid of spacing 0.01: the level is met to the grid's second order (measured 1.4e-4)
    assert np.max(np.abs(_jacobi(pts, v0, mu) - C)) < 1e-3


def test_recording_draws_the_zero_velocity_curve(tmp_path):
    res = rotframe.run("cr3bp", periods=2, samples=200)
    path = res.record(tmp_path / "cr3bp.rrd")
    from rerun.chunk import RrdReader

    entities = {str(chunk.entity_path) for chunk in RrdReader(str(path)).stream()}
    assert any("zero_velocity_curve" in e for e in entities), entities
