"""Source of the stepping shared by the generated drivers: DOP853 and RK4 steps, events, the loop.

Appended to a driver's ``rhs`` (`rotframe.problem.particle_driver`,
`rotframe.problem.body_driver`) by `rotframe.problem.codegen`. It needs from the
header ``D`` (state size), ``NE`` (events), ``rhs(t, y, dy, P, F, G)``,
``event_value(k, t, y, P)``, the DOP853 tableau ``A, B, C, E3, E5`` and ``error_norm``.

* DOP853: Hairer's step control (dop853.f: safety 0.9, growth at most 1/0.333, shrink at
  most 6, no growth right after a rejection) and starting step (hinit); a step never passes
  the next sample time, so every sample is a step's end.
* RK4 (method 1), and a driver's own fixed-step methods (``own_step``, methods 2 and 3: the
  rigid body's Lie-Poisson splittings, the particle's rotation splittings, each of order 2 and
  its Yoshida triple jump): a fixed step that divides each sample interval.
* Events: a sign change of g over a step (with its direction) is bisected on the step's
  length, each trial a re-step from the step's start by the same method, to round-off in
  time on the method's own discrete trajectory (as the built-in ground event,
  docs/physics/events.md). The earliest terminal crossing ends the particle; samples after
  it keep the state at the event.
* Stops: ``S``, sorted times inside the run where the right-hand side is not smooth (the knots
  of an omega or origin table, the samples of a body frame: the interpolant's higher
  derivatives jump there). No step crosses one: a step that would is cut to end on it, as
  DifferentialEquations.jl's ``tstops``, so each step integrates a smooth function and keeps its
  order; RK4's grid goes on from the knot. Without this, a finer table gave larger errors.
* ``atol`` is (N, D), one row per particle (its own scales).
* Each particle is integrated alone, ``budget`` steps per call, so results do not depend on
  the thread count and Python sees signals between calls. ``advance(lo, hi, ...)`` takes the
  particles ``lo:hi``; Python runs blocks of them on threads (the driver holds no GIL). numba's
  ``prange`` was measured at 15 ms a call on the 2-core reference machine (its OpenMP pool
  waking), more than a whole single-particle run.
"""

