"""The exact flow of a linear problem of your own: ``rotframe.simulate(method="exact")``.

Where every force is linear in ``(r, v)`` with constant coefficients and the frame turns
steadily, the equation of motion is ``r'' = K r + C v + b`` with constant ``K``, ``C``, ``b``
(docs/physics/earth.md, the exact linear flow), and its flow is exact: the scenes' own
(`rotframe.particles.linear.ExactFlow`, ``s(t) = expm(M t) s(0)`` with ``s = (r, v, 1)``; the
inertial straight line turned into the frame for a particle under the frame's terms alone).
The engine chooses it from the terms, as the scenes choose it from theirs:

- each built-in term that is linear carries its part, ``Force.linear`` (`rotframe.forces`:
  uniform gravity ``b += g``, a spring ``K -= k``, linear drag in uniform air ``C -= k1``, the
  Lorentz force ``C += (q/m) [. x B]``, ``b += (q/m) E``);
- the frame's terms add theirs, those the run keeps (``frame_terms``): Coriolis
  ``C -= 2 [w x]``, centrifugal ``K -= [w x]^2`` (Euler's is zero in a steady frame);
- a constant acceleration of the origin ``b -= a0``.

A particle under the frame's terms alone (all three of them) in a frame that turns about a fixed
axis at a piecewise-linear rate (``omega=(times, vectors, "linear")``, every vector along one axis)
moves on the inertial straight line too, turned into the frame by the rate's exact integral: the
scenes' turntable flow (`rotframe.particles.model.OmegaSchedule.table`).

Anything else is refused by name, in one line: a force of your own or a nonlinear built-in
term (no linear form), the pendulum's string, a frame whose omega is not constant (but that one),
an origin whose acceleration is not, an event of your own (the exact flow locates the built-in crossings of a
coordinate, `rotframe.events.crossing`, as the scenes' own), the GPU. The
frame's part is the scenes' model of the frame's terms
(`rotframe.particles.model.ParticleModel.linear_matrices` and ``is_force_free``), the forces' parts
added after it in the scenes' order, so a scene's model and the same terms given here have the
same matrices to the bit.
"""

from __future__ import annotations

import numpy as np

from rotframe.errors import ScenarioError
from rotframe.problem.terms import Force, StringConstraint

__all__ = ["LinearProblem", "linear_problem", "event_row"]


class LinearProblem:
    """What the exact flow (`rotframe.particles.linear.ExactFlow`) reads of a model: a linear problem's matrices.

    Attributes
    ----------
    terms : tuple of str
        The terms, by name (the frame's by the scenes' names).
    omega : OmegaSchedule
        The frame's steady rotation (its exact angle, for a particle under the frame's terms alone).
    is_force_free : bool
        Only the frame's Coriolis and centrifugal terms act: the inertial straight line, turned
        into the frame, is the flow (exact at every sample however long the run).
    is_linear : bool
        False where the coefficients vary (a frame turning at a piecewise-linear rate): the flow
        is then the force-free particle's closed form, never a matrix exponential.
    """

    def __init__(self, terms, omega, K, C, b, force_free, linear=True):
        self.terms = tuple(terms)
        self.omega = omega
        self._matrices = (K, C, b)
        self.is_force_free = bool(force_free)
        self.is_linear = bool(linear)

    def linear_matrices(self):
        """``(K, C, b)`` of ``r'' = K r + C v + b``."""
        K, C, b = self._matrices
        return K.copy(), C.copy(), b.copy()


def event_row(g, name):
    """The scenes' event row (`rotframe.particles.trajectory.Event`, named ``name``) of a built-in crossing
    (`rotframe.events.crossing`: its ``crossing`` attribute), which the exact flow locates; None for another
    function."""
    from rotframe.particles.trajectory import Event
    from rotframe.problem.callables import plain_function

    g = plain_function(g)
    what = getattr(g, "crossing", None)
    if what is None:
        return None
    of, component, value = what
    return Event(name, of, int(component), float(value), int(getattr(g, "direction", 0)),
                 bool(getattr(g, "terminal", False)))


