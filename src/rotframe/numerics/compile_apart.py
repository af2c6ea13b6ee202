"""A kernel compiled in a second process while this one compiles another: a first compile on two cores.

numba compiles one function at a time in a process (its compiler lock, and the GIL). Where a first
run must compile two kernels that do not call each other (the trajectory tier's trajectory loop,
and its stages and right-hand side, which the loop calls at their addresses:
`rotframe.problem.dop853_split.trajectory_tier`), `CompiledApart` has a second process compile one of
them into numba's disk cache while this process compiles the other; this process then loads it
from the cache (`rotframe.numerics.compiled.load_cached`), as any later process would.

The second process is made only where this one may run on two cores or more
(``os.sched_getaffinity``), in one of two ways:

* **forked** (``os.fork``) where that is safe: on Linux, from the main thread, with no other
  Python thread in the process, and numba's compiler lock held across the fork (so no lock that
  the child's compile takes is held by a thread that the child lacks). The child has this
  process's modules and numba already started, so it compiles at once; it writes nothing but
  numba's cache (its standard output and error go to ``os.devnull``) and ends with ``os._exit``.
  Measured on the 2-core reference machine (a first long run, 2026-12-01): the tier's compile
  took 2.1 s where a new interpreter took 2.9 s (its imports and numba's start, 0.75 s) and one
  process 3.8 s.
* **a new interpreter** (``sys.executable``) otherwise (a notebook's kernel, a Dask worker, other
  threads): it imports rotframe from the same place as this process, inherits the environment and
  so writes to the same caches (``NUMBA_CACHE_DIR``).

Whatever goes wrong there (no spare core, no process to start, a failure in the child, a child
that takes longer than `TIMEOUT_S`, a cache that cannot be written) ends in this process
compiling the kernel itself: the same machine code, later.

**Begun ahead** (`begin`). A run that will likely compile a kernel later, after work of its own on
one core (a problem's functions to compile, then a first call as plain Python:
`rotframe.problem.tiers`), may begin that kernel's second process before that work; the `made` that
needs it adopts the process instead of starting one. A process no `made` adopts runs on, for a later
run of this process to adopt (a short first run leaves it; a long one after it finds its kernels
compiled), or ends with its compile; this process stops any still running as it exits
(`stop_begun`). Such a process runs niced (`AHEAD_NICE`), so that it takes the cores this process
leaves idle and slows this one's own work less: a first short run of a spring, which begins two and
does not use them, took 1.09 to 1.26 of its time without them in a quiet hour (0.40 to 0.45 s against
0.34 to 0.39 s; at the same priority 1.35 to 1.59), 1.18 to 1.61 in a busier one, on the 2-core
reference machine, 2026-12-02. Adopted, it is put back at this process's priority where this one may
raise it (`CompiledApart.hurry`): under other load a niced process compiles slowly, and an unprivileged
process may not raise it back.
"""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time

__all__ = ["CompiledApart", "made", "is_made", "begin", "begun", "stop_begun", "spare_core", "TIMEOUT_S", "AHEAD_NICE"]

#: seconds the second process may take, from its start, before this one compiles the kernel itself
TIMEOUT_S = 120.0
#: a new interpreter's work: ``function(*args)`` of ``module``, each argument a string
_CHILD = ("import importlib, os, sys; n = int(sys.argv[1]); n and hasattr(os, 'nice') and os.nice(n); "
          "getattr(importlib.import_module(sys.argv[2]), sys.argv[3])(*sys.argv[4:])")


def spare_core() -> bool:
    """Whether this process may run on two cores or more (a second process would compile beside it)."""
    try:
        return len(os.sched_getaffinity(0)) >= 2
    except AttributeError:  # no affinity on this platform
        return (os.cpu_count() or 1) >= 2


def _may_fork() -> bool:
    """Whether this process may fork its compiler (module docstring): Linux, the main thread, no other Python thread."""
    return (sys.platform.startswith("linux") and hasattr(os, "fork") and threading.active_count() == 1
            and threading.current_thread() is threading.main_thread())


