"""GPU ensemble throughput (``rotframe bench gpu``): rotframe's GPU door beside hand-written kernels and JAX.

The work is the CPU ensemble bench's (`rotframe.app.bench.throughput`): gravity +
constant Coriolis, the exact-rotation splitting and classical RK4 at a fixed step,
with the ground event watched every step and without, every particle started
high enough that none lands (so all do the same steps; checked). Rows, each a
call from host arrays to host arrays (uploads, the kernel, downloads), the best
of repeated calls after one that compiles:

- rotframe: ``integrate_ensemble(..., device="gpu")``, the public door
  ([`rotframe.particles.gpu`][rotframe.particles.gpu]: the CPU kernels' Python source compiled for the GPU);
- hand-written, numba CUDA: the CPU ceiling's own hand-written per-particle loop
  (`rotframe.app.bench.ceiling`, state in registers, the method and the event
  flag constants of each compiled kernel), one thread per particle;
- hand-written, CUDA C (`_CUDA_C`, compiled by NVRTC through CuPy's ``RawKernel``)
  where CuPy is installed: the same steps written in C;
- JAX: ``jit(vmap(particle))`` with ``lax.fori_loop`` over the same steps in
  float64 (a landed particle masked by ``where``), on JAX's default device.

Then rotframe's kernel and the hand-written numba one alone, launched on arrays
already on the GPU (no transfers; rotframe's through
[`rotframe.particles.gpu.GpuLaunch`][rotframe.particles.gpu.GpuLaunch]).

``of_ceiling`` is rotframe's rate over the faster hand-written kernel's (the
goal is 0.5 or more), ``kernel_of_ceiling`` the same for the kernels alone,
``vs_jax_vmap`` over JAX's where JAX ran on the same GPU
(the goal is 10 or more; null with a note where JAX ran elsewhere or is not
installed). ``same_work``: every final state agrees with the numba kernel's to
round-off and no particle landed. On numba's CUDA simulator (``NUMBA_ENABLE_CUDASIM=1``)
the rows run a handful of particles, to test this code, and time nothing of
meaning (``simulator`` true).
"""

from __future__ import annotations

import math
import types

import numpy as np

from rotframe.app.bench.throughput import best_interleaved

__all__ = ["gpu_rows", "CEILING_GOAL", "JAX_GOAL", "USER_ROW", "BUILTIN_ROW"]

#: issue 26's goals: rotframe's GPU rate over the hand-written kernel's, and over JAX vmap's on the same GPU
CEILING_GOAL = 0.5
JAX_GOAL = 10.0


def gpu_rows(quick, each=None):
    """The rows of ``rotframe bench gpu`` (see the module docstring); ScenarioError without a GPU.

    ``each`` (optional) is called with the rows so far after every case, so that a run cut short
    (a lent machine's minutes) keeps the cases it finished (`tools/device_check.sh`).
    """
    from numba import config

    from rotframe.errors import ScenarioError
    from rotframe.particles.threads import gpu_available

    if not gpu_available():
        raise ScenarioError("bench: 'gpu' needs a CUDA GPU, and none is available here (numba.cuda.is_available() "
                            "is False); the other benchmarks run without one")
    simulator = bool(config.ENABLE_CUDASIM)
    if simulator:
        n, steps = 16, 32
    else:
        n, steps = (2**16, 1024) if quick else (2**20, 16384)
    name = _gpu_name()
    rows = []
    for method, rk4 in (("rotation-splitting", False), ("rk4", True)):
        for event in (True, False):
            for r in _case(method, rk4, event, n, steps, quick or simulator):
                rows.append({**r, "gpu": name, "simulator": simulator})
            if each is not None:
                each(rows)
    return rows


def _gpu_name():
    from numba import cuda

    try:
        name = cuda.get_current_device().name
    except Exception:  # noqa: BLE001 -- the simulator's device may have no name
        return "CUDA simulator"
    return name.decode() if isinstance(name, bytes) else str(name)


