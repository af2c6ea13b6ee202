"""``rotframe view FILE --web``: rerun's web viewer, served for as long as the command runs.

rerun's own command (``python -m rerun --web-viewer``) prints its URL among log lines
after an analytics banner, and a SIGTERM to its parent leaves its servers orphaned on
their ports. Here:

- the ports are free ones: rerun's defaults (9090 for the page, 9876 for its gRPC
  server) when they are free, else ports the system picks, so a second viewer, or
  a port left taken by something else, does not stop this one;
- rerun runs in a process group of its own, its output goes to a log file, and the
  command prints the URL in one line once the page answers;
- Ctrl-C or SIGTERM stops rerun's whole group (nothing is left on the ports), and a
  rerun that fails to start is reported in one line with the end of its log.
"""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import tempfile
import time
from urllib.parse import quote

__all__ = ["free_port", "serve"]

#: rerun's default ports: its web page, its gRPC server
WEB_PORT, GRPC_PORT = 9090, 9876
#: seconds to wait for the page to answer before giving up
START_TIMEOUT_S = 60.0


def free_port(bind: str, preferred: int) -> int:
    """``preferred`` if nothing listens there on ``bind``, else a port the system picks as free."""
    for port in (preferred, 0):
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
            try:
                s.bind((bind, port))
            except OSError:
                continue
            return s.getsockname()[1]
    raise OSError(f"no free port on {bind}")


def _answers(bind: str, port: int) -> bool:
    try:
        with socket.create_connection((bind, port), timeout=0.5):
            return True
    except OSError:
        return False


def _stop(proc) -> None:
    """End rerun's process group: SIGTERM, then SIGKILL if it lingers."""
    if proc.poll() is not None:
        return
    for sig, wait in ((signal.SIGTERM, 5.0), (signal.SIGKILL, 5.0)):
        try:
            os.killpg(proc.pid, sig)
        except ProcessLookupError:
            return
        try:
            proc.wait(timeout=wait)
            return
        except subprocess.TimeoutExpired:
            continue


def _log_tail(path: str) -> str:
    try:
        with open(path, errors="replace") as f:
            lines = [line.strip() for line in f if line.strip()]
    except OSError:
        return ""
    return lines[-1][:300] if lines else ""


def serve(path: str, bind: str, *, out=None) -> int:
    """Serve ``path`` in rerun's web viewer until interrupted; returns rerun's exit code (0 when stopped by us).

    Prints one line with the URL on ``out`` (default stdout) once the page answers.
    """
    out = out or sys.stdout
    try:
        web = free_port(bind, WEB_PORT)
        grpc = free_port(bind, GRPC_PORT if web != GRPC_PORT else GRPC_PORT + 1)
    except OSError as exc:
        print(f"rotframe: view --web: cannot listen on {bind} ({exc}); allowed: --bind with an address of "
              "this machine", file=sys.stderr)
        return 2
    if grpc == web:  # the system picked the same free port for both: ask again
        grpc = free_port(bind, 0)
    log = tempfile.NamedTemporaryFile("w", prefix="rotframe-rerun-", suffix=".log", delete=False)
    command = [sys.executable, "-m", "rerun", "--bind", bind, "--port", str(grpc), "--web-viewer",
               "--web-viewer-port", str(web), path]
    proc = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
                            start_new_session=True)  # its own process group: stopped whole below
    log.close()
    try:
        start = time.monotonic()
        while not _answers(bind, web):
            if proc.poll() is not None:
                print(f"rotframe: view --web: rerun stopped at start (exit {proc.returncode}): "
                      f"{_log_tail(log.name) or 'no output'} (log: {log.name})", file=sys.stderr)
                return 1
            if time.monotonic() - start > START_TIMEOUT_S:
                print(f"rotframe: view --web: rerun's page did not answer on {bind}:{web} within "
                      f"{START_TIMEOUT_S:g} s (log: {log.name})", file=sys.stderr)
                return 1
            time.sleep(0.1)
        host = "localhost" if bind in ("127.0.0.1", "0.0.0.0") else bind
        source = quote(f"rerun+http://{host}:{grpc}/proxy", safe="")
        print(f"rerun's web viewer for {path}: http://{host}:{web}/?url={source} (Ctrl-C stops it)",
              file=out, flush=True)
        code = proc.wait()
        if code:
            print(f"rotframe: view --web: rerun stopped (exit {code}): {_log_tail(log.name)} (log: {log.name})",
                  file=sys.stderr)
        return code
    finally:
        _stop(proc)
        if proc.returncode in (0, -signal.SIGTERM, -signal.SIGKILL, None):
            try:
                os.unlink(log.name)
            except OSError:
                pass