class CompiledApart:
    """``module.function(*args)`` run in a second process, which compiles a kernel into numba's cache.

    Use it around this process's own compile, then `load` the kernel::

        with CompiledApart("rotframe.problem.dop853_split", "compile_tier_trajectory", 0, 0, 6) as apart:
            stages.compile(signature)  # this process's share
        apart.load(trajectory, TRAJECTORY_ARGS[False])  # the other's: from the cache, or compiled here

    ``args`` are passed as strings. Leaving the block by an exception stops the second process.
    ``how`` says how it was made: ``"fork"``, ``"interpreter"``, or None (none was).
    """

    def __init__(self, module, function, *args, nice=0):
        self.call = (module, function, tuple(map(str, args)))
        self.nice = int(nice)
        self.how = None
        self._pid = None
        self._child = None
        self._started = 0.0

    def __enter__(self):
        if spare_core():
            self._started = time.monotonic()
            if _may_fork():
                self._fork()
            elif sys.executable:
                self._spawn()
        return self

    def __exit__(self, kind, value, traceback):
        if kind is not None:
            self.stop()
        return False

    def _fork(self):
        import warnings

        from numba.core.compiler_lock import global_compiler_lock

        with global_compiler_lock, warnings.catch_warnings():
            # Python 3.12 and later warn of a fork from a process with threads, counting the native ones (numpy's
            # BLAS pool): those take no part in the child's compile, and no other Python thread runs (`_may_fork`)
            warnings.simplefilter("ignore", DeprecationWarning)
            pid = os.fork()
        if pid == 0:  # the child: compile, and end without running this process's exit handlers
            code = 1
            try:
                quiet = os.open(os.devnull, os.O_RDWR)
                os.dup2(quiet, 1)
                os.dup2(quiet, 2)
                module, function, args = self.call
                if self.nice:
                    os.nice(self.nice)
                _run(module, function, *args)
                code = 0
            finally:
                os._exit(code)
        self._pid, self.how = pid, "fork"

    def _spawn(self):
        import rotframe

        env = dict(os.environ)
        here = os.path.dirname(os.path.dirname(os.path.abspath(rotframe.__file__)))
        env["PYTHONPATH"] = os.pathsep.join(p for p in (here, env.get("PYTHONPATH")) if p)
        module, function, args = self.call
        try:
            self._child = subprocess.Popen([sys.executable, "-c", _CHILD, str(self.nice), module, function, *args],
                                           env=env, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                           stderr=subprocess.DEVNULL)
        except OSError:
            return
        self.how = "interpreter"

    def _wait(self) -> bool:
        """Wait for the second process until `TIMEOUT_S` from its start: whether it ended well."""
        deadline = self._started + TIMEOUT_S
        if self._child is not None:
            try:
                return self._child.wait(timeout=max(0.0, deadline - time.monotonic())) == 0
            except subprocess.TimeoutExpired:
                return False
        while time.monotonic() < deadline:
            pid, status = os.waitpid(self._pid, os.WNOHANG)
            if pid:
                self._pid = None
                return os.waitstatus_to_exitcode(status) == 0
            time.sleep(0.005)
        return False

    def hurry(self):
        """The second process back at this process's priority, where this one may raise it (a process begun ahead
        runs niced, `AHEAD_NICE`; this one now waits for it): else it stays as it is."""
        pid = self._pid if self._pid is not None else getattr(self._child, "pid", None)
        if pid is not None and self.nice:
            try:
                os.setpriority(os.PRIO_PROCESS, pid, os.getpriority(os.PRIO_PROCESS, 0))
            except (OSError, AttributeError):  # no privilege to raise a priority, or no priorities on this platform
                pass

    def stop(self):
        """Stop the second process, if it still runs."""
        if self._child is not None and self._child.poll() is None:
            self._child.kill()
            self._child.wait()
        if self._pid is not None:
            import signal

            try:
                os.kill(self._pid, signal.SIGKILL)
                os.waitpid(self._pid, 0)
            except (ProcessLookupError, ChildProcessError):
                pass
            self._pid = None

    def load(self, dispatcher, signature) -> bool:
        """``dispatcher`` for ``signature``: loaded from the cache the second process wrote, else compiled here.

        Returns whether the second process's compile was used.
        """
        return self.load_all([(dispatcher, signature)])

    def load_all(self, kernels) -> bool:
        """`load` of each ``(dispatcher, signature)`` of ``kernels``, which the second process compiled together:
        whether its compile was used for every one."""
        from rotframe.numerics.compiled import load_cached

        done = self.how is not None and self._wait()
        self.stop()
        used = True
        for dispatcher, signature in kernels:
            if not (done and load_cached(dispatcher, signature)):
                dispatcher.compile(signature)
                used = False
        return used


def _run(module, function, *args):
    import importlib

    getattr(importlib.import_module(module), function)(*args)


