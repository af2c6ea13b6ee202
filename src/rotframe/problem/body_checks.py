"""What float64 and the work limits allow a rigid body's run, checked before it starts.

`check_integrable`: ``L x omega`` within float64's working range (else a ScenarioError naming
``L0``), and a free body's DOP853 run within the step limit by a lower bound of its steps
(`check_turns`, else a `rotframe.limits.LimitError`). Both are refusals that used to be an
IntegrationError in the run's first step, or a silent wrong answer (a subnormal ``L x omega``:
L did not move, and its drifts read 0). tests/test_body_scales.py.
"""

from __future__ import annotations

import math
import sys

import numpy as np

from rotframe import limits
from rotframe.errors import ScenarioError

__all__ = ["check_integrable", "check_turns", "RATE_RANGE", "SPLITTING_MAX_L", "DOP853_IMAGINARY_STABILITY"]


#: the stability interval of DOP853 on the imaginary axis: |R(iy)| <= 1 for |y| up to it (tests/test_body_scales.py)
DOP853_IMAGINARY_STABILITY = 5.96
#: the smallest and largest scale of ``L x omega`` (N m) an integrator steps in float64 at full precision
RATE_RANGE = (1e-290, 1e290)
#: the largest |L| (kg m^2/s) the splittings take: they keep |L| by its square (`rotframe.rigid.kernels.free_step`)
SPLITTING_MAX_L = 1e150


def check_integrable(s):
    """Refuse the run set up as ``s`` (a `rotframe.problem.body.BodySetUp`) where float64 cannot integrate it, or
    where it must take more steps than the limits allow, before it starts (`check_turns`).

    DOP853 and RK4 step ``L' = L x omega``, whose scale is ``|L|^2 / I``: below `RATE_RANGE` it is
    subnormal or zero (the body's L would not move, and its drifts would read 0), above it the products
    overflow. The splittings turn L by angles ``h L_i / I_i`` and keep ``|L|`` by its square, which
    overflows past `SPLITTING_MAX_L` (a square that underflows only skips that correction). The exact
    flow works in scaled numbers and takes any ``L`` of normal floats; an ``|L|`` below the smallest normal
    float64 keeps too few significant bits for any method and is refused.
    """
    size = math.hypot(*s.L)  # without overflow or underflow of the squares
    if 0.0 < size < sys.float_info.min:  # fewer than 53 significant bits: no method can be right to round-off
        raise ScenarioError(f"L0: |L0| = {size!r} kg m^2/s is below the smallest normal float64 "
                            f"({sys.float_info.min:.4g}); allowed: 0 or |L0| >= {sys.float_info.min:.4g} (state the "
                            "body in other units)")
    if s.method not in ("dop853", "rk4"):
        if s.method != "exact" and size > SPLITTING_MAX_L:
            raise ScenarioError(f"L0: |L0| = {size:.3g} kg m^2/s; method {s.method} keeps |L| by its square, which "
                                f"overflows float64 past |L0| = {SPLITTING_MAX_L:g}; state the body in other units "
                                "(or use the free body's exact flow, which takes any L0)")
        return
    moments = np.linalg.eigvalsh(s.I)
    moments = moments[moments > 0.0]  # a thin rod's zero moment: its L has none along the rod (checked before)
    if size == 0.0 or moments.size == 0:
        return
    # the scale's decimal exponent (the scale itself may be out of float64's range)
    low = 2.0 * math.log10(size) - math.log10(float(np.max(moments)))
    high = 2.0 * math.log10(size) - math.log10(float(np.min(moments)))
    if low < math.log10(RATE_RANGE[0]) or high > math.log10(RATE_RANGE[1]):
        raise ScenarioError(f"L0: |L0| = {size:.3g} kg m^2/s with moments {np.sort(moments).tolist()} kg m^2 puts "
                            f"L x omega near 1e{round(low if low < 0 else high)} N m, outside float64's "
                            f"working range [{RATE_RANGE[0]:g}, {RATE_RANGE[1]:g}]; state the body in other units "
                            "(or use a splitting, or the free body's exact flow)")
    check_turns(s)


def check_turns(s):
    """Refuse the free body's adaptive run set up as ``s`` (a `rotframe.problem.body.BodySetUp`) where it must take
    more steps than the limits allow, before it starts.

    A free body keeps its energy and ``|L|``, so ``|omega| >= |L| / I_max`` all along; its attitude
    quaternion turns at ``|omega| / 2``, and an explicit Runge-Kutta step of ``h`` follows a turn of at
    most its stability interval on the imaginary axis (`DOP853_IMAGINARY_STABILITY`, in ``h |omega| / 2``).
    So ``duration |L| / (2 I_max 5.96)`` steps is a lower bound of the work. A spin too fast for the
    limits is then a `rotframe.errors.LimitError` at once, where the run would collapse its first step
    or overflow (an IntegrationError that says nothing of the cause).
    """
    if s.method != "dop853" or s.terms:
        return
    rate = math.hypot(*s.L) / float(np.max(np.linalg.eigvalsh(s.I)))
    limits.check_run(steps=float(s.duration) * (rate / 2.0) / DOP853_IMAGINARY_STABILITY,
                     what=f"method dop853 (the attitude turns at |omega| / 2 >= {rate / 2:.3g} rad/s, a step "
                          f"{DOP853_IMAGINARY_STABILITY} rad of it at most)", remedy="shorten duration")