def linear_problem(terms, labels, frame, origin, events, frame_terms) -> LinearProblem:
    """The linear problem of the run's ``terms`` (`Force` or `StringConstraint`, named by ``labels``), or a one-line
    ScenarioError naming what the exact flow cannot take."""
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    refusal = "method='exact' takes terms linear in (r, v) with constant coefficients in a steady frame"
    for k, g in enumerate(events):
        if event_row(g, "") is None:
            raise ScenarioError(f"events[{k}]: {refusal}, and locates the crossings of a coordinate alone "
                                "(rotframe.events.crossing), no other event function; use dop853")
    if frame.kind == "table" and frame.interpolation == "linear":
        return _turning_frame(terms, frame, origin, frame_terms)
    if frame.kind != "constant":
        raise ScenarioError(f"omega: {refusal}; this frame's omega is a {frame.kind}, not a constant vector (a "
                            "piecewise-linear table, (times, vectors, 'linear'), takes a particle under the frame's "
                            "terms alone); use dop853")
    if origin.kind not in ("zero", "constant"):
        raise ScenarioError(f"origin_acceleration: {refusal}; a0 is a {origin.kind}, not a constant; use dop853")
    # the frame's terms are the scenes' model of them (its matrices, and whether it is force-free), then the
    # forces are added: the scenes' order of the sums
    frame_model = ParticleModel(tuple(frame_terms), omega=OmegaSchedule.constant(frame.data[0]))
    K, C, b = frame_model.linear_matrices()
    names = []
    for term, label in zip(terms, labels):
        if isinstance(term, StringConstraint):
            raise ScenarioError(f"{label} (pendulum): {refusal}; the string's constraint is not linear; use "
                                "rotation-splitting, rotation-splitting4, dop853 or rk4")
        if not isinstance(term, Force) or not term.linear or term.axes != "frame":
            what = term.name or "a force of your own"
            raise ScenarioError(f"{label} ({what}): {refusal}; it has no linear form (the built-in terms that do: "
                                "gravity, spring, drag(linear=...) in uniform air, lorentz); use dop853")
        Kf, Cf, bf = (np.asarray(m, dtype=float) for m in term.linear)
        K += Kf
        C += Cf
        b += bf
        names.append(term.name)
    if origin.kind == "constant":
        b -= np.asarray(origin.data[0], dtype=float)
    force_free = not terms and origin.kind == "zero" and frame_model.is_force_free
    return LinearProblem(names + list(frame_terms), frame_model.omega, K, C, b, force_free)


def _turning_frame(terms, frame, origin, frame_terms) -> LinearProblem:
    """A particle under the frame's terms alone in a frame turning about a fixed axis at a piecewise-linear rate: the
    inertial straight line turned into the frame (`rotframe.particles.linear.free_flow_matrices`), or a one-line
    ScenarioError naming what keeps the flow from being that."""
    from rotframe.particles.model import OmegaSchedule, ParticleModel

    refusal = ("method='exact' in a frame whose rate varies takes a particle under the frame's terms alone, the frame "
               "turning about one axis at a piecewise-linear rate")
    if terms:
        raise ScenarioError(f"forces[0]: {refusal}; use dop853")
    if origin.kind != "zero":
        raise ScenarioError(f"origin_acceleration: {refusal}, its origin at rest; use dop853")
    nodes = frame.nodes
    k = int(np.argmax(np.linalg.norm(nodes, axis=1)))
    axis = nodes[k] / np.linalg.norm(nodes[k]) if np.any(nodes[k]) else np.array([0.0, 0.0, 1.0])
    rates = nodes @ axis
    off_axis = np.linalg.norm(nodes - rates[:, None] * axis, axis=1)
    if np.any(off_axis > 1e-12 * max(1.0, float(np.max(np.abs(rates))))):
        j = int(np.argmax(off_axis))
        raise ScenarioError(f"omega: {refusal}; the table's vector at t = {frame.data[0][j]:g} s is off the axis "
                            f"{axis.tolist()}; use dop853")
    model = ParticleModel(tuple(frame_terms), omega=OmegaSchedule.table(axis, frame.data[0], rates))
    if not model.is_force_free:
        raise ScenarioError(f"frame_terms={tuple(frame_terms)}: {refusal}, and all three of the frame's terms "
                            "(coriolis, centrifugal, euler) acting; use dop853")
    return LinearProblem(frame_terms, model.omega, np.zeros((3, 3)), np.zeros((3, 3)), np.zeros(3), True, linear=False)