def _case(method, rk4, event, n, steps, quick):
    """The rows of one method, with or without the ground event."""
    from rotframe.app.bench import ceiling
    from rotframe.app.bench.throughput import same_state
    from rotframe.particles.ensemble import integrate_ensemble
    from rotframe.particles.integrators import Event
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    g = (0.0, 0.0, -9.81)
    w = (0.0, 4.6e-5, 5.7e-5)
    h = 1e-3
    duration = steps * h
    rng = np.random.default_rng(2)
    # 16 s of fall is 1.3 km: start at 10 km, so that no particle lands
    r0 = rng.normal(size=(n, 3)) + [0.0, 0.0, 1e4]
    v0 = rng.normal(size=(n, 3))
    model = ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.constant(np.array(w)), g=np.array(g))
    ground = Event("ground", "r", 2, 0.0, -1, True) if event else None
    c, s = ceiling.rotation_cos_sin(w, h)
    run = {"step": h, "samples": 16}  # the ensemble's sample count: its step is h (steps is a multiple of 16)

    def ours():
        return integrate_ensemble(model, r0, v0, duration, ground, method=method, run=run, device="gpu")

    def ours_state(res):
        return res.state, int(np.sum(np.isfinite(res.t_event)))

    def hand_state(rv):  # every particle starts 10 km up and falls 1.3 km at most: none lands (ours counts)
        return np.concatenate(rv, axis=1), 0

    numba_kernel = _numba_ceiling(rk4, event)
    # (name, the timed call from host arrays to host arrays, its result as ((N, 6) states, particles landed))
    cases = [("rotframe integrate_ensemble(device='gpu')", ours, ours_state),
             ("hand-written numba CUDA kernel", lambda: _host_to_host(numba_kernel, r0, v0, g, w, c, s, h, steps),
              hand_state),
             (USER_ROW, _user_problem(method, event, r0, v0, g, w, h, duration), _user_state),
             (BUILTIN_ROW, _user_problem(method, event, r0, v0, g, w, h, duration, builtin=True), _user_state)]
    # rotframe.simulate always models the frame's centrifugal term: its scene twin, for the user row's ratio and check
    spun = ParticleModel(("gravity", "coriolis", "centrifugal"), omega=model.omega, g=np.array(g))
    cases.append((SCENE_TWIN_ROW, lambda: integrate_ensemble(spun, r0, v0, duration, ground, method=method, run=run,
                                                             device="gpu"), ours_state))
    notes = []
    cuda_c = _cuda_c_ceiling(rk4, event, notes)
    if cuda_c is not None:
        cases.append(("hand-written CUDA C kernel (CuPy)", lambda: cuda_c(r0, v0, g, w, c, s, h, steps), hand_state))
    y0 = np.concatenate([r0, v0], axis=1)  # JAX's own layout, made once
    jax_run, jax_device = _jax_vmap(rk4, event, g, w, c, s, h, steps, notes)
    if jax_run is not None:
        cases.append((f"JAX jit(vmap) on {jax_device}", lambda: jax_run(y0), lambda out: (out, 0)))
    results = []
    for case in list(cases):  # the first call compiles each, and gives the states to compare
        try:
            results.append(case[2](case[1]()))
        except Exception as exc:  # noqa: BLE001 -- a peer that cannot run here is a note, not a failed bench
            if case[0].startswith(("rotframe", "hand-written numba")):
                raise
            cases.remove(case)
            notes.append(f"{case[0]}: failed here ({type(exc).__name__}: {exc})"[:300])
    ref = results[1][0]
    budget, rounds = (0.5, 3) if quick else (3.0, 10)
    walls = best_interleaved([fn for _, fn, _ in cases], budget, rounds)
    total = n * steps
    label = f"{method}{' + ground event' if event else ''}"
    what = f"{label}, gravity + Coriolis, {n} particles x {steps} steps of {h:g} s, fp64"
    rows = []
    for (name, _, _), (state, landed), wall in zip(cases, results, walls):
        same, rel, note = same_state(state, landed, ref)
        rows.append({"scenario": "gpu-ensemble", "method": f"{name}: {label}",
                     "setting": what + ", host arrays in and out", "wall_s": wall, "error": math.nan,
                     "error_kind": "throughput (best of repeats)", "nfev": int(total),
                     "particle_steps_per_s": total / wall, "integrator": method, "event": event,
                     "same_work": same, "same_work_max_rel": rel, "same_work_note": note})
    alone = _kernels_alone(model, duration, ground, method, run, numba_kernel, r0, v0, (g, w, c, s, h, steps),
                           budget, rounds)
    for name, wall in alone:
        rows.append({"scenario": "gpu-ensemble", "method": f"{name}: {label}",
                     "setting": what + ", the kernel alone on arrays already on the GPU", "wall_s": wall,
                     "error": math.nan, "error_kind": "throughput (best of repeats)", "nfev": int(total),
                     "particle_steps_per_s": total / wall, "integrator": method, "event": event, "kernel_alone": True})
    # the faster hand-written kernel that did the same work (the numba one is the reference, so it always counts)
    ceiling_rate = max(r["particle_steps_per_s"] for r in rows if r["method"].startswith("hand-written")
                       and r.get("same_work"))
    mine = rows[0]
    mine["of_ceiling"] = mine["particle_steps_per_s"] / ceiling_rate
    mine["kernel_of_ceiling"] = alone[0][1] / alone[1][1]  # rates: ours over the hand-written kernel's
    mine["ceiling_goal"] = CEILING_GOAL
    mine["ceiling_goal_met"] = bool(mine["of_ceiling"] >= CEILING_GOAL)
    jax_rows = [r for r in rows if r["method"].startswith("JAX")]
    if jax_rows and jax_device in ("gpu", "cuda"):
        mine["vs_jax_vmap"] = mine["particle_steps_per_s"] / jax_rows[0]["particle_steps_per_s"]
        mine["jax_goal"] = JAX_GOAL
        mine["jax_goal_met"] = bool(mine["vs_jax_vmap"] >= JAX_GOAL)
    else:
        mine["vs_jax_vmap"] = None
        if jax_rows:
            notes.append(f"JAX ran on {jax_device}, not this GPU: no ratio")
    user = next(r for r in rows if r["method"].startswith(USER_ROW))
    twin = next(r for r in rows if r["method"].startswith(SCENE_TWIN_ROW))
    twin_state = results[[name for name, _, _ in cases].index(SCENE_TWIN_ROW)][0]
    twin["same_work"], twin["same_work_max_rel"], twin["same_work_note"] = True, 0.0, "the user row's reference"
    user_state, user_landed = results[[name for name, _, _ in cases].index(USER_ROW)]
    user["same_work"], user["same_work_max_rel"], user["same_work_note"] = same_state(user_state, user_landed,
                                                                                       twin_state)
    user["same_work_note"] = "against the scene twin (+ centrifugal): " + user["same_work_note"]
    user["of_scene_gpu"] = user["particle_steps_per_s"] / twin["particle_steps_per_s"]
    builtin = next(r for r in rows if r["method"].startswith(BUILTIN_ROW))
    builtin_state, builtin_landed = results[[name for name, _, _ in cases].index(BUILTIN_ROW)]
    builtin["same_work"], builtin["same_work_max_rel"], note = same_state(builtin_state, builtin_landed, twin_state)
    builtin["same_work_note"] = "against the scene twin (+ centrifugal): " + note
    builtin["builtin_of_scene_gpu"] = builtin["particle_steps_per_s"] / twin["particle_steps_per_s"]
    mine["notes"] = "; ".join(notes)
    return rows


