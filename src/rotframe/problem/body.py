"""A rigid body of the user's own: any inertia tensor, torques of the user's and built-in ones, DOP853 or RK4.

`simulate_rigid_body` is the numerical core of ``rotframe.simulate_body``. A torque
is a function ``tau(t, L, q, *params) -> (3,)`` in body axes (N m), compiled with numba into
a driver generated for it (`rotframe.problem.codegen`, cached on disk), as the forces of
a particle problem are; ``torque=`` takes one, or a list of them summed in order, the built-in
torques of `rotframe.torques` among them (the same kind of object, `Torque`). A torque-free body
may also take ``exact``, the closed-form flow of ``rotframe.rigid.free_body_exact`` (principal axes).

The splitting methods of the built-in scenes (``lie-poisson``, ``rotation-splitting``...)
compose the free body's exact flow with a torque's flow, which exists in closed form only
for torques of a known shape (the heavy top's gravity); a user's torque is refused by them,
by name.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass

import numpy as np

from rotframe import limits
from rotframe.errors import IntegrationError, ScenarioError
from rotframe.particles.trajectory import RunInterrupted
from rotframe.problem import callables as uf
from rotframe.problem.body_checks import check_integrable
from rotframe.problem.codegen import Driver, build_module
from rotframe.problem.glue import body_source, flatten_params
from rotframe.problem.inlined import Inlining
from rotframe.problem.models import body_constants, inverse_inertia
from rotframe.problem.signatures import BODY
from rotframe.problem.terms import Torque
from rotframe.problem.pacing import FIRST_BUDGET, FIRST_BUDGET_OWN, Pacer
from rotframe.problem.tiers import PlainTierFailed, Tier, run_falling_back
from rotframe import method_registry as registry
from rotframe.problem.arguments import check_flag, check_inline, check_params, run_grid
from rotframe.problem.particles import STATUS
from rotframe.validation import refuse_units

__all__ = ["simulate_rigid_body", "BodyRun", "Torque"]

#: the splittings (the rigid scenes' own step, `rotframe.problem.models.lie_poisson_strang`): principal axes, the torque
#: as a kick at fixed attitude (a torque of (t, q) alone); the top-splittings need a symmetric body
KICK_METHODS = ("lie-poisson", "lie-poisson4", "lie-poisson6", "lie-poisson8", "top-splitting", "top-splitting4",
                "top-splitting6", "top-splitting8")


class BodyRun:
    """What `simulate_rigid_body` returns: samples of L and q, diagnostics, warnings.

    ``diagnostics`` and ``torque_samples`` are measured on the samples when first read (a callable
    in their place), not by every run: a scene reports its own, and a short run's would cost as
    much as its integration.
    """

    def __init__(self, times, L, q, method, steps, nfev, complete, inertia, diagnostics, warnings, notes,
                 torque_samples=None, compile_s=0.0):
        self.times, self.L, self.q = times, L, q
        self.method, self.steps, self.nfev, self.complete = method, steps, nfev, complete
        self.t_reached = float(times[-1]) if len(times) else math.nan
        self.inertia = inertia
        self._diagnostics, self.warnings, self.notes = diagnostics, warnings, notes
        self._torque_samples = torque_samples
        self.compile_s = compile_s
        self.extras = {"compile_s": compile_s}

    @property
    def diagnostics(self) -> dict:
        """``quaternion_norm_drift``, and for a free body ``energy_rel_drift`` and ``momentum_rel_drift``."""
        if callable(self._diagnostics):
            self._diagnostics = self._diagnostics()
        return self._diagnostics

    @property
    def torque_samples(self):
        """The torques' sum at each sample (n, 3), N m, body axes; None for a free body."""
        if callable(self._torque_samples):
            self._torque_samples = self._torque_samples()
        return self._torque_samples

    @property
    def trajectory(self):
        """Itself: a BodyRun is the trajectory of a body (``times``, ``L``, ``q``), usable as a frame."""
        return self


