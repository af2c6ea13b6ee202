"""Many runs of one rigid body from different start states, set up once: the bodies' `PreparedProblem`.

`rotframe.simulate_body` checks its arguments, calls each torque once, finds the body's compiled
glue and paces the run in calls: a fraction of a millisecond, more than a short run's
integration. A `PreparedBody` does the set-up once (`rotframe.problem.body.body_set_up`, the same
as ``simulate_body``'s) and loads the body's inlined loop (`rotframe.problem.inlined`: the torques
compiled into the engine's loop, cached on disk); each `PreparedBody.states` then makes the run's
arrays and makes one call of that loop. For the rigid scenes' bench rows, shooting and Monte Carlo
over start states: the engine's counterpart of the rigid scenes' `rotframe.rigid.prepared.PreparedBodyRun`.

A run gives ``simulate_body``'s samples for the same arguments, to the bit: the same loop, the same
steps (a call's budget of steps never changes them: `rotframe.problem.engine`). What it leaves out
is what ``simulate_body`` adds around them: the progress bar, the run's notes. A run that fails (a
torque that raised, a state not finite, a step that collapsed) is run again by ``simulate_body``
from the same start, which raises as it does (the time, the state, the torque to blame, the samples
up to there).
"""

from __future__ import annotations

import functools

import numpy as np

from rotframe.problem.body import (body_arrays, body_run, body_set_up, checked_body_state, exact_run,
                                   normalised_after_run, simulate_rigid_body, start_into)
from rotframe.problem.engine import scratch
from rotframe.problem.inlined import Inlining
from rotframe.problem.kept import ArrayBlocks
from rotframe.problem.signatures import BODY

__all__ = ["PreparedBody"]

#: a call's budget of steps: the whole run in one call (the budget never changes the steps)
_WHOLE_RUN = 2 ** 62


