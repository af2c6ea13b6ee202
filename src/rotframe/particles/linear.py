"""The exact flow of particle models that have one: s(t_k) = Phi_k s(0), s = (r, v, 1).

Two kinds of model have an exact flow (docs/physics/earth.md, the exact linear flow and the
exact flow of a force-free particle):

- **Linear with constant coefficients** (uniform gravity, constant omega, linear
  drag, the small-angle spring): r'' = K r + C v + b, and the augmented state
  s = (r, v, 1) obeys s' = M s with the constant 7x7 matrix
  M = [[0, I, 0], [K, C, b], [0, 0, 0]]. Then s(t) = expm(M t) s(0) exactly.
- **Force-free** (only the frame's own terms: Coriolis, centrifugal, and Euler's when
  the rate varies), any rotation schedule about a fixed axis: the particle moves on a
  straight line in inertial space, r_in(t) = r0 + t (v0 + w(0) x r0), seen from the
  frame turned by the schedule's exact angle theta(t):
  r(t) = R(n, -theta) r_in(t), v(t) = R(n, -theta) (v0 + w(0) x r0) - w(t) x r(t).

Both are linear maps of s(0), so `ExactFlow` holds the matrices Phi_k for a
sample grid and applies them to any initial states (a prepared run applies them many
times). This module also holds M, a vectorised propagator for many states over many
different times at once, and the location of event crossings on the linear flow,
all particles and brackets in one call.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["flow_matrix", "flow_at", "propagate", "locate_crossings", "turned_angle", "free_flow_matrices", "ExactFlow",
           "ordered_product"]


def flow_matrix(model) -> np.ndarray:
    """M (7, 7) of s' = M s for a linear ParticleModel (see ``ParticleModel.is_linear``)."""
    K, C, b = model.linear_matrices()
    M = np.zeros((7, 7))
    M[0:3, 3:6] = np.eye(3)
    M[3:6, 0:3] = K
    M[3:6, 3:6] = C
    M[3:6, 6] = b
    return M


def _power_of_two(x):
    """The power of two nearest ``x`` (> 0) within 2^-1000 .. 2^1000; 1.0 for 0, inf or nan."""
    if not (x > 0.0 and math.isfinite(x)):
        return 1.0
    return 2.0 ** min(1000, max(-1000, round(math.log2(x))))


def flow_at(M, t):
    """expm(M t) (7, 7) for the matrix M of `flow_matrix`: scipy's ``expm`` on a similarity-scaled M t.

    ``expm`` (scaling and squaring, Al-Mohy & Higham 2009) squares as often as the norm of
    M t asks, and two blocks of M make that norm grow with t where the motion has nothing
    to resolve: the kinematic r' = v (norm t) and the constant force b (norm |b| t). Each
    squaring adds round-off: plain ``expm`` of a projectile's M (gravity and Coriolis) is
    2e-15 off after 248 s and 8e-12 after 1e5 s (against mpmath at 40 digits,
    ``tests/test_linear_flow.py``; here: 1e-16 and 2e-15). With D = diag(a, a, a, 1, 1, 1, e),

        expm(M t) = D expm(D^-1 M D t) D^-1,

    and the blocks of D^-1 M D t are I t / a, K a t, C t and b e t. Here a is the time
    over which the velocity carries the position before the frame turns it or the spring
    pulls it back, a = min(t, 1/|C|, 1/sqrt(|K|)), and e = 1 / (|b| a) (1-norms); both
    are rounded to powers of two, so that the scaling itself is exact. What is left in
    the norm is the motion itself (turns of the frame, periods of the spring), which no
    scaling removes; it is halved until it is at most 1/2 before ``expm`` (whose Pade
    approximant is then accurate to round-off) and the result squared back.
    """
    from scipy.linalg import expm

    t = float(t)
    K, C, b = M[3:6, 0:3], M[3:6, 3:6], M[3:6, 6]
    norm_K = float(np.max(np.sum(np.abs(K), axis=0)))
    norm_C = float(np.max(np.sum(np.abs(C), axis=0)))
    norm_b = float(np.max(np.abs(b)))
    a = abs(t)
    if norm_C > 0.0:
        a = min(a, 1.0 / norm_C)
    if norm_K > 0.0:
        a = min(a, 1.0 / math.sqrt(norm_K))
    a = _power_of_two(a)
    e = _power_of_two(1.0 / (norm_b * a)) if norm_b > 0.0 else 1.0
    d = np.array([a, a, a, 1.0, 1.0, 1.0, e])
    scaled = (M * t) * (d[None, :] / d[:, None])
    norm = float(np.max(np.sum(np.abs(scaled), axis=0)))
    if not math.isfinite(norm):
        return expm(M * t)  # overflow: what expm makes of it
    # squarings chosen here, to a norm of 1/2: expm's own choice leaves a norm of up to 5.4 to its
    # Pade approximant, whose forward error on a turning (near-orthogonal) block is then some 10 times
    # that of squaring a smaller one (an f-plane after 1e5 s: 2.5e-15 against 7e-16)
    squarings = max(0, math.ceil(math.log2(norm / 0.5))) if norm > 0.0 else 0
    phi = expm(scaled / 2.0 ** squarings)
    for _ in range(squarings):
        phi = phi @ phi
    phi *= d[:, None] / d[None, :]
    phi[6] = 0.0  # the constant stays 1: M's last row is zero, so is that of M^k (k >= 1)
    phi[6, 6] = 1.0
    return phi


