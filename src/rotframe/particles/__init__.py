"""Point particles in a rotating frame: force models, compiled kernels, integrators.

Layer 2 of the house (see ``docs/architecture.md``): imports only
:mod:`rotframe.numerics`, :mod:`rotframe.errors` and :mod:`rotframe.limits`.

- :mod:`~rotframe.particles.model`: the terms of a scene (:class:`ParticleModel`).
- :mod:`~rotframe.particles.packed`: the packed parameter vector, the kernels' model and state.
- :mod:`~rotframe.particles.schedule`: the rotation-rate schedule w(t), compiled.
- :mod:`~rotframe.particles.forces`: compiled accelerations (one source for every method).
- :mod:`~rotframe.particles.kernels`: compiled fixed-step one-step maps (splitting, splitting4, rk4).
- :mod:`~rotframe.particles.dop853_steps`: one compiled Dormand-Prince 8(5,3) step.
- :mod:`~rotframe.particles.events`: event functions, crossings, their location by bisection.
- :mod:`~rotframe.particles.drivers`: compiled ensemble drivers (fixed-step and DOP853).
- :mod:`~rotframe.particles.integrators`: the method registry and chunked driver.
- :mod:`~rotframe.particles.linear`: exact flow of linear constant-coefficient scenes.
- :mod:`~rotframe.particles.ensemble`: many particles at once, on a thread pool.
- :mod:`~rotframe.particles.prepared`: a run set up once and repeated cheaply.
"""
