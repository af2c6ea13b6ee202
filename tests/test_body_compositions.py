"""The engine's splittings of a rigid body are the rigid scenes' own step, and its compositions keep their orders.

* `rotframe.simulate_body` under ``lie-poisson``, ``lie-poisson4/6/8`` and ``top-splitting``,
  ``top-splitting4/6/8`` gives the numbers of the rigid scenes' kernels (`rotframe.rigid.dynamics.lie_poisson`,
  `heavy_top_splitting`) to the bit: a free asymmetric body, a free symmetric one, the heavy top under
  `rotframe.torques.gravity`, whether the run begins in the plain tier or compiled. One step, written
  once (`rotframe.rigid.kernels.free_step`), and Kahan & Li's compositions of it.
* Against the closed-form free flow (`rotframe.rigid.free_body.free_body_closed_form`, elliptic
  functions, round-off accurate): the orders 6 and 8 of the compositions (errors at h and h/2 in the
  ratios 64 and 256), and a symmetric body's free flow exact at any step.
* ``top-splitting`` on a body with three different moments is refused by name.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import rotframe
from rotframe import torques
from rotframe.errors import ScenarioError
from rotframe.problem.body import simulate_rigid_body
from rotframe.rigid import dynamics as rigid
from rotframe.rigid.free_body import free_body_closed_form

Q0 = Rotation.from_euler("xyz", [0.3, 0.2, 0.1]).as_quat()
ASYMMETRIC = dict(inertia=np.array([1.0, 2.0, 3.0]), L0=np.array([0.3, 1.0, 0.2]))
SYMMETRIC = dict(inertia=np.array([2.0, 2.0, 1.0]), L0=np.array([0.3, 0.1, 1.5]))
TOP = dict(i1=0.02, i3=0.01, mass=0.5, length=0.04, g=9.81, L0=np.array([0.001, 0.0, 0.4]))


def _engine(inertia, L0, method, h, n, every, torque=None, plain_tier=True):
    return simulate_rigid_body(inertia=inertia, L0=L0, q0=Q0, duration=h * n, method=method, step=h,
                               samples=n // every, torque=torque, plain_tier=plain_tier)


@pytest.mark.parametrize("plain_tier", [True, False])
@pytest.mark.parametrize("order", [2, 4, 6, 8])
def test_the_free_bodys_splittings_are_the_scenes_to_the_bit(order, plain_tier):
    method = "lie-poisson" + ("" if order == 2 else str(order))
    for body in (ASYMMETRIC, SYMMETRIC):
        L, q, _ = rigid.lie_poisson(body["inertia"], body["L0"], Q0, 0.01, 400, order=order, sample_every=40)
        run = _engine(body["inertia"], body["L0"], method, 0.01, 400, 40, plain_tier=plain_tier)
        np.testing.assert_array_equal(run.L, L)
        np.testing.assert_array_equal(run.q, q)


@pytest.mark.parametrize("plain_tier", [True, False])
@pytest.mark.parametrize("order", [2, 4, 6, 8])
def test_the_heavy_tops_splittings_are_the_scenes_to_the_bit(order, plain_tier):
    method = "top-splitting" + ("" if order == 2 else str(order))
    t = TOP
    L, q, _ = rigid.heavy_top_splitting(t["i1"], t["i3"], t["mass"], t["length"], t["g"], t["L0"], Q0, 1e-3, 500,
                                        order=order, sample_every=50)
    run = _engine([t["i1"], t["i1"], t["i3"]], t["L0"], method, 1e-3, 500, 50,
                  torque=torques.gravity(t["mass"], t["length"], t["g"]), plain_tier=plain_tier)
    np.testing.assert_array_equal(run.L, L)
    np.testing.assert_array_equal(run.q, q)
    assert np.ptp(run.L[:, 0]) > 1e-6  # gravity turned the momentum: the kicks are compared, not skipped


def _error(run, inertia, L0):
    L, q = free_body_closed_form(np.asarray(inertia, float), L0, Q0, run.times[-1:])
    angle = (Rotation.from_quat(run.q[-1]) * Rotation.from_quat(q[-1]).inv()).magnitude()
    return max(float(np.linalg.norm(run.L[-1] - L[-1])), float(angle))


@pytest.mark.parametrize("method, order, h", [("lie-poisson6", 6, 0.4), ("lie-poisson8", 8, 1.0)])
def test_the_compositions_keep_their_order_against_the_closed_form(method, order, h):
    body = ASYMMETRIC
    errors = [_error(_engine(body["inertia"], body["L0"], method, step, round(10.0 / step), round(10.0 / step)),
                     body["inertia"], body["L0"]) for step in (h, h / 2)]
    observed = np.log2(errors[0] / errors[1])
    assert errors[1] > 1e-12 and abs(observed - order) < 0.3, (errors, observed)


def test_a_symmetric_bodys_free_flow_is_exact_at_any_step():
    body = SYMMETRIC
    run = _engine(body["inertia"], body["L0"], "lie-poisson", 0.5, 40, 40)
    assert _error(run, body["inertia"], body["L0"]) < 1e-12


def test_a_top_splitting_needs_a_symmetric_body():
    with pytest.raises(ScenarioError, match=r"top-splitting4.*two of the principal moments.*must be equal"):
        rotframe.simulate_body(inertia=[1.0, 2.0, 3.0], L0=[0.1, 1.0, 0.1], q0=Q0, duration=1.0, step=0.01,
                               method="top-splitting4")