def propagate(M, s, tau):
    """exp(M tau_j) s_j for every column j of ``s`` (7, m), ``tau`` (m,): Taylor series to round-off.

    The interval is cut into sub-steps with ||A h||_1 <= 1 for the linear block
    A = M[:6, :6]; the number of terms is fixed in advance by the remainder bound
    rho^n / n! < 1e-20, so no per-term convergence test is needed. Past `MAX_SUBSTEPS` sub-steps
    the columns are scaled and squared instead (`_propagate_squared`).
    """
    s = np.array(s, dtype=np.float64)
    tau = np.asarray(tau, dtype=np.float64)
    norm = float(np.max(np.sum(np.abs(M[:6, :6]), axis=0)))
    rho_total = norm * float(np.max(np.abs(tau), initial=0.0))
    if rho_total > MAX_SUBSTEPS:
        return _propagate_squared(M, s, tau, norm)
    n_sub = max(1, int(math.ceil(rho_total)))
    rho, bound, terms = rho_total / n_sub, 1.0, 0
    while bound > 1e-20 or terms < 4:
        terms += 1
        bound *= max(rho, 0.5) / terms
    h = tau / n_sub
    for _ in range(n_sub):
        acc, term = s.copy(), s
        for k in range(1, terms + 4):
            term = (M @ term) * (h / k)
            acc += term
        s = acc
    return s


#: sub-steps of `propagate`'s Taylor series at most; a longer ||A tau|| (a drop from 1e30 m: 1e11 sub-steps) is
#: scaled and squared instead (`_propagate_squared`), whose cost grows with log2 ||A tau||
MAX_SUBSTEPS = 1024


def _propagate_squared(M, s, tau, norm):
    """`propagate` by scaling and squaring, column by column: exp(M tau_j) = exp(M tau_j / 2^k)^(2^k).

    Each column's matrix exp(M tau_j / 2^k), with ||A tau_j|| / 2^k <= 1, is the Taylor series to
    the same remainder bound as `propagate`'s; it is squared k times (k = ceil(log2 ||A tau_j||),
    the columns of one k together), then applied to s_j.
    """
    out = np.empty_like(s)
    rho = norm * np.abs(tau)
    with np.errstate(divide="ignore"):
        k = np.where(rho > 1.0, np.ceil(np.log2(np.maximum(rho, 1.0))), 0.0).astype(np.int64)
    eye = np.eye(M.shape[0])
    for kk in np.unique(k):
        cols = np.flatnonzero(k == kk)
        h = tau[cols] / 2.0 ** int(kk)
        E = np.broadcast_to(eye, (cols.size,) + eye.shape).copy()
        term = E.copy()
        for n in range(1, 24):  # ||A h|| <= 1: 1/23! < 1e-22
            term = np.matmul(M, term) * (h / n)[:, None, None]
            E += term
        for _ in range(int(kk)):
            E = np.matmul(E, E)
        out[:, cols] = np.einsum("jab,bj->aj", E, s[:, cols])
    return out


