"""Repeated particle runs with everything prepared once (a few microseconds of overhead a run).

:func:`rotframe.particles.integrators.integrate_particles` checks its input, packs the
model, allocates output and event buffers and loads the kernel on every call:
some 70 microseconds, more than the integration of a short run costs. A
:class:`PreparedRun` does that once for a model, method, duration and sample
count (a :class:`rotframe.particles.chunked.KernelSetup`, the one set-up of
``integrate_particles`` too), and each call then only copies the initial state
in and makes one call of the compiled driver with the same arguments, so the
results are bitwise those of ``integrate_particles``. Method ``exact`` (a linear or
force-free model) keeps the matrices of the exact flow for the sample grid, made
once, and each call is one matrix product with the initial states: it agrees with
``integrate_particles`` to round-off (the products are grouped differently). For optimisation loops,
shooting, Monte Carlo over single particles and the bench. No events; a
non-finite state raises ``IntegrationError``.
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
        ``rotation-splitting``, ``rotation-splitting4``, ``rk4``, ``dop853`` (or an alias,
        :data:`rotframe.particles.integrators.ALIASES`), or ``exact`` for a model with an
        exact flow (linear or force-free: ``ParticleModel.has_exact_flow``). ``exact``
        makes the flow's matrices for the sample grid once, here; each call then only
        multiplies them into the initial states.
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

    Notes
    -----
    Calling ``run(r0, v0)`` returns ``(r, v)``, arrays (samples + 1, n, 3),
    owned by the caller (fresh each call); ``times`` holds the sample times and
    ``nfev`` the force evaluations of particle 0 in the last call.
    """

    def __init__(self, model, method, duration, *, step=None, rtol=1e-10, atol=None, samples=1, n=1):
        from rotframe.errors import ScenarioError
        from rotframe.particles.chunked import KernelSetup
        from rotframe.particles.integrators import METHODS, canonical_method
        from rotframe.particles.trajectory import EventBuffers

        method = canonical_method(method)
        duration = float(duration)
        if not duration > 0:
            raise ScenarioError(f"duration: {duration} s; must be > 0")
        self.info = METHODS[method]
        self.samples = samples = max(1, int(samples))
        self.n = n = int(n)
        self.nfev = 0
        if self.info.kind == "exact":
            from rotframe.particles.integrators import exact_times
            from rotframe.particles.linear import ExactFlow

            if not model.has_exact_flow:
                raise ScenarioError(f"method: 'exact' needs a linear or force-free model "
                                    f"({'; '.join(model.nonlinear_reasons())})")
            self.times = exact_times(duration, samples)
            with np.errstate(all="ignore"):  # an overflow (an unstable model run far) is caught per call
                phi = ExactFlow(model, self.times).matrices()  # (K, 7, 7)
            # out[p, k] = s0[p] @ phi[k]^T: one matrix product makes every sample's (r, v) at once
            self.phi_t = np.ascontiguousarray(np.transpose(phi[:, 0:6, :], (2, 0, 1)).reshape(7, -1))  # (7, K * 6)
            self.phi_finite = bool(np.isfinite(self.phi_t).all())  # else each product is made under errstate
            self.s0 = np.ones((n, 7))
            return
        self.setup = KernelSetup(model, self.info, duration, samples, step=step, rtol=rtol, atol=atol)
        self.times = self.setup.times
        self.alive = np.ones(n, dtype=np.bool_)
        self.evb = EventBuffers(n, 1)
        self.h_state = np.zeros(n)
        self.run(np.zeros((n, 3)), np.zeros((n, 3)))  # load or compile the kernel now

    def _run_exact(self, r0, v0):
        """The exact flow's states: one product of the kept matrices with the initial states."""
        s0 = self.s0
        s0[:, 0:3] = r0
        s0[:, 3:6] = v0
        if self.phi_finite:
            out = np.dot(s0, self.phi_t)  # (n, K * 6)
        else:
            with np.errstate(all="ignore"):
                out = np.dot(s0, self.phi_t)
        out = out.reshape(self.n, self.samples + 1, 6).transpose(1, 0, 2)  # (K, n, 6), a view
        if not math.isfinite(float(np.add.reduce(out, axis=None))):  # one reduction: inf or nan anywhere
            finite = np.all(np.isfinite(out), axis=(1, 2))
            if not finite.all():
                from rotframe.errors import IntegrationError

                k = int(np.argmin(finite))
                raise IntegrationError(f"exact propagator produced a non-finite state at t = {self.times[k]:.6g} s",
                                       t_reached=float(self.times[max(k - 1, 0)]), partial=None)
        return out[:, :, 0:3], out[:, :, 3:6]

    def run(self, r0, v0):
        """(r, v) samples (samples + 1, n, 3) from initial positions and velocities (n, 3) or (3,)."""
        if self.info.kind == "exact":
            return self._run_exact(r0, v0)
        n, samples = self.n, self.samples
        out_r = np.empty((samples + 1, n, 3))
        out_v = np.empty((samples + 1, n, 3))
        out_r[0] = r0
        out_v[0] = v0
        r = out_r[0].copy()
        v = out_v[0].copy()
        self.alive[:] = True
        self.evb.reset()
        self.h_state[:] = 0.0
        atol = self.setup.abs_tol(r, v) if self.info.kind == "adaptive" else 0.0
        n_done, bad, self.nfev, _ = self.setup.call(r, v, self.alive, 0, samples, out_r[1:], out_v[1:], self.evb,
                                                    atol, self.h_state)
        if n_done < samples or bad >= 0:
            from rotframe.errors import IntegrationError

            t = float(self.times[n_done])
            raise IntegrationError(f"non-finite state of particle {bad} after t = {t:.6g} s (method {self.info.name})",
                                   t_reached=t, partial=None)
        return out_r, out_v

    __call__ = run
