"""A progress line on stderr (rate and time left), shown on a terminal only.

::

    with Progress("sweep", unit="rows") as bar:
        for ...:
            bar.update(done, total)

Nothing is written unless stderr is a terminal and the work has taken longer
than ``delay`` seconds, so pipes, logs and ``--json`` output never see it
(pass ``enabled=False`` for ``--json``). The line is redrawn at most every
``interval`` seconds and erased by `close`.
"""

from __future__ import annotations

import sys
import time

__all__ = ["Progress", "auto_bar", "progress_callback"]


class Progress:
    """One progress line for one piece of work.

    Parameters
    ----------
    label : str
        What is being done (``"run"``, ``"sweep"``).
    unit : str
        What ``done`` and ``total`` count (``"%"`` for fractions).
    enabled : bool
        False never draws (``--json``); True draws only when ``stream`` is a terminal.
    delay, interval : float
        Seconds before the first draw; seconds between redraws.
    stream : file, optional
        Default ``sys.stderr``.
    """

    def __init__(self, label="", unit="", *, enabled=True, delay=1.0, interval=0.2, stream=None, tty_only=True):
        self.stream = stream if stream is not None else sys.stderr
        try:
            tty = bool(self.stream.isatty())
        except (AttributeError, ValueError, OSError):
            tty = False
        self.enabled = bool(enabled) and (tty or not tty_only)
        self.label, self.unit = label, unit
        self.delay, self.interval = delay, interval
        self.start = time.monotonic()
        self.first = None  # (elapsed, fraction) at the first report: rate and time left are measured from there
        self._last = 0.0
        self._width = 0

    def __call__(self, fraction):
        """Callable form for code that reports a fraction in [0, 1]."""
        self.update(float(fraction), 1.0)

    def update(self, done, total):
        """Report ``done`` of ``total``; draws the line when due."""
        if not self.enabled:
            return
        now = time.monotonic()
        elapsed = now - self.start
        frac = min(max(done / total, 0.0), 1.0) if total else 0.0
        if self.first is None:
            # the time before the first report (loading, compiling kernels) says nothing about the rate
            self.first = (elapsed, frac)
        if elapsed < self.delay or (now - self._last < self.interval and done < total):
            return
        self._last = now
        t1, f1 = self.first
        span = elapsed - t1
        rate = (frac - f1) * (total or 0.0) / span if span > 0 else 0.0
        left = 0.0 if frac >= 1.0 else span * (1.0 - frac) / (frac - f1) if frac > f1 else float("nan")
        if self.unit == "%" or total == 1.0:
            count = f"{100 * frac:5.1f}%"
            speed = ""
        else:
            count = f"{done:.0f}/{total:.0f} {self.unit} ({100 * frac:.1f}%)"
            speed = f", {rate:.3g} {self.unit}/s"
        left_text = _duration(left) if left == left else "?"
        text = f"  {self.label + ': ' if self.label else ''}{count}{speed}, {_duration(elapsed)} elapsed, " \
               f"{left_text} left"
        pad = max(0, self._width - len(text))
        self._width = len(text)
        try:
            self.stream.write("\r" + text + " " * pad)
            self.stream.flush()
        except (OSError, ValueError):
            self.enabled = False

    def close(self):
        """Erase the line (if one was drawn)."""
        if self._width and self.enabled:
            try:
                self.stream.write("\r" + " " * self._width + "\r")
                self.stream.flush()
            except (OSError, ValueError):
                pass
        self._width = 0

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False


class _TqdmFraction:
    """A tqdm bar fed fractions in [0, 1] (``tqdm.auto``: a widget in Jupyter, text elsewhere)."""

    def __init__(self, tqdm, label):
        self._bar = tqdm(total=100, desc=label, unit="%", bar_format="{desc}: {percentage:5.1f}%|{bar}| [{elapsed}<{remaining}]")

    def __call__(self, fraction):
        self.update(float(fraction), 1.0)

    def update(self, done, total):
        frac = min(max(done / total, 0.0), 1.0) if total else 0.0
        self._bar.update(100.0 * frac - self._bar.n)

    def close(self):
        self._bar.close()


def auto_bar(label: str = "run"):
    """A progress bar that suits where it is drawn, fed fractions: ``bar(fraction)``, then ``bar.close()``.

    With tqdm installed (the ``notebook`` extra), ``tqdm.auto``'s bar: a widget in
    Jupyter, a text bar on a terminal. Without it, a `Progress` line on stderr,
    drawn on any stream (a notebook's stderr is no terminal).
    """
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return Progress(label, "%", delay=0.0, tty_only=False)
    return _TqdmFraction(tqdm, label)


def _duration(seconds: float) -> str:
    if seconds < 90:
        return f"{seconds:.1f} s"
    if seconds < 5400:
        return f"{seconds / 60:.1f} min"
    return f"{seconds / 3600:.1f} h"


def progress_callback(progress, label: str = "run"):
    """What ``progress=`` means in the Python API: True, a bar that suits where it is drawn (`auto_bar`);
    a callable, itself (fed the fraction done); None or False, none. Anything else: ScenarioError."""
    from rotframe.errors import ScenarioError

    if progress is True:
        return auto_bar(label)
    if progress is False or progress is None:
        return None
    if not callable(progress):
        raise ScenarioError(f"progress={progress!r}: expected a callable(fraction), True or None")
    return progress