def locate_crossings(M, s_start, dt, g_lo, g_hi, column, value, t_start, max_iter=2200):
    """Sub-step tau in (0, dt] of each bracket where component ``column`` of s equals ``value``.

    Safeguarded Newton iteration on the exact flow, all brackets at once: Newton
    steps from the current point, bisection when a step leaves the bracket,
    stopping when a step changes tau by less than 4 ulp of the absolute time.
    ``max_iter`` allows bisection all the way down from ``dt`` to a root near
    the smallest doubles (a drop from 1e-320 m lands after 4.5e-161 s).

    Parameters
    ----------
    M : (7, 7) array
    s_start : (7, m) array
        State at the start of each bracket.
    dt : (m,) array
        Bracket lengths (s).
    g_lo, g_hi : (m,) arrays
        Event function (``s[column] - value``) at both ends; they differ in sign.
    t_start : (m,) array
        Absolute times of the bracket starts (for the stopping tolerance).

    Returns
    -------
    tau : (m,) array
    state : (7, m) array
        The state at the crossing.
    """
    lo, hi = np.zeros_like(dt), np.array(dt, dtype=float)
    g_lo = np.array(g_lo, dtype=float)
    g_hi = np.asarray(g_hi, dtype=float)
    # a bracket that starts on the zero (g_lo is then a signed tiny number: the sign just after
    # the start) has its root inside, not at tau = 0: start from its middle
    with np.errstate(divide="ignore", invalid="ignore"):
        tau = np.where(np.abs(g_lo) > 1e-290, dt * g_lo / (g_lo - g_hi), 0.5 * dt)
    for _ in range(max_iter):
        s = propagate(M, s_start, tau)
        g = s[column] - value
        dg = M[column] @ s
        same = ((g < 0.0) == (g_lo < 0.0)) & (g != 0.0)
        lo, g_lo, hi = np.where(same, tau, lo), np.where(same, g, g_lo), np.where(same, hi, tau)
        with np.errstate(divide="ignore", invalid="ignore"):
            newton = tau - g / dg
        converged = (g == 0.0) | (np.abs(newton - tau) <= 4 * np.finfo(float).eps * (t_start + tau))
        if np.all(converged):
            tau = np.where(g == 0.0, tau, newton)
            break
        bad = ~np.isfinite(newton) | (newton < lo) | (newton > hi)
        tau = np.where(converged, tau, np.where(bad, 0.5 * (lo + hi), newton))
    return tau, propagate(M, s_start, tau)


def turned_angle(omega, t):
    """Angle (rad) the frame has turned from t = 0 to each time ``t``, exact for the schedule (vectorised).

    The schedule's rate is piecewise linear through its nodes and held outside them
    ([`rotframe.particles.model.OmegaSchedule`][rotframe.particles.model.OmegaSchedule]), so the angle is piecewise
    quadratic: the node integrals plus the part of the current segment.
    """
    t = np.atleast_1d(np.asarray(t, dtype=np.float64))
    wt, wv = omega.times, omega.values
    wint = omega.cumulative()

    def from_first_node(x):
        if wt.size == 1:
            return wv[0] * (x - wt[0])
        k = np.clip(np.searchsorted(wt, x, side="right") - 1, 0, wt.size - 2)
        before, after = x <= wt[0], x >= wt[-1]
        dt = x - wt[k]
        slope = (wv[k + 1] - wv[k]) / (wt[k + 1] - wt[k])
        inside = wint[k] + wv[k] * dt + 0.5 * slope * dt * dt
        return np.where(before, wv[0] * (x - wt[0]), np.where(after, wint[-1] + wv[-1] * (x - wt[-1]), inside))

    return from_first_node(t) - from_first_node(np.zeros(1))


def free_flow_matrices(model, times):
    """Phi_k (K, 7, 7) of a force-free particle (see the module docstring) at ``times`` (K,), t = 0 the start.

    Row blocks: position, velocity, the constant 1. With u0 = v0 + W0 r0 (W = [w x],
    the inertial velocity), Q = R(n, -theta) and t the time: r = Q (r0 + t u0) and
    v = Q u0 - W(t) r.
    """
    from rotframe.numerics.hat import skew

    times = np.asarray(times, dtype=np.float64)
    n = np.asarray(model.omega.axis, dtype=np.float64)
    N = skew(n)
    theta = turned_angle(model.omega, times)
    c, s = np.cos(theta)[:, None, None], np.sin(theta)[:, None, None]
    Q = c * np.eye(3) - s * N + (1.0 - c) * np.outer(n, n)  # Rodrigues, angle -theta
    W0 = float(np.interp(0.0, model.omega.times, model.omega.values)) * N
    Wt = np.interp(times, model.omega.times, model.omega.values)[:, None, None] * N
    t = times[:, None, None]
    top_r = Q + t * (Q @ W0)  # d r / d r0
    top_v = t * Q  # d r / d v0
    phi = np.zeros((times.size, 7, 7))
    phi[:, 0:3, 0:3] = top_r
    phi[:, 0:3, 3:6] = top_v
    phi[:, 3:6, 0:3] = Q @ W0 - Wt @ top_r
    phi[:, 3:6, 3:6] = Q - Wt @ top_v
    phi[:, 6, 6] = 1.0
    return phi


