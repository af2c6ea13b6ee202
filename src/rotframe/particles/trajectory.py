"""What a particle run returns: samples, events, cost; and the records the kernels fill.

[`Trajectory`][rotframe.particles.trajectory.Trajectory] is the one result type of every particle method (fixed-step,
adaptive, exact); a run cut short keeps what it computed in
[`RunInterrupted`][rotframe.particles.trajectory.RunInterrupted] or [`rotframe.errors.IntegrationError`][rotframe.errors.IntegrationError]
(``partial``, a truncated [`Trajectory`][rotframe.particles.trajectory.Trajectory]).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Event", "Trajectory", "RunInterrupted", "EventBuffers", "event_table", "per_particle"]


@dataclass(frozen=True)
class Event:
    """A zero crossing located to round-off on the method's own trajectory.

    ``kind`` "r" or "v": the event function is ``r[component] - value`` or
    ``v[component] - value``; "altitude": height above the sphere of the
    model's ``radius`` centred at (0, 0, -radius), minus ``value`` (curved ground); ``direction`` +1 rising, -1 falling, 0 both;
    a ``terminal`` event stops that particle (ground impact).
    """

    name: str
    kind: str
    component: int
    value: float = 0.0
    direction: int = 0
    terminal: bool = False

    def row(self):
        kind = {"r": 0.0, "v": 1.0, "altitude": 2.0}[self.kind]
        return [kind, float(self.component), float(self.value),
                float(self.direction), float(self.terminal)]


@dataclass
class Trajectory:
    """Samples of an ensemble trajectory (rotating frame, SI).

    Attributes
    ----------
    times : (n,) array, s
    r, v : (n, N, 3) arrays, m and m/s
    event_times : dict name -> list (per particle) of arrays of event times
    event_states : dict name -> list (per particle) of (k, 6) arrays (r, v)
    method, steps, nfev : what was run and what it cost (one trajectory)
    complete : False when the run stopped early; ``t_reached`` says where.
    """

    times: np.ndarray
    r: np.ndarray
    v: np.ndarray
    method: str
    steps: int = 0
    nfev: int = 0
    complete: bool = True
    t_reached: float = math.nan
    event_times: dict = field(default_factory=dict)
    event_states: dict = field(default_factory=dict)
    extras: dict = field(default_factory=dict)

    def truncated(self, n: int) -> Trajectory:
        return Trajectory(self.times[:n], self.r[:n], self.v[:n], self.method, self.steps, self.nfev,
                          False, float(self.times[n - 1]) if n else math.nan,
                          self.event_times, self.event_states, self.extras)


class RunInterrupted(Exception):
    """Ctrl-C or SIGTERM during a run; ``partial`` holds what was computed."""

    def __init__(self, partial, reason="interrupted"):
        super().__init__(reason)
        self.partial = partial
        self.reason = reason


def event_table(events):
    """The events as the (E, 5) table of the compiled drivers (`rotframe.particles.events`)."""
    if not events:
        return np.zeros((0, 5))
    return np.array([e.row() for e in events], dtype=np.float64)


class EventBuffers:
    """Per-particle event records filled by the kernels, in order of occurrence."""

    def __init__(self, n, max_events):
        self.t = np.full((n, max_events), np.nan)
        self.r = np.zeros((n, max_events, 3))
        self.v = np.zeros((n, max_events, 3))
        self.count = np.zeros(n, dtype=np.int64)
        self.which = np.zeros((n, max_events), dtype=np.int64)
        self.max_events = max_events

    def args(self):
        """The record arrays in the order the compiled drivers take them."""
        return self.t, self.r, self.v, self.count, self.which, self.max_events

    def reset(self):
        """Forget every record (a new run with the same buffers)."""
        self.count[:] = 0

    def attach(self, traj, events):
        """Split the records by event name into ``traj.event_times`` / ``event_states``.

        Vectorised: each particle's arrays are slices of one array per event (in
        particle order, each in record order), so that large ensembles do not
        spend their time here holding the GIL.
        """
        if not events:
            return
        kept = np.minimum(self.count, self.max_events)
        valid = np.arange(self.max_events)[None, :] < kept[:, None]
        for e_idx, ev in enumerate(events):
            sel = valid & (self.which == e_idx)
            counts = sel.sum(axis=1)
            traj.event_times[ev.name] = per_particle(self.t[sel], counts)
            traj.event_states[ev.name] = per_particle(np.concatenate([self.r[sel], self.v[sel]], axis=1), counts)


def per_particle(records, counts):
    """``records`` (grouped by particle, in particle order) cut into a list of one array per particle.

    ``counts[i]`` rows are particle i's. Each particle's array is a slice (a view) of
    ``records``; the particles with none share one empty slice, so that an ensemble of a
    million particles with few events costs a list, not a million arrays (``np.split`` made
    each anew: 0.7 s a million on the 2-core development machine; a slice for each particle
    0.06 s; where few particles have events, a slice for each of those, 0.01 s).
    """
    counts = np.asarray(counts)
    empty = records[:0]
    some = np.flatnonzero(counts)
    ends = np.cumsum(counts)
    if 4 * some.size > counts.size:  # most particles have events: one pass over them all
        ends = ends.tolist()
        return [records[a:b] if b > a else empty for a, b in zip([0] + ends[:-1], ends)]
    out = [empty] * counts.size
    ends = ends[some]
    for i, a, b in zip(some.tolist(), (ends - counts[some]).tolist(), ends.tolist()):
        out[i] = records[a:b]
    return out
