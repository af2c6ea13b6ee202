"""The strongest peers a performance-minded user would pick, for ``rotframe bench``.

Every problem is described by a small ``spec`` dict (its equations and
constants), and each peer builds its own right-hand side from it, written as
an expert would:

- ``scipy-*``: scipy's ``solve_ivp`` with a plain-Python right-hand side in
  scalar arithmetic (no ``np.cross``, one small array per call, a few
  microseconds an evaluation);
- ``scipy-numba-DOP853``: the same solver with a ``numba``-compiled right-hand
  side (scipy's stepping stays in Python);
- ``diffrax-Dopri8`` / ``diffrax-Tsit5``: diffrax with the whole solve
  ``jax.jit``-compiled (CPU, 64-bit floats); the first call's compile time is
  reported apart as ``compile_s``. Needs the ``bench`` extra
  (``pip install rotframe[bench]``: jax, diffrax); without it the rows are
  skipped and the output says so.

Specs: ``{"kind": "particle", "w": (3,), "g": (3,), "ramp": (w0, alpha) or
None, "pendulum": (L, pivot (3,)) or None}`` (rotating-frame particle:
``a = g - 2 w x v - w x (w x r) - w' x r`` with ``w = (0, 0, w0 + alpha t)``
for a ramp; a pendulum adds the string force as a Lagrange multiplier) and
``{"kind": "rigid", "inertia": (3,), "mgl": float}`` (Euler's equations and
scalar-last quaternion kinematics; gravity torque ``mgl (z_b[1], -z_b[0], 0)``).
"""

from __future__ import annotations

import time

import numpy as np

__all__ = ["python_rhs", "numba_rhs", "diffrax_available", "diffrax_solver", "DIFFRAX_SOLVERS"]

DIFFRAX_SOLVERS = ("Dopri8", "Tsit5")


# ---------------------------------------------------------------------------
# plain Python, scalar arithmetic
# ---------------------------------------------------------------------------


def python_rhs(spec):
    """f(t, y) -> ndarray, scalar arithmetic (an expert's numpy right-hand side)."""
    if spec["kind"] == "rigid":
        i1, i2, i3 = (1.0 / float(x) for x in spec["inertia"])
        mgl = float(spec.get("mgl", 0.0))

        def rigid(t, y):
            L0, L1, L2, x, yq, z, w = y.tolist()
            o0, o1, o2 = L0 * i1, L1 * i2, L2 * i3
            n0 = n1 = 0.0
            if mgl:
                s = 1.0 / (x * x + yq * yq + z * z + w * w)
                n0 = mgl * 2 * s * (yq * z + x * w)
                n1 = -mgl * 2 * s * (x * z - yq * w)
            return np.array([L1 * o2 - L2 * o1 + n0, L2 * o0 - L0 * o2 + n1, L0 * o1 - L1 * o0,
                             0.5 * (w * o0 + yq * o2 - z * o1), 0.5 * (w * o1 + z * o0 - x * o2),
                             0.5 * (w * o2 + x * o1 - yq * o0), -0.5 * (x * o0 + yq * o1 + z * o2)])

        return rigid
    wx, wy, wz = (float(c) for c in spec["w"])
    gx, gy, gz = (float(c) for c in spec["g"])
    if spec.get("ramp"):
        w0, alpha = (float(c) for c in spec["ramp"])

        def turntable(t, y):  # w = (0, 0, W), W = w0 + alpha t; no gravity
            x, yy, z, vx, vy, vz = y.tolist()
            W = w0 + alpha * t
            return np.array([vx, vy, vz, 2 * W * vy + W * W * x + alpha * yy, -2 * W * vx + W * W * yy - alpha * x,
                             0.0])

        return turntable
    if spec.get("pendulum"):
        L, pivot = spec["pendulum"]
        L = float(L)
        px, py, pz = (float(c) for c in pivot)

        def pendulum(t, y):
            x, yy, z, vx, vy, vz = y.tolist()
            fx = gx - 2 * (wy * vz - wz * vy)
            fy = gy - 2 * (wz * vx - wx * vz)
            fz = gz - 2 * (wx * vy - wy * vx)
            nx, ny, nz = (x - px) / L, (yy - py) / L, (z - pz) / L
            lam = fx * nx + fy * ny + fz * nz + (vx * vx + vy * vy + vz * vz) / L
            return np.array([vx, vy, vz, fx - lam * nx, fy - lam * ny, fz - lam * nz])

        return pendulum

    def coriolis(t, y):
        vx, vy, vz = y[3], y[4], y[5]
        return np.array([vx, vy, vz, gx - 2 * (wy * vz - wz * vy), gy - 2 * (wz * vx - wx * vz),
                         gz - 2 * (wx * vy - wy * vx)])

    return coriolis


