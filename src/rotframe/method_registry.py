"""The one registry of integration methods, by name (``rotframe.methods()`` lists it).

Every method rotframe runs is one entry here: its order, how it steps, what it conserves, the
terms and frames it takes, the problems it runs and whether the GPU runs it. Each problem's
list of method names (a scene's ``METHODS``, what ``rotframe.simulate`` accepts, what the GPU
runs) is read from this registry with [`names`][rotframe.method_registry.names]; no other module
keeps a list of its own, and no integer code of a method leaves the module that compiles its
loop.

The problems (``Method.runs``):

==================  ==============================================================
``particle scenes``  the scenes' particle models (terms of `rotframe.particles.model`)
``particles``        ``rotframe.simulate``: your forces in any rotating frame
``bodies``           ``rotframe.simulate_body``: a rigid body under your torque
``free body``        the free-top and dzhanibekov scenes (torque-free body)
``heavy top``        the heavy-top scene
==================  ==============================================================

A name is matched without regard to case (scipy's ``"DOP853"`` is ``dop853``); some methods
keep the older names they were known by (``aliases``), each within the problems the method runs.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

from rotframe.errors import ScenarioError

__all__ = ["Method", "MethodNames", "methods", "get", "names", "check", "PROBLEMS", "UNREAD", "unread_settings"]

#: The problems a method may run (``Method.runs``), in the order `methods` lists them.
PROBLEMS = ("particle scenes", "particles", "bodies", "free body", "heavy top")


@dataclass(frozen=True)
class Method:
    """One integration method.

    Attributes
    ----------
    name : str
        The name a run is given (``--method``, ``method=``), lower case.
    order : int or None
        Order of the global error in the step (None for an exact flow).
    step : str
        ``"fixed"`` (a step of the run's ``step``), ``"adaptive"`` (steps chosen to keep the
        local error below ``rtol``) or ``"exact"`` (a closed-form flow, no step).
    conserves : str
        What it keeps exactly (to round-off) or without drift.
    accepts : str
        The terms and frames it takes; it refuses the others by name.
    runs : tuple of str
        The problems it runs (`PROBLEMS`).
    gpu : bool
        Whether the GPU ensembles run it (``--device gpu``).
    aliases : tuple of str
        Older names still accepted for it.

    An entry reads as a mapping too: ``dict(m)``, ``m["order"]``.
    """

    name: str
    order: int | None
    step: str
    conserves: str
    accepts: str
    runs: tuple
    gpu: bool = False
    aliases: tuple = ()

    def keys(self):
        return [f.name for f in fields(self)]

    def __getitem__(self, key):
        if key not in self.keys():
            raise KeyError(key)
        return getattr(self, key)

    @property
    def kind(self) -> str:
        """``step`` under the name the particle integrators' public ``METHODS`` entries had (``MethodInfo.kind``)."""
        return self.step


_ALL = ("particle scenes", "particles", "bodies", "free body", "heavy top")
_LIE_POISSON = ("|L| and the Casimir exactly, the energy without drift; the attitude stays a rotation; "
                "time-reversible")
_TOP = "|L| about the vertical and the symmetry axis exactly, the energy without drift; time-reversible"
_ROTATION = "|v| under the Coriolis force, the pendulum's constraint exactly; time-reversible"

