"""A first run of a loop not compiled yet: begun by the loop's plain-Python remake, compiled only if it runs on.

The engine's loops are compiled once, then loaded from numba's cache in a fraction of a second
(`rotframe.problem.engine`). The first run on a fresh install, with every cache empty, waits for
that compile: 4 to 5 s for the DOP853 particle loop on the 2-core reference machine, where the
run itself, a projectile or a few orbits, takes a few thousand right-hand sides. The loop's
plain-Python remake (`rotframe.numerics.plain`: the same functions, run by Python instead of
compiled) needs nothing compiled and takes some 30 us a right-hand side, so it answers such a
run in a few hundredths of a second. A run whose loop is neither made in this process nor in
numba's cache (`loop_is_compiled`) therefore begins in the *plain tier*:

* it runs calls of `PLAIN_STEPS` steps per particle as plain Python;
* after each, it projects the run's right-hand sides (summed over the particles): each running
  particle's so far, times the run's span over the span it has covered. Where the projection
  exceeds `PLAIN_FEVS`, the loop is compiled, as the run would have compiled it at its start,
  and the run goes on compiled from where it is (the loop keeps everything a step needs in its
  arrays, as between any two calls). A DOP853 run compiles its *trajectory tier* instead of the
  whole loop (below) where it fits;
* a run that ends first never compiles the loop; the next run's loop is then still cold, and it
  begins in the plain tier too. The right-hand sides of the runs of a loop that ended plain count
  against the same `PLAIN_FEVS` in the process (`plain_fevs_spent`): many short runs of one problem
  (a sweep, a loop over start states, the bench's repeats) compile the loop once they have spent
  that much Python, as one long run does, instead of staying plain for ever;
* a run that fails in the plain tier (a function raised, a state not finite) runs again compiled
  from its start (`PlainTierFailed`): Python raises where the compiled loop goes on with inf or
  NaN (a division by zero), so a failure is met and reported as compiled, whatever the caches
  held. numpy's warnings are off in a plain call (`Tier.quiet`), as compiled.

A long run is seen as long after its first plain call, a few milliseconds (DOP853's first steps
are its shortest, so the projection errs long, and a run near the line compiles). The problem's
own functions are compiled before either tier runs, as always: a function numba cannot compile
is refused at once, whatever the run's length.

**The numbers.** The remake runs the loop's own code, statement for statement, in float64: its
arithmetic is IEEE's, in the same order, so its numbers are the compiled loop's to the bit where
the problem's functions give the same numbers in Python as compiled. The built-in terms and plain
arithmetic do (`tests/test_tiers.py` checks every method, events, a varying frame and forces in
inertial axes). A user function calling numpy's vectorised functions on scalars may not: numpy
may round a transcendental differently from the C library numba calls, by an ulp. The switch
is decided on counts of steps and simulated time, not on the clock, so a run begins and switches
the same way every time its loop is cold. Each run says in its notes which tier ran it.

The energy diagnostic of a run with a potential of the user's own (not numpy's arrays) follows the same rule
(`Tier.energy_driver`): where the compiled `rotframe.problem.engine.energies` is neither made nor cached and the run
has at most `PLAIN_ENERGIES` states, the plain remake evaluates them, and nothing is compiled for a diagnostic.

Only runs on the CPU of at most `PLAIN_PARTICLES` particles (or one rigid body:
`rotframe.problem.body`), with ``inline`` not True, begin in the plain tier: a large ensemble's
first call alone would be too long as Python.

**The trajectory tier.** A DOP853 run of so few particles compiles less than the whole loop
(`rotframe.problem.dop853_split.trajectory_tier`): the loop's trajectory, where every step is taken
(through the run's stops, `rotframe.numerics.stops`), and its right-hand side, each compiled on its own
and cached; the loop over the particles stays the plain remake's Python, some 25 to 45 us a call of the
trajectory, one a particle. The whole loop compiles the trajectory a second time inside its own code, and an
entry point of thirty arguments: the tier compiled in 0.58 of its time on the 2-core reference
machine (4.2 s against 7.3 s on a slow day, numba's start included, 2026-12-01). Side by side with
the tree before, fresh caches, three runs each, the same day: a first run of 1,000 s of a spring
5.0 to 5.9 s against 6.3 to 8.9 s (medians 5.8 and 7.7), `rotframe run cr3bp` 5.5 to 8.0 s
against 7.1 to 9.2 s (medians 6.2 and 8.4), a new problem after them the same within the day's
noise (0.5 to 0.8 s in both: loading a loop is mostly numba's own start). A run begins there where
the whole loop is not compiled but the tier is (`loop_is_compiled` of the variant with
`rotframe.problem.engine.TRAJECTORY_TIER` fifth), and compiles it, not the whole loop, where it
switches; the whole loop is compiled by a run of more particles than `TRAJECTORY_CALLS`
(`trajectory_tier_fits`).
It is the same code, so the same numbers to the bit (`tests/test_tiers.py`).
"""