def _inertia(inertia, method):
    """The inertia tensor (3, 3), checked: symmetric, its principal moments >= 0 and a triangle's sides. A zero moment
    (a thin rod about its axis; at least two others non-zero) only on principal axes and for the methods that
    take it (the exact flow and the splittings, which turn about each axis: Euler's equations divide by it)."""
    refuse_units(inertia, "inertia", ScenarioError)
    try:
        I = np.asarray(inertia, dtype=float)
    except (TypeError, ValueError):
        raise ScenarioError(f"inertia: {str(inertia)[:80]!r} is not numbers (kg m^2)") from None
    if I.shape == (3,):
        I = np.diag(I)
    if I.shape != (3, 3) or not np.all(np.isfinite(I)):
        raise ScenarioError(f"inertia: expected 3 principal moments or a 3x3 tensor (kg m^2), got shape {I.shape}")
    if not np.allclose(I, I.T, rtol=1e-12, atol=0.0):
        raise ScenarioError("inertia: the tensor is not symmetric")
    ev = np.linalg.eigvalsh(I)
    if ev[0] < 0 or ev[1] <= 0:
        raise ScenarioError(f"inertia: principal moments {ev.tolist()} must be > 0 (one may be 0: a thin rod)")
    if ev[0] == 0 and (method not in KICK_METHODS and method != "exact" or np.any(I != np.diag(np.diag(I)))):
        raise ScenarioError(f"method {method}: principal moments {ev.tolist()} kg m2; it needs all > 0 (a thin rod has "
                            "a zero moment: use exact or a lie-poisson splitting, about the principal axes)")
    a, b, c = ev
    if a + b < c * (1 - 1e-12):
        raise ScenarioError(f"inertia: principal moments {ev.tolist()} break the triangle inequality "
                            "(no rigid body has them)")
    return np.ascontiguousarray(I)


def simulate_rigid_body(**kwargs) -> BodyRun:
    """Integrate a rigid body under the user's torque; see `rotframe.simulate_body`.

    A run begun in the plain tier that fails runs again compiled from its start (`rotframe.problem.tiers`).
    """
    return run_falling_back(_simulate_rigid_body, kwargs)


def torque_terms(torque) -> list:
    """``torque=`` as a list of ``(label, Torque)``: one callable or `Torque` (labelled ``torque``), or a list or
    tuple of them summed in order (``torque[k]``); None or an empty list: none. A one-line ScenarioError for an
    entry that is not callable."""
    if torque is None:
        return []
    single = not isinstance(torque, (list, tuple))
    entries = [torque] if single else list(torque)
    terms = []
    for k, f in enumerate(entries):
        label = "torque" if single else f"torque[{k}]"
        term = f if isinstance(f, Torque) else Torque(f, attitude_only=bool(getattr(f, "attitude_only", False)))
        if not callable(term.func):
            raise ScenarioError(f"{label}: {term.func!r} is not callable (a function tau(t, L, q, *params) -> (3,))")
        terms.append((label, term))
    return terms


def _named(label, term) -> str:
    """One torque for a message: ``torque=name`` or ``torque[k]=name``."""
    return f"{label}={term.name or uf.display_name(term.func)}"


def _describe_torques(terms) -> str:
    """The torques for a message: ``torque=name`` or ``torque[k]=name, ...``."""
    return ", ".join(_named(label, term) for label, term in terms)


_FLOAT = np.dtype(np.float64)


@dataclass
class BodySetUp:
    """A body's run set up (`body_set_up`): what `simulate_rigid_body` and a prepared run
    (`rotframe.problem.prepared_body.PreparedBody`) share."""

    I: np.ndarray  # the inertia tensor (3, 3), kg m^2
    L: np.ndarray  # the first start state, checked: L (3,) and q (4,), normalised
    q: np.ndarray
    method: str
    duration: float
    samples: int
    times: np.ndarray
    rtol: float
    hfix: float
    terms: list  # [(label, Torque)]
    params: tuple
    jit: bool
    inline: object
    driver: object = None  # the compiled driver and its problem (None for method exact)
    prob: tuple = ()
    fns: tuple = ()
    functions: dict = None
    glue: str = ""
    key: object = None
    cache_notes: list = None

    def plain_driver(self):
        """The same body as plain Python, for a first run whose loop is not compiled yet (`rotframe.problem.tiers`)."""
        plain = {name: uf.plain_function(f) for name, f in self.functions.items()}
        return Driver(build_module("body", self.key, plain, self.glue, compiled=False), compiled=False)


