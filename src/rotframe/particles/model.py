"""What a particle scene is: its force terms and their constants.

A [`ParticleModel`][rotframe.particles.model.ParticleModel] lists the terms a scene includes, and nothing else is
computed (a term that is absent costs one branch in the compiled kernel). It
is constant during a run; the state (positions and velocities) lives apart, in
the arrays the integrators advance, as MuJoCo keeps ``mjModel`` apart from
``mjData``.

All values are SI floats in the rotating frame's axes; units are converted at
the edge (`rotframe.app.scenario`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from rotframe.errors import ScenarioError

__all__ = ["OmegaSchedule", "ParticleModel", "TERMS", "NONLINEAR_TERMS"]

#: Force terms a particle scene can name.
TERMS = (
    "gravity",
    "altitude-gravity",
    "central-gravity",
    "coriolis",
    "centrifugal",
    "euler",
    "linear-drag",
    "quadratic-drag",
    "pendulum",
    "spring",
    "curvature",
)

#: Terms that make r'' nonlinear in (r, v): a model naming one has no exact linear flow
#: ([`ParticleModel.is_linear`][rotframe.particles.model.ParticleModel.is_linear]). ``curvature`` makes the ground a sphere (events on altitude).
NONLINEAR_TERMS = ("altitude-gravity", "central-gravity", "quadratic-drag", "pendulum", "curvature")


@dataclass(frozen=True)
class OmegaSchedule:
    """Rotation of the frame: a fixed unit axis times a magnitude w(t).

    w(t) is piecewise linear through the nodes ``(times, values)`` and held
    constant outside them; a single node is a constant rate. Its integral
    (the angle turned) and derivative (for the Euler force) are then exact.

    Parameters
    ----------
    axis : (3,) array_like
        Direction of omega in the rotating frame's axes (normalised here).
    times, values : (K,) array_like
        Node times (s, increasing) and rates (rad/s).
    """

    axis: np.ndarray
    times: np.ndarray
    values: np.ndarray

    @classmethod
    def constant(cls, omega_vector):
        """A constant angular velocity vector (rad/s), rotating-frame axes."""
        w = np.asarray(omega_vector, dtype=float)
        norm = float(np.linalg.norm(w))
        axis = w / norm if norm > 0 else np.array([0.0, 0.0, 1.0])
        return cls(axis, np.zeros(1), np.array([norm]))

    @classmethod
    def ramp(cls, axis, omega0, alpha, duration):
        """w(t) = omega0 + alpha t on [0, duration] about a fixed axis."""
        duration = float(duration)
        if alpha == 0.0 or duration <= 0.0:
            return cls.constant(np.asarray(axis, float) / np.linalg.norm(axis) * omega0)
        return cls.table(axis, [0.0, duration], [omega0, omega0 + alpha * duration])

    @classmethod
    def table(cls, axis, times, values):
        """Piecewise-linear w(t) through the given nodes."""
        axis = np.asarray(axis, dtype=float)
        times = np.asarray(times, dtype=float)
        values = np.asarray(values, dtype=float)
        if times.ndim != 1 or times.shape != values.shape or times.size == 0:
            raise ScenarioError("omega table: times and values must be 1-D arrays of one length")
        if np.any(np.diff(times) <= 0):
            raise ScenarioError("omega table: times must increase strictly")
        if not (np.all(np.isfinite(times)) and np.all(np.isfinite(values))):
            raise ScenarioError("omega table: times and values must be finite")
        return cls(axis / np.linalg.norm(axis), times, values)

    @classmethod
    def from_callable(cls, axis, func, t_end, nodes=4097):
        """Sample a callable w(t) (rad/s) on ``nodes`` points of [0, t_end].

        The compiled kernels cannot call Python, so a callable is tabulated;
        the piecewise-linear interpolant has error O((t_end / nodes)^2 w'').
        """
        times = np.linspace(0.0, float(t_end), int(nodes))
        values = np.array([float(func(t)) for t in times])
        return cls.table(axis, times, values)

    @property
    def is_constant(self) -> bool:
        return self.values.size == 1 or bool(np.all(self.values == self.values[0]))

    def cumulative(self) -> np.ndarray:
        """Integral of w from the first node to each node (rad).

        Computed once per schedule (the schedule is frozen) and returned as a
        copy: a run's per-call overhead stays a few microseconds.
        """
        cached = self.__dict__.get("_cumulative")
        if cached is None:
            dt = np.diff(self.times)
            seg = 0.5 * dt * (self.values[1:] + self.values[:-1])
            cached = np.concatenate([[0.0], np.cumsum(seg)])
            object.__setattr__(self, "_cumulative", cached)
        return cached.copy()

    def vector(self, t=0.0) -> np.ndarray:
        """omega(t) as a vector (rad/s)."""
        return self.axis * float(np.interp(t, self.times, self.values))

    def angle(self, t):
        """Angle turned since the first node, exact for the schedule (rad); vectorised."""
        from rotframe.particles.schedule import omega_angle

        wint = self.cumulative()
        return np.array([omega_angle(float(x), self.times, self.values, wint) for x in np.atleast_1d(t)])


@dataclass(frozen=True)
class ParticleModel:
    """The force terms of a particle scene and their constants (SI).

    Parameters
    ----------
    terms : tuple of str
        Names from `TERMS`. Only these are computed.
    omega : OmegaSchedule
        Rotation of the frame (used by coriolis, centrifugal and euler).
    g : (3,) array
        Uniform gravity vector (m/s^2) for ``gravity``. If the frame is the
        Earth's and ``g`` is the effective gravity, the centrifugal term is
        already inside it: do not name ``centrifugal`` too.
    g0, radius, gm : float
        For ``altitude-gravity`` (g0 (R/(R+z))^2, down) and ``central-gravity``
        (-GM (r - c)/|r - c|^3 with the centre c = (0, 0, -R)).
    k_linear, k_quadratic : float
        Drag: a = -k_linear v (1/s) and a = -k_quadratic |v| v (1/m).
    pendulum_length : float
        String length L (m) for ``pendulum``; the bob stays on the sphere
        |r - pivot| = L.
    pivot : (3,) array
        Suspension point (m).
    scale_height : float
        Density scale height H (m) of the drag: the drag coefficients are
        multiplied by exp(-z / H) (an isothermal atmosphere); 0 for uniform air.
    spring : float
        w0^2 (1/s^2) of a horizontal restoring force a = -w0^2 (x, y, 0), the
        linearised (small-angle) pendulum, for ``spring``.
    """

    terms: tuple
    omega: OmegaSchedule = field(default_factory=lambda: OmegaSchedule.constant([0.0, 0.0, 0.0]))
    g: np.ndarray = field(default_factory=lambda: np.zeros(3))
    g0: float = 0.0
    radius: float = 0.0
    gm: float = 0.0
    k_linear: float = 0.0
    k_quadratic: float = 0.0
    pendulum_length: float = 0.0
    pivot: np.ndarray = field(default_factory=lambda: np.zeros(3))
    spring: float = 0.0
    scale_height: float = 0.0

    def __post_init__(self):
        unknown = [t for t in self.terms if t not in TERMS]
        if unknown:
            raise ScenarioError(f"model: unknown term {unknown[0]!r}; allowed: {', '.join(TERMS)}")
        gravities = [t for t in self.terms if t.endswith("gravity")]
        if len(gravities) > 1:
            raise ScenarioError(f"model: name one gravity term, not {gravities}")
        if "pendulum" in self.terms and not self.pendulum_length > 0:
            raise ScenarioError("model: pendulum needs a positive length")

    def has(self, term: str) -> bool:
        return term in self.terms

    @property
    def is_linear(self) -> bool:
        """True when r'' is linear in (r, v) with constant coefficients.

        Then the exact propagator (matrix exponential) applies.
        """
        return not self.nonlinear_reasons()

    @property
    def is_force_free(self) -> bool:
        """True when no force acts in inertial space: the terms are just the frame's own.

        That is Coriolis and centrifugal, and Euler's too when the rate varies (named or not
        when it is steady, where it is zero), and nothing else. The particle then moves on a
        straight inertial line, which `rotframe.particles.linear` gives exactly for any
        rotation schedule.
        """
        frame = {"coriolis", "centrifugal"} if self.omega.is_constant else {"coriolis", "centrifugal", "euler"}
        return set(self.terms) in (frame, frame | {"euler"})

    @property
    def has_exact_flow(self) -> bool:
        """True when method ``exact`` applies: a linear model ([`is_linear`][rotframe.particles.model.ParticleModel.is_linear]) or a force-free one."""
        return self.is_linear or self.is_force_free

    def nonlinear_reasons(self) -> list:
        """Why the model is not linear with constant coefficients (empty when it is).

        One phrase per cause, for error messages: the `NONLINEAR_TERMS` it
        names, linear drag in a stratified atmosphere, a rotation rate that varies.
        """
        reasons = []
        nonlinear = [t for t in self.terms if t in NONLINEAR_TERMS]
        if nonlinear:
            reasons.append(f"terms {nonlinear} are nonlinear")
        if self.scale_height > 0 and "linear-drag" in self.terms:
            reasons.append("linear drag in air of varying density (scale_height > 0) is nonlinear")
        uses_omega = {"coriolis", "centrifugal", "euler"} & set(self.terms)
        if uses_omega and not self.omega.is_constant:
            reasons.append("omega varies in time")
        return reasons

    def pack(self) -> np.ndarray:
        """The flat parameter vector of `rotframe.particles.packed` (made once per model, returned as a copy)."""
        cached = self.__dict__.get("_packed")
        if cached is None:
            cached = self._pack()
            object.__setattr__(self, "_packed", cached)
        return cached.copy()

    def _pack(self) -> np.ndarray:
        from rotframe.particles import packed as k
        P = np.zeros(k.N_PARAMS)
        P[k.I_AXIS : k.I_AXIS + 3] = self.omega.axis
        P[k.I_CORIOLIS] = float(self.has("coriolis"))
        P[k.I_CENTRIFUGAL] = float(self.has("centrifugal"))
        P[k.I_EULER] = float(self.has("euler") and not self.omega.is_constant)
        P[k.I_KLIN] = self.k_linear if self.has("linear-drag") else 0.0
        P[k.I_KQUAD] = self.k_quadratic if self.has("quadratic-drag") else 0.0
        if self.has("gravity"):
            P[k.I_GMODE] = 0.0
            P[k.I_G : k.I_G + 3] = self.g
        elif self.has("altitude-gravity"):
            P[k.I_GMODE] = 1.0
        elif self.has("central-gravity"):
            P[k.I_GMODE] = 2.0
        else:
            P[k.I_GMODE] = -1.0
        P[k.I_GM] = self.gm
        P[k.I_R] = self.radius
        P[k.I_G0] = self.g0
        if self.has("pendulum"):
            P[k.I_PLEN] = self.pendulum_length
            P[k.I_PIVOT : k.I_PIVOT + 3] = self.pivot
        if self.has("spring"):
            P[k.I_SPRING] = self.spring
        P[k.I_SCALE_H] = self.scale_height
        return P

    def linear_matrices(self):
        """(K, C, b) with r'' = K r + C v + b, for a linear model (see [`is_linear`][rotframe.particles.model.ParticleModel.is_linear])."""
        from rotframe.numerics.hat import skew  # numba-free callers stay cheap to import

        w = self.omega.vector(0.0)
        W = skew(w)
        K = np.zeros((3, 3))
        C = np.zeros((3, 3))
        b = np.zeros(3)
        if self.has("gravity"):
            b = np.asarray(self.g, dtype=float).copy()
        if self.has("coriolis"):
            C -= 2.0 * W
        if self.has("centrifugal"):
            K -= W @ W
        if self.has("linear-drag"):
            C -= self.k_linear * np.eye(3)
        if self.has("spring"):
            K -= self.spring * np.diag([1.0, 1.0, 0.0])
        return K, C, b


def term_accelerations(model: ParticleModel, times, r, v) -> dict:
    """Size of each force term's acceleration along a path (m/s^2), for audits.

    Evaluates every term the model *could* have (whether or not it is on) at
    the samples ``r, v`` of shape (n, 3): gravity variants are reported as
    their difference from uniform gravity, since that is what switching them
    on changes. Returns ``{term: (n,) array}``.
    """
    r = np.asarray(r, dtype=float)
    v = np.asarray(v, dtype=float)
    t = np.asarray(times, dtype=float)
    axis = model.omega.axis
    w = np.interp(t, model.omega.times, model.omega.values)[:, None] * axis
    out = {"coriolis": np.linalg.norm(2 * np.cross(w, v), axis=1),
           "centrifugal": np.linalg.norm(np.cross(w, np.cross(w, r)), axis=1)}
    speed = np.linalg.norm(v, axis=1)
    air = np.exp(-r[:, 2] / model.scale_height) if model.scale_height > 0 else 1.0
    out["quadratic-drag"] = model.k_quadratic * air * speed**2
    out["linear-drag"] = model.k_linear * air * speed
    g_uniform = np.asarray(model.g, dtype=float)
    if model.radius > 0:
        c = np.array([0.0, 0.0, -model.radius])
        d = r - c
        dist = np.linalg.norm(d, axis=1)[:, None]
        if model.gm > 0:
            g_central = -model.gm * d / dist**3
            out["central-gravity"] = np.linalg.norm(g_central - g_uniform, axis=1)
        if model.g0 > 0:
            g_alt = np.zeros_like(r)
            g_alt[:, 2] = -model.g0 * (model.radius / (model.radius + r[:, 2])) ** 2
            out["altitude-gravity"] = np.linalg.norm(g_alt - g_uniform, axis=1)
    return out