# ---------------------------------------------------------------------------
# numba-compiled right-hand side for scipy
# ---------------------------------------------------------------------------


def numba_rhs(spec):
    """f(t, y) -> ndarray compiled with numba (no cache: closures over the constants)."""
    from numba import njit

    if spec["kind"] == "rigid":
        i1, i2, i3 = (1.0 / float(x) for x in spec["inertia"])
        mgl = float(spec.get("mgl", 0.0))

        @njit
        def rigid(t, y):
            out = np.empty(7)
            L0, L1, L2, x, yq, z, w = y[0], y[1], y[2], y[3], y[4], y[5], y[6]
            o0, o1, o2 = L0 * i1, L1 * i2, L2 * i3
            s = 1.0 / (x * x + yq * yq + z * z + w * w)
            out[0] = L1 * o2 - L2 * o1 + mgl * 2 * s * (yq * z + x * w)
            out[1] = L2 * o0 - L0 * o2 - mgl * 2 * s * (x * z - yq * w)
            out[2] = L0 * o1 - L1 * o0
            out[3] = 0.5 * (w * o0 + yq * o2 - z * o1)
            out[4] = 0.5 * (w * o1 + z * o0 - x * o2)
            out[5] = 0.5 * (w * o2 + x * o1 - yq * o0)
            out[6] = -0.5 * (x * o0 + yq * o1 + z * o2)
            return out

        return rigid
    wx, wy, wz = (float(c) for c in spec["w"])
    gx, gy, gz = (float(c) for c in spec["g"])
    ramp = spec.get("ramp")
    w0, alpha = (float(c) for c in ramp) if ramp else (0.0, 0.0)
    pend = spec.get("pendulum")
    L = float(pend[0]) if pend else 1.0
    px, py, pz = (float(c) for c in pend[1]) if pend else (0.0, 0.0, 0.0)
    has_ramp, has_pend = bool(ramp), bool(pend)

    @njit
    def particle(t, y):
        out = np.empty(6)
        x, yy, z, vx, vy, vz = y[0], y[1], y[2], y[3], y[4], y[5]
        out[0], out[1], out[2] = vx, vy, vz
        if has_ramp:
            W = w0 + alpha * t
            out[3] = 2 * W * vy + W * W * x + alpha * yy
            out[4] = -2 * W * vx + W * W * yy - alpha * x
            out[5] = 0.0
            return out
        fx = gx - 2 * (wy * vz - wz * vy)
        fy = gy - 2 * (wz * vx - wx * vz)
        fz = gz - 2 * (wx * vy - wy * vx)
        if has_pend:
            nx, ny, nz = (x - px) / L, (yy - py) / L, (z - pz) / L
            lam = fx * nx + fy * ny + fz * nz + (vx * vx + vy * vy + vz * vz) / L
            fx -= lam * nx
            fy -= lam * ny
            fz -= lam * nz
        out[3], out[4], out[5] = fx, fy, fz
        return out

    return particle


# ---------------------------------------------------------------------------
# diffrax (JAX)
# ---------------------------------------------------------------------------


def diffrax_available():
    """(True, versions) when jax and diffrax import, else (False, the reason)."""
    try:
        import diffrax
        import jax
    except Exception as exc:  # noqa: BLE001  (any import failure means: skip, with the reason)
        return False, f"diffrax rows skipped: {type(exc).__name__}: {exc} (pip install 'rotframe[bench]')"
    return True, f"jax {jax.__version__}, diffrax {diffrax.__version__}"