def ordered_product(P, S):
    """``P @ S`` for ``P`` (..., 7, 7) and ``S`` (7, N), each entry summed over the columns of P in order.

    numpy's elementwise arithmetic gives each entry the same bits whatever N is, where a BLAS
    product may not (its kernel, and so its order of summation, depends on the shapes).
    """
    total = P[..., :, 0, None] * S[0]
    for j in range(1, P.shape[-1]):
        total = total + P[..., :, j, None] * S[j]
    return total


class ExactFlow:
    """The exact flow of a model over a uniform sample grid, applied to any initial states.

    ``states(s0, out)`` writes s(t_k) = Phi_k s0 into ``out[k]`` (K, 7, N) for the
    augmented initial states ``s0`` (7, N), block by block (64 samples), so that a
    long run shows progress and can be interrupted. ``matrices()`` gives every
    Phi_k, for a run that applies them many times (a prepared run).

    Linear models that are not force-free: expm is evaluated directly at the first sample of every block
    (the anchor, `flow_at`) and the samples between are reached by powers of the one-interval
    propagator, so round-off stays at a few tens of ulps however long the run.
    Force-free models (a steady rate too, though it is linear): `free_flow_matrices`,
    exact at every sample.

    Parameters
    ----------
    model : ParticleModel
        ``model.is_linear`` or ``model.is_force_free``.
    times : (K,) array
        Sample times (s), uniform from 0.
    """

    BLOCK = 64

    def __init__(self, model, times):
        # a force-free model takes its closed form even where it is linear too (a steady rate): the rotating-frame
        # M of Coriolis and centrifugal is defective (double eigenvalues +-i w), and expm's round-off grows like
        # the square of the turns (1e-12 relative after 16 turns, 6e-10 after 160), where the closed form's does not
        self.linear = bool(model.is_linear) and not model.is_force_free
        self.model = model
        self.times = np.asarray(times, dtype=np.float64)
        self.M = flow_matrix(model) if model.is_linear else None  # events are located on it
        if self.linear:
            dt = self.times[1] - self.times[0] if self.times.size > 1 else 0.0
            powers = [np.eye(7)]
            step_matrix = flow_at(self.M, dt)
            for _ in range(self.BLOCK - 1):
                powers.append(step_matrix @ powers[-1])
            self.powers = np.stack(powers)  # (BLOCK, 7, 7): Phi of 0, 1, ... BLOCK - 1 intervals

    def _block(self, start):
        """expm at the block's first sample (linear), or Phi_k of the block's samples (force-free)."""
        if self.linear:
            return flow_at(self.M, self.times[start])
        return free_flow_matrices(self.model, self.times[start:start + self.BLOCK])

    def states(self, s0, out, progress=None, ordered=False):
        """Fill ``out`` (K, 7, N) with the states from ``s0`` (7, N); ``progress(fraction)`` after each block.

        ``ordered``: each product summed column by column in a fixed order (`ordered_product`), so
        that a particle's numbers do not depend on how many are run with it (BLAS's matrix
        products sum in an order of their own, which changes with N); the scenes' runs keep BLAS's.
        Returns the number of samples written (all of them unless interrupted).
        """
        product = ordered_product if ordered else np.matmul
        K = self.times.size
        done = 0
        for start in range(0, K, self.BLOCK):
            block = self._block(start)
            if self.linear:
                anchor = product(block, s0)
                m = min(self.BLOCK, K - start)
                if ordered:  # the block's samples in one product (the same bits as one at a time)
                    out[start:start + m] = ordered_product(self.powers[:m], anchor)
                else:
                    for j in range(m):
                        out[start + j] = self.powers[j] @ anchor
            else:
                out[start:start + block.shape[0]] = product(block, s0)
            done = min(K, start + self.BLOCK)
            if progress is not None:
                progress(done / K)
        return done

    def matrices(self):
        """Phi_k (K, 7, 7) for every sample: s(t_k) = Phi_k s(0) (for a run that applies them many times)."""
        out = np.empty((self.times.size, 7, 7))
        self.states(np.eye(7), out)
        return out
