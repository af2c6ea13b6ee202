"""Adaptive Dormand-Prince 8(5,3) for a rigid body: the one DOP853 loop with the body's right-hand side.

The state is ``y = (L_body, q)``: angular momentum in principal body axes
(kg m^2/s) and the body -> space orientation quaternion, scalar-last. The
equations are those of [`rotframe.rigid.torqued.rigid_rhs`][rotframe.rigid.torqued.rigid_rhs] (docs/physics.md,
rigid bodies): Euler's equations ``dL/dt = L x omega + N_body``,
``omega = L / I``, and the kinematics ``dq/dt = q * (omega, 0) / 2``, with the
torque of a heavy symmetric top ``mgl (z_b[1], -z_b[0], 0)``, a constant body
torque and a constant space torque turned into body axes with ``q/|q|``.

The method is Hairer's DOP853 (Hairer, Norsett & Wanner, Solving ODEs I,
II.10) as the scenes' one loop runs it (`rotframe.numerics.dop853_loop`): 12 stages, the
combined 5th/3rd-order error estimate, Hairer's step-size control and first step (II.4,
`rotframe.numerics.step_control`), and the 7th-order dense output (3 extra stages, only in
steps that hold an output time) for samples between steps. Tolerances are
relative: component ``j`` is scaled by ``atol_j + rtol max(|y_j|, |y_new_j|)``
with ``atol_j = atol |L0|`` for the momentum and ``atol`` for the quaternion
(dimensionless, so a body of any size is treated alike). The quaternion is
not projected during the run (the exact flow keeps ``|q| = 1``, and the drift
is of the order of the tolerance); outputs are normalised.

Every step and every sample is one compiled call (`_trajectory`); the checks, sample 0 and the first step run in Python (a few
microseconds), so that the kernel a first run compiles is as small as it can be
(docs/architecture.md, "What a first run compiles").
"""

from __future__ import annotations

import math

import numpy as np

from rotframe.numerics import step_control
from rotframe.numerics.compiled import jit_llvm_inline
from rotframe.numerics.dop853_loop import NONFINITE, UNLIMITED, dop853_stages, dop853_trajectory
from rotframe.numerics.plain import plain
from rotframe.rigid.kernels import euler_rates, euler_system

__all__ = ["rigid_dop853", "RigidRun", "dop853_kernel", "dop853_from", "steps_estimate"]

class RigidRun:
    """Samples of one adaptive run: ``times``, ``L`` (n, 3), ``q`` (n, 4), ``nfev``, ``steps``."""

    __slots__ = ("times", "L", "q", "nfev", "steps")

    def __init__(self, times, L, q, nfev, steps):
        self.times, self.L, self.q, self.nfev, self.steps = times, L, q, nfev, steps


@jit_llvm_inline
def _store_sample(out, k, p, y):
    """Sample ``k``: ``L`` into ``out[0]`` (n, 3), the normalised quaternion into ``out[1]`` (n, 4)."""
    out_L, out_q = out
    n = math.sqrt(y[3] * y[3] + y[4] * y[4] + y[5] * y[5] + y[6] * y[6])
    for i in range(3):
        out_L[k, i] = y[i]
    for i in range(4):
        out_q[k, i] = y[3 + i] / n


#: the one DOP853 loop for the body (`rotframe.numerics.dop853_loop`), called from Python: every step and sample
_trajectory = dop853_trajectory("rigid", dop853_stages("rigid", euler_system, 7), _store_sample, 7, entry=True)


def _first_step(y, K, p, h_max, atol_vec, rtol):
    """``K[0] = f(y)`` and Hairer's starting step (`rotframe.numerics.step_control`), ``K[1]`` f at its trial step.

    The shared functions run as plain Python here (`rotframe.numerics.plain`: a few microseconds,
    nothing to compile; numpy float64 scalars, the same IEEE double operations as compiled, x / 0
    giving inf or nan). Returns the step ``h``.
    """
    args = p.tolist()
    with np.errstate(all="ignore"):
        y = np.asarray(y, dtype=np.float64)
        K[0] = euler_rates(*y.tolist(), *args)
        h0 = plain(step_control.first_step_trial)(y, K[0], rtol, atol_vec, h_max)
        K[1] = euler_rates(*(y + h0 * K[0]).tolist(), *args)
        return plain(step_control.first_step)(y, K[0], K[1], h0, rtol, atol_vec, h_max)


def steps_estimate(inertia, L0, duration, rtol, mgl=0.0):
    """Steps ``dop853`` will take, roughly (for the run limits): ``duration w rtol^(-1/8) / 10``.

    ``w`` is the fastest rate, the initial ``|omega|`` plus the gravity rate ``sqrt(|mgl| / I_min)``
    of a heavy top; an 8th-order step resolves a turn of ``rtol^(1/8)`` rad times a constant. The
    constant 1/10 is measured: the default heavy top (10 s, 300 rad/s, rtol 1e-9) takes 4222
    steps, estimated 4529; the Dzhanibekov flip (100 s, 1 rad/s, rtol 1e-10) 189, estimated 180.
    A huge ``L0`` gives inf (a run refused by the limits), never an OverflowError.
    """
    moments = [float(x) for x in inertia]  # scalar arithmetic: a short run pays microseconds, not tens
    w = math.hypot(*[float(l) / i for l, i in zip(L0, moments) if i > 0])
    w += math.sqrt(abs(mgl) / max(min(moments), 1e-300))
    return duration * w * rtol ** (-1.0 / 8.0) / 10.0


