"""A problem's own functions, compiled once and cached on disk: the module of its glue.

The engine that steps every problem is compiled once (`rotframe.problem.engine`); what a problem
compiles is its glue (`rotframe.problem.glue`): the few small functions, of fixed signatures,
that call the user's. numba caches a compiled function under its module's file, so each problem's
glue is a small module of its own: a header binds the user's functions to global names (read
from `ENTRIES` when the module is imported), and the glue follows. Its file name is a
fingerprint of everything it is made of (`rotframe.problem.callables.fingerprint`), so the
same functions find the same file, compiled, in the next process, and an edited function makes
a new one. The glue's functions have explicit signatures, so they compile (or load from
numba's cache) as the module is imported.

Where the files go: ``$ROTFRAME_CACHE_DIR``, else ``$XDG_CACHE_HOME/rotframe/problems``, else
``~/.cache/rotframe/problems``; a folder that cannot be written falls back to a temporary one,
and where neither can be written the driver compiles in memory (once per process), with a note.
The files are written through `rotframe.files` (atomic). A damaged entry (a source that is not
UTF-8, a folder in its place, numba's cache files truncated or garbage) is dropped and rebuilt,
with a note (`is_cache_damage`); a cache never fails a run.

With ``jit=False`` the same source runs as plain Python (no numba at all), with the engine's
(`rotframe.numerics.plain`): slow, for a function numba cannot compile.
"""

from __future__ import annotations

import copy
import functools
import hashlib
import importlib.util
import itertools
import os
import shutil
import sys
import tempfile
import types
from pathlib import Path

__all__ = ["ENTRIES", "cache_dir", "build_module", "is_cache_damage", "Driver"]

#: fingerprint -> {global name: function} for the generated modules of this process
ENTRIES: dict[str, dict] = {}


def cache_dir(notes=None) -> Path | None:
    """The folder of the generated driver modules (created if missing), or None when none can be written.

    The configured folder, else a temporary one; each must take a real write (a probe of a few
    kilobytes through `rotframe.files`, so that a full disk shows), tried once per folder and
    process (a later failure to write a driver is caught where it is written). None means no
    caching: the drivers compile in memory, once per process, and ``notes`` says why.
    """
    base, fallback = _folders(os.environ.get("ROTFRAME_CACHE_DIR"), os.environ.get("XDG_CACHE_HOME"),
                              os.environ.get("HOME"))
    for folder in (base, fallback):
        if _writable(folder):
            return folder
    if notes is not None:
        notes.append(f"the compiled-driver cache cannot be written ({base} nor {fallback}): the driver was "
                     "compiled in memory, not cached")
    return None


@functools.lru_cache(maxsize=None)
def _folders(env, xdg, home) -> tuple[Path, Path]:
    """The configured cache folder and the temporary one, for the environment's values (``home``: HOME, which
    `pathlib.Path.home` reads), made once for each: making the paths cost more than a short run's integration."""
    if env:
        base = Path(env)
    else:
        base = (Path(xdg) if xdg else Path.home() / ".cache") / "rotframe" / "problems"
    fallback = Path(tempfile.gettempdir()) / f"rotframe-problems-{os.getuid() if hasattr(os, 'getuid') else 0}"
    return base, fallback


@functools.lru_cache(maxsize=None)
def _writable(folder: Path) -> bool:
    from rotframe.files import OutputError, write_bytes_atomic

    try:
        folder.mkdir(parents=True, exist_ok=True)
        probe = folder / f".probe-{os.getpid()}"
        write_bytes_atomic(probe, b"rotframe driver cache probe\n" * 256, what="driver cache probe")
        probe.unlink()
        return True
    except (OSError, OutputError):
        return False


def _cached_text(path: Path, notes) -> str | None:
    """The driver file's text, or None: missing, or damaged (not UTF-8, a folder in its place) and dropped."""
    try:
        return path.read_text(encoding="utf-8")
    except FileNotFoundError:
        return None
    except (OSError, UnicodeDecodeError) as exc:  # a damaged entry: dropped, then written anew
        _remove(path)
        notes.append(f"a damaged compiled-driver cache entry ({path.name}: {type(exc).__name__}) was dropped and "
                     "rebuilt")
        return None


def _remove(path: Path) -> None:
    try:
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path, ignore_errors=True)
        else:
            path.unlink()
    except OSError:
        pass


