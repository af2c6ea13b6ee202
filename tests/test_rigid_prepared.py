"""rotframe.rigid.prepared.PreparedBodyRun: bitwise the plain paths, checks once, per-call state checks.

The oracle here is the plain public path with the same settings (the rigid layer's
``lie_poisson`` and ``heavy_top_splitting`` for the fixed-step methods, ``rigid_dop853`` for
dop853): a prepared run promises the same IEEE operations in the same order, so the comparison is
exact (``np.array_equal``), no tolerance.
The physics of those plain paths is proven by their own tests (closed forms, DOP853 in scipy).
"""

import numpy as np
import pytest

from rotframe.errors import IntegrationError, RotframeError, ScenarioError
from rotframe.rigid.adaptive import rigid_dop853
from rotframe.rigid.prepared import FIXED_METHODS, PreparedBodyRun
from rotframe.rigid import dynamics as rigid

TOP_INERTIA = np.array([1.0, 1.0, 2.0])
ASYM_INERTIA = np.array([1.0, 2.0, 3.0])
TOP = (1.0, 0.5, 9.81)
Q0 = np.array([0.1, 0.0, 0.0, 1.0])  # not normalised: the runs normalise it, row 0 keeps it as given


def _plain_fixed(method, inertia, L0, q0, duration, samples, step, top):
    """The rigid layer's public splitting over the prepared run's grid (the step divides the sample interval), the
    start's row keeping ``q0`` as given, as a prepared run's does."""
    dt = duration / samples
    per = max(1, int(np.ceil(dt / step - 1e-9)))
    order = {"": 2, "4": 4, "6": 6, "8": 8}[method.rsplit("splitting", 1)[-1] if "top" in method else
                                             method.removeprefix("lie-poisson")]
    if top is not None:
        L, q, times = rigid.heavy_top_splitting(inertia[0], inertia[2], *top, L0, q0, dt / per, samples * per,
                                                order=order, sample_every=per)
    else:
        L, q, times = rigid.lie_poisson(inertia, L0, q0, dt / per, samples * per, order=order, sample_every=per)
    q = q.copy()
    q[0] = q0
    return L, q, times, samples * per


@pytest.mark.parametrize("method", FIXED_METHODS)
@pytest.mark.parametrize("top", [None, TOP])
@pytest.mark.parametrize("samples", [1, 7])
def test_fixed_step_bitwise_the_public_splitting(method, top, samples):
    inertia = TOP_INERTIA if top is not None else ASYM_INERTIA
    prep = PreparedBodyRun(inertia, method, 2.0, step=0.013, samples=samples, top=top)
    for omega in ([0.3, 0.1, 5.0], [1.0, -0.2, 0.4]):  # two calls: nothing of the first leaks into the second
        L0 = inertia * np.array(omega)
        L, q = prep.run(L0, Q0)
        ref_L, ref_q, _, steps = _plain_fixed(method, inertia, L0, Q0, 2.0, samples, 0.013, top)
        assert np.array_equal(L, ref_L) and np.array_equal(q, ref_q)
        assert prep.steps == steps
        np.testing.assert_array_equal(prep.times, np.linspace(0.0, 2.0, samples + 1))


def test_fixed_step_in_chunks_stays_on_the_one_call():
    # 3e6 steps a sample > one kernel call of 2e6: the run in pieces (each starts from a normalised attitude) stays
    # on the public function's one call to round-off
    prep = PreparedBodyRun(ASYM_INERTIA, "lie-poisson", 2.0, step=2.0 / 3e6 / 2, samples=2)
    L0 = ASYM_INERTIA * np.array([0.01, 1.0, 0.01])
    L, q = prep.run(L0, Q0)
    ref_L, ref_q, _, _ = _plain_fixed("lie-poisson", ASYM_INERTIA, L0, Q0, 2.0, 2, 2.0 / 3e6 / 2, None)
    np.testing.assert_allclose(L, ref_L, rtol=0, atol=1e-12)
    np.testing.assert_allclose(q[1:], ref_q[1:], rtol=0, atol=1e-12)
    assert not np.allclose(L[-1], L[0])


@pytest.mark.parametrize("top", [None, TOP])
@pytest.mark.parametrize("samples", [1, 9])
@pytest.mark.parametrize("rtol", [1e-3, 3e-9])
def test_dop853_bitwise_rigid_dop853(top, samples, rtol):
    inertia = TOP_INERTIA if top is not None else ASYM_INERTIA
    mgl = 0.0 if top is None else top[0] * top[1] * top[2]
    prep = PreparedBodyRun(inertia, "dop853", 2.0, rtol=rtol, samples=samples, top=top)
    for omega in ([0.3, 0.1, 5.0], [0.01, 1.0, 0.01]):
        L0 = inertia * np.array(omega)
        L, q = prep.run(L0, Q0)
        ref = rigid_dop853(inertia, L0, Q0, np.linspace(0.0, 2.0, samples + 1), rtol=rtol, mgl=mgl)
        assert np.array_equal(L, ref.L) and np.array_equal(q, ref.q)
        assert (prep.nfev, prep.steps) == (ref.nfev, ref.steps)