def dop853_kernel(y0, p, times, rtol, atol, h_max, out_L, out_q):
    """Integrate from times[0] to times[-1]; samples at every entry of ``times``.

    ``p[:3]`` holds the moments of inertia on entry and their inverses after;
    ``y0[3:]`` is normalised in place. Returns (samples done, nfev, accepted
    steps); samples done < len(times) when the step size collapsed or the
    state became non-finite, -1 for invalid input. The checks here, the rest
    in `dop853_from`.
    """
    n_out = times.shape[0]
    if n_out < 1 or times.ndim != 1 or not np.all(times[1:] > times[:-1]):
        return -1, 0, 0
    for i in range(3):
        if not p[i] > 0.0:
            return -1, 0, 0
        p[i] = 1.0 / p[i]
    return dop853_from(y0, p, times, rtol, atol, h_max, out_L, out_q)


def dop853_from(y0, p, times, rtol, atol, h_max, out_L, out_q):
    """`dop853_kernel` after its checks: ``times`` increasing, ``p[:3]`` the inverse moments (not changed).

    ``y0[3:]`` is normalised in place. Sample 0 and the first step in Python
    (Python floats: the same IEEE double operations as float64 scalars, in the
    order of Hairer's code), the steps in `_trajectory`. For callers that check
    once and run many times ([`rotframe.rigid.prepared.PreparedBodyRun`][rotframe.rigid.prepared.PreparedBodyRun]).
    """
    n_out = times.shape[0]
    y = y0.tolist()
    nq = math.sqrt(y[3] * y[3] + y[4] * y[4] + y[5] * y[5] + y[6] * y[6])
    if not nq > 0.0:
        return -1, 0, 0
    for i in range(3, 7):
        y[i] /= nq
    y0[3:] = y[3:]
    atol_L = atol * max(math.sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]), 1e-300)
    atol_vec = np.array([atol_L] * 3 + [atol] * 4)
    n = math.sqrt(y[3] * y[3] + y[4] * y[4] + y[5] * y[5] + y[6] * y[6])
    out_L[0] = y[:3]
    out_q[0] = [v / n for v in y[3:]]
    K = np.empty((16, 7))
    t_span = float(times[n_out - 1] - times[0])
    h = _first_step(y, K, p, min(abs(t_span), h_max), atol_vec, rtol)
    work = np.empty((10, 7))  # three states and the interpolant
    _, _, done, status, nfev, steps = _trajectory(p, times[0], np.array(y), h, times[n_out - 1], h_max, times, 1,
                                                  (out_L, out_q), 0, rtol, atol_vec, K, work[0], work[1], work[2],
                                                  work[3:10], None, UNLIMITED)
    if status == NONFINITE:
        done -= 1  # the sample that holds the non-finite state is not done
    return done, nfev + 2, steps


def rigid_dop853(inertia, L0_body, q0, times, *, rtol=1e-10, atol=None, mgl=0.0, torque=None,
                 torque_frame="body", h_max=math.inf) -> RigidRun:
    """Integrate a rigid body with compiled adaptive DOP853 and return samples at ``times``.

    Parameters
    ----------
    inertia : (3,) array_like
        Principal moments (kg m^2).
    L0_body : (3,) array_like
        Angular momentum (kg m^2/s) in body axes at ``times[0]``.
    q0 : (4,) array_like
        Orientation, scalar-last, body -> space, at ``times[0]``.
    times : (n,) array_like
        Increasing output times (s), ``times[0]`` the start.
    rtol, atol : float
        Relative tolerance, and the absolute one relative to ``|L0|`` (default ``rtol``).
    mgl : float
        ``m g l`` (N m) of a heavy symmetric top (centre of mass on body axis 3); 0 for none.
    torque : (3,) array_like, optional
        Constant torque (N m) in ``torque_frame`` ("body" or "space") axes.
    h_max : float
        Largest step (s).

    Returns
    -------
    RigidRun
        ``L`` and normalised ``q`` at ``times``; ``nfev`` and accepted ``steps``.

    Raises
    ------
    rotframe.errors.IntegrationError
        Step-size collapse or non-finite state; ``partial`` holds the samples before it.
    """
    times = np.ascontiguousarray(times, dtype=np.float64)
    y0 = np.empty(7)
    y0[:3] = L0_body
    y0[3:] = q0
    p = np.zeros(10)
    p[:3] = inertia
    p[3] = mgl
    if torque is not None:
        if torque_frame == "body":
            p[4:7] = torque
        elif torque_frame == "space":
            p[7:10] = torque
        else:
            from rotframe.errors import ScenarioError

            raise ScenarioError(f"torque_frame: {torque_frame!r}; allowed: body, space")
    out_L = np.empty((times.size, 3))
    out_q = np.empty((times.size, 4))
    done, nfev, steps = dop853_kernel(y0, p, times, float(rtol), rtol if atol is None else float(atol), float(h_max),
                             out_L, out_q)
    if done < 0:
        from rotframe.errors import ScenarioError

        raise ScenarioError("rigid dop853: times must be a non-empty 1-D increasing array (s), the moments of "
                            "inertia > 0 and the quaternion non-zero")
    if done < times.size:
        from rotframe.errors import IntegrationError

        good = max(done, 1)
        partial = RigidRun(times[:good], out_L[:good], out_q[:good], nfev, steps)
        raise IntegrationError(f"rigid dop853: step size collapsed or non-finite state after "
                               f"t = {times[good - 1]:.6g} s", t_reached=float(times[good - 1]), partial=partial)
    return RigidRun(times, out_L, out_q, nfev, steps)
