"""A wrong Dask scheduler fails fast, in one line: bad addresses, closed ports, listeners that are not Dask.

The listeners are plain TCP servers on 127.0.0.1 started by the test (loopback only).
The connection and handshake limit is lowered to 1 s in the subprocess so the test is short.
"""

import os
import socket
import subprocess
import sys
import threading
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
DRIVER = ("import sys; from rotframe.app.sweep import execute; execute.CONNECT_TIMEOUT_S = 1.0; from rotframe.app.cli import main; "
          "sys.exit(main(sys.argv[1:]))")


def sweep_with(tmp_path, address):
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"))
    return subprocess.run([sys.executable, "-c", DRIVER, "sweep", "tower-drop", "--grid", "latitude=0:90:3",
                           "--scheduler", address, "--out", str(tmp_path / "s.parquet")], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=120)


def one_line_error(res):
    assert res.returncode == 2, (res.returncode, res.stderr)
    assert "Traceback" not in res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1, res.stderr
    assert not (Path(res.args[-1]).exists())  # nothing computed, nothing written
    return lines[0]


class Listener:
    """A TCP server on 127.0.0.1 that accepts and then says nothing, or sends ``reply`` and waits."""

    def __init__(self, reply=b""):
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen()
        self.port = self.sock.getsockname()[1]
        self.reply = reply
        self.conns = []
        threading.Thread(target=self.serve, daemon=True).start()

    def serve(self):
        while True:
            try:
                conn, _ = self.sock.accept()
            except OSError:
                return
            self.conns.append(conn)
            if self.reply:
                try:
                    conn.sendall(self.reply)
                except OSError:
                    pass

    def close(self):
        for c in self.conns:
            c.close()
        self.sock.close()


@pytest.mark.parametrize("address", ["notaurl", "http://127.0.0.1:8786", "tcp://127.0.0.1", "tcp://:8786",
                                     "tcp://127.0.0.1:99999", "tcp://127.0.0.1:8786/path", ""])
def test_a_malformed_address_is_refused(tmp_path, address):
    line = one_line_error(sweep_with(tmp_path, address))
    assert "--scheduler" in line and "tcp://HOST:PORT" in line


def test_a_closed_port_is_refused(tmp_path):
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()  # nothing listens there now
    assert "cannot connect" in one_line_error(sweep_with(tmp_path, f"tcp://127.0.0.1:{port}"))


@pytest.mark.parametrize("reply", [b"", b"\xff" * 64, b"HTTP/1.1 200 OK\r\n\r\nhello"],
                         ids=["silent", "huge-frame-header", "http"])
def test_a_listener_that_is_not_dask_fails_fast(tmp_path, reply):
    server = Listener(reply)
    try:
        line = one_line_error(sweep_with(tmp_path, f"tcp://127.0.0.1:{server.port}"))
    finally:
        server.close()
    assert "not a Dask scheduler" in line
