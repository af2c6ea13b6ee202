"""Start rotframe in a subprocess that leaves a sign (a file) when a phase begins; wait for it, not a clock.

The driver wraps ``module.attr`` so that its ``nth`` call first creates the file ``sign``
and then does its work: a test that waits for the file knows the phase has started, on a
loaded machine as on an idle one, and signals the process from outside while it is in it.
"""

import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

DRIVER = textwrap.dedent('''
    import importlib, sys
    target, attr, nth, sign = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
    owner = importlib.import_module(target)
    for part in attr.split(".")[:-1]:
        owner = getattr(owner, part)
    name = attr.split(".")[-1]
    original = getattr(owner, name)
    calls = [0]
    def wrapped(*a, **k):
        calls[0] += 1
        if calls[0] == nth:
            open(sign, "w").close()
        return original(*a, **k)
    setattr(owner, name, wrapped)
    from rotframe.app.cli import main
    sys.exit(main(sys.argv[5:]))
''')


def start(tmp_path, target, attr, nth, *argv, env=None):
    """Popen of ``rotframe ARGV`` that creates ``tmp_path / 'sign'`` on the ``nth`` call of ``target.attr``."""
    sign = Path(tmp_path) / "sign"
    if sign.exists():
        sign.unlink()
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"), **(env or {}))
    proc = subprocess.Popen([sys.executable, "-c", DRIVER, target, attr, str(nth), str(sign), *map(str, argv)],
                            cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    return proc, sign


def wait_for(sign, proc, bound=240.0):
    """Wait until ``sign`` exists (the phase began); fails if the process ends first or after ``bound`` s.

    ``bound`` is no timing assertion: it only turns a hang into a failure.
    """
    t0 = time.monotonic()
    while not Path(sign).exists():
        if proc.poll() is not None:
            out, err = proc.communicate()
            raise AssertionError(f"the process ended ({proc.returncode}) before the sign: {err[-2000:]}")
        if time.monotonic() - t0 > bound:
            proc.kill()
            raise AssertionError("no sign within the bound")
        time.sleep(0.02)