_REGISTRY = (
    Method("exact", None, "exact", "everything (the exact flow)",
           "a linear particle model with constant coefficients or a force-free one (only the frame's terms): in "
           "rotframe.simulate the built-in linear terms (gravity, spring, linear drag in uniform air, the Lorentz "
           "force) in a steady frame, refusing any other term, events and a varying frame by name; a torque-free "
           "body", ("particle scenes", "particles", "bodies", "free body")),
    Method("rotation-splitting", 2, "fixed", _ROTATION,
           "the frame's Coriolis term as an exact rotation of v (exact for omega of fixed direction over a "
           "step), forces of (t, r) alone as kicks, drag (rotframe.forces.drag) as its exact flow, the "
           "pendulum's string (rotframe.forces.pendulum) on its sphere; refuses a force of your own that "
           "reads v or is given in inertial axes", ("particle scenes", "particles"),
           gpu=True, aliases=("splitting",)),
    Method("rotation-splitting4", 4, "fixed", _ROTATION + " (Yoshida's triple jump of rotation-splitting)",
           "as rotation-splitting", ("particle scenes", "particles"), gpu=True, aliases=("splitting4",)),
    Method("lie-poisson", 2, "fixed", _LIE_POISSON,
           "principal axes (a symmetric body's free flow exactly); torques of (t, q) alone (rotframe.torques), as "
           "kicks at fixed attitude", ("bodies", "free body")),
    Method("lie-poisson4", 4, "fixed", _LIE_POISSON, "as lie-poisson", ("bodies", "free body")),
    Method("lie-poisson6", 6, "fixed", _LIE_POISSON, "as lie-poisson", ("bodies", "free body")),
    Method("lie-poisson8", 8, "fixed", _LIE_POISSON, "as lie-poisson", ("bodies", "free body")),
    Method("top-splitting", 2, "fixed", _TOP,
           "a symmetric body (two equal principal moments), the heavy top: its free flow exactly, torques of "
           "(t, q) alone (gravity's: rotframe.torques.gravity) as kicks", ("bodies", "heavy top"),
           aliases=("splitting",)),
    Method("top-splitting4", 4, "fixed", _TOP, "as top-splitting", ("bodies", "heavy top"), aliases=("splitting4",)),
    Method("top-splitting6", 6, "fixed", _TOP, "as top-splitting", ("bodies", "heavy top"), aliases=("splitting6",)),
    Method("top-splitting8", 8, "fixed", _TOP, "as top-splitting", ("bodies", "heavy top")),
    Method("rk4", 4, "fixed", "nothing exactly",
           "every term and frame: forces, torques, events, omega(t) about any axis, an accelerating origin", _ALL,
           gpu=True),
    Method("dop853", 8, "adaptive", "nothing exactly; the local error of each step below rtol",
           "every term and frame: forces, torques, events, omega(t) about any axis, an accelerating origin", _ALL),
)
_BY_NAME = {m.name: m for m in _REGISTRY}


def methods(runs: str | None = None) -> list:
    """Every integration method, or those that run the problem ``runs`` (one of `PROBLEMS`).

    Returns
    -------
    list of Method
        Name, order, step, conserves, accepts, runs, gpu, aliases.

    Examples
    --------
    >>> [m.name for m in methods("particles")]
    ['exact', 'rotation-splitting', 'rotation-splitting4', 'rk4', 'dop853']
    >>> get("rotation-splitting4").order, get("rotation-splitting4").gpu
    (4, True)
    """
    if runs is None:
        return list(_REGISTRY)
    _check_problem(runs)
    return [m for m in _REGISTRY if runs in m.runs]


#: The run settings each kind of method does not read (`Method.step`): an adaptive method chooses its own steps,
#: a fixed-step one has no tolerance, the exact flow neither.
UNREAD = {"exact": ("step", "rtol", "atol"), "adaptive": ("step",), "fixed": ("rtol", "atol")}


def unread_settings(method: str, given: dict) -> list:
    """Warnings for the settings in ``given`` (name -> value, as the caller set them) that ``method`` does not read.

    The kind is the method's ``step`` in the registry (a method it does not hold, of a scene of
    your own, counts as fixed-step): ``exact`` reads neither a step nor a
    tolerance, ``dop853`` (adaptive) chooses its own steps from ``rtol``, and every other method
    takes fixed steps and has no tolerance (`UNREAD`). The one rule of the scenes' runs
    (`rotframe.app.runner.unused_settings`) and ``rotframe.simulate``'s.

    >>> unread_settings("dop853", {"step": 0.5, "rtol": 1e-10})
    ['step = 0.5 is not used: dop853 is adaptive and chooses its own steps (set rtol instead)']
    """
    known = _BY_NAME.get(method.lower() if isinstance(method, str) else method)
    kind = known.step if known is not None else "fixed"  # a method of a scene of your own (register_scene): fixed
    why = {"exact": f"{method} evaluates the exact flow, with no steps and no tolerance",
           "adaptive": f"{method} is adaptive and chooses its own steps (set rtol instead)",
           "fixed": f"{method} takes fixed steps and has no tolerance (set step instead)"}[kind]
    return [f"{key} = {given[key]} is not used: {why}" for key in UNREAD[kind] if key in given]