#: the row of a user's problem: the same work through ``rotframe.simulate(device="gpu")`` (the frame's centrifugal
#: term included, as simulate always models it)
USER_ROW = "rotframe.simulate(device='gpu'), user force and event"
#: the same work through ``rotframe.simulate(device="gpu")`` with the built-in terms (`rotframe.forces.gravity`, the
#: built-in crossing), one sample: the engine gives it to the scenes' GPU kernel (`rotframe.problem.steady`)
BUILTIN_ROW = "rotframe.simulate(device='gpu', samples=1), built-in terms"
#: the scenes' ensemble of the same terms as the user row (gravity, Coriolis, centrifugal): its reference
SCENE_TWIN_ROW = "rotframe integrate_ensemble(device='gpu'), + centrifugal"


def _user_problem(method, event, r0, v0, g, w, h, duration, builtin=False):
    """The same work as a user's problem: gravity as a force of the user's, the ground as an event of the user's;
    with ``builtin``, gravity and the ground as `rotframe.forces.gravity` and `rotframe.events.crossing`.

    Through the public door, ``rotframe.simulate`` (`rotframe.problem.gpu`; with ``builtin``, the steady
    specialisation that `rotframe.problem.steady` chooses from the terms): the frame's Coriolis term is rotframe's,
    from ``omega``; one sample at the end (the ensemble's calls keep no path).
    """
    import rotframe
    from rotframe import limits

    gx, gy, gz = g

    def gravity(t, r, v):
        return gx, gy, gz

    def ground(t, r, v):
        return r[2]

    ground.terminal = True
    ground.direction = -1
    force = gravity
    if builtin:
        from rotframe.events import crossing
        from rotframe.forces import gravity as builtin_gravity

        force, ground = builtin_gravity(g), crossing(2, 0.0, direction=-1, terminal=True, name="ground")
    events = [ground] if event else []
    work = limits.current().with_overrides(max_steps=math.inf)

    def call():
        with limits.applied(work):
            return rotframe.simulate(omega=list(w), r0=r0, v0=v0, duration=duration, forces=[force], events=events,
                                     method=method, step=h, samples=1, device="gpu", max_events=1)

    return call


