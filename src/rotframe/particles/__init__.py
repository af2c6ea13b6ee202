"""Point particles in a rotating frame: force models, compiled kernels, integrators.

Layer 2 of the house (see ``docs/architecture.md``): imports only
:mod:`rotframe.numerics`, :mod:`rotframe.errors` and :mod:`rotframe.limits`.

- :mod:`~rotframe.particles.model`: the terms of a scene (:class:`ParticleModel`).
- :mod:`~rotframe.particles.kernels`: compiled accelerations and one-step maps.
- :mod:`~rotframe.particles.integrators`: the method registry and chunked driver.
- :mod:`~rotframe.particles.linear`: exact flow of linear constant-coefficient scenes.
- :mod:`~rotframe.particles.ensemble`: many particles at once, on a thread pool.
- :mod:`~rotframe.particles.prepared`: a run set up once and repeated cheaply.
"""