def checked_body_state(L0, q0):
    """``(L, q)`` as float64 (3,) and (4,), finite, q within 1e-6 of unit length and normalised; a one-line
    ScenarioError otherwise. Float64 arrays of the right shapes are checked in plain Python (a short run's own checks
    in numpy cost as much as its integration), with the same numbers."""
    if (type(L0) is np.ndarray and type(q0) is np.ndarray and L0.dtype is _FLOAT and q0.dtype is _FLOAT
            and L0.shape == (3,) and q0.shape == (4,) and all(map(math.isfinite, L0.tolist() + q0.tolist()))):
        nq = float(np.linalg.norm(q0))
        if abs(nq - 1.0) <= 1e-6:
            return L0.copy(), q0 / nq
    refuse_units(L0, "L0", ScenarioError)
    refuse_units(q0, "q0", ScenarioError)
    L, q = (_numbers(key, value, n) for key, value, n in (("L0", L0, 3), ("q0", q0, 4)))
    nq = float(np.linalg.norm(q))
    if abs(nq - 1.0) > 1e-6:
        raise ScenarioError(f"q0: |q0| = {nq:.9g}; a scalar-last unit quaternion (x, y, z, w) is expected")
    return L, q / nq


def _numbers(key, value, n):
    """``value`` as ``n`` finite float64, or a one-line ScenarioError naming ``key`` and what is wrong."""
    if isinstance(value, (str, bytes)):
        raise ScenarioError(f"{key} = {value!r} is not numbers; it must be {n} finite numbers")
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ScenarioError(f"{key} = {str(value)[:60]!r} is not numbers; it must be {n} finite numbers") from None
    if a.shape != (n,):
        raise ScenarioError(f"{key} has shape {a.shape}; it must be {n} finite numbers")
    if not np.all(np.isfinite(a)):
        raise ScenarioError(f"{key} = {a.tolist()} is not finite; it must be {n} finite numbers")
    return a