def _user_state(res):
    traj = res.trajectory
    landed = sum(len(t) for t in traj.event_times.get("ground", []))
    return np.concatenate([traj.r[-1], traj.v[-1]], axis=1), int(landed)


def _kernels_alone(model, duration, event, method, run, hand, r0, v0, hand_args, budget, rounds):
    """``[(name, wall), ...]``: rotframe's kernel and the hand-written one alone, on arrays already on the GPU.

    No transfers: each launch starts from the same uploaded initial state (ours writes
    other arrays; the hand-written kernel advances its own copy, so each of its launches
    first copies the initial state on the GPU, a few hundred microseconds, counted
    against it) and is timed to its end (``cuda.synchronize``).
    """
    from numba import cuda

    from rotframe.particles.gpu import GpuLaunch, launch_shape

    launch = GpuLaunch(model, duration, event, method=method, run=run)
    n = len(r0)
    d_r0, d_v0 = cuda.to_device(r0), cuda.to_device(v0)
    out, ev_t = cuda.device_array((n, 6)), cuda.device_array(n)
    r, v = cuda.device_array_like(d_r0), cuda.device_array_like(d_v0)
    shape = launch_shape(n)

    def ours():
        launch(d_r0, d_v0, out, ev_t)
        cuda.synchronize()

    def theirs():
        r.copy_to_device(d_r0)
        v.copy_to_device(d_v0)
        hand[shape](r, v, *hand_args)
        cuda.synchronize()

    ours()
    theirs()
    walls = best_interleaved([theirs, ours], budget, rounds)
    return [("hand-written numba CUDA kernel alone", walls[0]), ("rotframe kernel alone (GpuLaunch)", walls[1])]


def _numba_ceiling_source(r, v, g, w, c, s, h, steps):
    """One thread per particle of the CPU ceiling's loop (``particle``, ``RK4`` and ``GROUND`` bound per copy)."""
    p = cuda.grid(1)  # noqa: F821 -- bound to numba.cuda in the compiled copy
    if p < r.shape[0]:
        particle(r, v, g, w, c, s, h, steps, p, RK4, GROUND)  # noqa: F821


def _numba_ceiling(rk4, ground):
    """The CPU ceiling's hand-written per-particle loop as a CUDA kernel, its flags constants."""
    from numba import cuda

    from rotframe.app.bench import ceiling
    from rotframe.particles.gpu import device_function

    fn = _numba_ceiling_source
    names = dict(fn.__globals__, cuda=cuda, particle=device_function(ceiling._particle), RK4=bool(rk4),
                 GROUND=bool(ground))
    return cuda.jit(types.FunctionType(fn.__code__, names, "rotframe_bench_ceiling"))


