"""Many runs of one particle problem from different start states, set up once.

`rotframe.simulate` checks its arguments, calls each of your functions once, finds the
problem's compiled glue, and after the run measures its energy and the frame's interpolation:
some milliseconds a call, more than a short run's integration. A `PreparedProblem` does the
set-up once (`rotframe.problem.particle_setup.set_up`, the same as ``simulate``'s) and loads the
problem's inlined loop (`rotframe.problem.inlined`: your functions compiled into the engine's
loop, cached on disk); each `PreparedProblem.run` then makes the run's arrays (one particle's it
keeps from run to run and resets) and makes one call of that loop: some 15 us of its own a run,
beside the scenes' 10. For optimisation loops, shooting, Monte Carlo over start states, and the scenes
built on the engine: the particles' counterpart of the scenes'
`rotframe.particles.prepared.PreparedRun`.

A run gives the numbers of ``simulate`` with the same arguments, to the bit: the same loop, the
same steps (a call's budget of steps never changes them: `rotframe.problem.engine`); only its
count of evaluations may be smaller, ``simulate``'s pacer cutting a run into calls that each
evaluate f once more at their start. What it
leaves out is what ``simulate`` adds around the trajectory: the energy diagnostic, the frame's
interpolation error, the progress bar, the GPU. A failed run raises as ``simulate`` does (the
particle, the time, the state, the function to blame, the samples up to there).
"""

from __future__ import annotations

import threading

import numpy as np

from rotframe.errors import IntegrationError, ScenarioError
from rotframe.limits import check_run
from rotframe.particles.trajectory import Trajectory
from rotframe.problem.engine import scratch
from rotframe.problem.inlined import Inlining
from rotframe.problem.kept import ArrayBlocks
from rotframe.problem.models import model_parts
from rotframe.problem.particle_setup import (check_arrays, checked_atol, checked_attitude, checked_states, fill_states,
                                             plain_states, run_state, set_up, tolerance_rows)
from rotframe.problem.particles import advance_blocks, exact_model, raise_if_failed, raised_later, trajectory_of
from rotframe.problem.terms import StringConstraint, check_on_string

__all__ = ["PreparedProblem"]

#: a call's budget of steps per particle: the whole run in one call (the budget never changes the steps)
_WHOLE_RUN = 2 ** 62