def body_set_up(*, inertia, L0, q0, duration, torque=None, params=(), method=None, rtol=None, step=None,
                samples=None, jit=True, inline=None) -> BodySetUp:
    """Check a body's run and build its driver (`rotframe.simulate_body`'s arguments): a `BodySetUp`.

    Every argument is checked, each torque called once at the start state and compiled into the
    problem's glue (cached on disk); ``method="exact"`` builds no driver.
    """
    terms = torque_terms(torque)
    attitude_only = all(term.attitude_only for _, term in terms)
    named = _describe_torques(terms)
    name = registry.check(method, "bodies", default="dop853", nor=named)
    if terms and name == "exact":
        raise ScenarioError(f"method={method!r} cannot take {named}: the exact flow is the "
                            "free body's; use dop853, rk4, or a Lie-Poisson splitting for a torque of (t, q) alone")
    if terms and name in KICK_METHODS and not attitude_only:
        late = next(_named(label, term) for label, term in terms if not term.attitude_only)
        raise ScenarioError(f"method={method!r} cannot take {late}: it splits the torque as a "
                            "kick at fixed attitude, exact only for a torque of (t, q) alone; mark such a torque "
                            "rotframe.Torque(f, attitude_only=True), or use dop853 or rk4")
    method = name
    I = _inertia(inertia, name)
    if method in KICK_METHODS and np.any(I != np.diag(np.diag(I))):
        raise ScenarioError(f"method={method!r} turns about the principal axes: give the 3 principal moments (a "
                            "diagonal inertia), or use dop853 or rk4")
    inv_principal, symmetry = _free_step_constants(I)
    if method.startswith("top-splitting") and symmetry < 0:
        raise ScenarioError(f"method={method!r} takes the free flow of a symmetric body: two of the principal moments "
                            f"{np.diag(I).tolist()} must be equal; use a lie-poisson splitting, dop853 or rk4")
    L, q = checked_body_state(L0, q0)
    _check_thin_rod(I, L)
    fixed = method not in ("exact", "dop853")
    duration, samples, times, rtol, hfix = run_grid(duration, samples, rtol, step, fixed=fixed, what=f"method {method}")
    check_flag(jit, "jit")
    check_inline(inline, jit)
    for label, term in terms:
        uf.check_compilable(label, term.func, jit)
    params = check_params(params)
    s = BodySetUp(I, L, q, method, duration, samples, times, rtol, hfix, terms, params, jit, inline)
    check_integrable(s)
    if method == "exact":
        return s
    if terms:
        for label, term in terms:
            uf.check_call(label, term.func, (0.0, L.copy(), q.copy(), *term.params_for(params)), (3,),
                          when=f"at t = 0 s, L = {L.tolist()}, q = {q.tolist()}")
        s.functions = {f"torque_{k}": uf.compiled_for_glue(term.func) if jit else uf.plain_function(term.func)
                       for k, (_, term) in enumerate(terms)}
        s.glue = body_source([term.takes_params for _, term in terms], params)
        s.key, cache_note = uf.cache_key([(label, term.func) for label, term in terms], "")
    else:
        s.functions, s.glue, s.key, cache_note = {}, "", "free", None
    s.cache_notes = [cache_note] if cache_note and jit else []
    try:
        s.driver = Driver(build_module("body", s.key, s.functions, s.glue, compiled=jit, notes=s.cache_notes),
                          compiled=jit)
    except Exception as exc:
        import numba

        if isinstance(exc, numba.core.errors.NumbaError):
            _compile_failed(exc, terms, L, q, params)
        raise
    s.prob = (BODY, body_constants(I, inv_principal, symmetry, bool(terms)), flatten_params(params), 0, np.zeros(1),
              np.zeros((1, 1, 3)), 0, np.zeros(1), np.zeros((1, 1, 3)))
    s.fns = s.driver.functions(s.prob)
    return s


#: the set-ups of recent runs of bodies without a torque of their own (`_cached_set_up`)
_SETUPS: dict = {}
_SETUPS_KEPT = 16


def _cached_set_up(**kwargs) -> BodySetUp:
    """`body_set_up`, made once for the same body and run settings where the run has no torque of the user's (a free
    body, or the built-in torques of `rotframe.torques`, whose constants are their own): a scene's run repeated, a
    bench's repeats, a sweep over start states. The start state is checked at every run; a user's torque is called
    and fingerprinted at every run, as always (a value it reads may have changed)."""
    torque = kwargs["torque"]
    entries = [] if torque is None else list(torque) if isinstance(torque, (list, tuple)) else [torque]
    key = None
    if not kwargs["params"] and all(built_in(t) for t in entries):  # the objects are their constants
        try:
            key = (np.asarray(kwargs["inertia"], dtype=float).tobytes(), tuple(id(t) for t in entries),
                   kwargs["method"], kwargs["rtol"], kwargs["step"], kwargs["samples"], kwargs["duration"],
                   kwargs["jit"], kwargs["inline"])
            hash(key)
        except (TypeError, ValueError):
            key = None
    cached = _SETUPS.get(key) if key is not None else None
    if cached is None or cached[1] is not limits.current():
        s = body_set_up(**kwargs)
        if key is not None:
            if len(_SETUPS) >= _SETUPS_KEPT:
                _SETUPS.pop(next(iter(_SETUPS)))
            _SETUPS[key] = (s, limits.current(), entries)  # the torques kept alive: their ids stay theirs
        return s
    s = copy.copy(cached[0])  # the set-up, with this run's start
    s.L, s.q = checked_body_state(kwargs["L0"], kwargs["q0"])
    _check_thin_rod(s.I, s.L)
    check_integrable(s)
    return s


