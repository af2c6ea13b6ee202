"""A kernel compiled in a second process (`rotframe.numerics.compile_apart`): forked, or a new interpreter where other
threads run, loaded from the cache it wrote; compiled here where there is no second core, where the child fails or
runs past its time; stopped where this process's own compile fails. Each case runs in a new process with an empty
numba cache, as a first run does."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
import time

import pytest

from rotframe.numerics.compile_apart import AHEAD_NICE

_KERNEL = textwrap.dedent('''
    import time
    from numba import njit

    @njit(cache=True)
    def kernel(x):
        return x * 2.0 + 1.0

    def compile_kernel():
        from numba import types
        kernel.compile((types.float64,))

    def compile_slowly():  # a compile that cannot have ended when this process asks for the kernel
        time.sleep(1.0)
        compile_kernel()

    def fail():
        raise RuntimeError("the child fails")

    def sleep():
        time.sleep(60.0)
''')

_DRIVER = textwrap.dedent('''
    import json, sys, threading, time
    from numba import types
    import apart_kernel
    from rotframe.numerics import compile_apart

    mode = sys.argv[1]
    if mode == "thread":  # another Python thread: no fork
        stop = threading.Event()
        threading.Thread(target=stop.wait, daemon=True).start()
    if mode == "one core":
        compile_apart.spare_core = lambda: False
    if mode == "time-out":
        compile_apart.TIMEOUT_S = 0.5
    function = {"fail": "fail", "time-out": "sleep", "raise": "sleep"}.get(mode, "compile_kernel")
    t0 = time.perf_counter()
    out = {}
    try:
        with compile_apart.CompiledApart("apart_kernel", function) as apart:
            if mode == "raise":
                raise KeyError("this process's own compile failed")
    except KeyError:
        out["stopped"] = apart._pid is None and (apart._child is None or apart._child.poll() is not None)
    else:
        out["used"] = apart.load(apart_kernel.kernel, (types.float64,))
        out["value"] = apart_kernel.kernel(3.0)
    out.update(how=apart.how, seconds=time.perf_counter() - t0)
    print(json.dumps(out))
''')


def _run(tmp_path, mode):
    (tmp_path / "apart_kernel.py").write_text(_KERNEL)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"), PYTHONPATH=str(tmp_path))
    out = subprocess.run([sys.executable, "-c", _DRIVER, mode], env=env, capture_output=True, text=True, timeout=300,
                         cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-2000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


needs_two_cores = pytest.mark.skipif(len(os.sched_getaffinity(0)) < 2, reason="one core: no second process is made")
linux = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="forks on Linux only")


@needs_two_cores
@linux
def test_a_single_threaded_process_forks_and_loads_what_the_child_compiled(tmp_path):
    out = _run(tmp_path, "fork")
    assert out == dict(out, how="fork", used=True, value=7.0)


@needs_two_cores
def test_with_other_threads_a_new_interpreter_compiles_it(tmp_path):
    out = _run(tmp_path, "thread")
    assert out == dict(out, how="interpreter", used=True, value=7.0)


def test_on_one_core_this_process_compiles_it(tmp_path):
    out = _run(tmp_path, "one core")
    assert out == dict(out, how=None, used=False, value=7.0)


@needs_two_cores
@pytest.mark.parametrize("mode", ["fail", "time-out"])
def test_a_child_that_fails_or_runs_past_its_time_is_replaced_by_a_compile_here(tmp_path, mode):
    out = _run(tmp_path, mode)
    assert out["how"] is not None and out["used"] is False and out["value"] == 7.0
    assert out["seconds"] < 30.0  # the time-out's child sleeps 60 s: it was stopped


@needs_two_cores
def test_a_failure_of_this_processs_compile_stops_the_child(tmp_path):
    out = _run(tmp_path, "raise")
    assert out["how"] is not None and out["stopped"] is True and out["seconds"] < 30.0


_KERNELS_CHILD = r"""
import json
from numba.core import event
from rotframe.numerics import compile_apart

made, load = [], compile_apart.CompiledApart.load_all  # each second process of a compile, as it was made
compile_apart.CompiledApart.load_all = lambda self, *args: made.append(self.how) or load(self, *args)
compiled = []


class Listener(event.Listener):
    def on_start(self, ev):
        compiled.append(ev.data["dispatcher"].py_func.__name__)

    def on_end(self, ev):
        pass


event.register("numba:compile", Listener())
from rotframe.particles import dop853_steady
from rotframe.problem import engine
from rotframe.problem.signatures import BODY, PARTICLE