def _host_to_host(kernel, r0, v0, g, w, c, s, h, steps):
    """A numba CUDA kernel's call from host arrays to host arrays: the final ``(r, v)``."""
    from numba import cuda

    from rotframe.particles.gpu import launch_shape

    r, v = cuda.to_device(r0), cuda.to_device(v0)
    kernel[launch_shape(len(r0))](r, v, g, w, c, s, h, steps)
    return r.copy_to_host(), v.copy_to_host()


#: the same steps in CUDA C: one thread per particle, the state in registers; RK4 and GROUND set per compile
_CUDA_C = r"""
__device__ __forceinline__ void acc(double vx, double vy, double vz, double gx, double gy, double gz,
                                    double wx, double wy, double wz, double* a) {
    a[0] = gx - 2.0 * (wy * vz - wz * vy);
    a[1] = gy - 2.0 * (wz * vx - wx * vz);
    a[2] = gz - 2.0 * (wx * vy - wy * vx);
}

extern "C" __global__ void ceiling(double* r, double* v, long long n, double gx, double gy, double gz,
                                   double wx, double wy, double wz, double c, double s, double h, long long steps) {
    long long p = blockDim.x * (long long)blockIdx.x + threadIdx.x;
    if (p >= n) return;
    double x = r[3 * p], y = r[3 * p + 1], z = r[3 * p + 2];
    double vx = v[3 * p], vy = v[3 * p + 1], vz = v[3 * p + 2];
    double wn = sqrt(wx * wx + wy * wy + wz * wz), ax = wx / wn, ay = wy / wn, az = wz / wn, hh = 0.5 * h;
    for (long long k = 0; k < steps; ++k) {
        double z_old = z;
#if RK4
        double a1[3], a2[3], a3[3], a4[3];
        acc(vx, vy, vz, gx, gy, gz, wx, wy, wz, a1);
        double v2x = vx + hh * a1[0], v2y = vy + hh * a1[1], v2z = vz + hh * a1[2];
        acc(v2x, v2y, v2z, gx, gy, gz, wx, wy, wz, a2);
        double v3x = vx + hh * a2[0], v3y = vy + hh * a2[1], v3z = vz + hh * a2[2];
        acc(v3x, v3y, v3z, gx, gy, gz, wx, wy, wz, a3);
        double v4x = vx + h * a3[0], v4y = vy + h * a3[1], v4z = vz + h * a3[2];
        acc(v4x, v4y, v4z, gx, gy, gz, wx, wy, wz, a4);
        double h6 = h / 6.0;
        x += h6 * (vx + 2.0 * v2x + 2.0 * v3x + v4x);
        y += h6 * (vy + 2.0 * v2y + 2.0 * v3y + v4y);
        z += h6 * (vz + 2.0 * v2z + 2.0 * v3z + v4z);
        vx += h6 * (a1[0] + 2.0 * a2[0] + 2.0 * a3[0] + a4[0]);
        vy += h6 * (a1[1] + 2.0 * a2[1] + 2.0 * a3[1] + a4[1]);
        vz += h6 * (a1[2] + 2.0 * a2[2] + 2.0 * a3[2] + a4[2]);
#else
        x += hh * vx; y += hh * vy; z += hh * vz;
        vx += hh * gx; vy += hh * gy; vz += hh * gz;
        double d = ax * vx + ay * vy + az * vz;
        double cx = ay * vz - az * vy, cy = az * vx - ax * vz, cz = ax * vy - ay * vx;
        double nx = vx * c + cx * s + ax * d * (1 - c), ny = vy * c + cy * s + ay * d * (1 - c),
               nz = vz * c + cz * s + az * d * (1 - c);
        vx = nx + hh * gx; vy = ny + hh * gy; vz = nz + hh * gz;
        x += hh * vx; y += hh * vy; z += hh * vz;
#endif
#if GROUND
        if (z_old > 0.0 && z <= 0.0) break;
#endif
    }
    r[3 * p] = x; r[3 * p + 1] = y; r[3 * p + 2] = z;
    v[3 * p] = vx; v[3 * p + 1] = vy; v[3 * p + 2] = vz;
}
"""