#: the niceness of a process begun ahead (`begin`): below this process's, so that it takes the cores this process
#: leaves idle and this one's own work (a problem's functions to compile, a run as plain Python) goes at its own pace
AHEAD_NICE = 10
#: the second processes begun ahead (`begin`) that no `made` has adopted yet, by ``(module, function, args)``
_BEGUN: dict = {}


def begin(module, function, *args) -> bool:
    """Begin ``module.function(*args)`` in a second process now, for a later `made` to adopt (module docstring).

    Nothing where this process has no spare core, or where no second process could be made (`CompiledApart`). The
    caller is sure the kernel is not in numba's cache. Returns whether a process was begun (or had been)."""
    key = (module, function, tuple(map(str, args)))
    if key not in _BEGUN:
        apart = CompiledApart(module, function, *args, nice=AHEAD_NICE).__enter__()
        if apart.how is None:
            return False
        if not _BEGUN:
            import atexit

            atexit.register(stop_begun)  # once a process (`stop_begun` leaves nothing to stop at a second call)
        _BEGUN[key] = apart
    return True


def begun(module, function, *args) -> bool:
    """Whether a process begun ahead for ``module.function(*args)`` (`begin`) waits for a `made` to adopt it."""
    return (module, function, tuple(map(str, args))) in _BEGUN


def stop_begun():
    """Stop every second process begun ahead (`begin`) that no `made` adopted, and reap those that ended: at this
    process's exit."""
    while _BEGUN:
        _BEGUN.popitem()[1].stop()


def is_made(kernel, signature) -> bool:
    """Whether ``kernel`` is made for ``signature``: in this process already, or loaded now from numba's cache (under
    the key numba saved it, the signature as compiled, `rotframe.numerics.compiled.load_cached`)."""
    from rotframe.numerics.compiled import load_cached

    return tuple(getattr(signature, "args", signature)) in kernel.overloads or load_cached(kernel, signature)


def made(kernels, module, load_only=False, apart=()) -> bool:
    """Load ``kernels`` (``[(dispatcher, signature), ...]``) from numba's cache, compiling those that are not there;
    False, compiling nothing, where ``load_only`` and one is not.

    A kernel made in this process is not loaded again: a run in the engine's trajectory tier asks whether the
    whole loop is made (`rotframe.problem.tiers.loop_is_compiled`), which would otherwise load the tier's kernels
    from the disk again each time (some 10 ms a run); the kernels are made once a process for that
    (``functools.cache`` where they are built, `rotframe.problem.dop853_split`).

    ``apart`` names, for some of them by index, the function of ``module`` that compiles it in another process
    (``{index: (name, its arguments)}``; one function may compile several, which share callees). Where more than one
    such function or kernel of this process's own is to compile, those functions run in processes of their own while
    this one compiles the rest (`rotframe.numerics.compile_apart`), then load what they compiled from the cache; a
    process begun ahead for one of them (`begin`) is adopted, however many are to compile. Each kernel is then closed
    to new compiles.
    """
    from contextlib import ExitStack

    todo = [k for k, (kernel, sig) in enumerate(kernels) if not is_made(kernel, sig)]
    if todo and load_only:
        return False
    key = {k: (module, apart[k][0], tuple(map(str, apart[k][1]))) for k in apart}  # as `begin` keys it
    groups: dict = {}  # each function of ``module`` to run apart -> the kernels to make that it compiles
    for k in todo:
        if k in key:
            groups.setdefault(key[k], []).append(k)
    for function in set(key.values()) - set(groups):
        if function in _BEGUN:  # begun ahead, and what it compiles is made: it has ended, or is about to
            _BEGUN.pop(function).stop()
    adopted = {function: _BEGUN.pop(function) for function in groups if function in _BEGUN}
    here = [k for k in todo if k not in apart]
    rest = [function for function in groups if function not in adopted]
    away = rest if len(here) + len(rest) > 1 else []
    if away and not here:
        away = away[:-1]  # one compiles here
    with ExitStack() as stack:
        for child in adopted.values():
            stack.callback(child.stop)  # stopped where this process's compile fails (`CompiledApart.__exit__`)
            child.hurry()
        children = {function: stack.enter_context(CompiledApart(function[0], function[1], *function[2]))
                    for function in away}
        children.update(adopted)
        for k in todo:
            if key.get(k) not in children:
                kernels[k][0].compile(kernels[k][1])
        for function, child in children.items():
            child.load_all([kernels[k] for k in groups[function]])
    for kernel, _ in kernels:
        kernel.disable_compile()
    return True