def _jax_field(spec):
    import jax.numpy as jnp

    if spec["kind"] == "rigid":
        i1, i2, i3 = (1.0 / float(x) for x in spec["inertia"])
        mgl = float(spec.get("mgl", 0.0))

        def rigid(t, y, args):
            L0, L1, L2, x, yq, z, w = y[0], y[1], y[2], y[3], y[4], y[5], y[6]
            o0, o1, o2 = L0 * i1, L1 * i2, L2 * i3
            s = 1.0 / (x * x + yq * yq + z * z + w * w)
            return jnp.stack([L1 * o2 - L2 * o1 + mgl * 2 * s * (yq * z + x * w),
                              L2 * o0 - L0 * o2 - mgl * 2 * s * (x * z - yq * w), L0 * o1 - L1 * o0,
                              0.5 * (w * o0 + yq * o2 - z * o1), 0.5 * (w * o1 + z * o0 - x * o2),
                              0.5 * (w * o2 + x * o1 - yq * o0), -0.5 * (x * o0 + yq * o1 + z * o2)])

        return rigid
    wx, wy, wz = (float(c) for c in spec["w"])
    gx, gy, gz = (float(c) for c in spec["g"])
    ramp = spec.get("ramp")
    pend = spec.get("pendulum")

    def particle(t, y, args):
        x, yy, z, vx, vy, vz = y[0], y[1], y[2], y[3], y[4], y[5]
        if ramp:
            w0, alpha = (float(c) for c in ramp)
            W = w0 + alpha * t
            return jnp.stack([vx, vy, vz, 2 * W * vy + W * W * x + alpha * yy, -2 * W * vx + W * W * yy - alpha * x,
                              jnp.zeros_like(x)])
        fx = gx - 2 * (wy * vz - wz * vy)
        fy = gy - 2 * (wz * vx - wx * vz)
        fz = gz - 2 * (wx * vy - wy * vx)
        if pend:
            L = float(pend[0])
            px, py, pz = (float(c) for c in pend[1])
            nx, ny, nz = (x - px) / L, (yy - py) / L, (z - pz) / L
            lam = fx * nx + fy * ny + fz * nz + (vx * vx + vy * vy + vz * vz) / L
            fx, fy, fz = fx - lam * nx, fy - lam * ny, fz - lam * nz
        return jnp.stack([vx, vy, vz, fx, fy, fz])

    return particle


def diffrax_solver(spec, solver_name, t_end, y0, atol_scale):
    """A function ``run(rtol) -> (y_end (dim,), nfev)`` and its compile time in seconds.

    The whole solve is ``jax.jit``-compiled once (``rtol`` is a traced argument,
    so every tolerance reuses the compiled code). ``atol = rtol * atol_scale``
    (per component, like rotframe's own scaling). Adaptive steps with a PID
    controller at its defaults (I-controller), the final state only.
    ``run.timed_call(rtol)`` is ``(call, finish)``: ``call()`` the compiled solve alone
    (what the bench times, as it times a prepared rotframe run's call alone) and
    ``finish`` its conversion to numpy and the evaluation count.
    """
    import jax

    jax.config.update("jax_enable_x64", True)
    jax.config.update("jax_platforms", "cpu")
    import diffrax
    import jax.numpy as jnp

    term = diffrax.ODETerm(_jax_field(spec))
    solver = getattr(diffrax, solver_name)()
    y0j = jnp.asarray(y0, dtype=jnp.float64)
    scale = jnp.asarray(atol_scale, dtype=jnp.float64)

    @jax.jit
    def solve(rtol):
        sol = diffrax.diffeqsolve(term, solver, t0=0.0, t1=float(t_end), dt0=None, y0=y0j,
                                  stepsize_controller=diffrax.PIDController(rtol=rtol, atol=rtol * scale),
                                  saveat=diffrax.SaveAt(t1=True), max_steps=2_000_000)
        return sol.ys[-1], sol.stats["num_steps"]

    t0 = time.perf_counter()
    y, n = solve(1e-6)
    y.block_until_ready()
    compile_s = time.perf_counter() - t0
    stages = {"Dopri8": 13, "Tsit5": 6}.get(solver_name, 1)

    def timed_call(rtol):  # the solve (what the bench times) and, apart, its conversion to numpy
        rtol = float(rtol)

        def call():
            y, n = solve(rtol)
            return y.block_until_ready(), n

        return call, lambda yn: (np.asarray(yn[0]), int(yn[1]) * stages)

    def run(rtol):
        call, finish = timed_call(rtol)
        return finish(call())

    run.timed_call = timed_call
    return run, compile_s


def atol_scale(spec, y0):
    """Per-component absolute-tolerance scale: |L0| for momenta, 1 for quaternions, the state scale else."""
    y0 = np.asarray(y0, float)
    if spec["kind"] == "rigid":
        M = float(np.linalg.norm(y0[:3]))
        return np.array([M] * 3 + [1.0] * 4)
    return np.full(y0.shape, max(1.0, float(np.max(np.abs(y0)))))