def built_in(term) -> bool:
    """Whether a torque is one of `rotframe.torques` (its function defined there: its constants its own, its
    arithmetic rotframe's): no value it reads can change between runs, and it is never slow."""
    return isinstance(term, Torque) and getattr(term.func, "__module__", None) == "rotframe.torques"


def _check_thin_rod(I, L):
    """A one-line ScenarioError where ``L`` has a part along an axis of zero moment (`_inertia`)."""
    if I[0, 0] != 0.0 and I[1, 1] != 0.0 and I[2, 2] != 0.0:
        return
    for k in np.flatnonzero(np.diag(I) == 0.0):
        if L[k] != 0.0:
            raise ScenarioError(f"L0: body axis {k + 1} has a zero moment of inertia (a thin rod), so L0[{k}] must be 0, "
                                f"not {float(L[k])!r} (its spin would be infinite)")


def body_arrays(s, L, q):
    """A run's arrays from the start state ``L``, ``q`` (`checked_body_state`): ``y`` (1, 7), the samples ``OUT``
    (n, 1, 7) with the start in row 0, the tolerances ``atol`` (1, 7), the per-body counters ``st``, time ``TC`` and
    step ``H``, and the (empty) event arrays, by the names `rotframe.problem.engine.advance` takes them."""
    counts = np.zeros(6, np.int64)  # IDX, SUB, ST, EVN, NSTEP, NFEV: views of one array
    a = {"y": np.zeros((1, 7)), "OUT": np.full((s.samples + 1, 1, 7), np.nan), "atol": np.full((1, 7), s.rtol),
         "st": {k: counts[j:j + 1] for j, k in enumerate(("IDX", "SUB", "ST", "EVN", "NSTEP", "NFEV"))},
         "TC": np.zeros(1), "H": np.zeros(1), **_NO_EVENTS}
    start_into(a, s.rtol, L, q)
    return a


def start_into(a, rtol, L, q):
    """Write the start ``L``, ``q`` into a run's arrays ``a`` (`body_arrays`' names): the state ``y``, the samples'
    row 0 (a run stopped before its first call keeps it) and ``L``'s absolute tolerance, ``rtol`` times max |L|."""
    start = L.tolist() + q.tolist()
    a["y"][0] = start
    a["OUT"][0, 0] = start
    a["atol"][0, :3] = rtol * max(abs(start[0]), abs(start[1]), abs(start[2]), 1e-300)


#: a body's event arrays: it has none (the loop's variant without events never reads or writes them)
_NO_EVENTS = {"EVT": np.zeros((1, 1)), "EVY": np.zeros((1, 1, 7)), "EVK": np.zeros((1, 1), np.int64),
              "GPREV": np.zeros((1, 1)), "EDIR": np.zeros(0), "ETERM": np.zeros(0, dtype=bool), "S": np.empty(0)}