class PreparedProblem:
    """A particle problem of `rotframe.simulate`, set up once and run from many start states.

    Parameters
    ----------
    r0, v0 : array_like
        The first start states, (3,) or (N, 3) (m, m/s; the frame's axes): every check of
        ``simulate`` is made on them (each function is called once at particle 0's).
    omega, duration, forces, params, origin_acceleration, events, method, rtol, step, samples, omega_dot, atol, \
frame_attitude, frame_terms
        As `rotframe.simulate` takes them (SI floats here: the core takes no units).
    inline : bool
        True (default): the runs use the problem's inlined loop (`rotframe.problem.inlined`),
        loaded from the disk cache or compiled here (seconds, once per problem ever), or, for a
        problem that ``simulate`` runs on the engine's steady loop (`rotframe.problem.steady`),
        that loop (compiled once for every such problem); False: the engine's loop, which calls
        your functions by address (nothing to compile).

    Examples
    --------
    >>> import numpy as np
    >>> from rotframe import forces
    >>> from rotframe.problem.prepared import PreparedProblem
    >>> spin = PreparedProblem(r0=[1.0, 0.0, 0.0], v0=[0.0, 0.0, 0.0], omega=[0.0, 0.0, 1.0], duration=1.0,
    ...                        forces=[forces.spring(4.0, [0.0, 0.0, 0.0])], inline=False)
    >>> a = spin.run([1.0, 0.0, 0.0], [0.0, 0.0, 0.0]).r[-1, 0]
    >>> b = spin.run([2.0, 0.0, 0.0], [0.0, 0.0, 0.0]).r[-1, 0]
    >>> bool(np.allclose(b, 2.0 * a, rtol=1e-8) and not np.allclose(a, [1.0, 0.0, 0.0]))  # linear: twice the start
    True
    """

    def __init__(self, *, r0, v0, omega, duration, forces=(), params=(), origin_acceleration=None, events=(),
                 method=None, rtol=None, step=None, samples=None, omega_dot=None, atol=None, frame_attitude=None,
                 frame_terms=None, inline=True):
        if not isinstance(inline, bool):
            raise ScenarioError(f"inline={inline!r}: True (the problem's functions compiled into the loop) or False "
                                "(called by address)")
        arguments = dict(r0=r0, v0=v0, omega=omega, duration=duration, forces=forces, params=params,
                         origin_acceleration=origin_acceleration, events=events, method=method, rtol=rtol, step=step,
                         samples=samples, omega_dot=omega_dot, atol=atol, frame_attitude=frame_attitude,
                         frame_terms=frame_terms)
        # the steady loop where simulate takes it (`rotframe.problem.steady`): inline=True is this class's default,
        # so the choice is made as simulate makes it with its own default (None)
        s = set_up(r0, v0, omega=omega, duration=duration, forces=forces, params=params,
                   origin_acceleration=origin_acceleration, events=events, method=method, rtol=rtol, step=step,
                   samples=samples, omega_dot=omega_dot, jit=True, max_events=256, device=None,
                   frame_terms=frame_terms, inline=None if inline is True else inline, fixed_steady=False)
        self.setup = s
        self._omega = omega
        #: the frame's attitude, checked once (refused even where no force reads it, as simulate refuses it)
        self._attitude = None if frame_attitude is None else checked_attitude(frame_attitude)
        self._atol = checked_atol(atol)  # checked once: each run takes it as it is
        #: the string (`forces[k]`, the constraint) the start states are checked against at each run, or None
        self._string = next(((k, f) for k, f in enumerate(s.terms) if isinstance(f, StringConstraint)), None)
        #: the sample times (s), (samples + 1,)
        self.times = s.times
        self.notes = []
        #: the exact flow's matrices for the sample grid (`_ExactFlow`), where the method is ``exact``
        self._exact = _ExactFlow(s) if s.method == "exact" else None
        if self._exact is not None:  # its calls bound here: a run of a few microseconds pays no second dispatch
            self.states, self.run = self._exact.states, self._exact.run
            return
        if s.steady is not None:  # the steady loop (as simulate runs this problem): its calls bound here too
            self._steady = _SteadyLoop(s, self._atol, self._string, arguments)
            self.run = self._steady.run
            self.notes = ["method dop853: the engine's steady loop (rotframe.problem.steady)"]
            return
        inlining = Inlining(s.driver.module, s.prob[0], s.method, s.events, s.D, model_parts(s.prob), inline)
        inlining.start()
        self._kernel = inlining.kernel
        self._kept = None  # a run's arrays, kept for the next (`_KeptArrays`)
        self.notes = [inlining.note] if inlining.note else []

    def states(self, r0, v0):
        """The samples of a run from ``r0``, ``v0`` as arrays, ``(r, v)``, each (samples + 1, N, 3): what `run` gives
        as ``traj.r`` and ``traj.v``, without the `Trajectory` around them. For ``method="exact"`` the least a run
        costs (the kept matrices times the start states, some 1.6 us for one particle); the other methods run
        `run`."""
        traj = self.run(r0, v0)  # (the exact flow's own `states` is bound in its place)
        return traj.r, traj.v

    def run(self, r0, v0):
        """Integrate from the start states ``r0``, ``v0`` ((3,) or (N, 3)): a `rotframe.particles.trajectory.Trajectory`.

        ``simulate``'s trajectory for the same arguments, to the bit. The states are checked as
        ``simulate`` checks them (finite; on the string's sphere where there is one; more particles
        than the first run's within the memory and work limits, `rotframe.limits`); the
        functions are not called again in plain Python. Raises as ``simulate`` does where a
        particle fails (`rotframe.problem.particles.raise_if_failed`).
        """
        s = self.setup
        r, v = checked_states(r0, v0)
        N = r.shape[0]
        if N > s.r.shape[0]:  # more particles than the set-up's: the limits checked for them
            check_arrays(N, s.times.size, s.D, s.slots, s.stops.size)
            check_run(steps=s.duration / s.hfix if s.hfix else 0.0, particles=N,
                      what=f"method {s.method}")  # a fixed step's count, as simulate's grid checks it
        if self._string is not None:
            check_on_string(*self._string, r, v)
        if N == 1 and self._kept is None:
            self._kept = _KeptArrays(s, self._atol)
        kept = self._kept if N == 1 else None
        if kept is not None and kept.lock.acquire(blocking=False):  # one call at a time uses them
            try:
                return self._run(r, v, *kept.reset())
            finally:
                kept.lock.release()
        return self._run(r, v, *_fresh_arrays(s, N, self._atol))

    def _run(self, r, v, y, state, atol, OUT, work):
        """The run from ``r``, ``v`` with its arrays (`_KeptArrays` or `_fresh_arrays`): the states ``y``, the
        per-particle ``state``, the tolerances, the samples and the loop's work arrays (None: made per block)."""
        s = self.setup
        self._start(r, v, y, state)
        OUT[0] = y  # the start, as the loop writes it: a particle the run never reached keeps it (as simulate)
        before = (s.times, y, state["TC"], state["H"], state["IDX"], state["SUB"], state["ST"], OUT, state["EVT"],
                  state["EVY"], state["EVK"], state["EVN"], state["GPREV"], state["NSTEP"], state["NFEV"])
        after = (s.method, s.rtol, atol, s.hfix, s.EDIR, s.ETERM, s.stops, s.prob, s.fns)
        advance = self._advance
        try:
            if work is not None:  # one particle: no thread to start, the kept work arrays
                advance(0, 1, *before, _WHOLE_RUN, *after, work=work)
            else:
                advance_blocks(advance, r.shape[0], before + (_WHOLE_RUN,) + after)
        except Exception as exc:  # a user function raised in the inlined loop: replayed from the start, as simulate
            y0, saved, _, _, _ = _fresh_arrays(s, r.shape[0], self._atol)  # replays a call (`raised_later`)
            self._start(r, v, y0, saved)
            saved["Y"] = y0
            raised_later(exc, advance, y, saved, {"before": before, "after": after, "budget": _WHOLE_RUN}, s, OUT,
                         state)
        raise_if_failed(s, state, y, OUT)
        traj = trajectory_of(s.times, OUT, state, s.events, s.method, s.times.size, s.hfix)
        if s.D == 10:
            traj.extras["frame_q"] = OUT[:, 0, 6:10].copy()
        return traj

    def _start(self, r, v, y, state):
        """The engine's states of the start states ``r``, ``v`` into ``y``, and their events' values into the run's
        ``state``."""
        s = self.setup
        fill_states(s, r, v, self._attitude, self._omega, y)
        if s.events:
            s.driver.start_events(0.0, y, state["GPREV"], s.prob, s.fns)

    def _advance(self, lo, hi, *args, work=None):
        self.setup.driver.advance(lo, hi, *args, kernel=self._kernel, work=work)