def test_dop853_mgl_keyword_equals_top():
    a = PreparedBodyRun(TOP_INERTIA, "dop853", 1.0, rtol=1e-8, samples=3, top=TOP)
    b = PreparedBodyRun(TOP_INERTIA, "dop853", 1.0, rtol=1e-8, samples=3, mgl=TOP[0] * TOP[1] * TOP[2])
    L0 = TOP_INERTIA * np.array([0.3, 0.1, 5.0])
    for x, y in zip(a.run(L0, Q0), b.run(L0, Q0)):
        assert np.array_equal(x, y)


def test_results_are_fresh_arrays():
    prep = PreparedBodyRun(TOP_INERTIA, "top-splitting4", 1.0, step=0.01, samples=2, top=TOP)
    L0 = TOP_INERTIA * np.array([0.3, 0.1, 5.0])
    L1, _ = prep.run(L0, Q0)
    keep = L1.copy()
    prep.run(2 * L0, Q0)
    assert np.array_equal(L1, keep)


@pytest.mark.parametrize("method", ["top-splitting4", "dop853"])
@pytest.mark.parametrize("L0, q0, key", [
    ([1.0, np.nan, 0.0], Q0, "L0"),
    ([1.0, 2.0], Q0, "L0"),
    ([1.0, 2.0, 3.0], [0.0, 0.0, 0.0, 0.0], "q0"),
    ([1.0, 2.0, 3.0], [0.0, 0.0, np.inf, 1.0], "q0"),
    ([1.0, 2.0, 3.0], [0.0, 0.0, 1.0], "q0"),
])
def test_bad_state_is_one_line_scenario_error(method, L0, q0, key):
    prep = PreparedBodyRun(TOP_INERTIA, method, 1.0, step=0.01, samples=1, top=TOP)
    with pytest.raises(ScenarioError) as exc:
        prep.run(L0, q0)
    msg = str(exc.value)
    assert msg.startswith(f"{key}:") and "\n" not in msg


@pytest.mark.parametrize("kwargs, key", [
    (dict(method="euler"), "method"),
    (dict(duration=-1.0), "duration"),
    (dict(duration=float("nan")), "duration"),
    (dict(method="dop853", rtol=2.0), "rtol"),
    (dict(method="dop853", inertia=[1.0, 0.0, 2.0]), "inertia"),
])
def test_bad_setup_is_scenario_error(kwargs, key):
    args = dict(inertia=TOP_INERTIA, method="top-splitting", duration=1.0)
    args.update(kwargs)
    with pytest.raises(ScenarioError, match=key):
        PreparedBodyRun(args.pop("inertia"), args.pop("method"), args.pop("duration"), **args)


def test_bad_body_refused_by_the_plain_checks():
    # a negative moment: the public function's own check (InvalidBodyError, a RotframeError: exit 2), once at set-up
    with pytest.raises(RotframeError, match="-1.0"):
        PreparedBodyRun([1.0, -1.0, 2.0], "lie-poisson", 1.0)


def test_a_huge_momentum_is_refused_by_the_limits_not_run_for_ever():
    """|L| = 1e300 would take ~1e300 dop853 steps: the prepared run refuses it (LimitError, exit 2 on the
    command line) before integrating; the estimate gives inf rather than an OverflowError."""
    from rotframe.limits import LimitError

    L0, q0 = np.array([1e300, 2e300, 1e300]), np.array([1.0, 0.0, 0.0, 0.0])
    run = PreparedBodyRun(ASYM_INERTIA, "dop853", 10.0, samples=5, rtol=1e-6)
    with pytest.raises(LimitError, match="integration steps"):
        run(L0, q0)
    L, _ = run(np.array([1.0, 2.0, 1.0]), q0)  # the same prepared run still takes a sane state
    assert np.isfinite(L).all()


@pytest.mark.parametrize("method", ["lie-poisson", "top-splitting4"])
def test_a_non_finite_state_raises_integration_error(method):
    """A momentum of 1e300 overflows within the first step of a splitting: an error, never inf returned."""
    top = TOP if method.startswith("top") else None
    inertia = TOP_INERTIA if top else ASYM_INERTIA
    run = PreparedBodyRun(inertia, method, 10.0, samples=5, step=0.5, top=top)
    with pytest.raises(IntegrationError, match="non-finite"):
        run(np.array([1e300, 2e300, 1e300]), np.array([1.0, 0.0, 0.0, 0.0]))
