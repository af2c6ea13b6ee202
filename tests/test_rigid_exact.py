"""The compiled exact free-body flow (rotframe.rigid.exact_flow) against independent references.

Carlson's integrals and K against scipy.special (other implementations of the
same functions); the flow, which the public ``rigid.free_body_exact`` runs where it
applies, against ``free_body.free_body_closed_form`` (the same closed form,
checked against mpmath in test_rigid, evaluated with scipy's special functions)
and against the compiled DOP853 at a tight tolerance (a different method).
"""

import numpy as np
import pytest
from scipy import special

from rotframe.rigid import dynamics as rigid
from rotframe.rigid.adaptive import rigid_dop853
from rotframe.rigid.elliptic import carlson_rf, carlson_rj, ellipk_agm
from rotframe.rigid.exact_flow import flow_into, flow_ready
from rotframe.rigid.free_body import free_body_closed_form

free_body_flow = rigid.free_body_exact  # the public door: the compiled flow where it applies


def _body(rng):
    while True:
        inertia = rng.uniform(0.5, 3.0, 3)
        if 2 * inertia.max() <= inertia.sum():
            return inertia


def test_carlson_integrals_match_scipy():
    # duplication truncated at relative deviation 8e-4: series error ~1e-19, so the difference is
    # round-off of a few dozen operations; 1e-14 relative bounds it with margin
    rng = np.random.default_rng(1)
    for _ in range(500):
        x, y, z = rng.uniform(0.0, 1.0, 3) * 10.0 ** rng.uniform(-6, 3, 3)
        p = rng.uniform(0.01, 5.0) * 10.0 ** rng.uniform(-2, 2)
        assert carlson_rf(x, y, z) == pytest.approx(special.elliprf(x, y, z), rel=1e-14)
        assert carlson_rj(x, y, z, p) == pytest.approx(special.elliprj(x, y, z, p), rel=1e-14)


@pytest.mark.parametrize("m1", [1e-300, 1e-100, 1e-12, 1e-4, 0.3, 0.9, 1.0])
def test_complete_integral_by_agm_matches_scipy(m1):
    assert ellipk_agm(m1) == pytest.approx(special.ellipkm1(m1), rel=2e-15)


def test_flow_matches_free_body_exact_on_random_bodies():
    # the same formulas with different special-function routines: they differ by round-off, which
    # grows with the phase u = u0 + lambda t (|lambda t| up to a few hundred here): 1e-12 bounds it
    rng = np.random.default_rng(2)
    for _ in range(200):
        inertia = _body(rng)
        L0 = rng.normal(size=3) * rng.uniform(0.1, 10.0)
        q0 = rng.normal(size=4)
        t = np.concatenate([[0.0], rng.uniform(-50.0, 200.0, 4)])
        fast = flow_into(inertia, L0, q0, t)  # compiles the flow (or loads it): then the door takes it
        La, qa = free_body_flow(inertia, L0, q0, t)
        assert fast is not None and np.array_equal(La, fast[0]) and np.array_equal(qa, fast[1])  # compiled
        Lb, qb = free_body_closed_form(inertia, L0, q0, t)
        assert np.max(np.abs(La - Lb)) / np.linalg.norm(L0) < 1e-12
        assert np.max(np.abs(qa - qb)) < 1e-12
        assert np.allclose(qa[0], q0 / np.linalg.norm(q0), atol=1e-15, rtol=0)  # q(0) = q0, same sign


def test_flow_matches_an_integrator():
    # the Dzhanibekov flip: DOP853 at rtol 1e-13 is good to ~1e-12 over 2.6 flips; 1e-10 leaves a margin
    inertia = np.array([1.0, 2.0, 3.0])
    L0 = inertia * np.array([0.01, 1.0, 0.01])
    q0 = np.array([0.1, -0.2, 0.3, 0.9])
    t = np.linspace(0.0, 100.0, 11)
    La, qa = free_body_flow(inertia, L0, q0, t)
    run = rigid_dop853(inertia, L0, q0, t, rtol=1e-13)
    assert np.max(np.abs(La - run.L)) / np.linalg.norm(L0) < 1e-10
    sign = np.sign(np.sum(qa * run.q, axis=1))[:, None]
    assert np.max(np.abs(qa - sign * run.q)) < 1e-10


