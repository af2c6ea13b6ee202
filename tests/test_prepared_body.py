"""A prepared body (`rotframe.problem.prepared_body.PreparedBody`) gives ``simulate_body``'s samples to the bit.

Every method, a torque-free body and the heavy top under `rotframe.torques.gravity` beside a
torque of yours with parameters, several start states in a row (the kept arrays reset between
runs), inlined or not; a run that fails raises what ``simulate_body`` raises.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from rotframe import torques
from rotframe.errors import IntegrationError, ScenarioError
from rotframe.problem.body import simulate_rigid_body
from rotframe.problem.callables import UserFunctionError
from rotframe.problem.prepared_body import PreparedBody

Q0 = Rotation.from_euler("xyz", [0.3, 0.2, 0.1]).as_quat()
STARTS = [(np.array([0.3, 1.0, 0.2]), Q0), (np.array([0.1, 0.2, 1.4]), Rotation.from_euler("x", 0.4).as_quat()),
          ([0.3, 1.0, 0.2], list(Q0))]


def _spin_down(t, L, q, c):
    return -c * L[0], -c * L[1], -c * L[2]


CASES = {
    "free, dop853": dict(inertia=[1.0, 2.0, 3.0], method="dop853", rtol=1e-9),
    "free, rk4": dict(inertia=[1.0, 2.0, 3.0], method="rk4", step=0.01),
    "free, lie-poisson4": dict(inertia=[1.0, 2.0, 3.0], method="lie-poisson4", step=0.05),
    "free, lie-poisson8": dict(inertia=[2.0, 2.0, 1.0], method="lie-poisson8", step=0.2),
    "free, exact": dict(inertia=[1.0, 2.0, 3.0], method="exact"),
    "heavy top, top-splitting8": dict(inertia=[2.0, 2.0, 1.0], method="top-splitting8", step=0.05,
                                      torque=torques.gravity(1.0, 0.5, 9.81)),
    "heavy top and yours, dop853": dict(inertia=[2.0, 2.0, 1.0], method="dop853", rtol=1e-10, params=(0.05,),
                                        torque=[torques.gravity(1.0, 0.5, 9.81), _spin_down]),
    "a tensor, rk4": dict(inertia=[[2.0, 0.1, 0.0], [0.1, 1.5, 0.0], [0.0, 0.0, 1.0]], method="rk4", step=0.02),
}


@pytest.mark.parametrize("inline", [True, False])
@pytest.mark.parametrize("case", list(CASES))
def test_a_prepared_body_gives_simulate_bodys_samples_to_the_bit(case, inline):
    args = dict(CASES[case], duration=3.0, samples=15)
    prepared = PreparedBody(L0=STARTS[0][0], q0=STARTS[0][1], inline=inline, **args)
    for L0, q0 in STARTS:
        expected = simulate_rigid_body(L0=L0, q0=q0, **args)
        L, q = prepared.states(L0, q0)
        np.testing.assert_array_equal(L, expected.L)
        np.testing.assert_array_equal(q, expected.q)
        run = prepared.run(L0, q0)
        np.testing.assert_array_equal(run.L, expected.L)
        np.testing.assert_array_equal(run.q, expected.q)
        assert run.diagnostics == expected.diagnostics and run.steps == expected.steps
        assert not np.allclose(L[-1], L[0]) or case.startswith("free, lie-poisson8")  # the body moved


def test_a_prepared_run_that_fails_raises_what_simulate_body_raises():
    def blows_up(t, L, q):
        return 0.0, 0.0, 1.0 / (2.0 - t) ** 40

    def raises(t, L, q):
        if t > 1.0:
            raise ValueError("the thruster failed")
        return 0.0, 0.0, 0.0

    args = dict(inertia=[1.0, 2.0, 3.0], duration=3.0, samples=6, method="rk4", step=0.01)
    for torque, error in ((blows_up, IntegrationError), (raises, UserFunctionError)):
        prepared = PreparedBody(L0=STARTS[0][0], q0=Q0, torque=torque, **args)
        with pytest.raises(error) as expected:
            simulate_rigid_body(L0=STARTS[0][0], q0=Q0, torque=torque, **args)
        with pytest.raises(error) as got:
            prepared.states(*STARTS[0])
        assert str(got.value) == str(expected.value)


@pytest.mark.parametrize("L0, q0, says", [("0.01,2,0", [0, 0, 0, 1], "L0 = '0.01,2,0' is not numbers"),
                                          ([np.nan, 2.0, 0.0], [0, 0, 0, 1], "L0 = [nan, 2.0, 0.0] is not finite"),
                                          ([0.01, 2.0], [0, 0, 0, 1], "L0 has shape (2,)"),
                                          ([0.01, 2.0, 0.0], [0, 0, np.inf, 1], "q0 = [0.0, 0.0, inf, 1.0] is not "
                                                                                 "finite")])
def test_a_start_state_that_is_not_finite_numbers_is_named_in_one_line(L0, q0, says):
    body = PreparedBody(inertia=[1.0, 2.0, 3.0], L0=[0.01, 2.0, 0.0], q0=[0, 0, 0, 1], duration=1.0)
    with pytest.raises(ScenarioError) as err:
        body.run(L0, q0)
    assert str(err.value).startswith(says), str(err.value)
