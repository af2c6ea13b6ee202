"""rotframe's one event locator (`rotframe.numerics.bisection.locator`): its answer, and that it is the only one.

The oracle is a trial whose crossing is known exactly: ``g(tau) = tau - c`` (rising) or
``c - tau`` (falling), for a double ``c`` in ``(0, h]``. Bisection to round-off with "a zero counts
as crossed" must return ``c`` itself, to the bit, wherever it lies in the step: at 1e-100 s inside
a step of 0.01 s (some 320 halvings), at the step's end, or anywhere between. Then every event
locator of rotframe (the scenes' fixed-step and DOP853 drivers, each method of the engine) must
be that one function, compiled for its own trial: no module but `rotframe.numerics.bisection`
halves a bracket.
"""

from __future__ import annotations

import pathlib
import re

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rotframe.numerics.bisection import locator
from rotframe.numerics.compiled import jit_inline

SRC = pathlib.Path(__file__).resolve().parents[1] / "src" / "rotframe"


@jit_inline
def _rising(ctx, tau):
    return tau - ctx[0]


@jit_inline
def _falling(ctx, tau):
    return ctx[0] - tau


_locate_rising = locator("test_rising", _rising)
_locate_falling = locator("test_falling", _falling)

H = 0.01


@pytest.mark.parametrize("c", [1e-100, 5e-324, 1e-300, 0.25 * H, H * (1.0 - 2.0**-52), H])
def test_the_crossing_to_the_bit_anywhere_in_the_step(c):
    assert _locate_rising((c,), H, -c) == c
    assert _locate_falling((c,), H, c) == c


@settings(max_examples=200, deadline=None)
@given(st.floats(min_value=5e-324, max_value=H, allow_nan=False, allow_infinity=False))
def test_the_crossing_to_the_bit_for_any_double_in_the_step(c):
    assert _locate_rising((c,), H, -c) == c
    assert _locate_falling((c,), H, c) == c


def test_the_returned_end_is_on_the_far_side():
    """The upper end of the bracket: at or past the crossing, never short of it (the state there has crossed)."""
    c = 0.3 * H + 1e-19  # not a midpoint of any bracket: the answer is the first double at or past it
    tau = _locate_rising((c,), H, -c)
    assert tau >= c
    assert tau - c <= 4 * (c * 2.0**-52)


def test_no_other_module_bisects():
    """One event locator: only `rotframe.numerics.bisection` calls the bisection's midpoint or narrows a bracket."""
    callers = []
    for path in SRC.rglob("*.py"):
        if path.relative_to(SRC).as_posix() == "numerics/bisection.py":
            continue
        text = path.read_text()
        if re.search(r"\b(bisection_midpoint|narrow)\s*\(", text):
            callers.append(path.relative_to(SRC).as_posix())
    assert callers == []


def test_every_locator_is_the_one_template():
    """The scenes' two locators and the engine's are copies of one code object, bound to their own trials."""
    from rotframe.numerics import bisection
    from rotframe.particles import dop853_particles, events
    from rotframe.problem import engine, event_watch

    watch = event_watch.watcher("test_locator", None, None, engine.METHOD_CODES["rk4"], None)
    engine_locate = watch.py_func.__globals__["LOCATE"]
    for located in (events.locate_fixed, dop853_particles.locate_dop853, engine_locate):
        assert located.py_func.__code__ is bisection._locate.__code__
    assert events.locate_fixed.py_func.__globals__["TRIAL"] is events.fixed_event_value
    assert dop853_particles.locate_dop853.py_func.__globals__["TRIAL"] is dop853_particles.dop853_event_value
    assert engine_locate.py_func.__globals__["TRIAL"] is watch.py_func.__globals__["TRIAL"]