@pytest.mark.parametrize("inertia,L0", [([1.0, 1.0, 1.5], [0.3, 0.2, 1.0]),  # symmetric: other formula
                                         ([1.0, 2.0, 3.0], [0.0, 2.0, 0.0]),  # steady about the middle axis
                                         ([1.0, 2.0, 3.0], [0.0, 0.0, 0.0])])
def test_special_cases_are_passed_on(inertia, L0):
    t = np.array([0.0, 1.0, 7.5])
    assert flow_into(inertia, L0, [0, 0, 0, 1.0], t) is None
    La, qa = free_body_flow(inertia, L0, [0, 0, 0, 1.0], t)
    Lb, qb = free_body_closed_form(inertia, L0, [0, 0, 0, 1.0], t)
    assert np.array_equal(La, Lb) and np.array_equal(qa, qb)


def test_scalar_time_takes_the_compiled_flow():
    assert flow_into([1.0, 2.0, 3.0], [0.1, 1.0, 0.1], [0, 0, 0, 1.0], 2.5) is not None
    assert flow_ready()
    L, q = free_body_flow([1.0, 2.0, 3.0], [0.1, 1.0, 0.1], [0, 0, 0, 1.0], 2.5)
    Lb, qb = free_body_closed_form([1.0, 2.0, 3.0], [0.1, 1.0, 0.1], [0, 0, 0, 1.0], 2.5)
    assert L.shape == Lb.shape == (1, 3) and q.shape == qb.shape == (1, 4)
    assert np.max(np.abs(L - Lb)) < 1e-13 and np.max(np.abs(q - qb)) < 1e-13


def test_invalid_input_raises_like_free_body_exact():
    with pytest.raises(Exception) as fast:
        free_body_flow([1.0, 1.0, 5.0], [1.0, 0.0, 0.0], [0, 0, 0, 1.0], [0.0, 1.0])  # no such body
    with pytest.raises(Exception) as slow:
        free_body_closed_form([1.0, 1.0, 5.0], [1.0, 0.0, 0.0], [0, 0, 0, 1.0], [0.0, 1.0])
    assert type(fast.value) is type(slow.value) and str(fast.value) == str(slow.value)


def test_a_first_run_does_not_compile_the_flow(tmp_path):
    """With an empty compile cache, free_body_exact answers by the closed form and compiles nothing."""
    import os
    import subprocess
    import sys

    code = ("import numpy as np\n"
            "from rotframe.rigid import exact_flow\n"
            "from rotframe.rigid.dynamics import free_body_exact\n"
            "from rotframe.rigid.free_body import free_body_closed_form\n"
            "args = ([1.0, 2.0, 3.0], [0.1, 1.0, 0.1], [0, 0, 0, 1.0], np.array([0.0, 100.0]))\n"
            "L, q = free_body_exact(*args)\n"
            "Lc, qc = free_body_closed_form(*args)\n"
            "assert np.array_equal(L, Lc) and np.array_equal(q, qc)\n"
            "assert not exact_flow.flow_ready() and not exact_flow._flow.overloads\n"
            "print('ok')\n")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path))
    res = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert res.returncode == 0 and res.stdout.strip() == "ok", res.stderr[-2000:]


def test_free_body_exact_compiles_the_flow_when_a_process_needs_it_twice(monkeypatch):
    """The first call of a process takes the numpy path (no compile for one call); the second compiles the
    flow (cached on disk), as do all later calls; the scenes' reference path never compiles it."""
    from rotframe.rigid import exact_flow, free_body

    calls = []
    real = exact_flow.flow_into
    monkeypatch.setattr(exact_flow, "flow_ready", lambda: False)
    monkeypatch.setattr(exact_flow, "flow_into", lambda *a: calls.append(1) or real(*a))
    monkeypatch.setattr(free_body, "_CALLS", [0])
    I, L0, q0, t = [1.0, 2.0, 3.0], [0.3, 0.1, 1.0], [0.0, 0.0, 0.0, 1.0], np.linspace(0.0, 5.0, 7)
    first = free_body.free_body_exact(I, L0, q0, t)
    assert calls == []
    second = free_body.free_body_exact(I, L0, q0, t)
    assert calls == [1]
    free_body.free_body_closed_form(I, L0, q0, t)  # the scenes' and simulate_body's path: never the compiled one
    assert calls == [1]
    assert np.max(np.abs(first[0] - second[0])) < 1e-13 and np.max(np.abs(first[1] - second[1])) < 1e-13