def is_cache_damage(exc: BaseException) -> bool:
    """An exception raised while numba loaded or saved a driver's cache (truncated or garbage files, a full disk)."""
    import pickle

    if isinstance(exc, pickle.UnpicklingError):
        return True
    tb = exc.__traceback__
    while tb is not None:
        if tb.tb_frame.f_code.co_filename.replace("\\", "/").endswith("numba/core/caching.py"):
            return True
        tb = tb.tb_next
    return False


class Driver:
    """A problem's glue module and the engine that runs it.

    ``advance``, ``start_events`` and ``energies`` are the engine's entry points
    (`rotframe.problem.engine`: ``advance`` runs the problem's variant of the loop; their plain Python remakes with ``compiled=False``,
    `rotframe.numerics.plain`), which take `functions` as their last argument.
    """

    def __init__(self, module, compiled=True):
        from rotframe.problem import engine

        self.module = module
        self.compiled = compiled
        # the variant of the engine's loop that a problem needs is chosen (and compiled, once) at its first call
        self.advance = engine.advance if compiled else functools.partial(engine.advance, compiled=False)

    def trajectory_tier(self):
        """This driver with the engine's trajectory tier as its loop (`rotframe.problem.dop853_split.trajectory_tier`:
        each trajectory compiled, the loop over the particles as Python), its functions' addresses the same."""
        from rotframe.problem import engine

        made = copy.copy(self)
        made.advance = functools.partial(engine.advance, compiled=engine.TRAJECTORY_TIER)
        return made

    def _entry(self, name):
        """The engine's entry point ``name``, compiled when first needed (or its plain Python remake)."""
        from rotframe.problem import engine

        kernel = getattr(engine, name)
        if not self.compiled:
            from rotframe.numerics.plain import plain

            return plain(kernel)
        return engine.ready(kernel)

    @property
    def start_events(self):
        return self._entry("start_events")

    @property
    def energies(self):
        return self._entry("energies")

    def _own(self, name, stub, signature):
        """The module's function ``name`` (else ``stub``): its address (`rotframe.problem.calls`), or itself in plain Python."""
        found = getattr(self.module, name, None)
        function = stub if found is None else found
        if not self.compiled:
            return getattr(function, "py_func", function)
        return self._address(function, signature)

    @staticmethod
    def _address(function, signature):
        """``function``'s address (`rotframe.problem.calls.address`), compiled for ``signature`` if it is not yet."""
        from rotframe.problem.calls import address

        known = _ADDRESSES.get(id(function))
        if known is None or known[0] is not function:  # each function's address looked up once a process
            if not function.signatures:
                function.compile(signature)
            known = _ADDRESSES[id(function)] = (function, address(function, signature))
        return known[1]

    def functions(self, prob):
        """What the engine calls for the problem ``prob`` (`rotframe.problem.signatures.FUNCTIONS`): terms, event,
        omega, origin, and the engine's evaluator of a varying frame or origin, compiled only where ``prob`` has one
        (else 0: a problem in a steady frame never compiles it)."""
        from rotframe.problem import signatures as sg, stubs, varying as vary

        kinds = (int(prob[3]), int(prob[6]))
        if not vary.needs_varying(kinds):
            varying = 0
        elif self.compiled:  # the evaluator of the problem's own kinds alone (`varying_into_for`)
            varying = self._address(vary.varying_into_for(kinds), sg.VARYING_SIG)
        else:
            from rotframe.numerics.plain import plain

            varying = plain(vary.varying_into_for(kinds))
        return (self._own("terms", stubs.no_terms, sg.TERMS_SIG), self._own("event", stubs.no_event, sg.EVENT_SIG),
                self._own("omega", stubs.no_vector, sg.VECTOR_SIG), self._own("origin", stubs.no_vector, sg.VECTOR_SIG),
                varying)

    def potential(self):
        from rotframe.problem import signatures as sg, stubs

        return self._own("potential", stubs.no_potential, sg.POTENTIAL_SIG)


_HEADER_COMPILED = """\
import math
import numpy as np
from numba import njit
from rotframe.problem.codegen import ENTRIES as _ENTRIES
from rotframe.problem.readonly import readonly
from rotframe.problem.signatures import TERMS_SIG, EVENT_SIG, POTENTIAL_SIG, VECTOR_SIG


def jit(signature):
    # called by address alone (rotframe.problem.calls): no CPython or C entry point to build
    return njit(signature, cache={cache}, error_model="numpy", nogil=True, no_cpython_wrapper=True,
                no_cfunc_wrapper=True, forceinline=True)


# compiled where first asked for (the potential: only the compiled energy diagnostic reads it, `Driver._own`)
jit_lazy = njit(cache={cache}, error_model="numpy", nogil=True, no_cpython_wrapper=True, no_cfunc_wrapper=True,
                forceinline=True)
"""