SOURCE = r'''

FACC1 = 1.0 / 0.333   # Hairer's dop853: the step may grow at most by 1/0.333 and shrink by 6
FACC2 = 1.0 / 6.0
SAFE = 0.9


@jit
def attitude_rate(y, dy, k, wx, wy, wz):
    """q' = q (w, 0) / 2 for the scalar-last quaternion y[k:k + 4] (w in the rotating axes), into dy."""
    qx = y[k]
    qy = y[k + 1]
    qz = y[k + 2]
    qw = y[k + 3]
    dy[k] = 0.5 * (qw * wx + qy * wz - qz * wy)
    dy[k + 1] = 0.5 * (qw * wy + qz * wx - qx * wz)
    dy[k + 2] = 0.5 * (qw * wz + qx * wy - qy * wx)
    dy[k + 3] = -0.5 * (qx * wx + qy * wy + qz * wz)


@jit
def dop853_step(t, y, h, t_end, K, yt, yn, P, F, G):
    """One DOP853 step from (t, y) with K[0] = f(t, y): yn and K[1..12] (K[12] = f(t + h, yn))."""
    for s in range(1, 12):
        for j in range(D):
            acc = 0.0
            for m in range(s):
                acc += A[s, m] * K[m, j]
            yt[j] = y[j] + h * acc
        rhs(t + C[s] * h, yt, K[s], P, F, G)
    for j in range(D):
        acc = 0.0
        for s in range(12):
            acc += B[s] * K[s, j]
        yn[j] = y[j] + h * acc
    rhs(t_end, yn, K[12], P, F, G)  # at the time the step ends on (a sample time exactly where it lands)


@jit
def rk4_step(t, y, h, K, yt, yn, P, F, G):
    """One classical Runge-Kutta step from (t, y) with K[0] = f(t, y)."""
    for j in range(D):
        yt[j] = y[j] + 0.5 * h * K[0, j]
    rhs(t + 0.5 * h, yt, K[1], P, F, G)
    for j in range(D):
        yt[j] = y[j] + 0.5 * h * K[1, j]
    rhs(t + 0.5 * h, yt, K[2], P, F, G)
    for j in range(D):
        yt[j] = y[j] + h * K[2, j]
    rhs(t + h, yt, K[3], P, F, G)
    for j in range(D):
        yn[j] = y[j] + h * (K[0, j] + 2.0 * K[1, j] + 2.0 * K[2, j] + K[3, j]) / 6.0


@jit
def take_step(method, t, y, h, t_end, K, yt, yn, P, F, G):
    if method == 0:
        dop853_step(t, y, h, t_end, K, yt, yn, P, F, G)
    elif method == 1:
        rk4_step(t, y, h, K, yt, yn, P, F, G)
    else:  # a driver's own fixed-step method, 2 or 3 (the body's or the particle's splittings, orders 2 and 4)
        own_step(method, t, y, h, yn, P, F, G)


@jit
def all_finite(y):
    for j in range(D):
        if not math.isfinite(y[j]):
            return False
    return True


@jit
def first_step(t, y, K, yt, rtol, atol, P, F, G, span):
    """Hairer's starting step (hinit of dop853.f, order 8), K[0] = f(t, y) given."""
    d0 = 0.0
    d1 = 0.0
    for j in range(D):
        sc = atol[j] + rtol * abs(y[j])
        d0 += (y[j] / sc) ** 2
        d1 += (K[0, j] / sc) ** 2
    d0 = math.sqrt(d0 / D)
    d1 = math.sqrt(d1 / D)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, span)
    for j in range(D):
        yt[j] = y[j] + h0 * K[0, j]
    rhs(t + h0, yt, K[1], P, F, G)
    d2 = 0.0
    for j in range(D):
        sc = atol[j] + rtol * abs(y[j])
        d2 += ((K[1, j] - K[0, j]) / sc) ** 2
    d2 = math.sqrt(d2 / D) / h0
    big = max(d1, d2)
    h1 = max(1e-6, h0 * 1e-3) if big <= 1e-15 else (0.01 / big) ** 0.125
    return min(100.0 * h0, h1, span)


@jit
def next_stop(S, t):
    """The first stop time in the sorted S after t (inf if none): a knot where the right-hand side is not smooth."""
    n = S.shape[0]
    if n == 0 or S[n - 1] <= t:
        return math.inf
    lo = 0
    hi = n - 1
    while lo < hi:  # the first S[k] > t
        mid = (lo + hi) // 2
        if S[mid] > t:
            hi = mid
        else:
            lo = mid + 1
    return S[lo]


@jit
def locate(method, k, t, y, h, g_lo, Kb, ytb, yhi, ybuf, P, F, G):
    """Bisect for event k's crossing inside the step (t, t + h], re-stepping from (t, y) with the method.

    Returns tau in (0, h]; ``yhi`` holds the state there. The crossing is bracketed to round-off
    in time on the method's own discrete trajectory.
    """
    lo = 0.0
    hi = h
    rhs(t, y, Kb[0], P, F, G)
    # yhi holds the full step's end on entry
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if not (lo < mid < hi):
            break
        take_step(method, t, y, mid, t + mid, Kb, ytb, ybuf, P, F, G)
        gm = event_value(k, t + mid, ybuf, P)
        if (gm < 0.0) == (g_lo < 0.0) and gm != 0.0:
            lo = mid
            g_lo = gm
        else:
            hi = mid
            for j in range(D):
                yhi[j] = ybuf[j]
    return hi


@jit
def advance_one(i, T, Y, TC, H, IDX, SUB, ST, OUT, EVT, EVY, EVK, EVN, GPREV, NSTEP, NFEV, budget, method,
                rtol, atol, hfix, EDIR, ETERM, P, F, G, S, K, Kb, V):
    # K, Kb (13, D) stages and V (7, D) state vectors: scratch of the calling block, made once for all its particles
    n = T.shape[0]
    y = V[0]
    yt = V[1]
    yn = V[2]
    ytb = V[3]
    yhi = V[4]
    ybuf = V[5]
    yev = V[6]
    for j in range(D):
        y[j] = Y[i, j]
    t = TC[i]
    h = H[i]
    idx = IDX[i]
    sub = SUB[i]
    rhs(t, y, K[0], P, F, G)
    NFEV[i] += 1
    if h <= 0.0 and method == 0:
        h = first_step(t, y, K, yt, rtol, atol, P, F, G, T[n - 1] - T[0])
        NFEV[i] += 1
    steps = 0
    # DOP853 keeps in SUB whether its last try was rejected (no growth right after a rejection), so that
    # the steps, and the numbers, do not depend on where the budget cut the calls
    rejected = method == 0 and sub != 0
    status = 0
    while idx < n and steps < budget:
        if t >= T[idx]:
            for j in range(D):
                OUT[idx, i, j] = y[j]
            idx += 1
            sub = 0
            continue
        # a step ends on the next sample or the next stop (a knot of a table or a body frame), whichever is first
        stop = next_stop(S, t)
        at_knot = stop < T[idx]
        target = stop if at_knot else T[idx]
        if method == 0:
            span = target - t
            hh = h if h < span else span
            landing = hh == span
        else:
            interval = T[idx] - T[idx - 1]
            on_grid = t == (T[idx - 1] + sub * hfix if sub > 0 else T[idx - 1])
            last = (sub + 1) * hfix >= interval * (1.0 - 1e-12)
            grid_next = T[idx] if last else T[idx - 1] + (sub + 1) * hfix
            if at_knot and stop < grid_next:
                hh = stop - t  # to the knot; the grid goes on from there
                landing = True
            else:
                target = T[idx]
                hh = hfix if on_grid else grid_next - t
                sub += 1
                landing = last
        take_step(method, t, y, hh, target if landing else t + hh, K, yt, yn, P, F, G)
        steps += 1
        NSTEP[i] += 1
        NFEV[i] += 12 if method == 0 else 3 if method == 1 else 2
        ok = all_finite(yn)
        err = 0.0
        if method == 0:
            err = error_norm(K, hh, y, yn, rtol, atol, E3, E5)
            ok = ok and math.isfinite(err)
        if method == 0 and (not ok or err > 1.0):
            if ok:
                fac11 = err ** 0.125
                h = hh / min(FACC1, fac11 / SAFE)
            else:
                h = hh * 0.1
            rejected = True
            if h < 1e-14 * abs(t) or h < 1e-290:  # below round-off of t (the run's span has no say in that)
                status = 4 if ok else 3
                break
            continue
        if not ok:
            status = 3
            break
        t_new = target if landing else t + hh
        if method != 0 and not landing:
            t_new = T[idx - 1] + sub * hfix
        # events over (t, t_new]: every crossing located; the earliest terminal one ends the particle
        stop_tau = -1.0
        stop_k = -1
        for k in range(NE):
            g_new = event_value(k, t_new, yn, P)
            g_old = GPREV[i, k]
            rising = g_old < 0.0 and g_new >= 0.0
            falling = g_old > 0.0 and g_new <= 0.0
            if (rising and EDIR[k] >= 0) or (falling and EDIR[k] <= 0):
                for j in range(D):
                    yhi[j] = yn[j]
                tau = locate(method, k, t, y, t_new - t, g_old, Kb, ytb, yhi, ybuf, P, F, G)
                m = EVN[i]
                if m < EVT.shape[1]:
                    EVT[i, m] = t + tau
                    EVK[i, m] = k
                    for j in range(D):
                        EVY[i, m, j] = yhi[j]
                EVN[i] = m + 1
                if ETERM[k] and (stop_tau < 0.0 or tau < stop_tau):
                    stop_tau = tau
                    stop_k = k
                    for j in range(D):
                        yev[j] = yhi[j]
            GPREV[i, k] = g_new
        if stop_k >= 0:
            # drop records of non-terminal crossings after the terminal one
            m = EVN[i]
            keep = 0
            for r in range(min(m, EVT.shape[1])):
                if EVT[i, r] <= t + stop_tau:
                    EVT[i, keep] = EVT[i, r]
                    EVK[i, keep] = EVK[i, r]
                    for j in range(D):
                        EVY[i, keep, j] = EVY[i, r, j]
                    keep += 1
            EVN[i] = keep
            t = t + stop_tau
            for j in range(D):
                y[j] = yev[j]
            while idx < n:
                for j in range(D):
                    OUT[idx, i, j] = y[j]
                idx += 1
            status = 2
            break
        if method == 0:
            fac11 = err ** 0.125
            fac = max(FACC2, min(FACC1, fac11 / SAFE))
            h_next = hh / fac
            if rejected:
                h_next = min(h_next, hh)
            rejected = False
            h = h_next if not (landing and hh < h) else max(h, h_next)
            for j in range(D):
                K[0, j] = K[12, j]
        t = t_new
        for j in range(D):
            y[j] = yn[j]
        if method != 0:
            rhs(t, y, K[0], P, F, G)
            NFEV[i] += 1
    if status == 0 and idx >= n:
        status = 1
    for j in range(D):
        Y[i, j] = y[j]
    TC[i] = t
    H[i] = h
    IDX[i] = idx
    SUB[i] = sub if method != 0 else (1 if rejected else 0)
    ST[i] = status


@jit
def advance(lo, hi, T, Y, TC, H, IDX, SUB, ST, OUT, EVT, EVY, EVK, EVN, GPREV, NSTEP, NFEV, budget, method, rtol,
            atol, hfix, EDIR, ETERM, P, F, G, S):
    K = np.empty((13, D))
    Kb = np.empty((13, D))
    V = np.empty((7, D))
    for i in range(lo, hi):
        if ST[i] == 0:
            advance_one(i, T, Y, TC, H, IDX, SUB, ST, OUT, EVT, EVY, EVK, EVN, GPREV, NSTEP, NFEV, budget, method,
                        rtol, atol[i], hfix, EDIR, ETERM, P, F, G, S, K, Kb, V)


@jit
def start_events(t, Y, GPREV, P):
    for i in range(Y.shape[0]):
        for k in range(NE):
            GPREV[i, k] = event_value(k, t, Y[i], P)


'''