dop853_steady.run_dop853_steady._make()
engine.variant(PARTICLE, "dop853", False)
engine.variant(BODY, "lie-poisson6", False)
print(json.dumps({"apart": made, "compiled": compiled}))
"""


def test_kernels_compiled_apart_load_from_the_cache_in_the_next_process(tmp_path):
    """The steady loop (`rotframe.particles.dop853_steady.SteadyDriver`), the engine's whole DOP853 loop
    (`rotframe.problem.dop853_split.whole_loop`) and a body's splitting of order 6
    (`rotframe.problem.body_split_step`) compile apart in a fresh install, and the next process loads every
    one of their kernels from numba's cache: no compile, no second process (numba keys its cache on the signature
    as it was compiled, `rotframe.numerics.compiled.load_cached`)."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"))

    def child():
        out = subprocess.run([sys.executable, "-c", _KERNELS_CHILD], env=env, capture_output=True, text=True,
                             timeout=900)
        assert out.returncode == 0, out.stderr[-2000:]
        return json.loads(out.stdout.strip().splitlines()[-1])

    first = child()
    assert "_run_at" in first["compiled"] and "dop853_stages_by_reference_particle6" in first["compiled"], first
    if len(os.sched_getaffinity(0)) >= 2 and sys.platform.startswith("linux"):
        # the steady trajectory; the engine's trajectory and its whole loop, beside its stages compiled here; the
        # body's step, beside its loop
        assert first["apart"] == ["fork"] * 4, first
        assert "advance_body7_splitting6_step_at" in first["compiled"], first
    else:
        assert {"advance_particle6_dop853_at", "body_step_splitting6"} <= set(first["compiled"]), first
    assert child() == {"apart": [], "compiled": []}


_BEGUN_DRIVER = textwrap.dedent('''
    import json, os, sys, time
    from numba import types
    import apart_kernel
    from rotframe.numerics import compile_apart

    mode = sys.argv[1]
    used, load = [], compile_apart.CompiledApart.load_all
    compile_apart.CompiledApart.load_all = lambda self, *args: used.append(load(self, *args)) or used[-1]
    t0 = time.perf_counter()
    began = compile_apart.begin("apart_kernel", "compile_slowly" if mode == "adopted" else "sleep")
    pid = next(iter(compile_apart._BEGUN.values()))._pid if began else None
    out = {"began": began}
    if mode == "adopted":  # one kernel to make: made compiles it here unless it adopts the process begun
        out["made"] = compile_apart.made([(apart_kernel.kernel, (types.float64,))], "apart_kernel",
                                         apart={0: ("compile_slowly", ())})
        out["value"] = apart_kernel.kernel(3.0)
    elif mode == "exit":  # left running: this process stops it as it exits
        print(json.dumps({"pid": pid}))
        sys.exit(0)
    else:  # its niceness relative to this process's (it nices itself once forked: a moment to do so)
        for _ in range(200):
            out["nice"] = os.getpriority(os.PRIO_PROCESS, pid) - os.getpriority(os.PRIO_PROCESS, 0)
            if out["nice"]:
                break
            time.sleep(0.005)
        compile_apart.stop_begun()
    try:
        os.kill(pid, 0)
        out["alive"] = True
    except (ProcessLookupError, TypeError):
        out["alive"] = False
    out.update(used=used, left=len(compile_apart._BEGUN), seconds=time.perf_counter() - t0)
    print(json.dumps(out))
''')


@needs_two_cores
@linux
@pytest.mark.parametrize("mode", ["adopted", "unused", "exit"])
def test_a_process_begun_ahead_is_adopted_by_made_or_stopped_unused(tmp_path, mode):
    """`compile_apart.begin` starts a kernel's second process before it is asked for, niced (`AHEAD_NICE`): the `made`
    that asks for it adopts it, loading what it compiled (one kernel to make, which `made` alone would compile here);
    `stop_begun` stops it, at once, not after its work; a process that exits with one still running stops it."""
    (tmp_path / "apart_kernel.py").write_text(_KERNEL)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"), PYTHONPATH=str(tmp_path))
    done = subprocess.run([sys.executable, "-c", _BEGUN_DRIVER, mode], env=env, capture_output=True, text=True,
                          timeout=300, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-2000:]
    out = json.loads(done.stdout.strip().splitlines()[-1])
    if mode == "exit":  # its child sleeps 60 s: gone as the driver ended (killed, then reaped by the system)
        for _ in range(400):
            try:
                os.kill(out["pid"], 0)
            except ProcessLookupError:
                break
            time.sleep(0.005)
        else:
            pytest.fail(f"the process begun ahead ({out['pid']}) outlived the process that began it")
        return
    assert out["began"] is True and out["left"] == 0 and out["alive"] is False
    if mode == "adopted":
        assert out["made"] is True and out["used"] == [True] and out["value"] == 7.0
    else:
        assert out["used"] == [] and out["seconds"] < 30.0  # its child sleeps 60 s: it was stopped
        assert out["nice"] == min(AHEAD_NICE, 19 - os.getpriority(os.PRIO_PROCESS, 0))  # nice is at most 19