def _simulate_rigid_body(*, inertia, L0, q0, duration, torque=None, params=(), method=None, rtol=None, step=None,
                         samples=None, jit=True, progress=None, inline=None, plain_tier=True) -> BodyRun:
    import time

    t0 = time.perf_counter()  # the glue's compile and the first call count as compile time
    s = _cached_set_up(inertia=inertia, L0=L0, q0=q0, duration=duration, torque=torque, params=params, method=method,
                       rtol=rtol, step=step, samples=samples, jit=jit, inline=inline)
    if s.method == "exact":
        return exact_run(s.I, s.L, s.q, s.times, progress)
    I, L, q, method, times, rtol, hfix, terms, params = s.I, s.L, s.q, s.method, s.times, s.rtol, s.hfix, s.terms, s.params
    duration, driver, prob, fns, cache_notes = s.duration, s.driver, s.prob, s.fns, s.cache_notes
    a = body_arrays(s, L, q)
    y, OUT, atol, st, TC, H = a["y"], a["OUT"], a["atol"], a["st"], a["TC"], a["H"]
    EVT, EVY, EVK, GPREV, EDIR, ETERM = a["EVT"], a["EVY"], a["EVK"], a["GPREV"], a["EDIR"], a["ETERM"]
    n = s.samples + 1
    compile_s = None
    # the engine's loop, or the same loop with the torque compiled in where the run is long (`rotframe.problem.inlined`)
    inlining = Inlining(driver.module, BODY, method, False, 7, None, inline if jit else False)
    tier = Tier(driver, fns, s.plain_driver if jit and inline is not True and plain_tier else None,
                (BODY, method, False, 7), prob, 1)

    def call(budget):
        tier.driver.advance(0, 1, times, y, TC, H, st["IDX"], st["SUB"], st["ST"], OUT, EVT, EVY, EVK, st["EVN"], GPREV,
                            st["NSTEP"], st["NFEV"], budget, method, rtol, atol, hfix, EDIR, ETERM, a["S"], prob,
                            tier.fns, kernel=None if tier.plain else inlining.kernel)

    # calls sized in time: signals and progress between them; a compiled loop of no torque of the user's begins long
    own = not tier.plain and all(built_in(term) for _, term in terms)
    pacer = Pacer(f"method {method}", duration, adaptive=method == "dop853",
                  first_budget=FIRST_BUDGET_OWN if own else FIRST_BUDGET)
    try:
        inlining.start()
        while True:
            # what a replay needs where a torque of the user's may raise (`_torque_raised`); the pace from two numbers
            saved = None if own else (y.copy(), TC.copy(), H.copy(), {key: a.copy() for key, a in st.items()})
            steps_before, t_before = float(st["NSTEP"][0]), float(TC[0])
            budget = tier.budget(pacer.start())
            t_call = time.perf_counter()
            try:
                with tier.quiet():
                    call(budget)
            except Exception as exc:
                if tier.plain:  # met again compiled, from the start (`simulate_rigid_body`)
                    raise PlainTierFailed from None
                if saved is None:
                    raise
                _torque_raised(exc, call, saved, y, TC, H, st, terms, budget)
            if compile_s is None:  # the glue's compile and the first call; begun plain, the glue's alone
                compile_s = (t_call if tier.began_plain else time.perf_counter()) - t0
            if tier.plain:  # a failure met again compiled; compiled from here where the run is seen to be long
                tier.after_call(st["NFEV"], st["NSTEP"], TC, st["ST"], duration)
            else:
                pacer.done(float(st["NSTEP"][0]) - steps_before)
                inlining.after_call(pacer.last_seconds, float(TC[0]) - t_before,
                                    float(duration - TC[0]) if st["ST"][0] == 0 else 0.0)
            if progress is not None:
                progress(float(st["IDX"][0]) / n)
            if st["ST"][0] != 0:
                break
            pacer.check(st["NSTEP"], TC, H)
    except KeyboardInterrupt:
        k = max(int(st["IDX"][0]), 1)
        raise RunInterrupted(_settings(body_run(times[:k], OUT[:k, 0], method, st, I, False, params, terms,
                                            compile_s or 0.0, [], jit), s)) from None
    k = int(st["IDX"][0])
    if st["ST"][0] >= 3:
        partial = _settings(body_run(times[:max(k, 1)], OUT[:max(k, 1), 0], method, st, I, False, params, terms, compile_s,
                                 [], jit), s)
        t_bad = float(TC[0])
        blame = ""
        if terms:  # a torque that turns non-finite at a time: probe each inside the failed step
            dt = hfix if method != "dop853" else (1.0 if int(st["ST"][0]) == 6 else 10.0) * float(H[0])
            L_last, q_last = y[0, :3].copy(), y[0, 3:].copy()

            def at_state(own):
                return lambda tp: (tp, *uf.read_only_args((L_last, q_last)), *own)

            blame, _ = uf.blame_in_step([(label, term.func, at_state(term.params_for(params)), "")
                                         for label, term in terms], t_bad, dt)
        if int(st["ST"][0]) == 6:  # the torque raised (compiled: the engine stopped at that step)
            raise uf.raised_during_run(f"simulate_body: {blame[2:] or 'the torque raised'} in the step from "
                                       f"t = {t_bad:.9g} s, L = {y[0, :3].tolist()}, q = {y[0, 3:].tolist()}",
                                       t_bad, partial)
        raise IntegrationError(f"simulate_body: {STATUS[int(st['ST'][0])]}{blame} after t = {t_bad:.9g} s "
                               f"(method {method})", t_reached=t_bad, partial=partial)
    compile_s += inlining.seconds_mid_run + tier.seconds_mid_run  # loops made after the first call: compile time too
    run = _settings(body_run(times, OUT[:, 0], method, st, I, True, params, terms, compile_s, [], jit), s)
    run.notes.extend(cache_notes + [note for note in (tier.note, inlining.note) if note])
    return run


