"""The terms of a user's particle problem: forces, and the pendulum's string (a constraint).

A `Force` is a function of ``(t, r, v, *params)`` giving an acceleration, with what rotframe
should know about it (its potential, its axes); the built-in terms of `rotframe.forces` are
Forces too. A `StringConstraint` is not a force but the condition ``|r - pivot| = length``,
kept by removing the normal part of the total acceleration (`rotframe.problem.models.particle_rhs`,
its constants from `model_constants`). `as_term` checks one entry of ``forces=``; `check_splitting` says what a
splitting method cannot take as a kick. The frame's own terms (`FRAME_TERMS`: Coriolis, centrifugal, Euler)
are not forces to add: the run chooses which of them act (`check_frame_terms`; every one unless told).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rotframe.errors import ScenarioError
from rotframe.problem import callables as uf

__all__ = ["Force", "StringConstraint", "Torque", "energy_by_numpy", "as_term", "one_constraint", "check_on_string", "check_splitting",
           "model_constants", "FRAME_TERMS", "check_frame_terms"]

#: The frame's own terms, by the scenes' names for them (``-2 w x v``, ``-w x (w x r)``, ``-w' x r``): the ones a
#: run may choose with ``frame_terms`` (every one by default).
FRAME_TERMS = ("coriolis", "centrifugal", "euler")


@dataclass(frozen=True)
class Force:
    """A user force with what rotframe should know about it.

    Attributes
    ----------
    accel : callable
        ``accel(t, r, v, *params) -> (ax, ay, az)``, m/s^2.
    potential : callable, optional
        ``U(t, r, *params)``, J/kg, with ``accel = -grad U`` (frame axes); enables the energy
        or Jacobi diagnostic.
    axes : str
        ``"frame"`` (default: the frame's axes) or ``"inertial"``.
    name : str, optional
        For messages and the run's list of terms (the built-in terms of `rotframe.forces` give
        the scenes' names for them).
    flow : tuple, optional
        The term's exact flow, where it has one that the splittings use instead of a kick:
        ``("drag", k1, k2, H)`` for `rotframe.forces.drag` (`model_constants`). Set by the built-in
        terms; a force of your own leaves it empty.
    takes_params : bool
        Whether ``accel`` and ``potential`` take the run's ``params`` after their own arguments
        (default True). The built-in terms of `rotframe.forces` do not: their constants are their
        own, and they sit beside forces of yours that take ``params``.
    linear : tuple, optional
        ``(K, C, b)`` where the term is linear in ``(r, v)`` with constant coefficients,
        ``a = K r + C v + b`` (K and C as three rows of three, b three numbers): what the exact
        flow takes (``method="exact"``, `rotframe.problem.exact`). Set by the built-in terms that
        are (uniform gravity, a spring, linear drag in uniform air, the Lorentz force); empty
        otherwise, and for a force of your own.
    array_potential : bool
        Whether ``potential`` takes ``t`` and ``r`` as arrays, ``r`` (3, M), and gives the M values: the run's
        energy diagnostic is then computed by numpy, with nothing compiled for it. Set by the built-in terms
        of `rotframe.forces` whose potential is arithmetic on ``r[0]``, ``r[1]``, ``r[2]``; False for a force
        of your own, whose potential is compiled.
    scene : tuple, optional
        The term as the scenes' model (`rotframe.particles.model.ParticleModel`) holds it, where nothing else of the
        term says what it is: ``("altitude-gravity", g0, R)`` for `rotframe.forces.altitude_gravity`. The GPU's
        steady specialisation reads it (`rotframe.problem.steady`). Set by the built-in terms; empty for a force of
        your own.
    """

    accel: object
    potential: object = None
    axes: str = "frame"
    name: str = ""
    flow: tuple = ()
    takes_params: bool = True
    linear: tuple = ()
    array_potential: bool = False
    scene: tuple = ()

    def params_for(self, params) -> tuple:
        """The ``params`` this force's functions are called with: the run's, or none (`takes_params`)."""
        return tuple(params) if self.takes_params else ()

    def __call__(self, *args):
        return self.accel(*args)


def energy_by_numpy(forces) -> bool:
    """Whether every force's potential takes arrays (`Force.array_potential`: the built-in terms) in the frame's axes:
    the run's energy diagnostic is then numpy's (`rotframe.problem.particles.array_energies`), and nothing is
    compiled for it (no potential in the problem's glue, no `rotframe.problem.engine.energies`)."""
    return all(f.array_potential and f.axes == "frame" for f in forces)


@dataclass(frozen=True)
class StringConstraint:
    """A particle held at distance ``length`` from a fixed ``pivot`` by a taut string (the pendulum's term).

    Not a force of its own: the string's tension is whatever keeps ``|r - pivot| = length``
    under every other term. The driver removes the normal part of the total acceleration
    ``a`` (the frame's terms included) and adds the centripetal one (the index-1 form, exact on
    the sphere): ``a <- a - (a . n + |v_t|^2 / length) n`` with ``n = (r - pivot) / length``.
    Made by `rotframe.forces.pendulum`; it does no work, so it adds nothing to the energy.
    """

    length: float
    pivot: tuple
    name: str = "pendulum"


@dataclass(frozen=True)
class Torque:
    """A torque with what rotframe should know about it: a user's, or a built-in one (`rotframe.torques`).

    Attributes
    ----------
    func : callable
        ``tau(t, L, q, *params) -> (3,)``, N m, body axes.
    attitude_only : bool
        True when ``tau`` depends on ``t`` and ``q`` alone (gravity gradient, a field fixed in
        space, a thruster's schedule), not on ``L``: its flow at fixed attitude is a kick, and
        the Lie-Poisson splittings take it.
    name : str, optional
        For messages and the run's list of terms (the built-in torques give theirs).
    takes_params : bool
        Whether ``func`` takes the run's ``params`` after ``(t, L, q)`` (default True). The built-in
        torques do not: their constants are their own.
    """

    func: object
    attitude_only: bool = False
    name: str = ""
    takes_params: bool = True

    def params_for(self, params) -> tuple:
        """The ``params`` ``func`` is called with: the run's, or none (`takes_params`)."""
        return tuple(params) if self.takes_params else ()

    def __call__(self, *args):
        return self.func(*args)


def as_term(f, k):
    """Entry ``k`` of ``forces=`` as a `Force` (a plain function gets its ``axes``/``potential`` attributes) or the
    `StringConstraint` it is; a one-line ScenarioError for anything else."""
    if isinstance(f, StringConstraint):
        return f
    if isinstance(f, Force):
        force = f
    elif callable(f):
        force = Force(f, potential=getattr(f, "potential", None), axes=getattr(f, "axes", "frame"))
    else:
        raise ScenarioError(f"forces[{k}]: {f!r} is not callable (a function f(t, r, v, *params) -> (3,))")
    if force.axes not in ("frame", "inertial"):
        raise ScenarioError(f"forces[{k}]: axes={force.axes!r}; allowed: 'frame', 'inertial'")
    if not callable(force.accel) or (force.potential is not None and not callable(force.potential)):
        raise ScenarioError(f"forces[{k}]: accel and potential must be callables")
    return force


def check_splitting(method, forces, labels):
    """A splitting kicks with the forces: each must be a force of ``(t, r)`` alone, in the frame's axes.

    A pendulum's string needs no check: the splittings run it on its sphere (`rotframe.problem.models`).

    ``labels``: each force as the user's list names it (``forces[k]``, counted with the string).
    """
    flows = [k for k, f in enumerate(forces) if f.flow]
    if len(flows) > 1:
        raise ScenarioError(f"method={method!r} cannot take {labels[flows[1]]} ({forces[flows[1]].name}): one drag "
                            "term a run: give linear and quadratic to one rotframe.forces.drag, or use dop853 or rk4")
    for k, f in enumerate(forces):
        why = ("" if f.flow else
               "reads v: a kick is exact only for a force of (t, r) alone (rotframe.forces.drag, which has an "
               "exact flow, runs under the splittings)" if uf.reads_argument(f.accel, 2)
               else "is given in inertial axes" if f.axes == "inertial" else "")
        if why:
            raise ScenarioError(f"method={method!r} cannot take {labels[k]} ({f.name or uf.display_name(f.accel)}): "
                                f"it {why}; use dop853 or rk4")


def one_constraint(terms, r, v):
    """The run's `StringConstraint` (at most one), its particles checked to start on the string's sphere."""
    found = [(k, f) for k, f in enumerate(terms) if isinstance(f, StringConstraint)]
    if len(found) > 1:
        raise ScenarioError(f"forces[{found[1][0]}]: a second pendulum; a particle hangs on one string")
    if not found:
        return None
    check_on_string(*found[0], r, v, compiled=r.shape[0] > 8)  # a few particles, once: Python's, no compile
    return found[0][1]


def check_on_string(k, c, r, v, compiled=True):
    """Refuse start states ``r``, ``v`` (N, 3; finite, C-ordered) off the sphere of the string ``c``, ``forces[k]``, or
    moving along it, in one line naming the particle (`rotframe.problem.string_start.string_defect`: compiled, as a
    prepared run checks at every run; imported at first use, as this module imports no numba). ``compiled=False``
    runs the same function as plain Python (the same arithmetic: a check once of a few particles compiles nothing)."""
    from rotframe.problem.string_start import ALONG_STRING, OFF_SPHERE, string_defect

    kind, i, value = (string_defect if compiled else string_defect.py_func)(r, v, *c.pivot, c.length)
    if kind == OFF_SPHERE:
        raise ScenarioError(f"r0: particle {i} is {value:.9g} m from the pivot of forces[{k}] (pendulum), not its "
                            f"length {c.length:.9g} m; start it on the string's sphere")
    if kind == ALONG_STRING:
        raise ScenarioError(f"v0: particle {i} moves along the string of forces[{k}] (pendulum) at "
                            f"{value:.3g} m/s; a taut string allows only velocities across it")


def check_frame_terms(frame_terms) -> tuple:
    """The frame's terms a run keeps (`FRAME_TERMS`, in their order): ``None`` for all of them, else the names given.

    One name may be given as a string. An unknown name, or a value that is not a name, is a
    one-line ScenarioError naming it and the names allowed.

    A term is left out where the problem holds it elsewhere, as the scenes do: on the Earth the
    centrifugal term is inside the effective gravity (``frame_terms=("coriolis",)`` with
    `rotframe.forces.gravity` of the local g), and the inertial oscillation's f-plane keeps the
    Coriolis term alone.
    """
    if frame_terms is None:
        return FRAME_TERMS
    names = (frame_terms,) if isinstance(frame_terms, str) else frame_terms
    try:
        names = list(names)
    except TypeError:
        raise ScenarioError(f"frame_terms={frame_terms!r}: a sequence of names from {', '.join(FRAME_TERMS)} "
                            "(or None for all of them)") from None
    for name in names:
        if not isinstance(name, str) or name.lower() not in FRAME_TERMS:
            raise ScenarioError(f"frame_terms: {name!r} is not a term of the frame; allowed: {', '.join(FRAME_TERMS)} "
                                "(None for all of them)")
    chosen = {name.lower() for name in names}
    return tuple(name for name in FRAME_TERMS if name in chosen)


def model_constants(constraint, drag, frame_terms=FRAME_TERMS):
    """The particle model's constants ``M`` for the engine (`rotframe.problem.models`): the string, a drag's flow,
    the frame's terms.

    ``M = (string, px, py, pz, length, drag, k1, k2, H, coriolis, centrifugal, euler)``: the
    `StringConstraint` (1 and its pivot and length, or zeros); under a splitting, the drag term
    whose exact flow it applies (``drag.flow = ("drag", k1, k2, H)``: ``v' = -(k1 + k2 |v|) rho(z) v``,
    ``rho = exp(-z / H)``, 1 for ``H = 0``; the flow itself is the scenes'
    `rotframe.particles.forces.drag_flow`), or zeros; and 1 or 0 for each of the frame's terms
    (`FRAME_TERMS`) the run keeps (`check_frame_terms`).
    """
    M = np.zeros(12)
    for k, name in enumerate(FRAME_TERMS):
        M[9 + k] = float(name in frame_terms)
    if constraint is not None:
        M[0] = 1.0
        M[1:4] = np.asarray(constraint.pivot, dtype=float)
        M[4] = float(constraint.length)
    if drag is not None:
        _, k1, k2, H = drag.flow
        M[5:9] = 1.0, float(k1), float(k2), float(H)
    return M