def _cuda_c_ceiling(rk4, ground, notes):
    """The CUDA C kernel as a host-to-host call, or None (with a note) where CuPy cannot run it."""
    from numba import config

    if config.ENABLE_CUDASIM:
        notes.append("CUDA C kernel: not on the simulator")
        return None
    from rotframe.particles.gpu import launch_shape

    try:
        import cupy
    except ImportError:
        notes.append("CUDA C kernel: CuPy is not installed")
        return None
    try:
        kernel = cupy.RawKernel(_CUDA_C, "ceiling", options=(f"-DRK4={int(rk4)}", f"-DGROUND={int(ground)}"))
    except Exception as exc:  # noqa: BLE001 -- no NVRTC, or a driver CuPy does not support
        notes.append(f"CUDA C kernel: CuPy could not compile it ({type(exc).__name__}: {exc})"[:200])
        return None

    def call(r0, v0, g, w, c, s, h, steps):
        r, v = cupy.asarray(r0), cupy.asarray(v0)
        n = len(r0)
        blocks, threads = launch_shape(n)
        kernel((blocks,), (threads,), (r, v, np.int64(n), *map(np.float64, g), *map(np.float64, w),
                                       np.float64(c), np.float64(s), np.float64(h), np.int64(steps)))
        return cupy.asnumpy(r), cupy.asnumpy(v)

    return call


def _jax_vmap(rk4, ground, g, w, c, s, h, steps, notes):
    """(call, device platform) of the same steps in JAX, ``jit(vmap(...))`` in float64; (None, None) without JAX."""
    try:
        import jax
        import jax.numpy as jnp
    except ImportError:
        notes.append("JAX: not installed (the bench extra)")
        return None, None
    jax.config.update("jax_enable_x64", True)
    gx, gy, gz = g
    wx, wy, wz = w
    wn = math.sqrt(wx * wx + wy * wy + wz * wz)
    ax, ay, az = wx / wn, wy / wn, wz / wn
    hh = 0.5 * h

    def acc(vx, vy, vz):
        return gx - 2.0 * (wy * vz - wz * vy), gy - 2.0 * (wz * vx - wx * vz), gz - 2.0 * (wx * vy - wy * vx)

    def rk4_step(x, y, z, vx, vy, vz):
        a1 = acc(vx, vy, vz)
        v2 = (vx + hh * a1[0], vy + hh * a1[1], vz + hh * a1[2])
        a2 = acc(*v2)
        v3 = (vx + hh * a2[0], vy + hh * a2[1], vz + hh * a2[2])
        a3 = acc(*v3)
        v4 = (vx + h * a3[0], vy + h * a3[1], vz + h * a3[2])
        a4 = acc(*v4)
        h6 = h / 6.0
        vel = (vx, vy, vz)
        pos = tuple(q + h6 * (vel[i] + 2.0 * v2[i] + 2.0 * v3[i] + v4[i]) for i, q in enumerate((x, y, z)))
        new_v = tuple(vel[i] + h6 * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i]) for i in range(3))
        return (*pos, *new_v)

    def split_step(x, y, z, vx, vy, vz):
        x, y, z = x + hh * vx, y + hh * vy, z + hh * vz
        vx, vy, vz = vx + hh * gx, vy + hh * gy, vz + hh * gz
        d = ax * vx + ay * vy + az * vz
        cx, cy, cz = ay * vz - az * vy, az * vx - ax * vz, ax * vy - ay * vx
        vx, vy, vz = (vx * c + cx * s + ax * d * (1 - c), vy * c + cy * s + ay * d * (1 - c),
                      vz * c + cz * s + az * d * (1 - c))
        vx, vy, vz = vx + hh * gx, vy + hh * gy, vz + hh * gz
        return x + hh * vx, y + hh * vy, z + hh * vz, vx, vy, vz

    step = rk4_step if rk4 else split_step

    def particle(y0):
        def body(_, carry):
            y, alive = carry
            new = jnp.stack(step(*y))
            if ground:
                new = jnp.where(alive, new, y)
                alive = alive & ~((y[2] > 0.0) & (new[2] <= 0.0))
            return new, alive

        return jax.lax.fori_loop(0, steps, body, (y0, jnp.bool_(True)))[0]

    run = jax.jit(jax.vmap(particle))
    device = jax.devices()[0].platform

    def call(y0):
        return np.asarray(run(jnp.asarray(y0)))

    return call, device
