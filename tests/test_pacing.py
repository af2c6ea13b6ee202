"""`rotframe.problem.pacing.Pacer`: a call's budget from its own pace and from the host's work between calls."""

from __future__ import annotations

import pytest

from rotframe.problem import pacing


class Clock:
    """A clock the test moves (`time.perf_counter` of the pacer)."""

    def __init__(self):
        self.now = 100.0

    def perf_counter(self):
        return self.now


def paced(monkeypatch, between, call=0.05, budget=1000):
    """The budget after a first call and a second one of ``call`` s, with ``between`` s of host work before it."""
    clock = Clock()
    monkeypatch.setattr(pacing, "time", clock)
    pacer = pacing.Pacer("method rk4", 10.0, adaptive=False, first_budget=budget)
    pacer.start()
    clock.now += 3.0  # the first call compiles: its time sizes nothing
    pacer.done(budget)
    assert pacer.budget == budget
    clock.now += between
    pacer.start()
    clock.now += call
    pacer.done(budget)
    assert pacer.between_seconds == pytest.approx(between)
    return pacer.budget


def test_a_call_is_sized_to_call_seconds_where_the_host_works_little_between_calls(monkeypatch):
    # 1000 steps took 0.05 s: the next call takes 0.1 s of them, whatever the host's millisecond between
    assert paced(monkeypatch, between=0.001) == pytest.approx(1000 * pacing.CALL_SECONDS / 0.05, rel=1e-9)


def test_a_call_is_sized_to_ten_times_the_hosts_work_between_calls_where_that_is_longer(monkeypatch):
    # 0.03 s between calls (a million particles' copies): the next call takes 0.3 s, not 0.1 s
    wanted = 1000 * pacing.BETWEEN_CALLS_FACTOR * 0.03 / 0.05
    assert wanted > 1000 * pacing.CALL_SECONDS / 0.05
    assert paced(monkeypatch, between=0.03) == pytest.approx(wanted, rel=1e-9)


def test_a_call_grows_at_most_eightfold(monkeypatch):
    assert paced(monkeypatch, between=10.0) == 8 * 1000


def test_a_call_is_never_sized_past_the_longest_call(monkeypatch):
    # a second of host work between calls would ask for 10 s calls: a signal would wait that long
    assert paced(monkeypatch, between=1.0, call=0.5) == pytest.approx(1000 * pacing.LONGEST_CALL_SECONDS / 0.5, rel=1e-9)
