"""Python drivers shared by the fixed-step rigid-body integrators.

Output arrays and sample times (steps ``0, s, 2s, ...`` and always the last), the
composition weights (`rotframe.numerics.composition.composition_weights`,
refused orders as [`InvalidStateError`][rotframe.rigid.checks.InvalidStateError]; the order of a
method name's suffix in `SPLITTING_ORDERS`), the end of
a run (an [`IntegrationError`][rotframe.errors.IntegrationError] that keeps the finite
samples), and the drivers of the compiled splitting `run_splitting` and
`splitting_stepper` (the body checked once, for runs in chunks).
"""

from __future__ import annotations

import numpy as np

from rotframe.errors import IntegrationError
from rotframe.numerics import composition
from rotframe.rigid.checks import InvalidStateError, check_quaternion, check_steps
from rotframe.rigid.kernels import split_run

__all__ = ["SPLITTING_ORDERS", "composition_weights", "allocate_samples", "finish_samples", "splitting_stepper",
           "run_splitting"]


#: Order of a splitting method from its name's suffix: ``lie-poisson`` 2, ``lie-poisson4`` 4, ... ``8``.
SPLITTING_ORDERS = {"": 2, "4": 4, "6": 6, "8": 8}


def composition_weights(order):
    """Fractions of the order-2 step in the composition of ``order`` (2, 4, 6 or 8).

    Yoshida's triple jump for order 4, Kahan & Li's 9- and 17-stage methods for 6
    and 8 (`rotframe.numerics.composition.composition_weights`).
    """
    if order not in composition.COMPOSITION_ORDERS:
        raise InvalidStateError(f"order = {order!r}; allowed: 2, 4, 6 or 8")
    return composition.composition_weights(order)


def allocate_samples(h, n_steps, sample_every):
    """Output arrays and sample times: steps 0, s, 2s, ... and always the last."""
    steps = np.arange(0, n_steps + 1, sample_every)
    if steps[-1] != n_steps:
        steps = np.append(steps, n_steps)
    return np.empty((steps.size, 3)), np.empty((steps.size, 4)), steps * h


def finish_samples(out_L, out_q, times, kept, name):
    """Return the samples, or raise IntegrationError keeping the finite ones."""
    if kept == times.size:
        return out_L, out_q, times
    t_reached = float(times[kept - 1])
    raise IntegrationError(
        f"{name}: state became non-finite after t = {t_reached:.6g} s (last finite sample); "
        "reduce the step",
        t_reached=t_reached, partial=(out_L[:kept], out_q[:kept], times[:kept]),
    )


def splitting_stepper(inv_i, sym, mgl, torque_body, torque_space, order):
    """``step(L0, q0, h, n_steps, sample_every) -> (L, q, times)``: the compiled splitting of one body.

    The body's constants (``inv_i``, ``sym``, ``mgl``, the torques, as the public
    functions check them) and the composition weights of ``order`` are fixed
    once, so a driver that calls ``step`` again and again (a run in chunks) pays
    only the checks of the state and the steps (a quaternion normalised, as
    `run_splitting` does).
    """
    weights = composition_weights(order)

    def step(L0, q0, h, n_steps, sample_every):
        q0 = check_quaternion(q0)
        h, n_steps, sample_every = check_steps(h, n_steps, sample_every)
        out_L, out_q, times = allocate_samples(h, n_steps, sample_every)
        kept = split_run(inv_i, sym, mgl, torque_body, torque_space, L0, q0, h, n_steps, weights,
                         sample_every, out_L, out_q)
        return finish_samples(out_L, out_q, times, kept, "splitting")

    return step


def run_splitting(inv_i, sym, mgl, torque_body, torque_space, L0, q0, h, n_steps, order,
                   sample_every):
    """Shared driver of lie_poisson and heavy_top_splitting."""
    return splitting_stepper(inv_i, sym, mgl, torque_body, torque_space, order)(L0, q0, h, n_steps, sample_every)
