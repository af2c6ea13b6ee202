"""Repeated particle runs with everything prepared once (a few microseconds of overhead a run).

:func:`rotframe.particles.integrators.integrate_particles` checks its input, packs the
model, allocates output and event buffers and loads the kernel on every call:
some 70 microseconds, more than the integration of a short run costs. A
:class:`PreparedRun` does that once for a model, method, duration and sample
count, and each call then only copies the initial state in and calls the
compiled kernel (``drivers.run_fixed`` or ``drivers.run_dop853``, the same
kernels with the same arguments, so the results are bitwise those of
``integrate_particles``). For optimisation loops, shooting, Monte Carlo over
single particles and the bench. No events; a non-finite state raises
``IntegrationError``.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["PreparedRun"]


class PreparedRun:
    """Integrate ``n`` particles of ``model`` over ``duration`` with ``method``, many times.

    Parameters
    ----------
    model : ParticleModel
    method : str
        ``splitting``, ``splitting4``, ``rk4`` or ``dop853``.
    duration : float
        Simulated time (s), > 0.
    step : float, optional
        Step (s) of the fixed-step methods (default 1/20 of the sample interval);
        the step used divides the sample interval, as in ``integrate_particles``.
    rtol, atol : float
        Tolerances of ``dop853``; ``atol`` defaults, per call, to ``rtol`` times
        the initial state's scale (max(1, |r0|, |v0|)), as in ``integrate_particles``.
    samples : int
        Output samples after t = 0 (uniform in time).
    n : int
        Particles per call.

    Calling ``run(r0, v0)`` returns ``(r, v)``, arrays (samples + 1, n, 3),
    owned by the caller (fresh each call); ``times`` holds the sample times and
    ``nfev`` the force evaluations of particle 0 in the last call.
    """

    def __init__(self, model, method, duration, *, step=None, rtol=1e-10, atol=None, samples=1, n=1):
        from rotframe.errors import ScenarioError
        from rotframe.particles.integrators import METHODS

        if method not in METHODS or METHODS[method].kind not in ("fixed", "adaptive"):
            raise ScenarioError(f"method: {method!r}; allowed: splitting, splitting4, rk4, dop853")
        duration = float(duration)
        if not duration > 0:
            raise ScenarioError(f"duration: {duration} s; must be > 0")
        self.info = info = METHODS[method]
        self.samples = samples = max(1, int(samples))
        self.n = n = int(n)
        self.P = model.pack()
        self.wt, self.wv = model.omega.times, model.omega.values
        self.wint = model.omega.cumulative()
        dt = duration / samples
        self.times = np.arange(samples + 1) * dt
        self.times[-1] = duration
        self.rtol = float(rtol)
        self.atol = None if atol is None else float(atol)
        self.events = np.zeros((0, 5))
        self.alive = np.ones(n, dtype=np.bool_)
        self.ev = (np.full((n, 1), np.nan), np.zeros((n, 1, 3)), np.zeros((n, 1, 3)), np.zeros(n, dtype=np.int64),
                   np.zeros((n, 1), dtype=np.int64), 1)
        if info.kind == "fixed":
            h_req = float(step) if step else dt / 20.0
            if not h_req > 0:
                raise ScenarioError(f"step: {step}; must be > 0")
            self.sps = max(1, math.ceil(dt / h_req - 1e-9))
            self.h = dt / self.sps
        else:
            from rotframe.numerics.dop853 import coefficients

            self.tableau = coefficients()
            self.h_state = np.zeros(n)
            self.h0 = dt / 10.0
        self.run(np.zeros((n, 3)), np.zeros((n, 3)))  # load or compile the kernel now

    def run(self, r0, v0):
        """(r, v) samples (samples + 1, n, 3) from initial positions and velocities (n, 3) or (3,)."""
        from rotframe.particles import drivers as kernels
        n, samples = self.n, self.samples
        out_r = np.empty((samples + 1, n, 3))
        out_v = np.empty((samples + 1, n, 3))
        out_r[0] = r0
        out_v[0] = v0
        r = out_r[0].copy()
        v = out_v[0].copy()
        alive = self.alive
        alive[:] = True
        ev = self.ev
        ev[3][:] = 0
        if self.info.kind == "fixed":
            n_done, bad, self.nfev = kernels.run_fixed(self.info.code, r, v, alive, 0.0, self.h, self.sps, samples, self.P,
                                               self.wt, self.wv, self.wint, self.events, out_r[1:], out_v[1:], *ev)
        else:
            atol = self.atol
            if atol is None:
                atol = self.rtol * max(1.0, float(np.abs(r).max()), float(np.abs(v).max()))
            self.h_state[:] = 0.0
            A, B, C, E3, E5 = self.tableau
            n_done, bad, self.nfev, _ = kernels.run_dop853(r, v, alive, 0.0, self.times[1:], self.P, self.wt, self.wv,
                                                   self.rtol, atol, self.h0, A, B, C, E3, E5, self.events,
                                                   out_r[1:], out_v[1:], *ev, self.h_state)
        if n_done < samples or bad >= 0:
            from rotframe.errors import IntegrationError

            t = float(self.times[n_done])
            raise IntegrationError(f"non-finite state of particle {bad} after t = {t:.6g} s (method {self.info.name})",
                                   t_reached=t, partial=None)
        return out_r, out_v

    __call__ = run
