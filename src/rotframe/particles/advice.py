"""Advice that fits the method that failed: what to change when a run went unstable or diverged.

One home for the remedy a failure's message ends with, so that it never contradicts the run (a
DOP853 run was once told to "use a smaller step or dop853"). It takes the method's kind, as
`rotframe.method_registry.Method.step` gives it: ``"fixed"``, ``"adaptive"`` or ``"exact"``.
"""

from __future__ import annotations

__all__ = ["remedy"]


def remedy(kind: str, step=None, rtol=None) -> str:
    """What to change after a failure of a method of this ``kind``.

    A fixed step: a smaller step, or the adaptive method; DOP853 (adaptive): a tighter rtol (its
    step is its own); the exact flow: nothing of the integrator's (the model's parameters).

    >>> remedy("fixed", step=0.5)
    'use a smaller step (now 0.5 s) or dop853'
    >>> remedy("adaptive", rtol=1e-6)
    'tighten rtol (now 1e-06), or shorten the run'
    """
    if kind == "adaptive":
        return f"tighten rtol{f' (now {rtol:.3g})' if rtol else ''}, or shorten the run"
    if kind == "exact":
        return "the exact flow has no step to change: check the model's parameters"
    return f"use a smaller step{f' (now {step:.3g} s)' if step else ''} or dop853"
