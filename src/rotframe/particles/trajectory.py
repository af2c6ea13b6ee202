"""What a particle run returns: samples, events, cost; and the records the kernels fill.

[`Trajectory`][rotframe.particles.trajectory.Trajectory] is the one result type of every particle method (fixed-step,
adaptive, exact); a run cut short keeps what it computed in
[`RunInterrupted`][rotframe.particles.trajectory.RunInterrupted] or [`rotframe.errors.IntegrationError`][rotframe.errors.IntegrationError]
(``partial``, a truncated [`Trajectory`][rotframe.particles.trajectory.Trajectory]).
"""

from __future__ import annotations

import math
import operator
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Event", "Trajectory", "RunInterrupted", "EventBuffers", "event_table", "per_particle", "PerParticle"]


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
    event_times : dict name -> sequence (per particle: a `PerParticle`, or a list) of arrays of event times
    event_states : dict name -> sequence (per particle) of (k, 6) arrays (r, v)
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

    def first_events(self, name):
        """``(t, state)``: each particle's first ``name`` event, its time (N,) and its state (N, 6) (r, v); NaN and
        the state at the last sample where a particle had none."""
        t = np.full(self.r.shape[1], math.nan)
        state = np.concatenate([self.r[-1], self.v[-1]], axis=1)
        times, states = self.event_times.get(name, ()), self.event_states.get(name, ())
        if isinstance(times, PerParticle) and isinstance(states, PerParticle):
            hit, first = times.firsts()
            t[hit] = first
            state[hit] = states.firsts()[1]
            return t, state
        hit = [i for i, ts in enumerate(times) if len(ts)]
        if hit:
            t[hit] = [times[i][0] for i in hit]
            state[hit] = [states[i][0] for i in hit]
        return t, state

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
    """``records`` (grouped by particle, in particle order) as one array per particle: a `PerParticle`.

    ``counts[i]`` rows are particle i's. Each particle's array is a slice (a view) of
    ``records``, made when it is asked for, so that an ensemble of a million particles costs
    two arrays, not a million (``np.split`` made each anew: 0.7 s a million on the 2-core
    development machine; a list of slices 0.06 s).
    """
    return PerParticle(records, counts)


class PerParticle(Sequence):
    """Each particle's records, a read-only sequence of arrays (slices of one array): what `per_particle` returns.

    ``seq[i]`` is particle i's records in their order (an empty slice where it has none); ``len(seq)`` the
    number of particles. `firsts` reads every particle's first record at once.
    """

    def __init__(self, records, counts):
        self.records = records
        self.counts = np.asarray(counts, dtype=np.int64)
        self.ends = np.cumsum(self.counts)

    def __len__(self):
        return self.counts.size

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self[k] for k in range(*i.indices(len(self)))]
        i = operator.index(i)
        n = len(self)
        if i < 0:
            i += n
        if not 0 <= i < n:
            raise IndexError(f"particle {i} of {n}")
        end = int(self.ends[i])
        return self.records[end - int(self.counts[i]):end]

    def __iter__(self):
        ends = self.ends.tolist()
        return (self.records[a:b] for a, b in zip([0] + ends[:-1], ends))

    def firsts(self):
        """``(hit, rows)``: which particles have a record (N,) and, for those, their first records."""
        hit = self.counts > 0
        return hit, self.records[(self.ends - self.counts)[hit]]

    def __repr__(self):
        return repr(list(self))
