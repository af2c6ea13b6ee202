"""Did-you-mean suggestions for a mistyped name (one source for every error message that offers one)."""

from __future__ import annotations

import difflib

__all__ = ["did_you_mean"]


def did_you_mean(word: str, options, cutoff: float = 0.6) -> str:
    """``" (did you mean 'x'?)"`` for the closest of ``options`` to ``word``, or ``""`` if none is close.

    Parameters
    ----------
    word : str
        What was given.
    options : iterable of str
        What is allowed.
    cutoff : float
        `difflib.get_close_matches` similarity threshold in [0, 1].
    """
    close = difflib.get_close_matches(word, list(options), n=1, cutoff=cutoff)
    return f" (did you mean {close[0]!r}?)" if close else ""
