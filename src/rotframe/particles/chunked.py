"""The one driver of the compiled particle kernels: set up once, run in chunks, interruptible.

`KernelSetup` holds what does not change between runs of one model,
method, duration and sample count (the packed model, the schedule, the sample
times, the step or the DOP853 tableau, the event table) and makes every call of
the compiled drivers (`rotframe.particles.drivers`) with the same
arguments. `run_chunked` is the run of
[`rotframe.particles.integrators.integrate_particles`][rotframe.particles.integrators.integrate_particles]: calls of a bounded
amount of work, so that progress is shown, Ctrl-C and SIGTERM interrupt cleanly
and a numerical failure returns everything computed before it.
[`rotframe.particles.prepared.PreparedRun`][rotframe.particles.prepared.PreparedRun] calls the same setup once per
run, so its results are bitwise those of ``integrate_particles``.
"""

from __future__ import annotations

import math
import time

import numpy as np

from rotframe.errors import IntegrationError, ScenarioError
from rotframe import limits
from rotframe.particles import threads
from rotframe.particles.advice import remedy
from rotframe.particles.trajectory import EventBuffers, RunInterrupted, Trajectory, event_table

__all__ = ["KernelSetup", "run_chunked", "sample_times", "steps_per_sample", "GROWTH_LIMIT", "RunNeedsCuts"]

#: Relative growth of the inertial speed beyond which a run of a force-free model is unstable.
GROWTH_LIMIT = 1e-3


#: step-evaluations of one call of a fixed-step driver, at most (a run's calls and a long sample
#: interval's pieces are cut to it). A constant, so that the cut never depends on the thread count
#: (a piece's start time enters a varying rate's plan). 0.1 to 0.2 s on one core: how often Python
#: regains control (signals, progress). Each call costs a hand-off to every thread: from 4e6 to this,
#: the 100,000-particle RK4 ensemble of ``rotframe bench ensemble`` ran 1.56x faster on 16 threads and
#: went from 0.695 to 0.87 of the hand-written ceiling on two (issue 26).
CALL_EVALS = 1.6e7


def sample_times(duration, samples):
    """``samples`` equal intervals from 0, the last sample at ``duration`` exactly: (samples + 1,) times."""
    times = np.arange(samples + 1) * (duration / samples)
    times[-1] = duration
    return times


def own_tolerance_rows(r0, v0, duration, rtol):
    """Each particle's own absolute tolerances (N, 6) from its start ``r0``, ``v0`` (N, 3): the engine's rule
    (`rotframe.numerics.step_control.own_tolerances`, the function itself), made before the loop rather than in
    it (inlined into the steady loop, it made its first compile 0.2 to 0.3 s longer). A few particles by Python,
    more by the compiled rule (`rotframe.numerics.step_control.own_tolerance_rows`)."""
    from rotframe.numerics.step_control import own_tolerance_rows as compiled_rows, own_tolerances

    n = r0.shape[0]
    rows = np.empty((n, 6))
    y = np.concatenate([r0, v0], axis=1)
    if n <= 256:
        for i in range(n):
            own_tolerances.py_func(y[i], duration, rtol, rows[i])
    else:
        compiled_rows(y, duration, rtol, rows)
    return rows


def steps_per_sample(dt_sample, step):
    """Fixed steps per sample interval: the fewest whose length ``dt_sample / n`` is at most ``step``.

    ``step`` None or 0 means 1/20 of the sample interval (20 steps a sample).

    Raises
    ------
    ScenarioError
        A step that is not > 0.
    """
    h_req = float(step) if step else dt_sample / 20.0
    if not h_req > 0:
        raise ScenarioError(f"step: {step}; must be > 0")
    return max(1, math.ceil(dt_sample / h_req - 1e-9))


