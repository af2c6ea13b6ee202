"""`rotframe view FILE --web`: the URL in one line, free ports, and nothing left behind on SIGTERM."""

from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

from rotframe.app.web_view import free_port

ROOT = Path(__file__).resolve().parents[1]


def _listening(port: int) -> bool:
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=0.5):
            return True
    except OSError:
        return False


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    path = tmp_path_factory.mktemp("web") / "drop.rrd"
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    subprocess.run([sys.executable, "-m", "rotframe", "run", "tower-drop", "--out", str(path)], check=True,
                   env=env, capture_output=True, timeout=600)
    return path


def test_free_port_prefers_the_default_and_avoids_a_taken_one():
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        busy = taken.getsockname()[1]
        assert free_port("127.0.0.1", busy) != busy
    spare = free_port("127.0.0.1", 0)
    assert free_port("127.0.0.1", spare) == spare


@pytest.mark.parametrize("block_default", [False, True], ids=["default-port", "default-port-taken"])
def test_web_prints_one_url_line_and_stops_rerun_on_sigterm(recording, block_default):
    blocker = None
    if block_default:
        blocker = socket.socket()
        try:
            blocker.bind(("127.0.0.1", 9090))
            blocker.listen()
        except OSError:  # already taken by something else: the case under test all the same
            blocker.close()
            blocker = None
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    proc = subprocess.Popen([sys.executable, "-m", "rotframe", "view", str(recording), "--web"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        line = proc.stdout.readline()  # the sign the server is up: the command prints it once the page answers
        m = re.fullmatch(r"rerun's web viewer for .+: http://localhost:(\d+)/\?url=rerun%2Bhttp%3A%2F%2F"
                         r"localhost%3A(\d+)%2Fproxy \(Ctrl-C stops it\)\n", line)
        assert m, (line, proc.stderr.read() if proc.poll() is not None else "")
        web, grpc = int(m.group(1)), int(m.group(2))
        if block_default:
            assert web != 9090
        assert urllib.request.urlopen(f"http://127.0.0.1:{web}/", timeout=10).status == 200
        assert _listening(grpc)
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=60) == 143
        deadline = time.monotonic() + 10
        while (_listening(web) or _listening(grpc)) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not _listening(web) and not _listening(grpc), "rerun's server outlived the command"
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        if blocker is not None:
            blocker.close()