def _settings(run, s):
    """The run's settings in its ``extras`` (what a scene's stated accuracy reads): ``rtol`` of DOP853, ``step`` of a
    fixed-step method (the step taken, which divides the sample interval), and ``nfev``."""
    run.extras.update({"rtol": s.rtol} if s.method == "dop853" else {"step": s.hfix} if s.hfix else {})
    run.extras["nfev"] = run.nfev
    return run


def _free_step_constants(I):
    """``(inv_principal (4,), symmetry axis or -1)`` of the splittings' free step (`rotframe.rigid.kernels.free_step`),
    as the rigid scenes compute them (`rotframe.rigid.checks.check_inertia`); zeros and -1 off principal axes."""
    from rotframe.rigid.checks import check_inertia, symmetry_axis

    if np.any(I != np.diag(np.diag(I))):
        return np.zeros(4), -1
    moments, inv_principal = check_inertia(np.diag(I).copy())
    symmetry = symmetry_axis(moments)
    return inv_principal, -1 if symmetry is None else symmetry


def _compile_failed(exc, terms, L, q, params):
    own = {label: term.params_for(params) for label, term in terms}
    reason = uf.diagnose_compile([(label, term.func) for label, term in terms],
                                 lambda role: (0.0, L.copy(), q.copy(), *own[role]))
    raise uf.UserFunctionError(f"simulate_body: {reason or uf.numba_reason(exc)}; pass jit=False to run it in plain "
                               "Python (slow)") from None


def _restore(saved, y, TC, H, st):
    """The body's state as it was before a driver call (``saved``), for a replay or a retry."""
    y[...], TC[...], H[...] = saved[0], saved[1], saved[2]
    for key, a in saved[3].items():
        st[key][...] = a


def _torque_raised(exc, call, saved, y, TC, H, st, terms, budget):
    """The torque raised inside a compiled call: replay the call one step at a time to give the time and state."""
    _restore(saved, y, TC, H, st)
    what = f"{type(exc).__name__}: {exc}".replace("\n", " ")
    where = f"after t = {float(TC[0]):.9g} s"
    for _ in range(int(budget) + 1):
        t, yi = float(TC[0]), y[0].copy()
        try:
            call(1)
        except Exception:  # raised again: in this step
            where = f"in the step from t = {t:.9g} s, L = {yi[:3].tolist()}, q = {yi[3:].tolist()}"
            break
        if st["ST"][0] != 0:
            break
    names = ", ".join(f"{label} ({term.name or uf.display_name(term.func)})" for label, term in terms) or "torque (?)"
    raise uf.UserFunctionError(f"simulate_body: {names} raised {what} {where}") from None


def normalised_after_run(method) -> bool:
    """Whether a run's attitudes are normalised after it: those of DOP853 and RK4 (the splittings normalise each
    step's, as the scenes do, and the exact flow's are unit to round-off)."""
    return method not in KICK_METHODS and method != "exact"


