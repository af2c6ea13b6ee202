"""What a problem compiles of its own: the few small functions that call the user's, behind fixed signatures.

The engine (`rotframe.problem.engine`) is compiled once for every problem; it calls a
problem's functions by address (`rotframe.problem.calls`), each of one of the signatures of
`rotframe.problem.signatures`. This module writes their source for one problem: it sums the
forces (turning a force given in inertial axes into the frame's by the integrated attitude),
names each event, sums the potentials, calls the user's omega(t) and a0(t), or calls the torque
of a body. `rotframe.problem.codegen` compiles that source (and, through it, the user's own
functions) and caches it on disk under the functions' fingerprints; a function the problem does
not have is one of `rotframe.problem.stubs`, compiled once.

Each function hands the user's functions read-only views of the state (``r``, ``v``, ``L``,
``q``; `rotframe.problem.readonly`) and the parameters in their own shapes: ``params`` travel
flattened in one float64 array ``p`` (`flatten_params`), each entry a number or a read-only
view of its slice. `render` shows the source of a problem, for debugging.
"""

from __future__ import annotations

import math

import numpy as np

from rotframe.problem.terms import energy_by_numpy

__all__ = ["flatten_params", "params_source", "particle_source", "body_source", "render"]


def flatten_params(params) -> np.ndarray:
    """``params`` (numbers and float arrays, `rotframe.problem.arguments.check_params`) as one float64 array."""
    parts = [np.ravel(np.asarray(v, dtype=float)) for v in params]
    return np.ascontiguousarray(np.concatenate(parts) if parts else np.zeros(0))


def params_source(params) -> str:
    """Lines that unpack ``p`` into ``P0, P1, ...``: a number, or a read-only view in the entry's shape."""
    lines = []
    offset = 0
    for j, v in enumerate(params):
        shape = np.shape(v)
        size = int(math.prod(shape))
        if shape == ():
            lines.append(f"    P{j} = p[{offset}]")
        elif len(shape) == 1:
            lines.append(f"    P{j} = readonly(p[{offset}:{offset + size}])")
        else:
            lines.append(f"    P{j} = readonly(p[{offset}:{offset + size}]).reshape({shape!r})")
        offset += size
    return "".join(line + "\n" for line in lines)


def _args(params) -> str:
    return "".join(f", P{j}" for j in range(len(params)))


#: R^T a with R = R(q) (the frame's attitude, y[6:10]): a - 2 s (u x a) + 2 u x (u x a)
_TO_FRAME_AXES = """\
    qx = y[6]
    qy = y[7]
    qz = y[8]
    qs = y[9]
    bx = a[0]
    by = a[1]
    bz = a[2]
    cx = qy * bz - qz * by
    cy = qz * bx - qx * bz
    cz = qx * by - qy * bx
    ax += bx - 2.0 * qs * cx + 2.0 * (qy * cz - qz * cy)
    ay += by - 2.0 * qs * cy + 2.0 * (qz * cx - qx * cz)
    az += bz - 2.0 * qs * cz + 2.0 * (qx * cy - qy * cx)
"""


def particle_source(forces, events, params, *, splitting: bool, omega: str, origin: bool) -> str:
    """The glue of a particle problem: ``terms``, and ``event``, ``potential``, ``omega``, ``origin`` where it has them.

    Parameters
    ----------
    forces : list of `rotframe.problem.terms.Force`
        Bound as ``force_k`` (and ``potential_k`` where given). Under a splitting, a term with an
        exact flow is left out of the sum: the splitting applies its flow
        (`rotframe.problem.models.drag_rates`).
    events : list of callables
        Bound as ``event_k``.
    params : tuple
        The checked ``params`` (their shapes are compiled in).
    omega : str
        ``"function"`` (bound ``omega_fn``), ``"function_dot"`` (and ``omega_dot_fn``) or ``""``.
    origin : bool
        The origin's acceleration is the user's function (bound ``origin_fn``).
    """
    unpack = params_source(params)
    args = _args(params)
    views = "    r = readonly(y[0:3])\n    v = readonly(y[3:6])\n"
    src = ["\n@jit(TERMS_SIG)\ndef terms(t, y, p, out):\n", views, unpack, "    ax = 0.0\n    ay = 0.0\n    az = 0.0\n"]
    for k, f in enumerate(forces):
        if splitting and f.flow:  # the splitting applies this term's exact flow
            continue
        src.append(f"    a = force_{k}(t, r, v{args if f.takes_params else ''})\n")
        src.append(_TO_FRAME_AXES if f.axes == "inertial" else "    ax += a[0]\n    ay += a[1]\n    az += a[2]\n")
    src.append("    out[0] = ax\n    out[1] = ay\n    out[2] = az\n")
    if events:
        src += ["\n@jit(EVENT_SIG)\ndef event(k, t, y, p):\n", views, unpack]
        src += [f"    if k == {k}:\n        return float(event_{k}(t, r, v{args}))\n" for k in range(len(events))]
        src.append("    return 0.0\n")
    if any(f.potential is not None for f in forces) and not energy_by_numpy(forces):  # else numpy's energies
        src += ["\n@jit_lazy\ndef potential(t, y, p):\n", "    r = readonly(y[0:3])\n", unpack, "    u = 0.0\n"]
        src += [f"    u += float(potential_{k}(t, r{args if f.takes_params else ''}))\n" for k, f in enumerate(forces)
                if f.potential is not None]
        src.append("    return u\n")
    if omega:
        src += ["\n@jit(VECTOR_SIG)\ndef omega(t, out):\n", "    w = omega_fn(t)\n",
                "    out[0] = w[0]\n    out[1] = w[1]\n    out[2] = w[2]\n"]
        if omega == "function_dot":
            src.append("    e = omega_dot_fn(t)\n    out[3] = e[0]\n    out[4] = e[1]\n    out[5] = e[2]\n")
    if origin:
        src += ["\n@jit(VECTOR_SIG)\ndef origin(t, out):\n", "    a = origin_fn(t)\n",
                "    out[0] = a[0]\n    out[1] = a[1]\n    out[2] = a[2]\n"]
    return "".join(src)


def body_source(takes_params, params) -> str:
    """The glue of a body under its torques (bound ``torque_0``, ``torque_1``...; ``takes_params[k]``: whether
    torque k takes the run's ``params``): ``terms``, their sum in order (one torque: its value)."""
    src = ["\n@jit(TERMS_SIG)\ndef terms(t, y, p, out):\n", params_source(params),
           "    L = readonly(y[0:3])\n    q = readonly(y[3:7])\n"]
    for k, takes in enumerate(takes_params):
        src.append(f"    a = torque_{k}(t, L, q{_args(params) if takes else ''})\n")
        src.append("    tx = a[0]\n    ty = a[1]\n    tz = a[2]\n" if k == 0 else
                   "    tx += a[0]\n    ty += a[1]\n    tz += a[2]\n")
    src.append("    out[0] = tx\n    out[1] = ty\n    out[2] = tz\n")
    return "".join(src)


def render(source: str) -> str:
    """The glue's source with its lines numbered (for a bug report or a look at what a problem compiles)."""
    return "\n".join(f"{n:4d}  {line}" for n, line in enumerate(source.splitlines(), 1))
