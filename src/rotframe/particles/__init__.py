"""Point particles in a rotating frame: force models, compiled kernels, integrators.

Layer 2 of the house (see ``docs/architecture.md``): imports only
`rotframe.numerics`, [`rotframe.errors`][rotframe.errors] and `rotframe.limits`.

- [`model`][rotframe.particles.model]: the terms of a scene (`ParticleModel`).
- `packed`: the packed parameter vector, the kernels' model and state.
- `schedule`: the rotation-rate schedule w(t), compiled.
- `forces`: compiled accelerations (one source for every method).
- `kernels`: compiled fixed-step one-step maps (splitting, splitting4, rk4).
- `dop853_particles`: the particle on the one DOP853 loop (`rotframe.numerics.dop853_loop`).
- `events`: event functions, crossings, their location by bisection.
- `drivers`: compiled ensemble drivers (fixed-step and DOP853).
- [`integrators`][rotframe.particles.integrators]: the method registry and chunked driver.
- `linear`: exact flow of linear constant-coefficient scenes.
- `ensemble`: many particles at once, on a thread pool.
- [`prepared`][rotframe.particles.prepared]: a run set up once and repeated cheaply.
"""
