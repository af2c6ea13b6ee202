"""Repeated rigid-body runs with everything prepared once (microseconds of overhead a run).

The rigid layer's splittings (`rotframe.rigid.dynamics.lie_poisson`, ``heavy_top_splitting``) and
`rotframe.rigid.adaptive.rigid_dop853` check the body, the method and the
step, build the step's constants and allocate output on every call: some 50 to
200 microseconds, more than a short run's integration costs. A
[`PreparedBodyRun`][rotframe.rigid.prepared.PreparedBodyRun] does all of that once for one body, method, duration,
step (or rtol) and sample count; each call then checks only that ``L0`` and
``q0`` are finite vectors of the right shape, copies them in and makes one call
of the same compiled kernel with the same arguments, so the results are bitwise
those of the plain functions (the splittings over the sample grid, in pieces of at most 2e6 steps a
kernel call, each from a normalised attitude; ``rigid_dop853`` at the sample times for ``dop853``).
For optimisation loops and Monte Carlo over initial states on the rigid layer alone; the rigid
scenes and their bench rows run the engine's `rotframe.problem.prepared_body.PreparedBody`.
"""

from __future__ import annotations

import math

import numpy as np

from rotframe.errors import IntegrationError, ScenarioError
from rotframe.rigid.adaptive import steps_estimate

__all__ = ["PreparedBodyRun", "FIXED_METHODS"]

#: the fixed-step methods (canonical names); ``dop853`` is adaptive
FIXED_METHODS = ("lie-poisson", "lie-poisson4", "lie-poisson6", "lie-poisson8", "top-splitting",
                 "top-splitting4", "top-splitting6", "top-splitting8")