from __future__ import annotations

import contextlib
import math
import time
import warnings

import numpy as np

__all__ = ["Tier", "PlainTierFailed", "SteadyLoopFailed", "run_falling_back", "loop_is_compiled", "plain_fevs_spent",
           "begin_ahead",
           "projected_fevs", "trajectory_tier_fits", "PLAIN_FEVS", "PLAIN_STEPS", "PLAIN_PARTICLES", "PLAIN_ENERGIES",
           "TRAJECTORY_CALLS"]

#: the most right-hand sides (summed over the particles) a run may take in the plain tier, as projected: some
#: 0.6 s of DOP853 as plain Python (30 us each on the reference machine; RK4's and the splittings' 8 to 15 us),
#: against 4 to 5 s to compile its loop
PLAIN_FEVS = 20_000
#: the most states whose energy a run evaluates by the plain remake where `energies` is not compiled yet
#: (`Tier.energy_driver`): some 15 us each on the reference machine, 0.15 s, against some 0.5 s to compile it
PLAIN_ENERGIES = 10_000
#: the steps per particle of each call in the plain tier (a count, not a time: the same run switches at the same step)
PLAIN_STEPS = 8
#: the most particles a run may have to begin in the plain tier (a first call of PLAIN_STEPS DOP853 steps each: some
#: 3,300 right-hand sides, 0.1 s)
PLAIN_PARTICLES = 32


#: the most particles a call of the trajectory tier takes: one call of the trajectory loop each, from the particle's
#: time to the run's end through every stop of the run (the knots of a frame's table or a body frame's samples), with
#: the particle's loading and saving as Python, where the whole loop makes them compiled (`trajectory_tier_fits`). A run
#: stays in the tier, warm runs too, until a larger one compiles the whole loop. Measured warm against the whole loop
#: (a spring, 2026-12-01): 10 s of 1, 8 and 32 particles, 1.15 ms -> 1.28, 0.95 -> 1.38 and 1.91 -> 3.63 ms; 1,000 s,
#: 3 to 4 % longer. So 16: at most some 0.8 ms a short run
TRAJECTORY_CALLS = 16


def trajectory_tier_fits(method, particles) -> bool:
    """Whether a first run of ``particles`` particles (at most `PLAIN_PARTICLES`), whose whole loop is not compiled
    yet, compiles DOP853's trajectory tier instead (`rotframe.problem.dop853_split.trajectory_tier`; the module
    docstring): DOP853's, and at most `TRAJECTORY_CALLS` calls of the trajectory loop in a call."""
    return method == "dop853" and particles <= TRAJECTORY_CALLS


def begin_ahead(variant, particles, varying) -> bool:
    """Begin compiling the loop that a first run of ``variant`` (`rotframe.problem.engine.variant`'s ``(model, method,
    events, D)``) and ``particles`` particles will compile if it is long, in second processes, before the run's own
    functions compile: DOP853's trajectory tier's trajectory and stages (`rotframe.problem.dop853_split.begin_tier`),
    where the run may begin in the plain tier (the caller's to say: on the CPU, ``inline`` not True) and would
    compile the tier.

    A long first run then compiles them beside its functions' compile and its first plain call, on the second core; a
    run that ends plain leaves them to a later run of the process, stopped if still running at its exit
    (`rotframe.numerics.compile_apart.stop_begun`). Whether any was begun.

    Only where the run has much of its own to compile first: a varying frame's or origin's evaluator (``varying``).
    A steady frame's own compile is too short for the overlap to pay for the processes a short run never uses
    (`tools/startup_side_by_side.py`, 2026-12-02: a short first problem 0.82 to 1.00 of its time without them, a
    long one 0.92 to 1.10).
    """
    from rotframe.problem.engine import TRAJECTORY_TIER

    model, method, events, D = variant
    # the tier first: once made in this process, it answers without a look in numba's cache (a warm run's case)
    if not varying or particles > PLAIN_PARTICLES or not trajectory_tier_fits(method, particles) \
            or loop_is_compiled(tuple(variant) + (TRAJECTORY_TIER,)) or loop_is_compiled(variant):
        return False
    from rotframe.problem.dop853_split import begin_tier

    return begin_tier(model, events, D)


