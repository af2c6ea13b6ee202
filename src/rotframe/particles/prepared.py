"""Repeated particle runs with everything prepared once (a few microseconds of overhead a run).

[`rotframe.particles.integrators.integrate_particles`][rotframe.particles.integrators.integrate_particles] checks its input, packs the
model, allocates output and event buffers and loads the kernel on every call:
some 70 microseconds, more than the integration of a short run costs. A
[`PreparedRun`][rotframe.particles.prepared.PreparedRun] does that once for a model, method, duration and sample
count (a `rotframe.particles.chunked.KernelSetup`, the one set-up of
``integrate_particles`` too), and each call then only copies the initial state
in and makes one call of the compiled driver with the same arguments, so the
results are bitwise those of ``integrate_particles``. Method ``exact`` (a linear or
force-free model) keeps the matrices of the exact flow for the sample grid, made
once, and each call multiplies them into the initial states in one compiled loop
(`rotframe.particles.exact_kernel`): it agrees with ``integrate_particles`` to
round-off (the products are grouped differently). For optimisation loops,
shooting, Monte Carlo over single particles and the bench. No events; a
non-finite state raises ``IntegrationError``.
"""

from __future__ import annotations

import numpy as np

__all__ = ["PreparedRun"]


class PreparedRun:
    """Integrate ``n`` particles of ``model`` over ``duration`` with ``method``, many times.

    Parameters
    ----------
    model : ParticleModel
    method : str
        ``rotation-splitting``, ``rotation-splitting4``, ``rk4``, ``dop853`` (or an alias,
        `rotframe.particles.integrators.ALIASES`), or ``exact`` for a model with an
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
    steady : (12,) array, optional
        ``dop853`` on the steady loop with these parameters (`rotframe.particles.chunked.KernelSetup`): the engine's
        steady problems prepared (`rotframe.problem.prepared`), ``model`` the same problem.

    Notes
    -----
    Calling ``run(r0, v0)`` returns ``(r, v)``, arrays (samples + 1, n, 3),
    owned by the caller (fresh each call); ``times`` holds the sample times and
    ``nfev`` and ``steps`` the force evaluations and steps of particle 0 in the last call.
    """

    def __init__(self, model, method, duration, *, step=None, rtol=1e-10, atol=None, samples=1, n=1, steady=None):
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
        self.nfev = self.steps = 0
        if self.info.step == "exact":
            from rotframe.particles.chunked import sample_times
            from rotframe.particles.linear import ExactFlow

            if not model.has_exact_flow:
                raise ScenarioError(f"method: 'exact' needs a linear or force-free model "
                                    f"({'; '.join(model.nonlinear_reasons())})")
            self.times = sample_times(duration, samples)
            with np.errstate(all="ignore"):  # an overflow (an unstable model run far) is caught per call
                phi = ExactFlow(model, self.times).matrices()  # (K, 7, 7)
            self.phi_t = np.ascontiguousarray(np.transpose(phi[:, 0:6, :], (0, 2, 1)))  # (K, 7, 6)
            from rotframe.particles.exact_kernel import apply_flow

            self._apply = apply_flow
            apply_flow(self.phi_t, np.zeros((n, 3)), np.zeros((n, 3)))  # load or compile the kernel now
            return
        self.setup = KernelSetup(model, self.info, duration, samples, step=step, rtol=rtol, atol=atol, steady=steady)
        self.times = self.setup.times
        self.alive = np.ones(n, dtype=np.bool_)
        self.evb = EventBuffers(n, 1)
        self.h_state = np.zeros(n)
        self.setup.warm_up()  # load or compile the kernel now (an empty call: no state that the model may refuse)

    def _run_exact(self, r0, v0):
        """The exact flow's states: the kept matrices times the initial states, one compiled loop."""
        r0 = np.asarray(r0, dtype=np.float64)
        v0 = np.asarray(v0, dtype=np.float64)
        if r0.ndim == 1:
            r0 = r0[None]
        if v0.ndim == 1:
            v0 = v0[None]
        if r0.shape != (self.n, 3) or v0.shape != (self.n, 3):
            raise _bad_state(r0, v0, self.n)
        r, v, k_bad = self._apply(self.phi_t, r0, v0)
        if k_bad >= 0:
            from rotframe.errors import IntegrationError

            raise IntegrationError(f"exact propagator produced a non-finite state at t = {self.times[k_bad]:.6g} s",
                                   t_reached=float(self.times[max(k_bad - 1, 0)]), partial=None)
        return r, v

    def run(self, r0, v0):
        """(r, v) samples (samples + 1, n, 3) from initial positions and velocities (n, 3) or (3,)."""
        if self.info.step == "exact":
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
        atol = self.setup.abs_tol(r, v) if self.info.step == "adaptive" else None
        n_done, bad, self.nfev, self.steps = self.setup.call(r, v, self.alive, 0, samples, out_r[1:], out_v[1:],
                                                              self.evb, atol, self.h_state)
        if n_done < samples or bad >= 0:
            from rotframe.errors import IntegrationError

            t = float(self.times[n_done])
            raise IntegrationError(f"non-finite state of particle {bad} after t = {t:.6g} s (method {self.info.name})",
                                   t_reached=t, partial=None)
        return out_r, out_v

    __call__ = run


def _bad_state(r0, v0, n):
    from rotframe.errors import ScenarioError

    return ScenarioError(f"initial state: r0 and v0 must be (3,) or ({n}, 3) for this prepared run, "
                         f"got {r0.shape} and {v0.shape}")