class _ExactFlow:
    """``method="exact"`` prepared: the exact flow's matrices for the run's sample grid, made once (the scenes'
    `rotframe.particles.linear.ExactFlow` of the problem's `rotframe.problem.particles.exact_model`); each run
    multiplies them into its start states in one compiled loop (`rotframe.particles.exact_kernel.apply_flow`), a few
    microseconds. ``simulate``'s numbers to round-off, not to the bit: the products are grouped otherwise."""

    def __init__(self, s):
        from rotframe.particles.exact_kernel import apply_flow
        from rotframe.particles.linear import ExactFlow

        if s.events:  # the kept matrices give samples alone: a crossing is located by simulate's exact run
            raise ScenarioError("events: a prepared exact flow keeps the flow's matrices for the samples and locates "
                                "no event; call rotframe.simulate (method='exact' locates a crossing) or prepare "
                                "dop853")
        model = exact_model(s.terms, s.frame, s.origin, s.events, s.frame_terms)
        with np.errstate(all="ignore"):  # an overflow (an unstable problem run far) is caught per run
            phi = ExactFlow(model, s.times).matrices()  # (samples + 1, 7, 7)
        self._phi_t = np.ascontiguousarray(np.transpose(phi[:, 0:6, :], (0, 2, 1)))  # (samples + 1, 7, 6)
        self._apply = apply_flow
        apply_flow(self._phi_t[:1], np.zeros((1, 3)), np.zeros((1, 3)))  # load or compile the kernel now
        self._times = s.times.copy()
        self._times.flags.writeable = False  # shared by every run's Trajectory, as its sample times
        self._particles = s.r.shape[0]  # the set-up's, whose samples simulate's checks held to the limits

    def run(self, r0, v0):
        """The `Trajectory` from the start states ``r0``, ``v0`` (as ``simulate`` takes them)."""
        rs, vs = self.states(r0, v0)
        return Trajectory(self._times, rs, vs, "exact", 0, 0, True, float(self._times[-1]))

    def states(self, r0, v0):
        """``(r, v)`` samples from the start states ``r0``, ``v0``; IntegrationError at a non-finite state."""
        times = self._times
        if plain_states(r0, v0):  # the states as a run takes them: their finiteness is the flow's sample 0
            r, v = (r0[None], v0[None]) if r0.ndim == 1 else (r0, v0)
        else:
            r, v = checked_states(r0, v0)
        if r.shape[0] > self._particles:  # more particles than the set-up's: their samples within the limits
            check_run(samples=times.size, particles=r.shape[0], what="method exact")
        rs, vs, k_bad = self._apply(self._phi_t, r, v)
        if k_bad == 0:  # sample 0 is the start itself (the flow's identity): the start is not finite
            checked_states(r0, v0)
        if k_bad >= 0:
            good = max(int(k_bad), 1)
            partial = Trajectory(times[:good].copy(), rs[:good], vs[:good], "exact", 0, 0, False,
                                 float(times[good - 1]))
            raise IntegrationError(f"simulate: the exact flow gave a non-finite state at t = {times[k_bad]:.9g} s; "
                                   "samples up to there are kept", t_reached=float(times[good - 1]), partial=partial)
        return rs, vs