def body_run(times, Y, method, st, I, complete, params, terms, compile_s, warnings, jit):
    L = Y[:, :3].copy()
    q = Y[:, 3:7].copy()
    norms = np.linalg.norm(q, axis=1)
    if normalised_after_run(method):
        q /= norms[:, None]

    def diagnostics():  # measured when first read (`BodyRun.diagnostics`)
        out = {"quaternion_norm_drift": float(np.max(np.abs(norms - 1.0)))}
        if not terms:
            # in units of the largest component (both drifts are relative, so the same numbers): no square of a
            # momentum near 1e154 overflows
            size = float(np.max(np.abs(L))) if L.size and np.all(np.isfinite(L)) else 0.0
            Ls = L / size if size > 0.0 else L
            w = Ls @ inverse_inertia(I).T
            E = 0.5 * np.einsum("ij,ij->i", Ls, w)
            Lm = np.linalg.norm(Ls, axis=1)
            out["energy_rel_drift"] = float(np.max(np.abs(E - E[0])) / abs(E[0])) if E[0] else 0.0
            out["momentum_rel_drift"] = float(np.max(np.abs(Lm - Lm[0])) / Lm[0]) if Lm[0] else 0.0
        return out

    def torque_samples():  # evaluated when first read (`BodyRun.torque_samples`)
        plain = [(uf.plain_function(term.func), term.params_for(params)) for _, term in terms]
        return np.array([_summed(plain, t, L[i], q[i]) for i, t in enumerate(times)])

    warnings = list(warnings)
    if not jit:
        warnings.append("jit=False: the torque and the integrator ran as plain Python, some 100 to 1000 times "
                        "slower than compiled")
    return BodyRun(times, L, q, method, int(st["NSTEP"][0]), int(st["NFEV"][0]), complete, I, diagnostics,
                   warnings, [], torque_samples if terms else None, compile_s or 0.0)


#: samples of the closed-form flow per call (`exact_run`): between calls progress shows and Ctrl-C is seen
EXACT_SAMPLES_PER_CALL = 4096


def exact_run(I, L, q, times, progress=None):
    """The torque-free body's closed-form flow (principal axes required), `EXACT_SAMPLES_PER_CALL` samples a call:
    progress between them, and Ctrl-C a `RunInterrupted` with the samples before it."""
    from rotframe.rigid.free_body import free_body_closed_form

    if np.any(I != np.diag(np.diag(I))):
        raise ScenarioError("method='exact' needs principal axes (a diagonal inertia); give the 3 principal "
                            "moments, or use dop853")
    st = {"NSTEP": np.zeros(1, np.int64), "NFEV": np.zeros(1, np.int64)}
    n = times.size
    Y = np.full((n, 7), np.nan)
    Y[0, :3], Y[0, 3:] = L, q  # the start, until the flow's first call writes it
    done = 0
    try:
        for start in range(0, n, EXACT_SAMPLES_PER_CALL):
            stop = min(n, start + EXACT_SAMPLES_PER_CALL)
            # the reference path: the same bits on every machine, whatever the calls' sizes (one time a sample)
            Y[start:stop, :3], Y[start:stop, 3:] = free_body_closed_form(np.diag(I).copy(), L, q, times[start:stop])
            done = stop
            if progress is not None:
                progress(stop / n)
    except KeyboardInterrupt:
        k = max(done, 1)
        raise RunInterrupted(body_run(times[:k], Y[:k], "exact", st, I, False, (), [], 0.0, [], True)) from None
    return body_run(times, Y, "exact", st, I, True, (), [], 0.0, [], True)


def _summed(plain, t, L, q):
    """The torques' sum at one sample, in their order (as the glue sums them), from their plain functions."""
    total = None
    for f, own in plain:
        tau = np.asarray(f(t, *uf.read_only_args((L, q)), *own), float)
        total = tau if total is None else total + tau
    return total
