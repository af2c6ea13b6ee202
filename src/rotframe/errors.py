"""Exceptions raised by rotframe.

Every error a user can cause is a [`RotframeError`][rotframe.errors.RotframeError]. The ones that mean
"your input was wrong" are also `ValueError`, so code that already
catches ``ValueError`` keeps working; the command line turns them into exit
code 2 with one line of text. [`IntegrationError`][rotframe.errors.IntegrationError] is a numerical failure
(exit code 3) and carries the simulated time that was reached.
"""

from __future__ import annotations

import re

__all__ = [
    "RotframeError",
    "NotARotationError",
    "GimbalLockError",
    "ScenarioError",
    "IntegrationError",
    "RotframeWarning",
    "MissingExtraError",
]


#: The longest message an error keeps (characters): a value of a million numbers is cut, not printed.
MAX_MESSAGE = 600


def readable(message: str, limit: int = MAX_MESSAGE) -> str:
    """``message`` on one readable line: its line breaks (a numpy array's repr echoed back spans lines) made single
    spaces, and at most ``limit`` characters, the middle cut out and counted."""
    if "\n" in message:
        message = re.sub(r"\s*\n\s*", " ", message.strip())
    if len(message) <= limit:
        return message
    head, tail = message[:limit * 2 // 3], message[-(limit // 4):]
    return f"{head} ... [{len(message) - len(head) - len(tail)} characters cut] ... {tail}"


class RotframeError(Exception):
    """Base class of every error rotframe raises on purpose.

    The one door for messages: a message longer than `MAX_MESSAGE` characters
    (a huge value echoed back) is cut to a readable length here, for every subclass.
    """

    def __init__(self, *args):
        if args and isinstance(args[0], str):
            args = (readable(args[0]),) + args[1:]
        super().__init__(*args)


class NotARotationError(RotframeError, ValueError):
    """A matrix that should be a proper rotation is not (not orthogonal, or det != +1)."""


class GimbalLockError(RotframeError, ValueError):
    """Euler angles or their rates are not unique at a singular middle angle."""


class ScenarioError(RotframeError, ValueError):
    """A scenario file, parameter or command-line value is invalid.

    The message names the file or key, the offending value and what is allowed.
    """


class IntegrationError(RotframeError):
    """The integration failed (non-finite state, step-size collapse).

    Attributes
    ----------
    t_reached : float
        Simulated time (s) of the last good state.
    partial : object or None
        What was computed up to ``t_reached`` (a trajectory), so that nothing is lost.
    """

    def __init__(self, message: str, t_reached: float = float("nan"), partial=None):
        super().__init__(message)
        self.t_reached = t_reached
        self.partial = partial


class RotframeWarning(UserWarning):
    """A run's result should be read with care (an entry of ``Result.warnings``).

    ``rotframe.run`` emits one Python warning of this category for each entry of the
    result's ``warnings`` list (which stays), so that notebooks and scripts show them.
    Silence them with ``warnings.simplefilter("ignore", rotframe.RotframeWarning)``;
    turn them into errors with ``warnings.simplefilter("error", rotframe.RotframeWarning)``.
    """


class MissingExtraError(RotframeError, ImportError):
    """An optional dependency is not installed; the message names the extra that brings it.

    For example pictures need matplotlib, the ``plot`` extra
    (``pip install "rotframe[plot]"``). The command line exits with code 2.
    """