class PreparedBody:
    """A rigid body of `rotframe.simulate_body`, set up once and run from many start states.

    Parameters
    ----------
    inertia, L0, q0, duration, torque, params, method, rtol, step, samples
        As `rotframe.simulate_body` takes them (SI floats here: the core takes no units); ``L0``,
        ``q0`` the first start state, on which every check is made (each torque is called once).
    inline : bool
        True (default): the runs use the body's inlined loop (`rotframe.problem.inlined`), loaded
        from the disk cache or compiled here (seconds, once per torque ever); False: the engine's
        loop, which calls the torques by address (nothing to compile).

    Examples
    --------
    >>> import numpy as np
    >>> from rotframe.problem.prepared_body import PreparedBody
    >>> spin = PreparedBody(inertia=[1.0, 2.0, 3.0], L0=[0.0, 2.0, 0.0], q0=[0, 0, 0, 1], duration=1.0,
    ...                     method="lie-poisson4", step=0.01, samples=10, inline=False)
    >>> L, q = spin.states([0.0, 2.0, 0.0], [0, 0, 0, 1])
    >>> L.shape, q.shape
    ((11, 3), (11, 4))
    >>> bool(np.allclose(L, [0.0, 2.0, 0.0]))        # a steady spin about the middle axis stays one
    True
    """

    def __init__(self, *, inertia, L0, q0, duration, torque=None, params=(), method=None, rtol=None, step=None,
                 samples=None, inline=True):
        from rotframe.errors import ScenarioError

        if not isinstance(inline, bool):
            raise ScenarioError(f"inline={inline!r}: True (the torques compiled into the loop) or False (called by "
                                "address)")
        self._arguments = dict(inertia=inertia, duration=duration, torque=torque, params=params, method=method,
                               rtol=rtol, step=step, samples=samples)
        s = self.setup = body_set_up(L0=L0, q0=q0, jit=True, inline=inline, **self._arguments)
        #: the sample times (s), (samples + 1,), and the method's canonical name
        self.times, self.method = s.times, s.method
        #: the last run's accepted steps and evaluations of the right-hand side
        self.steps = self.nfev = 0
        self.notes = []
        self._kernel = None
        self._exact = s.method == "exact"
        if not self._exact:
            inlining = Inlining(s.driver.module, BODY, s.method, False, 7, None, inline)
            inlining.start()
            self._kernel = inlining.kernel
            self.notes = [inlining.note] if inlining.note else []
        self._arrays = None if self._exact else ArrayBlocks(body_arrays(s, s.L, s.q))
        self._call = None if self._exact else self._bound_call()
        #: whether the samples' attitudes are normalised after the run (as simulate_body's)
        self._normalise = normalised_after_run(s.method)

    def states(self, L0, q0):
        """The samples of a run from ``L0``, ``q0`` as arrays ``(L (n, 3), q (n, 4))``: ``simulate_body``'s
        ``trajectory.L`` and ``.q`` for the same arguments, to the bit, without the result around them."""
        if self._exact:  # the closed-form free flow
            from rotframe.rigid.free_body import free_body_closed_form

            L, q = checked_body_state(L0, q0)
            return free_body_closed_form(np.diag(self.setup.I).copy(), L, q, self.times)
        Y = self._integrate(L0, q0)
        Ls, qs = Y[:, 0, :3].copy(), Y[:, 0, 3:7].copy()
        if self._normalise:
            qs /= np.linalg.norm(qs, axis=1)[:, None]
        return Ls, qs

    def run(self, L0, q0):
        """Integrate from ``L0``, ``q0``: a `rotframe.problem.body.BodyRun` (samples, steps and the free body's
        energy and momentum drifts, as ``simulate_body``'s)."""
        s = self.setup
        if self._exact:
            L, q = checked_body_state(L0, q0)
            return exact_run(s.I, L, q, s.times)
        Y = self._integrate(L0, q0)
        counts = {"NSTEP": np.array([self.steps]), "NFEV": np.array([self.nfev])}
        return body_run(s.times, Y[:, 0], s.method, counts, s.I, True, s.params, s.terms, 0.0, [], True)

    def _bound_call(self):
        """The loop's call with every argument bound: the kept arrays (`ArrayBlocks`, the same objects at every run),
        the run's settings, the problem, and the loop itself (the inlined one, or the engine's variant)."""
        from rotframe.problem import engine
        from rotframe.problem.calls import direct_functions

        s, a = self.setup, self._arrays.views
        st = a["st"]
        kernel = self._kernel if self._kernel is not None else engine.variant(BODY, s.method, False, True, 7)
        fns = direct_functions() if self._kernel is not None else s.fns  # the inlined loop takes tags, not addresses
        return functools.partial(kernel, 0, 1, s.times, a["y"], a["TC"], a["H"], st["IDX"], st["SUB"], st["ST"],
                                 a["OUT"], a["EVT"], a["EVY"], a["EVK"], st["EVN"], a["GPREV"], st["NSTEP"], st["NFEV"],
                                 _WHOLE_RUN, s.rtol, a["atol"], s.hfix, a["EDIR"], a["ETERM"], a["S"], s.prob, fns,
                                 *scratch(7))

    def _integrate(self, L0, q0):
        """The run's samples (n, 1, 7), as the loop wrote them (the kept array: copy what is kept): one call."""
        L, q = checked_body_state(L0, q0)
        a = self._arrays.reset()
        start_into(a, self.setup.rtol, L, q)
        st = a["st"]
        try:
            self._call()
        except Exception:  # a torque raised in the compiled loop: simulate_body names it
            self._failed(L0, q0)
            raise
        if st["ST"][0] >= 3:
            self._failed(L0, q0)
        self.steps, self.nfev = int(st["NSTEP"][0]), int(st["NFEV"][0])
        return a["OUT"]

    def _failed(self, L0, q0):
        """The run from ``L0``, ``q0`` failed: ``simulate_body`` runs it again and raises as it does."""
        simulate_rigid_body(L0=L0, q0=q0, jit=True, plain_tier=False, **self._arguments)
        from rotframe.errors import IntegrationError

        raise IntegrationError(f"simulate_body: the prepared run from L0 = {np.asarray(L0).tolist()} failed, and "
                               "simulate_body's did not")