#: the right-hand sides the plain tier has spent in this process on the runs of each loop variant that ended plain
_SPENT = {}


def plain_fevs_spent(variant) -> float:
    """The right-hand sides the runs of ``variant``'s loop (`rotframe.problem.engine.variant`'s arguments) that
    ended in the plain tier have spent in this process: they count against `PLAIN_FEVS` with a run's own."""
    return _SPENT.get(tuple(variant), 0.0)


class PlainTierFailed(Exception):
    """A run in the plain tier failed (a function raised, a state not finite): it runs again compiled from its start,
    so that the failure is met and reported as the compiled loop meets it (Python raises on a division by zero or a
    square root of a negative number where the compiled loop goes on with inf or NaN)."""


class SteadyLoopFailed(Exception):
    """A run on the engine's steady loop (`rotframe.problem.steady`) failed: it runs again on the engine's own loop,
    which gives the same numbers to the bit up to there and names the failure's cause (a state not finite, a step
    that collapsed) and the term to blame, as any run's failure is named."""


def run_falling_back(run, kwargs):
    """``run(**kwargs)`` (a particle or body run that may begin in the plain tier); where it fails there
    (`PlainTierFailed`), ``run(**kwargs, plain_tier=False)``: the same run compiled from its start; where it fails on
    the steady loop (`SteadyLoopFailed`), the same run on the engine's loop (``steady=False``), itself falling back
    so."""
    try:
        return run(**kwargs)
    except PlainTierFailed:
        return run(**kwargs, plain_tier=False)
    except SteadyLoopFailed:
        return run_falling_back(run, dict(kwargs, steady=False))


def loop_is_compiled(variant) -> bool:
    """Whether the engine's loop of ``variant`` (`rotframe.problem.engine.variant`'s ``(model, method, events, D)``,
    and `rotframe.problem.engine.TRAJECTORY_TIER` fifth for DOP853's trajectory tier) is made in this process or in
    numba's disk cache (then it is loaded): whether a run may begin there without compiling it."""
    from rotframe.problem import engine

    model, method, events, D, *tier = variant
    return engine.variant(model, method, events, tier[0] if tier else True, D=D, load_only=True) is not None


def projected_fevs(NFEV, TC, ST, span) -> float:
    """The run's right-hand sides at its end, projected from each particle's so far (``NFEV``) over the span it has
    covered (``TC``, from 0): a running particle's (``ST`` 0) scaled by ``span / TC`` (infinite before it has moved),
    an ended one's as counted."""
    total = 0.0
    for nf, t, status in zip(NFEV, TC, ST):
        if status != 0:
            total += float(nf)
        else:
            total += float(nf) * span / t if t > 0.0 else math.inf
    return total