class PreparedBodyRun:
    """Integrate one rigid body over ``duration`` with ``method``, many times from different states.

    Parameters
    ----------
    inertia : (3,) array_like
        Principal moments (kg m^2), body axes.
    method : str
        A name of `FIXED_METHODS` (splitting of order 2, 4, 6 or 8; the free
        body or, with ``top``, the heavy symmetric top), or ``dop853``.
    duration : float
        Simulated time (s), finite and > 0.
    step : float, optional
        Step (s) of the fixed-step methods (default 1/20 of the sample interval);
        the step used divides the sample interval.
    rtol : float
        Relative (and, relative to ``|L0|``, absolute) tolerance of ``dop853``, 1e-15 <= rtol < 1.
    samples : int
        Output samples after t = 0, uniform in time (``np.linspace(0, duration, samples + 1)``).
    top : (mass, length, g), optional
        A heavy symmetric top (centre of mass on body axis 3, ``inertia[0] == inertia[1]``
        for the splitting); ``mgl = mass * length * g`` for ``dop853``.
    mgl : float, optional
        ``m g l`` (N m) for ``dop853`` without ``top``.

    Notes
    -----
    Checked once, at set-up (with the plain functions' own checks, by one run from
    a zero momentum): the moments, the top, the method, the duration, the step or
    rtol and the run's size (`rotframe.limits.check_run`); the kernel is
    loaded or compiled then. Checked every call: ``L0`` three finite numbers,
    ``q0`` four finite numbers not all zero (else ``ScenarioError`` naming the
    key and value). ``run(L0, q0)`` returns ``(L, q)``, arrays (samples + 1, 3)
    and (samples + 1, 4) owned by the caller: ``L`` in body axes, ``q``
    scalar-last, body -> space (the fixed-step methods keep ``q0`` as given in
    row 0; ``dop853`` normalises it, as ``rigid_dop853``
    does; the later rows are normalised). ``times`` holds the sample times; ``steps`` and ``nfev`` (0 for
    the fixed-step methods) count the last call's work. A non-finite state (or,
    for ``dop853``, a step-size collapse) raises ``IntegrationError``.
    """

    def __init__(self, inertia, method, duration, *, step=None, rtol=1e-10, samples=1, top=None, mgl=None):
        from rotframe import limits

        self.method = method = str(method).lower()  # any case: scipy's "DOP853" is dop853
        duration = float(duration)
        if not (math.isfinite(duration) and duration > 0):
            raise ScenarioError(f"duration: {duration:g} s; must be finite and > 0")
        self.samples = samples = max(1, int(samples))
        self.times = np.linspace(0.0, duration, samples + 1)
        self.inertia = inertia = np.array(inertia, dtype=float)
        self.steps = 0
        self.nfev = 0
        if method == "dop853":
            self._setup_adaptive(inertia, float(rtol), top, mgl)
        elif method in FIXED_METHODS:
            self._setup_fixed(inertia, duration, step, top)
        else:
            raise ScenarioError(f"method: {method!r}; allowed: {', '.join(FIXED_METHODS)}, dop853")
        limits.check_run(steps=self._steps_estimate, samples=samples + 1, what=f"method {method}",
                         remedy="shorten duration or loosen rtol" if method == "dop853" else
                         "shorten duration or enlarge step")
        self.run(np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]))  # every input checked; kernel loaded or compiled

    def _setup_fixed(self, inertia, duration, step, top):
        from rotframe.rigid import dynamics as rigid
        from rotframe.rigid.checks import check_inertia, heavy_top_mgl, symmetry_axis
        from rotframe.rigid.drivers import SPLITTING_ORDERS, composition_weights, splitting_stepper
        from rotframe.rigid.kernels import split_run

        samples = self.samples
        step = float(step or duration / samples / 20)
        dt_sample = duration / samples
        sps = max(1, math.ceil(dt_sample / step - 1e-9))
        self.h = h = dt_sample / sps
        self.sps = sps
        self._steps_estimate = samples * sps
        prefix = "lie-poisson" if self.method.startswith("lie-poisson") else "top-splitting"
        k = SPLITTING_ORDERS[self.method[len(prefix):]]
        zero = np.zeros(3)
        i1, i2, i3 = inertia
        if top is not None:
            mass, length, g = top
            # the public function's own checks of the body and the top
            rigid.heavy_top_splitting(i1, i3, mass, length, g, np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]), h, 1,
                                      order=k, sample_every=1)
            # the constants exactly as heavy_top_splitting computes them
            self._consts = (check_inertia((i1, i1, i3))[1], 2, heavy_top_mgl(mass, length, g), zero, zero)
        else:
            rigid.lie_poisson(inertia, np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]), h, 1, order=k, sample_every=1)
            moments, inv_i = check_inertia(inertia)
            sym = symmetry_axis(moments)
            self._consts = (inv_i, -1 if sym is None else sym, 0.0, zero, zero)
        self._weights = composition_weights(k)
        self._split = split_run
        self._stepper = splitting_stepper(*self._consts, k)
        # chunks of samples per kernel call (at most 2e6 steps); one call when the run fits in one
        self._chunk = max(1, int(2e6 // sps))
        self._one_call = sps <= 2e6 and samples <= self._chunk

    def _setup_adaptive(self, inertia, rtol, top, mgl):
        if not (math.isfinite(rtol) and 1e-15 <= rtol < 1.0):
            raise ScenarioError(f"rtol = {rtol:g}: method dop853 needs 1e-15 <= rtol < 1")
        if not (inertia.shape == (3,) and np.all(np.isfinite(inertia)) and np.all(inertia > 0)):
            raise ScenarioError(f"inertia: {inertia.tolist()} kg m2; method dop853 needs 3 finite moments > 0")
        if top is not None:
            mgl = top[0] * top[1] * top[2]
        mgl = 0.0 if mgl is None else float(mgl)
        if not math.isfinite(mgl):
            raise ScenarioError(f"mgl: {mgl!r} N m; must be finite")
        from rotframe import limits
        from rotframe.rigid.adaptive import dop853_from

        self._max_steps = limits.current().max_steps  # read once: the limits in force at set-up
        self.rtol = rtol
        self._kernel = dop853_from
        self._p = np.zeros(10)
        self._p[:3] = inertia
        self._p[3] = mgl
        for i in range(3):  # the inverse moments, as dop853_kernel computes them
            self._p[i] = 1.0 / self._p[i]
        self._steps_estimate = 0.0

    def _state(self, L0, q0):
        L0 = np.asarray(L0, dtype=float)
        if L0.shape != (3,) or not np.isfinite(L0).all():
            raise ScenarioError(f"L0: {np.asarray(L0).tolist()}; must be 3 finite numbers (kg m2/s, body axes)")
        q0 = np.asarray(q0, dtype=float)
        if q0.shape != (4,) or not np.isfinite(q0).all() or not q0.any():
            raise ScenarioError(f"q0: {np.asarray(q0).tolist()}; must be 4 finite numbers (x, y, z, w), not all zero")
        return L0, q0

    def run(self, L0, q0):
        """(L, q) samples, (samples + 1, 3) and (samples + 1, 4), from ``L0`` (body axes) and ``q0``."""
        L0, q0 = self._state(L0, q0)
        if self.method == "dop853":
            return self._run_adaptive(L0, q0)
        return self._run_fixed(L0, q0)

    __call__ = run

    def _run_fixed(self, L0, q0):
        samples, sps, h = self.samples, self.sps, self.h
        if self._one_call:
            out_L = np.empty((samples + 1, 3))
            out_q = np.empty((samples + 1, 4))
            kept = self._split(*self._consts, L0, q0 / np.linalg.norm(q0), h, samples * sps, self._weights, sps,
                             out_L, out_q)
            out_q[0] = q0
            self.steps = samples * sps
            if kept < samples + 1:
                self._raise_fixed(kept - 1)
            return out_L, out_q
        # the loop of chunks, each from the last sample's state
        out_L = np.empty((samples + 1, 3))
        out_q = np.empty((samples + 1, 4))
        out_L[0], out_q[0] = L0, q0
        L, q, done = L0, q0, 0
        while done < samples:
            m = min(self._chunk, samples - done)
            try:
                if sps > 2e6:
                    n = 0
                    while n < sps - 1:
                        k = min(1_000_000, sps - 1 - n)
                        Ls, qs, _ = self._stepper(L, q, h, k, k)
                        L, q = Ls[-1], qs[-1]
                        n += k
                Ls, qs, _ = self._stepper(L, q, h, m * sps if sps <= 2e6 else 1, sps if sps <= 2e6 else 1)
            except IntegrationError:
                self._raise_fixed(done)
            out_L[done + 1:done + 1 + m] = Ls[1:]
            out_q[done + 1:done + 1 + m] = qs[1:]
            L, q = Ls[-1], qs[-1]
            done += m
        self.steps = samples * sps
        return out_L, out_q

    def _raise_fixed(self, good):
        t = float(self.times[good])
        raise IntegrationError(f"non-finite state after t = {t:.6g} s (method {self.method}); reduce the step",
                               t_reached=t, partial=None)

    def _run_adaptive(self, L0, q0):
        times = self.times
        # the run's size depends on the state: refuse, as rigid_dop853's callers do, a run past the limits
        steps = steps_estimate(self.inertia, L0, float(times[-1]), self.rtol, self._p[3])
        if not steps <= self._max_steps:
            from rotframe import limits

            limits.check_run(steps=steps, what="method dop853", remedy="shorten duration or loosen rtol")
        y0 = np.empty(7)
        y0[:3] = L0
        y0[3:] = q0
        out_L = np.empty((times.size, 3))
        out_q = np.empty((times.size, 4))
        rtol = self.rtol
        done, self.nfev, self.steps = self._kernel(y0, self._p, times, rtol, rtol, math.inf, out_L, out_q)
        if done < times.size:
            good = max(done, 1)
            t = float(times[good - 1])
            raise IntegrationError(f"rigid dop853: step size collapsed or non-finite state after t = {t:.6g} s",
                                   t_reached=t, partial=None)
        return out_L, out_q