_HEADER_PLAIN = """\
import math
import numpy as np
from rotframe.problem.codegen import ENTRIES as _ENTRIES
from rotframe.problem.callables import readonly_view as readonly
from rotframe.problem.signatures import TERMS_SIG, EVENT_SIG, POTENTIAL_SIG, VECTOR_SIG


def jit(signature):
    return lambda f: f


def jit_lazy(f):
    return f

"""


def build_module(kind: str, key_material, functions: dict, glue: str, *, compiled: bool, notes=None):
    """The generated module for one problem: imported from the cache (compiled) or built in memory.

    Parameters
    ----------
    kind : str
        ``"particle"`` or ``"body"`` (part of the module's name).
    key_material : str or None
        The fingerprints of the functions and the structure; with the sources, it names the file.
        None: a function reads a value that cannot be fingerprinted
        (`rotframe.problem.callables.Unfingerprintable`), so the driver is compiled for this call
        alone, in memory, never cached or reused.
    functions : dict or callable
        Global name -> the user's function (a numba dispatcher when ``compiled``, else plain Python),
        or a function that makes that dict (called only when the module is not built in this process).
    glue : str
        The problem's own functions (`rotframe.problem.glue`), compiled as the module is imported.
    notes : list, optional
        Receives a line for what the cache could not do (a damaged entry rebuilt, no cache
        writable): never a failure, the driver is then compiled in memory.
    """
    notes = [] if notes is None else notes
    folder = cache_dir(notes) if compiled and key_material is not None else None
    cached = folder is not None
    head = _HEADER_COMPILED.format(cache=cached) if compiled else _HEADER_PLAIN
    if not cached:
        key_material = f"uncached {os.getpid()} {next(_UNCACHED)}"
    from rotframe.numerics.compiled import source_fingerprint

    # the package's sources in the name too: the glue's machine code holds rotframe's helpers, which numba's
    # own stamp (the glue file's text) does not see
    digest = hashlib.sha256((key_material + glue + head).encode() + source_fingerprint()).hexdigest()[:24]
    name = f"rotframe_{kind}_problem_{digest}"
    if name in sys.modules:  # built in this process already: the user's functions are not compiled again
        return sys.modules[name]
    functions = functions() if callable(functions) else functions
    ENTRIES[digest] = functions
    binding = "".join(f"{g} = _ENTRIES[{digest!r}][{g!r}]\n" for g in functions)
    text = '"""Generated by rotframe.problem.codegen for one problem; safe to delete."""\n' + head + binding + glue
    if cached:
        from rotframe.files import OutputError, write_text_atomic

        path = folder / f"{name}.py"
        if _cached_text(path, notes) != text:
            try:
                write_text_atomic(path, text, what="compiled-driver cache entry")
            except OutputError as exc:
                notes.append(f"the compiled-driver cache could not be written ({exc}): the driver was compiled in "
                             "memory, not cached")
                return build_module(kind, None, functions, glue, compiled=compiled, notes=notes)
        try:
            return _import(name, path)
        except Exception as exc:
            if not is_cache_damage(exc):
                raise
            _drop_files(name, path)  # numba's cache of it is damaged: dropped, written and compiled anew
            notes.append(f"the compiled-driver cache of this problem was damaged ({type(exc).__name__}): dropped and "
                         "rebuilt")
            write_text_atomic(path, text, what="compiled-driver cache entry")
            return _import(name, path)
    module = types.ModuleType(name)
    exec(compile(text, f"<{name}>", "exec"), module.__dict__)  # nothing on disk
    return module


def _import(name, path):
    """Import the module at ``path`` as ``name`` (its functions compile, or load from numba's cache, as it runs)."""
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        sys.modules.pop(name, None)
        raise
    return module


def _drop_files(name, path):
    for cached in (path.parent / "__pycache__").glob(f"{name}.*"):
        _remove(cached)
    _remove(path)


#: id -> (compiled function, its address): the glue's and the stubs' addresses, looked up once
_ADDRESSES: dict[int, tuple] = {}

#: numbers the uncached drivers of this process (each its own module)
_UNCACHED = itertools.count()
