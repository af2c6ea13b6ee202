"""How rotframe compiles its kernels: one numba configuration for every layer.

``jit_kernel`` compiles with ``cache=True`` (on disk, reused by later processes),
``error_model="numpy"`` (a division by zero gives inf or nan, which the drivers report
as a non-finite state, instead of raising; it also lets numba drop bounds and reference
bookkeeping in small inlined functions) and ``nogil=True`` (ensembles run blocks of
particles on threads).

``jit_internal`` is the same for a kernel that only compiled code calls (a force, a
step, a schedule reader that takes the packed model or a state tuple). numba builds no
CPython entry point for it (``no_cpython_wrapper``, ``no_cfunc_wrapper``): that entry
point unboxes every argument from Python objects, and for a kernel that takes the
19-field packed model it is most of the kernel's code, and so of the time a first run
spends compiling it (a three-line kernel: 524 lines of LLVM IR with it, 25 without;
its compile 0.2 s -> 0.03 s). Called from Python, such a kernel raises
`TypeError` (numba alone would crash the interpreter); its ``py_func`` is the
plain Python function.
"""

from __future__ import annotations

import functools
import hashlib
import os

from numba import njit
from numba.core import caching
from numba.core.registry import CPUDispatcher

__all__ = ["jit_kernel", "jit_internal", "jit_uncounted", "jit_llvm_inline", "jit_inline", "inlined", "uncounted", "bound",
           "CompiledOnlyDispatcher", "source_fingerprint", "global_names", "load_cached"]

#: The package's folder: a kernel defined in a file below it is cached with `source_fingerprint` as its stamp.
PACKAGE_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


@functools.cache
def source_fingerprint() -> bytes:
    """SHA-256 of every Python source file of the package (their paths and contents), made once a process.

    numba stamps a kernel's disk cache with its own file's contents alone, so a kernel whose callee
    lives in another file (the engine's entry in ``engine.py``, its equations in ``models.py``) would
    load stale machine code after that file changed: in a checkout being edited, or in an install
    upgraded over an old cache. Every rotframe kernel is stamped with this fingerprint instead
    (`_StampedByPackage`): any change to the package's sources makes each kernel compile once again.
    Reading the sources (about 1.4 MB) takes a few milliseconds.
    """
    digest = hashlib.sha256()
    for folder, subfolders, files in os.walk(PACKAGE_DIR):
        subfolders[:] = sorted(d for d in subfolders if d != "__pycache__")
        for name in sorted(files):
            if name.endswith(".py"):
                path = os.path.join(folder, name)
                digest.update(os.path.relpath(path, PACKAGE_DIR).encode())
                with open(path, "rb") as f:
                    digest.update(f.read())
    return digest.digest()


def _in_package(py_file) -> bool:
    return os.path.abspath(py_file).startswith(PACKAGE_DIR + os.sep)


class _StampedByPackage:
    """A numba cache locator for rotframe's own kernels: numba's, with `source_fingerprint` as the stamp."""

    def get_source_stamp(self):
        return source_fingerprint()

    @classmethod
    def from_function(cls, py_func, py_file):
        if not _in_package(py_file):
            return None  # a kernel of another package (a user's): numba's own locators
        return super().from_function(py_func, py_file)


class _UserProvided(_StampedByPackage, caching.UserProvidedCacheLocator):
    """``NUMBA_CACHE_DIR``, where it is set."""


class _InTree(_StampedByPackage, caching.InTreeCacheLocator):
    """``__pycache__`` beside the source, where it is writable."""


class _UserWide(_StampedByPackage, caching.UserWideCacheLocator):
    """numba's user-wide cache folder otherwise."""


def _install_locators():
    """Put rotframe's locators first in numba's list (once); kernels of other packages pass through them."""
    classes = caching.CacheImpl._locator_classes
    if _UserProvided not in classes:
        classes[:0] = [_UserProvided, _InTree, _UserWide]


_install_locators()

#: The decorator of every compiled kernel that reports failures as non-finite numbers.
jit_kernel = njit(cache=True, error_model="numpy", nogil=True)

_jit_without_entry_point = njit(cache=True, error_model="numpy", nogil=True, no_cpython_wrapper=True,
                                no_cfunc_wrapper=True)


class CompiledOnlyDispatcher(CPUDispatcher):
    """A numba dispatcher compiled without a CPython entry point: callable from compiled code only."""

    def __call__(self, *args, **kwargs):
        raise TypeError(f"{self.py_func.__module__}.{self.py_func.__qualname__} is a kernel for compiled code "
                        f"only (it has no Python entry point); call its .py_func from Python")


def jit_internal(func):
    """`jit_kernel` for a kernel called only from compiled code (see the module docstring)."""
    dispatcher = _jit_without_entry_point(func)
    dispatcher.__class__ = CompiledOnlyDispatcher
    return dispatcher


_jit_without_reference_counts = njit(cache=True, error_model="numpy", nogil=True, no_cpython_wrapper=True,
                                     no_cfunc_wrapper=True, _nrt=False)
#: numba's options of a kernel called from Python without reference counts (its caller owns every array): the
#: engine's loops and the trajectory tier's entry points (`rotframe.problem.engine`, `rotframe.numerics.dop853_loop`)
ENTRY_OPTIONS = {"cache": True, "error_model": "numpy", "nogil": True, "_nrt": False, "no_cfunc_wrapper": True}


