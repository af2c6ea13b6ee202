"""A rigid body's run at the edges of float64 and of the work limits: refused at once with its reason, or run right.

The classes (each tried over its whole range, not one example):

- a free body that spins too fast for the step limit under DOP853 is a LimitError before it runs
  (a lower bound of its steps: its attitude must turn, and a step follows at most DOP853's
  stability interval of it), where it used to collapse its first step or overflow (an
  IntegrationError that said nothing of the cause);
- ``L x omega`` outside float64's working range (subnormal: L would not move and the drifts
  would read 0; or overflowing) is a ScenarioError naming L0 under DOP853 and RK4, which step
  that product; the exact flow and the splittings take any L0;
- a time scale far from 1 s (the steps grow from DOP853's short first one) runs to its end
  instead of being refused by a pace projected from its first steps;
- the drifts of a huge momentum are measured (relative numbers, computed in scaled units), not NaN;
- an over-limit adaptive run names its method, as a fixed-step one does.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rotframe import limits
from rotframe.errors import ScenarioError
from rotframe.limits import LimitError
from rotframe.problem.body import simulate_rigid_body
from rotframe.problem.body_checks import DOP853_IMAGINARY_STABILITY, check_turns

INERTIA = [1.0, 2.0, 3.0]
SYMMETRIC = [2.0, 2.0, 3.0]
Q0 = [0.0, 0.0, 0.0, 1.0]


def _run(scale, method="dop853", duration=None, **kw):
    L0 = np.array([1.0, 0.1, 0.01]) * scale
    return simulate_rigid_body(inertia=SYMMETRIC if method.startswith("top") else INERTIA, L0=L0, q0=Q0, duration=10.0 / scale if duration is None else duration,
                               method=method, **kw)


def test_the_stability_interval_is_dop853s():
    """|R(iy)| <= 1 up to the constant and > 1 just past it, R the stability function of DOP853's order-8 weights
    (Hairer's tableau as numpy reads it, solved here, not by the integrator)."""
    from rotframe.numerics.dop853_dense import extended_tableau

    A = np.array(extended_tableau()[0], dtype=float)
    a, b = A[:12, :12], A[12, :12]

    def gain(y):
        z = 1j * y
        return abs(1 + z * b @ np.linalg.solve(np.eye(12) - z * a, np.ones(12)))

    assert all(gain(y) <= 1 + 1e-9 for y in np.linspace(0.0, DOP853_IMAGINARY_STABILITY, 400))
    assert gain(DOP853_IMAGINARY_STABILITY + 0.01) > 1.0


@pytest.mark.parametrize("rtol", [1e-1, 1e-4, 1e-9])
@pytest.mark.parametrize("L0, inertia", [([3.0, 0.01, 0.001], [1.0, 2.0, 3.0]), ([0.01, 0.02, 3.0], [1.0, 2.0, 3.0]),
                                         ([1.0, 1.0, 1.0], [2.0, 2.0, 1.0]), ([0.0, 2.0, 0.01], [1.0, 2.0, 3.0])])
def test_the_lower_bound_of_the_steps_holds(L0, inertia, rtol):
    """The refusal's bound, duration |L| / (2 I_max 5.96), is below the steps DOP853 takes (fast and slow axes,
    a symmetric body, the intermediate axis; loose to tight tolerances)."""
    duration = 300.0
    run = simulate_rigid_body(inertia=inertia, L0=L0, q0=Q0, duration=duration, method="dop853", rtol=rtol)
    bound = duration * np.linalg.norm(L0) / max(inertia) / 2.0 / DOP853_IMAGINARY_STABILITY
    assert run.steps >= bound


@pytest.mark.parametrize("scale", [1e10, 1e50, 1e140])
def test_a_spin_too_fast_for_the_limits_is_refused_before_it_runs(scale):
    with pytest.raises(LimitError, match=r"^method dop853 \(the attitude turns .*over the limit") as err:
        _run(scale, duration=10.0)
    assert "shorten duration" in str(err.value) and "enlarge step" not in str(err.value)
    with limits.applied(limits.Limits(max_steps=1e300)):  # under a higher limit it is not refused by the bound
        from rotframe.problem.body import body_set_up

        check_turns(body_set_up(inertia=INERTIA, L0=np.array([1.0, 0.1, 0.01]) * scale, q0=Q0, duration=10.0))


@pytest.mark.parametrize("method", ["dop853", "rk4"])
@pytest.mark.parametrize("scale", [1e-150, 1e-200, 1e150, 1e200])
def test_l_cross_omega_out_of_float64s_range_is_refused_naming_l0(scale, method):
    step = None if method == "dop853" else 0.01 / scale
    with pytest.raises(ScenarioError, match=r"^L0: \|L0\| = .* outside float64's working range") as err:
        _run(scale, method=method, step=step)
    exponent = round(2 * math.log10(np.linalg.norm([1.0, 0.1, 0.01]) * scale) - math.log10(3.0 if scale < 1 else 1.0))
    assert f"near 1e{exponent} N m" in str(err.value)


@pytest.mark.parametrize("method, scale", [("exact", 1e-200), ("exact", 1e200), ("lie-poisson4", 1e-200),
                                           ("lie-poisson4", 1e140), ("top-splitting4", 1e140)])
def test_the_exact_flow_and_the_splittings_take_their_range_and_measure_its_drifts(scale, method):
    """They turn L by angles h L_i / I_i (no L x omega product): the same motion at any scale in their range, its
    drifts finite (the splittings keep |L| by its square: up to 1e150)."""
    step = None if method == "exact" else 0.01 / scale
    run = _run(scale, method=method, step=step)
    d = run.diagnostics
    assert all(math.isfinite(d[k]) for k in ("energy_rel_drift", "momentum_rel_drift"))
    assert d["momentum_rel_drift"] < 1e-13
    # the same motion in time scaled by 1 / scale: the body-frame L, in units of the scale, is the unscaled run's
    ref = _run(1.0, method=method, step=None if step is None else 0.01)
    assert d["energy_rel_drift"] == pytest.approx(ref.diagnostics["energy_rel_drift"], rel=1e-6, abs=1e-13)
    np.testing.assert_allclose(run.L / scale, ref.L, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(np.abs(np.sum(run.q * ref.q, axis=1)), 1.0, atol=1e-12)


@pytest.mark.parametrize("scale", [1e-140, 1e-100, 1e100, 1e140])
def test_a_time_scale_far_from_one_second_runs_to_its_end(scale):
    """The same motion at any scale (L times s, time over s): the steps grow from DOP853's short first one, and the
    run is neither refused nor wrong; in units of the scale it is the unscaled run to its tolerance."""
    run = _run(scale)
    ref = _run(1.0)
    assert run.complete
    np.testing.assert_allclose(run.L[-1] / scale, ref.L[-1], rtol=1e-6, atol=1e-8)
    np.testing.assert_allclose(np.abs(run.q[-1] @ ref.q[-1]), 1.0, atol=1e-6)


def test_an_adaptive_run_over_the_limit_names_its_method():
    with limits.applied(limits.Limits(max_steps=2000)):
        with pytest.raises(LimitError, match=r"^method dop853: about .* steps \(at the pace of its first") as err:
            simulate_rigid_body(inertia=INERTIA, L0=[0.3, 1.0, 0.3], q0=Q0, duration=1e5, method="dop853",
                                torque=lambda t, L, q: (0.0, 0.0, 0.0))
    assert "--max-steps N" in str(err.value) and "simulate_body" not in str(err.value)


@pytest.mark.parametrize("method", ["lie-poisson", "lie-poisson8", "top-splitting"])
def test_a_momentum_whose_square_overflows_is_refused_by_the_splittings(method):
    with pytest.raises(ScenarioError, match=rf"^L0: \|L0\| = 1e\+200 kg m\^2/s; method {method} keeps \|L\| by its "
                                            r"square"):
        simulate_rigid_body(inertia=SYMMETRIC, L0=[0.0, 0.0, 1e200], q0=Q0, duration=1e-199, method=method,
                            step=1e-202)


def test_a_particle_energy_that_overflows_is_null_with_a_note():
    import rotframe
    from rotframe import forces

    run = rotframe.simulate(omega=[0.0, 0.0, 1.0], r0=[1.0, 0.0, 0.0], v0=[1e200, 0.0, 0.0], duration=10.0,
                            forces=[forces.spring(1.0)], method="rk4")
    assert math.isnan(run.diagnostics["jacobi_rel_drift"])
    assert any(n.startswith("jacobi_rel_drift: not measured") for n in run.notes)
    assert run.to_dict()["diagnostics"]["jacobi_rel_drift"] is None or math.isnan(
        run.to_dict()["diagnostics"]["jacobi_rel_drift"])


@pytest.mark.parametrize("argv, keys", [(["heavy-top", "--set", "psidot0=1e170"], "phidot0, psidot0, wobble"),
                                        (["dzhanibekov", "--set", "omega=1e-160,1e-160,1e-160", "--method", "rk4"],
                                         "omega"),
                                        (["free-top", "--set", "omega3=1e-170", "--set", "omega_perp=1e-170", "--method", "dop853"],
                                         "omega3, omega_perp")])
def test_a_scene_whose_spin_is_out_of_range_is_refused_naming_its_keys(capsys, argv, keys):
    from cli_calls import assert_clean, call

    code, out, err = call(capsys, "run", *argv, "--no-record")
    assert_clean(code, out, err)
    assert code == 2 and err.startswith(f"rotframe: error: {keys}: the body's angular momentum |L0| = "), err


@pytest.mark.parametrize("method", ["exact", "dop853", "lie-poisson"])
def test_a_subnormal_momentum_is_refused_by_every_method(method):
    with pytest.raises(ScenarioError, match=r"^L0: \|L0\| = 1e-310 kg m\^2/s is below the smallest normal float64"):
        simulate_rigid_body(inertia=INERTIA, L0=[1e-310, 0.0, 0.0], q0=Q0, duration=1.0, method=method,
                            step=None if method in ("exact", "dop853") else 0.1)