class Tier:
    """Which loop runs a particle run's calls: the compiled engine's, or its plain remake first (module docstring).

    Parameters
    ----------
    driver : rotframe.problem.codegen.Driver
        The run's compiled driver.
    fns : tuple
        Its functions' addresses (`rotframe.problem.codegen.Driver.functions`).
    plain : callable or None
        Makes the run's plain driver (the same problem as plain Python), where the run may begin in the plain
        tier (on the CPU, ``inline`` not True); None where it may not.
    variant : tuple
        The engine's variant of the run, ``(model, method, events, D)`` (`rotframe.problem.engine.variant`).
    prob : tuple
        The problem's data (`rotframe.problem.signatures.PROBLEM`).
    particles : int
        The run's particles (at most `PLAIN_PARTICLES` to begin in the plain tier).
    """

    def __init__(self, driver, fns, plain, variant, prob, particles):
        self.driver = driver
        self.fns = fns
        self.variant = variant
        self._make_plain, self._prob = plain, prob
        from rotframe.problem.engine import TRAJECTORY_TIER

        cold = plain is not None and particles <= PLAIN_PARTICLES and not loop_is_compiled(variant)
        #: whether the loop the run compiles, if it compiles one, is DOP853's trajectory tier (`trajectory_tier_fits`)
        self._stepped = cold and trajectory_tier_fits(variant[1], particles)
        #: whether the calls run on DOP853's trajectory tier now (its callees compiled, the loop over particles Python)
        self.trajectory = self._stepped and loop_is_compiled(tuple(variant) + (TRAJECTORY_TIER,))
        #: whether the calls run as plain Python now
        self.plain = cold and not self.trajectory
        #: whether the run began in the plain tier (its first call then integrates: no compile to count)
        self.began_plain = self.plain
        self._compiled = (driver, fns)
        #: the seconds the compile took where the run switched to it after its first call: compile time, not
        #: integration
        self.seconds_mid_run = 0.0
        self._plain_steps = 0
        self._switched_at = None  # the steps (all particles) the plain tier ran before the switch
        if self.trajectory:
            self.driver = driver.trajectory_tier()
        elif self.plain:
            self.driver = plain()
            self.fns = self.driver.functions(prob)

    def budget(self, paced: int) -> int:
        """The steps per particle of the next call: ``paced`` (the run's `rotframe.problem.pacing.Pacer`) where
        compiled, `PLAIN_STEPS` in the plain tier."""
        return PLAIN_STEPS if self.plain else paced

    @contextlib.contextmanager
    def quiet(self):
        """The context of a call: numpy's RuntimeWarnings off in the plain tier, as the compiled loop gives none (an
        overflow is an inf); nothing where compiled."""
        if not self.plain:
            yield
            return
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            yield

    def after_call(self, NFEV, NSTEP, TC, ST, span) -> bool:
        """After a call in the plain tier, with the run's right-hand sides ``NFEV``, steps ``NSTEP``, times ``TC`` and
        statuses ``ST`` so far (per particle) and its ``span`` (s): `PlainTierFailed` where a particle failed; where
        the run goes on and its projected right-hand sides, with those the loop's earlier runs spent plain in this
        process (`plain_fevs_spent`), exceed `PLAIN_FEVS`, compile the loop and switch to it. Returns whether it
        switched."""
        if not self.plain:
            return False
        if np.any(ST >= 3):
            raise PlainTierFailed
        self._plain_steps = int(np.sum(NSTEP))
        if not np.any(ST == 0):  # the run ended plain: its right-hand sides count against the next runs'
            key = tuple(self.variant)
            _SPENT[key] = _SPENT.get(key, 0.0) + float(np.sum(NFEV))
            return False
        if plain_fevs_spent(self.variant) + projected_fevs(NFEV, TC, ST, span) <= PLAIN_FEVS:
            return False
        from rotframe.problem import engine

        model, method, events, D = self.variant
        t0 = time.perf_counter()
        # the compile the run would have begun with: DOP853's trajectory tier where it fits, else the whole loop
        engine.variant(model, method, events, engine.TRAJECTORY_TIER if self._stepped else True, D=D)
        self.seconds_mid_run = time.perf_counter() - t0
        self.driver, self.fns = self._compiled
        if self._stepped:
            self.driver = self.driver.trajectory_tier()
            self.trajectory = True
        self.plain = False
        self._switched_at = self._plain_steps
        return True

    def energy_driver(self, states):
        """``(driver, fns)`` that evaluate the run's energy at ``states`` states (`rotframe.problem.engine.energies`):
        the plain remake's where the compiled `energies` is neither made in this process nor in numba's cache and the
        states are at most `PLAIN_ENERGIES` (a first run of a problem with a potential of its own, as `cr3bp`'s,
        compiled `energies` and the potential's glue for its diagnostic alone), else the run's own. The numbers are
        the compiled ones where the potential gives the same numbers in Python (the module docstring): `cr3bp`'s
        Jacobi integral differs in its last bit at some samples, its drift not at all (2026-12-01)."""
        if self.plain or self._make_plain is None or states > PLAIN_ENERGIES:
            return self.driver, self.fns
        from rotframe.numerics.compiled import load_cached
        from rotframe.problem import engine

        kernel = engine.energies
        if kernel.signatures or load_cached(kernel, engine.SIGNATURES[kernel]):
            return self.driver, self.fns
        plain = self._make_plain()
        return plain, plain.functions(self._prob)

    @property
    def note(self):
        """What the run's notes say of its tier (None where it ran compiled from the start)."""
        method = self.variant[1]
        if self.plain:
            return (f"the engine's {method} loop was not compiled yet (a first run): this run was short enough for "
                    f"its plain-Python remake, which ran all {self._plain_steps} steps (the same code and "
                    "numbers; rotframe.problem.tiers); a longer run compiles the loop, once")
        if self._switched_at is not None:
            what = "then the loop compiled" + (", its trajectories alone (" if self.trajectory else " (")
            return (f"the engine's {method} loop was not compiled yet (a first run): its plain-Python remake ran the "
                    f"first {self._switched_at} steps, {what}{self.seconds_mid_run:.2g} s, once) and ran the rest (the "
                    "same code and numbers; rotframe.problem.tiers)")
        return None