def jit_uncounted(func):
    """`jit_internal` without numba's reference counting (NRT): for hot loops over arrays their caller owns.

    numba counts the references to every array a function holds (an atomic add and a call at each
    binding and at each exit); on a loop whose functions take many arrays, that was measured to
    cost more than the arithmetic. Such a kernel may not allocate an array; it may index, slice
    and pass the arrays it is given, which live in its caller for the whole call.
    """
    dispatcher = _jit_without_reference_counts(func)
    dispatcher.__class__ = CompiledOnlyDispatcher
    return dispatcher


#: A kernel that numba inlines into each caller (its IR, before typing): for small functions on a hot path,
#: and for those that take first-class functions (a call across which one is passed costs some 20 ns).
jit_inline = njit(inline="always", error_model="numpy", nogil=True)


def jit_llvm_inline(func):
    """`jit_uncounted`, compiled once on its own and inlined by LLVM into each compiled caller (``forceinline``).

    The machine code of an inlined call, without numba's IR inlining (`jit_inline`): numba inlines
    by running its passes over the callee's IR again at every call site, which for a right-hand
    side that inlines its own helpers cost more of a first compile than the caller's own code.
    LLVM inlines the compiled function when it optimises the caller, for a fraction of that.
    """
    dispatcher = njit(cache=True, error_model="numpy", nogil=True, no_cpython_wrapper=True, no_cfunc_wrapper=True,
                      _nrt=False, forceinline=True)(_copy(func, "llvm_inline"))
    dispatcher.__class__ = CompiledOnlyDispatcher
    return dispatcher


def _copy(func, suffix):
    """``func`` as a new function object named ``<qualname>.<suffix>``, for a copy compiled with other flags.

    numba's disk cache knows a function by its file, qualified name and bytecode, not by the flags it
    was compiled with: a copy of a cached kernel compiled with other flags (no reference counts,
    inlined by LLVM) under the same name would load the other's machine code from the cache.
    """
    import types

    clone = types.FunctionType(func.__code__, func.__globals__, func.__name__, func.__defaults__, func.__closure__)
    clone.__qualname__ = f"{func.__qualname__}.{suffix}"
    clone.__module__ = func.__module__
    clone.__doc__ = func.__doc__
    return clone


def bound(template, name, **names):
    """A copy of the function ``template`` named ``name`` that reads ``names`` as its globals.

    How a loop is compiled for a system's functions (`rotframe.numerics.dop853_loop`, the engine's
    variants, the GPU's kernels): the template reads them as global names, which numba freezes as
    constants (direct calls, pruned branches). Not as a closure's variables: numba's disk cache
    keys a closure by a pickle of its cells, and a numba function pickles with a random id of its
    process, so a loop that closes over one is compiled again in every process (measured: the
    heavy top's DOP853 loop, 2.2 s each run). A copy's globals are not in the key; its name is
    (the cache file), so each system's copy is named apart, and the package's fingerprint stamps
    it (`source_fingerprint`).
    """
    import types

    clone = types.FunctionType(template.__code__, dict(template.__globals__, **names), name, template.__defaults__,
                               template.__closure__)
    clone.__qualname__ = name
    clone.__module__ = template.__module__
    clone.__doc__ = template.__doc__
    return clone


def uncounted(kernel):
    """A copy of compiled ``kernel`` without reference counting (`jit_uncounted`), for callers that are so too.

    The same Python function, compiled again: a counted kernel called from an uncounted loop
    still counts the references to its array arguments, atomically, at every call.
    """
    return jit_uncounted(_copy(kernel.py_func, "uncounted"))


def inlined(kernel):
    """A copy of compiled ``kernel`` that numba inlines into each caller (its IR, before typing).

    For a kernel whose callers are few and large: a first run compiles one function less.
    """
    return njit(inline="always", error_model="numpy", nogil=True)(kernel.py_func)


def load_cached(dispatcher, signature) -> bool:
    """Whether ``dispatcher`` was found in numba's disk cache for ``signature`` (then it is loaded), never compiling.

    numba's `Dispatcher.compile` loads from the cache or compiles; this is its first half alone
    (numba's own calls), so that a caller can tell a loop it may load from one it would have to
    compile: a long run's inlined loop (`rotframe.problem.inlined`), the engine's loop before a
    first run (`rotframe.problem.tiers`). Any failure reads as "not in the cache".

    ``signature`` is the one the kernel was compiled with: numba keys its cache on it as given, so a
    signature with its return type (``float64(int64)``) and its argument types alone (``(int64,)``) are
    two entries.
    """
    from numba.core.compiler_lock import global_compiler_lock

    try:
        with global_compiler_lock:
            cres = dispatcher._cache.load_overload(signature, dispatcher.targetctx)
            if cres is None:
                return False
            dispatcher._cache_hits[signature] += 1  # numba's count of loads, as its own compile keeps it
            dispatcher.targetctx.insert_user_function(cres.entry_point, cres.fndesc, [cres.library])
            dispatcher.add_overload(cres)
    except Exception:  # noqa: BLE001 -- numba's internals changed, or a damaged entry: compile instead, if at all
        return False
    return True


def global_names(code) -> set:
    """Every global name ``code`` (and the code objects nested in it) may read: what a copy of a compiled function
    rebinds (`rotframe.particles.gpu.device_function`, `rotframe.problem.inlined`) and what a user function's
    fingerprint reads (`rotframe.problem.callables.fingerprint`)."""
    import types

    names = set(code.co_names)
    for const in code.co_consts:
        if isinstance(const, types.CodeType):
            names |= global_names(const)
    return names