class _SteadyLoop:
    """``method="dop853"`` on a steady problem prepared (`rotframe.problem.steady`): the steady loop's set-up made once
    per count of particles (the scenes' `rotframe.particles.prepared.PreparedRun` with the problem's parameters); each
    run is one call of it. ``simulate``'s numbers to the bit. A run that fails runs again on the engine's loop
    (a `PreparedProblem` made with ``inline=False`` from the same ``arguments``), which raises as ``simulate`` does."""

    def __init__(self, s, atol, string, arguments):
        self._s, self._string, self._arguments = s, string, arguments
        self._atol = "own" if atol is None else tuple(atol.tolist())
        self._runs = {}  # particles -> PreparedRun
        self._times = s.times.copy()
        self._times.flags.writeable = False  # shared by every run's Trajectory, as its sample times
        self._prepared(s.r.shape[0])  # load or compile the loop now

    def _prepared(self, N):
        from rotframe.particles.prepared import PreparedRun

        pr = self._runs.get(N)
        if pr is None:
            s = self._s
            if N > s.r.shape[0]:  # more particles than the set-up's: their samples within the limits
                check_arrays(N, s.times.size, s.D, 1, 2)
            model, q = s.steady.model, s.steady.q
            pr = self._runs[N] = PreparedRun(model, "dop853", s.duration, rtol=s.rtol, atol=self._atol,
                                             samples=s.times.size - 1, n=N, steady=q)
        return pr

    def run(self, r0, v0):
        """The `Trajectory` from the start states ``r0``, ``v0`` (as ``simulate`` takes them)."""
        r, v = checked_states(r0, v0)
        if self._string is not None:
            check_on_string(*self._string, r, v)
        pr = self._prepared(r.shape[0])
        try:
            rs, vs = pr.run(r, v)
        except IntegrationError:  # met again, and named, by the engine's loop
            return PreparedProblem(**dict(self._arguments, r0=r, v0=v), inline=False).run(r, v)
        return Trajectory(self._times, rs, vs, "dop853", pr.steps, pr.nfev, True, float(self._times[-1]))


def _fresh_arrays(s, N, atol):
    """A run's arrays made anew, as `PreparedProblem._run` takes them: ``(y, state, atol, OUT, work)``; ``work`` None
    (the loop's work arrays made per block of particles). A run of many particles, or of one while another call holds
    the kept ones (`_KeptArrays`)."""
    return (np.zeros((N, s.D)), run_state(N, s.D, s.slots, len(s.events)), tolerance_rows(N, s.D, s.rtol, atol),
            np.full((s.times.size, N, s.D), np.nan), None)


#: the loop's work arrays, by `rotframe.problem.engine.scratch`'s names
_WORK = ("K", "Kb", "V", "F", "W")


class _KeptArrays:
    """The arrays of a prepared run of one particle, made once (`rotframe.problem.kept.ArrayBlocks`) and reset at each run.

    Nothing of them leaves a run: its `Trajectory` holds
    copies. A run that finds them in use (a call on another thread) makes its own
    (`_fresh_arrays`); so does a run of many particles, whose blocks on threads each need work
    arrays of their own, and whose integration outweighs the arrays.
    """

    def __init__(self, s, atol):
        y, state, tolerances, OUT, _ = _fresh_arrays(s, 1, atol)
        self.lock = threading.Lock()
        self._arrays = ArrayBlocks({"y": y, "atol": tolerances, "OUT": OUT, "state": state,
                                    **dict(zip(_WORK, scratch(s.D)))})
        v = self._arrays.views
        self._views = (v["y"], v["state"], v["atol"], v["OUT"], tuple(v[k] for k in _WORK))

    def reset(self):
        """The arrays as a fresh run finds them: ``(y, state, atol, OUT, work)``."""
        self._arrays.reset()
        return self._views