def get(name: str) -> Method:
    """The method of that name (any case; not an alias); ScenarioError naming the methods otherwise."""
    key = name.lower() if isinstance(name, str) else name
    if key not in _BY_NAME:
        raise ScenarioError(f"method={name!r}: unknown; the methods: {', '.join(_BY_NAME)}")
    return _BY_NAME[key]


class MethodNames(tuple):
    """The method names of one problem: the canonical ones in order, plus the old names (aliases) it accepts.

    A tuple of the canonical names (iterating, printing and ``len`` see only
    those, so messages and ``rotframe show`` list them), whose ``in`` also
    accepts an alias; `canonical` maps an alias to its name, which is the
    name a run reports (the JSON ``method``). Names are matched without regard
    to case.
    """

    def __new__(cls, names, aliases=None):
        self = super().__new__(cls, names)
        self.aliases = dict(aliases or {})
        unknown = [a for a, target in self.aliases.items() if not tuple.__contains__(self, target)]
        if unknown:
            raise ValueError(f"MethodNames: aliases {unknown} point to no method of {tuple(self)}")
        return self

    def __contains__(self, name) -> bool:
        if not isinstance(name, str):
            return False
        name = name.lower()
        return tuple.__contains__(self, name) or name in self.aliases

    def canonical(self, name):
        """The canonical name of ``name`` (any case; itself when it is one; unknown names and None unchanged)."""
        if not isinstance(name, str) or name not in self:
            return name
        name = name.lower()
        return self.aliases.get(name, name)


def names(runs: str, *, gpu: bool = False) -> MethodNames:
    """The names of the methods that run the problem ``runs`` (and the GPU, with ``gpu=True``), with their aliases."""
    chosen = [m for m in methods(runs) if m.gpu or not gpu]
    return MethodNames(tuple(m.name for m in chosen), {a: m.name for m in chosen for a in m.aliases})


def check(method, runs: str, *, default: str | None = None, gpu: bool = False, nor: str = "") -> str:
    """``method``'s canonical name if it runs the problem ``runs``; a one-line ScenarioError otherwise.

    The error says what the method is and what it takes when it exists but runs other
    problems (``rotation-splitting`` given to ``rotframe.simulate``), and lists the
    methods that do run the problem. ``nor`` names what else it is refused with (``"torque=kick"``).

    Examples
    --------
    >>> check("DOP853", "particles"), check("splitting4", "particle scenes")
    ('dop853', 'rotation-splitting4')
    """
    if method is None and default is not None:
        return default
    allowed = names(runs, gpu=gpu)
    if method in allowed:
        return allowed.canonical(method)
    where = " on the GPU" if gpu else ""
    if gpu and method in names(runs):
        raise ScenarioError(f"method={method!r} does not run on the GPU; the GPU runs {', '.join(allowed)} "
                            "(any case), or use device 'cpu'")
    known = _BY_NAME.get(method.lower()) if isinstance(method, str) else None
    if known is None and isinstance(method, str):
        known = next((m for m in _REGISTRY if method.lower() in m.aliases), None)
    if known is not None:
        takes = known.accepts
        if takes.startswith("as "):  # "as rotation-splitting": say what that one takes
            takes = _BY_NAME[takes[3:]].accepts
        nor = f" and cannot take {nor}" if nor else ""
        raise ScenarioError(f"method={method!r} does not run {_PROBLEM_WORDS[runs]}{where}{nor} (it takes "
                            f"{takes}); allowed: {', '.join(allowed)} (any case)")
    raise ScenarioError(f"method={method!r}: unknown; allowed for {_PROBLEM_WORDS[runs]}{where}: "
                        f"{', '.join(allowed)} (any case)")


_PROBLEM_WORDS = {"particle scenes": "a scene's particles", "particles": "rotframe.simulate's particles",
                  "bodies": "rotframe.simulate_body's bodies", "free body": "the free body",
                  "heavy top": "the heavy top"}


def _check_problem(runs):
    if runs not in PROBLEMS:
        raise ScenarioError(f"runs={runs!r}: allowed: {', '.join(PROBLEMS)}")
