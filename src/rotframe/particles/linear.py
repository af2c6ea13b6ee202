"""The exact flow of linear particle models, s' = M s with s = (r, v, 1).

When a scene is linear with constant coefficients (uniform gravity, constant
omega, linear drag, the small-angle spring), r'' = K r + C v + b, and the
augmented state s = (r, v, 1) obeys s' = M s with the constant 7x7 matrix
M = [[0, I, 0], [K, C, b], [0, 0, 0]] (docs/physics/earth.md, the exact linear flow). Then
s(t) = expm(M t) s(0) exactly. This module holds M, a vectorised propagator
for many states over many different times at once, and the location of event
crossings on the exact flow, all particles and brackets in one call.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["flow_matrix", "propagate", "locate_crossings"]


def flow_matrix(model) -> np.ndarray:
    """M (7, 7) of s' = M s for a linear ParticleModel (see ``ParticleModel.is_linear``)."""
    K, C, b = model.linear_matrices()
    M = np.zeros((7, 7))
    M[0:3, 3:6] = np.eye(3)
    M[3:6, 0:3] = K
    M[3:6, 3:6] = C
    M[3:6, 6] = b
    return M


def propagate(M, s, tau):
    """exp(M tau_j) s_j for every column j of ``s`` (7, m), ``tau`` (m,): Taylor series to round-off.

    The interval is cut into sub-steps with ||A h||_1 <= 1 for the linear block
    A = M[:6, :6]; the number of terms is fixed in advance by the remainder bound
    rho^n / n! < 1e-20, so no per-term convergence test is needed.
    """
    s = np.array(s, dtype=np.float64)
    tau = np.asarray(tau, dtype=np.float64)
    rho_total = float(np.max(np.sum(np.abs(M[:6, :6]), axis=0))) * float(np.max(np.abs(tau), initial=0.0))
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
