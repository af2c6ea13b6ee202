"""Ctrl-C and SIGTERM in every phase of a run and a sweep: exit 130 / 143, one line, a partial kept.

Each test runs rotframe in a subprocess whose driver wraps one function of the
phase under test so that the process signals itself when it gets there
(``os.kill(os.getpid(), sig)``): the phase is hit deterministically, without
sleeping and hoping. One test also signals from outside, during a long compiled
loop, to check that the loop returns to Python often enough.
"""

import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]

DRIVER = textwrap.dedent('''
    import os, signal, sys
    import importlib
    target, attr, nth, sig = sys.argv[1], sys.argv[2], int(sys.argv[3]), getattr(signal, sys.argv[4])
    mod = importlib.import_module(target)
    owner = mod
    for part in attr.split(".")[:-1]:
        owner = getattr(owner, part)
    name = attr.split(".")[-1]
    original = getattr(owner, name)
    calls = [0]
    def wrapped(*a, **k):
        calls[0] += 1
        if calls[0] == nth:
            os.kill(os.getpid(), sig)
        return original(*a, **k)
    setattr(owner, name, wrapped)
    from rotframe.app.cli import main
    sys.exit(main(sys.argv[5:]))
''')


def drive(tmp_path, target, attr, nth, sig, *argv, timeout=240):
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"))
    return subprocess.run([sys.executable, "-c", DRIVER, target, attr, str(nth), sig, *argv], cwd=tmp_path,
                          capture_output=True, text=True, timeout=timeout, env=env)


def check(res, sig):
    assert res.returncode == (143 if sig == "SIGTERM" else 130), (res.returncode, res.stderr)
    assert "Traceback" not in res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1, res.stderr
    assert ("terminated" if sig == "SIGTERM" else "interrupted") in lines[0]
    return lines[0]


def readable(path):
    from rerun.chunk import RrdReader

    return sum(1 for _ in RrdReader(str(path)).stream()) > 0


PHASES = [
    # (module, attribute, nth call, scenario and options, partial recording expected)
    ("rotframe.scenes", "get", 1, ["run", "tower-drop"], False),                        # loading the scene
    # foucault on the engine's steady loop: its compile (the first call), then a call of the run
    ("rotframe.particles.blocks", "run_blocks", 1, ["run", "foucault", "--set", "duration=60"], True),
    ("rotframe.particles.blocks", "run_blocks", 4, ["run", "foucault", "--set", "duration=600"], True),
    # the scenes on the engine: its loop's calls (the first may compile it), and one in the middle of a long run
    ("rotframe.problem.particles", "advance_blocks", 1, ["run", "turntable", "--method", "splitting"], True),
    ("rotframe.problem.particles", "advance_blocks", 3, ["run", "turntable", "--method", "splitting", "--set", "step=1e-7"], True),
    ("scipy.linalg", "expm", 20, ["run", "inertial-oscillation", "--set", "samples=100000"], True),  # exact
    ("rotframe.rigid.free_body", "free_body_closed_form", 3, ["run", "free-top", "--set", "samples=20000"], True),  # rigid exact
    ("rotframe.app.runner", "summarize", 1, ["run", "tower-drop"], True),                     # analysis
    ("rotframe.app.record.Recording", "finish", 1, ["run", "tower-drop"], True),               # recording
]


# each phase gets one of the two signals, alternating (both go through the same InterruptScope)
CASES = [(*p, ("SIGINT", "SIGTERM")[i % 2]) for i, p in enumerate(PHASES)]


@pytest.mark.parametrize("module,attr,nth,argv,partial,sig", CASES, ids=[f"{c[1]}#{c[2]}-{c[5]}" for c in CASES])
def test_a_signal_in_every_phase_of_a_run(tmp_path, module, attr, nth, argv, partial, sig):
    target, _, owner_attr = (module, None, attr)
    if module == "rotframe.app.record.Recording":
        target, owner_attr = "rotframe.app.record", "Recording.finish"
    res = drive(tmp_path, target, owner_attr, nth, sig, *argv, "--json")
    check(res, sig)
    recordings = list((tmp_path / "recordings").glob("*")) if (tmp_path / "recordings").exists() else []
    assert not [p for p in recordings if p.name.endswith(".tmp")]
    if partial:
        parts = [p for p in recordings if p.name.endswith(".partial.rrd")]
        assert len(parts) == 1 and readable(parts[0]), (recordings, res.stderr)
        assert not [p for p in recordings if not p.name.endswith(".partial.rrd")]  # never under the final name
    if res.stdout:  # --json: whatever is on stdout is one JSON document
        import json

        json.loads(res.stdout)


@pytest.mark.parametrize("attr,nth,sig", [("run_batch", 2, "SIGTERM"), ("write_plots", 1, "SIGINT"),
                                          ("write_recording", 1, "SIGTERM")])
def test_a_signal_in_every_phase_of_a_sweep(tmp_path, attr, nth, sig):
    # foucault runs row by row: the first two rows are timed alone, so run_batch is called more than once
    argv = ["sweep", "foucault", "--grid", "latitude=0:90:6", "--set", "duration=20", "--out", "s.parquet"]
    res = drive(tmp_path, "rotframe.app.sweep.execute", attr, nth, sig, *argv)
    line = check(res, sig)
    assert "--resume" in line
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"))
    again = subprocess.run([sys.executable, "-m", "rotframe", *argv, "--resume", "--json"], cwd=tmp_path,
                           capture_output=True, text=True, timeout=240, env=env)
    assert again.returncode == 0, again.stderr
    import json

    assert json.loads(again.stdout)["rows"] == 6


@pytest.mark.parametrize("target,attr,nth,argv", [
    # the engine: 1e9 steps of the pendulum (foucault) in one sample interval, 5.7e8 of the tower drop, both on the
    # scenes' fixed-step drivers (`rotframe.problem.steady`), a sample interval in pieces of a tenth of a second
    # (`KernelSetup.one_sample_in_pieces`); the engine's own loop, called in paced pieces, is the turntable's below
    ("rotframe.particles.chunked", "KernelSetup.call", 3, ["foucault", "--set", "step=1e-8", "--set", "duration=10"]),
    ("rotframe.particles.chunked", "KernelSetup.call", 3, ["tower-drop", "--set", "step=1e-8"]),
    ("rotframe.problem.particles", "advance_blocks", 2, ["turntable", "--set", "step=1e-8", "--set", "duration=10"]),
])
def test_a_signal_from_outside_stops_a_long_compiled_loop(tmp_path, target, attr, nth, argv):
    # a single sample interval of many steps (tens of seconds of compiled splitting): the loop is called in pieces,
    # so SIGINT is seen within it
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"))
    warm = subprocess.run([sys.executable, "-m", "rotframe", "run", argv[0], "--method", "splitting",
                           "--set", "step=1e-2", "--no-record"], cwd=tmp_path, env=env, capture_output=True)
    assert warm.returncode == 0
    from signs import start, wait_for

    proc, sign = start(tmp_path, target, attr, nth, "run", *argv, "--method", "splitting", "--set", "samples=1",
                       "--no-record")
    wait_for(sign, proc)  # the long compiled loop has begun
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=60)  # not a timing assertion: a bound so that a hang fails the test
    assert proc.returncode == 130, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_signal_handlers_do_not_outlive_a_command():
    from rotframe.app.cli import main

    before = (signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM))
    assert main(["list", "--json"]) == 0
    assert (signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)) == before