class KernelSetup:
    """The fixed arguments of the compiled drivers for one model, method, duration and sample count.

    Parameters
    ----------
    model : ParticleModel
    info : rotframe.method_registry.Method
        A fixed-step or adaptive entry of `rotframe.particles.integrators.METHODS`.
    duration : float
        Simulated time (s), > 0.
    samples : int
        Output samples after t = 0 (uniform in time; the last one at ``duration`` exactly).
    step : float, optional
        Fixed-step methods: the requested step (s), default 1/20 of the sample
        interval; the step used, `h`, divides the sample interval (``sps``
        steps a sample) and is never larger.
    rtol : float
        DOP853's relative tolerance.
    atol : float, tuple of 6 floats or "own", optional
        DOP853's absolute tolerance (`abs_tol`): one number for the six components, six (r then v),
        ``"own"`` for each particle's own scales (the engine's default,
        `rotframe.numerics.step_control.own_tolerances`), or a falsy value for ``rtol`` times the
        initial states' scale (the scenes' default).
    events : sequence of Event
    steady : (12,) array, optional
        The parameters of the steady DOP853 loop (`rotframe.particles.dop853_steady.steady_parameters`), which then
        runs the calls: the engine's steady problems (`rotframe.problem.steady`), ``model`` the same problem.

    Raises
    ------
    ScenarioError
        A step that is not > 0.
    """

    def __init__(self, model, info, duration, samples, *, step=None, rtol=1e-10, atol=None, events=(), steady=None):
        self.info = info
        self.P = model.pack()
        self.wt, self.wv = model.omega.times, model.omega.values
        self.wint = model.omega.cumulative()
        # what a run does not have is passed as None, which the compiled drivers prune at compile
        # time: a steady rate compiles no table reader, a run without events no event code
        self.wt_arg = None if model.omega.is_constant else self.wt
        self.events = tuple(events)
        self.ev_tab = event_table(self.events) if self.events else None
        from rotframe.particles.kernels import EVALS_PER_STEP

        # the fixed-step family, None where absent (pruned): RK4, the splitting on the sphere
        self.rk4 = True if info.name == "rk4" else None
        self.sphere = True if model.pendulum_length > 0 else None
        self.fixed = info.step == "fixed"
        # the engine's steady problems run the steady loop (rotframe.problem.steady): in one call (`run_chunked`), as a call ends with
        # a step cut to land on its last sample, which the engine's loop never cuts (`RunNeedsCuts` where the run is
        # longer than a call), and with a probe from a 4^-8 part of the first interval up (a short run's 25 probing
        # calls were most of its time; the work's bound from the motion's rate, checked before, keeps it small)
        self.steady_args = None if self.fixed else steady
        self.probe_depth = PROBE_DEPTH if steady is None else STEADY_PROBE_DEPTH
        # the arguments of every fixed-step driver call that do not change (unpacked into it)
        self._model_args = (self.P, self.wt_arg, self.wv, self.wint, self.ev_tab)
        self._family = (self.rk4, self.sphere)
        self.samples = samples
        self.duration = duration
        self.dt_sample = dt = duration / samples
        self.times = sample_times(duration, samples)
        self.rtol = float(rtol)
        self.atol = atol
        if info.step == "fixed":
            self.sps = steps_per_sample(dt, step)
            self.h = dt / self.sps
            self.evals_per_step = EVALS_PER_STEP[info.name]
        else:
            self.sps = 0
            self.h = 0.0

    def kernel(self):
        """The compiled driver of this method."""
        kernel = self.__dict__.get("_kernel")
        if kernel is not None:
            return kernel
        if self.steady_args is not None:
            from rotframe.particles.dop853_steady import run_dop853_steady, steady_events_kernel

            kernel = run_dop853_steady if self.ev_tab is None else steady_events_kernel()
        else:
            from rotframe.particles import drivers

            # a kernel of its own with events (rotframe.particles.drivers): a run compiles only its own loops
            if self.info.step == "fixed":
                kernel = drivers.fixed_step_driver(self.info.name, self.ev_tab is not None)
            else:
                kernel = drivers.run_dop853 if self.ev_tab is None else drivers.run_dop853_events
        self._kernel = kernel
        return kernel

    def guarded(self, model):
        """Whether runs of ``model`` need the energy guard (`_energy_guard`); made once."""
        g = self.__dict__.get("_guarded")
        if g is None:
            g = self._guarded = _guard_applies(model)
        return g

    def abs_tol(self, r0, v0):
        """DOP853's absolute tolerances of the particles ``r0``, ``v0`` (N, 3), a row (r then v) each, (N, 6): ``atol``
        (`KernelSetup`), else ``rtol`` times max(1, |r0|, |v0|) (componentwise max over the ensemble); for ``"own"``,
        each particle's own (`own_tolerance_rows`)."""
        n = r0.shape[0]
        if isinstance(self.atol, str):
            return own_tolerance_rows(r0, v0, self.duration, self.rtol)
        if self.atol is not None and np.ndim(self.atol):
            return np.repeat(np.asarray(self.atol, dtype=float).reshape(1, 6), n, axis=0)
        if self.atol:
            return np.full((n, 6), float(self.atol))
        from rotframe.numerics.step_control import ensemble_scale

        return np.full((n, 6), self.rtol * ensemble_scale(r0, v0))

    def event_records(self, evb):
        """The record arrays of ``evb`` as the drivers take them; None for each without an event table.

        A run without events passes them as None too, so the driver's Python entry point
        does not unbox five arrays that it never reads (and is that much smaller to compile).
        """
        if self.ev_tab is None:
            return None, None, None, None, None, evb.max_events
        return evb.args()

    def call(self, r, v, alive, first, count, out_r, out_v, evb, atol=None, h_state=None, t0=None,
             sps=None, times=None, j0=0):
        """Advance ``r, v`` (N, 3) in place over samples ``first + 1 .. first + count``.

        ``out_r, out_v`` (count, N, 3) receive the samples; ``evb`` ([`EventBuffers`][rotframe.particles.trajectory.EventBuffers])
        the events; ``atol`` (N, 6) and ``h_state`` (N,) are DOP853's (`abs_tol`). Returns
        ``(n_done, bad, nfev, steps)`` as the compiled drivers (``n_done`` samples
        completed, ``bad`` the first particle with a non-finite state or -1, the cost
        of particle 0). ``j0`` (steps of the interval made before) and ``sps`` (default
        `sps`) let a fixed-step call start inside a sample interval and take part
        of it (`one_sample_in_pieces`): a fixed step starts on its interval's grid, ``T[s] + j h``, whatever
        the call (`rotframe.numerics.step_control.grid_time`). ``t0`` (adaptive only: default the sample time
        ``first``) and ``times`` (adaptive only) replace the start and the sample times the call lands on: the
        probe's short spans, or the pieces of a long sample interval (`run_chunked`).

        More particles than one block (`rotframe.particles.threads.BLOCK`) run in
        blocks on every core (`rotframe.particles.blocks.run_blocks`),
        bitwise as one call.
        """
        kernel = self.__dict__.get("_kernel") or self.kernel()
        records = self.event_records(evb)
        if self.fixed:
            grid = self.times[first:first + count + 1]  # the call's sample times, from its first interval's start
        if self.fixed and r.shape[0] <= threads.BLOCK:
            # one block: the driver itself, without the pool's bookkeeping (a short run's overhead)
            k = self.sps if sps is None else sps
            n_done, bad, nfev = kernel(r, v, alive, grid, j0, self.h, k, count, *self._model_args,
                                       out_r, out_v, *records, *self._family)
            return n_done, bad, nfev, k * n_done
        from rotframe.particles.blocks import run_blocks

        ev_t, ev_r, ev_v, ev_count, ev_which, max_events = records
        per_particle = (r, v, alive, ev_t, ev_r, ev_v, ev_count, ev_which, h_state, atol)
        if self.info.step == "fixed":
            k = self.sps if sps is None else sps

            def one(r, v, alive, ev_t, ev_r, ev_v, ev_count, ev_which, h_state, atol, out_r, out_v):
                return kernel(r, v, alive, grid, j0, self.h, k, count, self.P, self.wt_arg,
                              self.wv, self.wint, self.ev_tab, out_r, out_v, ev_t, ev_r, ev_v, ev_count, ev_which,
                              max_events, self.rk4, self.sphere) + (k * count,)

            n_done, bad, nfev, steps = run_blocks(one, r.shape[0], per_particle, (out_r, out_v))
            return n_done, bad, nfev, k * n_done
        start = float(self.times[first]) if t0 is None else t0
        span = self.duration  # the starting step's bound: the whole run, however it is cut into calls
        end = first + 1 + max(count, 1)
        times = self.times[first + 1:end] if times is None else np.ascontiguousarray(times, dtype=float)
        from rotframe.particles.dop853_ensemble import WORK_ROWS  # here: importing a scene compiles nothing

        # the engine's steady problem: the steady loop at any size (`rotframe.problem.steady`)
        if self.steady_args is not None:
            q = self.steady_args

            def one(r, v, alive, ev_t, ev_r, ev_v, ev_count, ev_which, h_state, atol, out_r, out_v):
                work = np.empty((WORK_ROWS, 6))
                if self.ev_tab is None:
                    return kernel(r, v, start, times, q, self.rtol, atol, span, work, out_r, out_v, h_state)
                return kernel(r, v, alive, start, times, q, self.rtol, atol, span, self.ev_tab, work, out_r, out_v,
                              h_state, ev_t, ev_r, ev_v, ev_count, ev_which, max_events, np.empty((13, 6)))

            return run_blocks(one, r.shape[0], per_particle, (out_r, out_v), most=True)  # its count: the engine's

        def one(r, v, alive, ev_t, ev_r, ev_v, ev_count, ev_which, h_state, atol, out_r, out_v):
            return kernel(r, v, alive, start, times, self.P, self.wt_arg, self.wv, self.rtol, atol, span,
                          self.ev_tab, out_r, out_v, ev_t, ev_r, ev_v, ev_count, ev_which, max_events, h_state,
                          np.empty((WORK_ROWS, 6)), np.empty((13, 6)))
        return run_blocks(one, r.shape[0], per_particle, (out_r, out_v))

    def warm_up(self):
        """Load or compile the driver now; the seconds it took, or 0.0 if it was ready.

        An empty call (no particle) makes numba compile the driver, or load it
        from its disk cache, when this process has not yet used it with these
        argument types. Whether it did is read from the dispatcher itself (it
        gained a compiled version), not from any record of earlier runs, so
        the result depends on this call only: the time of that empty call when
        it loaded or compiled, else 0.0. A dispatcher that already holds a
        compiled version is not called (every run's arguments have the same
        types, so the run's own call only dispatches).
        """
        kernel = self.kernel()
        # the dispatcher's compiled versions (a dict, O(1) to count; a wrapped kernel has none), a fixed-step
        # driver's behind its bound method (`rotframe.particles.drivers.fixed_step_driver`)
        kernel = getattr(kernel, "func", kernel)
        overloads = getattr(kernel, "overloads", None)
        if overloads:
            return 0.0  # loaded or compiled before, in this process: the run's call only dispatches
        before = 0 if overloads is None else len(overloads)
        t_load = time.perf_counter()
        empty = np.empty((0, 3))
        out = np.empty((0, 0, 3))
        self.call(empty.copy(), empty.copy(), np.ones(0, dtype=np.bool_), 0, 0, out, out.copy(),
                  EventBuffers(0, 1), np.empty((0, 6)), np.zeros(0), 1.0)
        elapsed = time.perf_counter() - t_load
        return elapsed if overloads is not None and len(kernel.overloads) > before else 0.0

    def one_sample_in_pieces(self, r, v, alive, first, out_r, out_v, evb, n):
        """One sample interval of ``sps`` fixed steps as several calls of at most `CALL_EVALS` step-evaluations.

        The calls are of equal length (within one step): 48 steps of 100,000 RK4 particles
        (1.9e7 evaluations) are two calls of 24, not 40 and 8 (a short call is all dispatch and
        waiting on the threads).
        Returns ``(n_done, bad, nfev, steps)`` as `call` for that one sample.
        """
        most = max(1, int(CALL_EVALS // (n * self.evals_per_step)))
        sps = self.sps
        pieces = -(-sps // most)
        j = 0
        nfev = 0
        for p in range(pieces):
            k = (p + 1) * sps // pieces - j
            # each piece writes its end state into the sample's slot; the last piece's is the sample
            # (a slot of megabytes allocated for each piece cost page faults on every thread)
            n_done, bad, nf, _ = self.call(r, v, alive, first, 1, out_r[:1], out_v[:1], evb, j0=j, sps=k)
            nfev += nf
            if n_done < 1 or bad >= 0:
                return 0, bad, nfev, 0
            j += k
        return 1, -1, nfev, sps


#: an adaptive call is kept under this many particle-steps (about a tenth of a second)
CALL_STEPS = 2e5
class RunNeedsCuts(Exception):
    """A run whose set-up runs in one call (one with `KernelSetup.steady_args`: the engine's steady loop) needs more than one: a
    call ends on a sample with a step cut short to land there, where the engine's loop only samples inside its steps,
    so the steps would differ. ``args[0]``: the steps its probe projected for the run."""


#: the probe's spans: from the first sample interval over 4^PROBE_DEPTH up, by factors of 4, until it took
#: PROBE_STEPS steps (a span of 1e15 s is never integrated whole to learn its cost)
PROBE_DEPTH = 24
#: the same for the engine's steady loop (`KernelSetup`)
STEADY_PROBE_DEPTH = 8
PROBE_STEPS = 2000


def _probe(setup, r, v, alive, evb, atol, h_state, out_r, out_v, whole):
    """Steps per particle an adaptive method takes over one sample interval, measured in bounded calls.

    The first sample interval is probed from a short span up (its 4^-24 part, then 4 times longer at
    each try) until a try took `PROBE_STEPS` steps or covered the interval; the count is scaled to
    the whole interval. Each try is a fraction of a second however long the interval, so that a
    signal is seen. The tries run on copies, so the run's own calls do not depend on them; where
    the run is that one interval (``whole``), the last try is the run's own call on its arrays.

    Returns ``(steps per sample interval, the run's own call's result or None)``.
    """
    t0, t1 = float(setup.times[0]), float(setup.times[1])
    dt = t1 - t0
    # the count is particle 0's (the drivers report its cost), so the tries integrate particle 0 alone:
    # a try over the whole ensemble cost its every particle a first step and more, 25 times
    scratch = np.empty((1, 1, 3))
    for k in range(setup.probe_depth, -1, -1):
        end = t1 if k == 0 else t0 + dt / 4.0 ** k
        if k > 0 and not end > t0:
            continue
        if k == 0 and whole:
            result = setup.call(r, v, alive, 0, 1, out_r, out_v, evb, atol, h_state)
            return float(result[3]), result
        steps = setup.call(r[:1].copy(), v[:1].copy(), alive[:1].copy(), 0, 1, scratch, scratch.copy(),
                           EventBuffers(1, evb.max_events), atol[:1].copy(), h_state[:1].copy(),
                           times=np.array([end]))[3]
        if k == 0 or steps >= PROBE_STEPS:
            return float(steps) * dt / (end - t0), None
    return 1.0, None


def _pieces(per_sample, n):
    """Pieces of a sample interval such that each is at most `CALL_STEPS` particle-steps (1: the interval whole)."""
    return int(max(1, math.ceil(float(per_sample) * max(n, 1) / CALL_STEPS)))


def _sample_in_pieces(setup, r, v, alive, done, pieces, out_r, out_v, evb, atol, h_state):
    """One sample interval of an adaptive method landed on in ``pieces`` equal parts, a call each (`call`'s return)."""
    t0, t1 = float(setup.times[done]), float(setup.times[done + 1])
    steps = nfev = 0
    for j in range(1, pieces + 1):
        end = t1 if j == pieces else t0 + (t1 - t0) * j / pieces
        start = t0 + (t1 - t0) * (j - 1) / pieces
        n_done, bad, nf, st = setup.call(r, v, alive, done, 1, out_r[:1], out_v[:1], evb, atol, h_state,
                                         t0=start, times=np.array([end]))
        steps += st
        nfev += nf
        if n_done < 1 or bad >= 0:
            return 0, bad, nfev, steps
    return 1, -1, nfev, steps


def _adaptive_chunk(info, per_sample, samples, n):
    """Samples per call of an adaptive kernel that took ``per_sample`` steps over its first sample.

    The run's total is projected from that rate and refused (`rotframe.limits`) when it
    is over the work limit; a call is kept under `CALL_STEPS` particle-steps (a tenth of a
    second), so that Python regains control (signals, progress) that often.
    """
    per_sample = max(float(per_sample), 1.0)
    limits.check_run(steps=per_sample * samples, particles=n,
                     what=f"method {info.name} (projected from its first sample interval)",
                     remedy="shorten duration or loosen rtol")
    return int(max(1.0, CALL_STEPS / (per_sample * max(n, 1))))


def run_chunked(setup, model, r0, v0, progress=None, max_events=64, records=False, owned=False):
    """Integrate ``r0, v0`` (N, 3) with ``setup`` in interruptible chunks; a [`Trajectory`][rotframe.particles.trajectory.Trajectory].

    ``owned=True``: ``r0, v0`` are the caller's own copies, advanced in place (one copy fewer).
    ``records=True`` leaves a complete run's events in their record arrays
    (``traj.extras["event_records"]``, an [`EventBuffers`][rotframe.particles.trajectory.EventBuffers]) instead of splitting
    them into per-particle lists (about 1 us a particle, holding the GIL).

    ``traj.extras``: ``step`` (the fixed step, 0 for DOP853) and ``compile_s``
    (`KernelSetup.warm_up`: seconds spent loading or compiling the compiled
    driver in this call, 0.0 when it was already loaded); for DOP853, ``atol``, the absolute
    tolerances each particle took (`KernelSetup.abs_tol`, (N, 6)).

    Raises
    ------
    IntegrationError
        Non-finite state or an unstable step; ``partial`` holds the samples before it.
    RunInterrupted
        KeyboardInterrupt during the run; ``partial`` holds the samples before it.
    """
    info = setup.info
    samples, times, events = setup.samples, setup.times, setup.events
    n = r0.shape[0]
    if progress is None and info.step == "fixed" and n <= threads.BLOCK and owned:
        traj = _run_once(setup, model, r0, v0, max_events, records)
        if traj is not None:
            return traj
    # no event: no records (a (N, 64) table of them would cost more than a short run)
    slots = max_events if events else 0
    limits.check_memory(f"method {info.name}", {"samples (r and v at each sample)": 48.0 * (samples + 1) * n,
                                                "event slots": 64.0 * n * slots, "state (r, v, alive)": 56.0 * n})
    evb = EventBuffers(n, slots)
    alive = np.ones(n, dtype=np.bool_)
    out_r = np.empty((samples + 1, n, 3))
    out_v = np.empty((samples + 1, n, 3))
    out_r[0] = r0
    out_v[0] = v0
    r = r0 if owned else r0.copy()
    v = v0 if owned else v0.copy()
    r0, v0 = out_r[0], out_v[0]  # the initial state, kept (r, v advance in place)
    if info.step == "fixed":
        cost = setup.sps * n * setup.evals_per_step
        atol = None
        h_state = None
    else:
        atol = setup.abs_tol(r0, v0)
        h_state = np.zeros(n)
        cost = n * 200
    guard = _energy_guard(model, r0, v0)
    chunk = max(1, int(CALL_EVALS // max(cost, 1)))
    done = 0
    nfev = 0
    steps = 0
    pieces = 1
    first = None  # the result of a first call already made on the run's own arrays
    try:
        compile_s = setup.warm_up()
        if info.step != "fixed":
            # an adaptive method's cost is known only once it ran: a probe of the first sample
            # interval projects the work and sizes the calls. On copies (the run itself is untouched,
            # so its chunks do not depend on the probe), except when that interval is the whole run
            per_sample, first = _probe(setup, r, v, alive, evb, atol, h_state, out_r[1:2], out_v[1:2], samples == 1)
            chunk = min(chunk, _adaptive_chunk(info, per_sample, samples, n))
            pieces = _pieces(per_sample, n)
            if setup.steady_args is not None and (pieces > 1 or chunk < samples):
                raise RunNeedsCuts(per_sample * samples)
        # fixed steps: calls of equal length (within a sample), no short last call that is all dispatch
        # (an adaptive method's last step in a call ends on the call's last sample: its calls keep their cut)
        calls = -(-samples // chunk) if info.step == "fixed" else None
        call = 0
        while done < samples:
            call += 1
            m = call * samples // calls - done if calls else min(chunk, samples - done)
            sl = slice(done + 1, done + 1 + m)
            if first is not None:
                (n_done, bad, nf, st), first = first, None
            elif info.step != "fixed" and pieces > 1:
                # a sample interval of more steps than a call should take: landed on in pieces (a number fixed by
                # the probe, so the same on every run), each a call of its own, so that signals are seen
                n_done, bad, nf, st = _sample_in_pieces(setup, r, v, alive, done, pieces, out_r[sl], out_v[sl], evb,
                                                        atol, h_state)
            elif info.step == "fixed" and cost > CALL_EVALS:
                # one sample interval is more than a chunk of work: advance it in pieces, so that
                # Python regains control (signals, progress) between them
                n_done, bad, nf, st = setup.one_sample_in_pieces(r, v, alive, done, out_r[sl], out_v[sl], evb, n)
            else:
                n_done, bad, nf, st = setup.call(r, v, alive, done, m, out_r[sl], out_v[sl], evb, atol, h_state)
            steps += st
            nfev += nf
            if n_done < m or bad >= 0:
                good = done + 1 + n_done
                partial = Trajectory(times, out_r, out_v, info.name, steps, nfev).truncated(good)
                evb.attach(partial, events)
                raise IntegrationError(
                    f"non-finite state of particle {bad} after t = {times[good - 1]:.6g} s "
                    f"(method {info.name})", t_reached=float(times[good - 1]), partial=partial)
            bad_k = _energy_growth(model, guard, times, out_r, out_v, done + 1, done + 1 + m)
            if bad_k is not None:
                partial = Trajectory(times, out_r, out_v, info.name, steps, nfev).truncated(bad_k)
                evb.attach(partial, events)
                raise IntegrationError(
                    f"unstable step: the inertial speed of a particle under no real force grew by more than "
                    f"{GROWTH_LIMIT:g} (relative) by t = {times[bad_k]:.6g} s (method {info.name}); "
                    + remedy(info.step, step=setup.h, rtol=setup.rtol),
                    t_reached=float(times[bad_k - 1]), partial=partial)
            done += m
            if progress is not None:
                progress(done / samples)
            if not alive.any():
                # every particle stopped at a terminal event: fill the rest and finish
                out_r[done + 1:] = r
                out_v[done + 1:] = v
                done = samples
    except KeyboardInterrupt:
        partial = Trajectory(times, out_r, out_v, info.name, steps, nfev).truncated(done + 1)
        evb.attach(partial, events)
        raise RunInterrupted(partial) from None
    traj = Trajectory(times, out_r, out_v, info.name, steps, nfev, True, setup.duration)
    traj.extras["step"] = setup.h
    traj.extras["compile_s"] = compile_s
    if atol is not None:
        traj.extras["atol"] = atol
    if records:
        traj.extras["event_records"] = evb
    else:
        evb.attach(traj, events)
    return traj


#: the shared records of a run without events (never written: the drivers get None for them)
_NO_RECORDS = EventBuffers(0, 0)


def _run_once(setup, model, r, v, max_events, records):
    """A short fixed-step run in one call of the driver, with the least Python around it; None if it does not apply.

    The run of `run_chunked` when it is one chunk (at most `CALL_EVALS` step-evaluations),
    one block and the model needs no energy guard: the same call of the driver with the same
    arguments, so the same numbers. A failure (a non-finite state) returns None after
    restoring nothing: the caller runs the general path from the initial state, which
    raises with the partial trajectory.
    """
    samples, n = setup.samples, r.shape[0]
    if setup.sps * n * setup.evals_per_step * samples > CALL_EVALS or setup.guarded(model):
        return None
    out_r = np.empty((samples + 1, n, 3))
    out_v = np.empty((samples + 1, n, 3))
    out_r[0] = r
    out_v[0] = v
    evb = EventBuffers(n, max_events) if setup.events else _NO_RECORDS
    alive = np.empty(n, dtype=np.bool_)
    alive[:] = True
    compile_s = setup.warm_up()
    n_done, bad, nfev, steps = setup.call(r, v, alive, 0, samples, out_r[1:], out_v[1:], evb)
    if n_done < samples or bad >= 0:
        r[...] = out_r[0]  # the general path starts again from the initial state, and raises
        v[...] = out_v[0]
        return None
    traj = Trajectory(setup.times, out_r, out_v, setup.info.name, steps, nfev, True, setup.duration)
    traj.extras["step"] = setup.h
    traj.extras["compile_s"] = compile_s
    if records:
        traj.extras["event_records"] = evb
    else:
        evb.attach(traj, setup.events)
    return traj


def _inertial_speed(model, t, r, v):
    """|v + w(t) x r| for positions and velocities (..., N, 3) at times t (...,)."""
    w = np.interp(t, model.omega.times, model.omega.values)
    wv = np.asarray(w)[..., None, None] * model.omega.axis
    return np.linalg.norm(v + np.cross(wv, r), axis=-1)


def _energy_guard(model, r0, v0):
    """The initial inertial speeds when the model's true motion keeps them (else None).

    A particle under the fictitious forces alone (Coriolis, centrifugal, and
    Euler when the rate varies) moves on a straight line at constant speed in
    inertial space; drag only slows it. So its inertial speed |v + w x r| never
    grows, whatever the frame does, and a growth beyond `GROWTH_LIMIT`
    is the mark of an unstable step (docs/physics/stability.md). Models with a
    real force that can add energy (gravity, springs, a pendulum) return None.
    """
    if not _guard_applies(model):
        return None
    return _inertial_speed(model, 0.0, r0, v0)


def _guard_applies(model):
    """Whether the model's true motion keeps the inertial speeds from growing (see `_energy_guard`)."""
    terms = set(model.terms)
    fictitious = {"coriolis", "centrifugal"} | (set() if model.omega.is_constant else {"euler"})
    return fictitious <= terms and terms <= fictitious | {"euler", "linear-drag", "quadratic-drag"}


def _energy_growth(model, guard, times, out_r, out_v, lo, hi):
    """Index of the first sample in [lo, hi) where the inertial speed grew past the limit, or None."""
    if guard is None:
        return None
    with np.errstate(all="ignore"):
        speed = _inertial_speed(model, times[lo:hi], out_r[lo:hi], out_v[lo:hi])
    scale = np.maximum(guard, 1e-300)
    grown = np.any(speed > (1.0 + GROWTH_LIMIT) * scale + 1e-12, axis=1) | ~np.all(np.isfinite(speed), axis=1)
    if not grown.any():
        return None
    return lo + int(np.argmax(grown))
