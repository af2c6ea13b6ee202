"""Door 1 (issue 27): every file rotframe writes goes through one writer, rotframe.app.outputs.write_atomic.

Every output kind (recording, --export npz/csv/parquet, --png / Result.plot, section --png,
bench --plots pictures and bench.json) is driven through each fault: a full disk (a real 64 KiB
tmpfs where this process may mount one, else ENOSPC injected into the writer's file), a file
size limit (``ulimit -f``, in a subprocess with SIGXFSZ ignored), an unwritable folder and two
writers at once. Each time: a RotframeError (OutputError) of one line naming the path, no
temporary file left, and an earlier file under the final name untouched.
"""

import argparse
import errno
import json
import os
import subprocess
import sys
import threading
from pathlib import Path

import pytest

import rotframe
from rotframe.app import outputs
from rotframe.app.outputs import OutputError
from rotframe.errors import RotframeError

REPO = Path(__file__).resolve().parents[1]
GOOD = b"an earlier good file\n"


@pytest.fixture(scope="module")
def result():
    return rotframe.run("turntable", samples=60, duration=0.5)


def _bench_rows():
    rows = []
    for method, wall, err in (("exact", 1e-4, 1e-15), ("rk4", 1e-3, 1e-7), ("scipy-DOP853", 1e-2, 1e-9)):
        rows.append({"scenario": "turntable", "horizon": "4 s", "method": method, "setting": 1e-3,
                     "wall_s": wall, "error": err, "error_kind": "final position error (m)", "nfev": 10,
                     "kind": "run", "family": "peer" if method.startswith("scipy") else "rotframe"})
    return rows


def write_kind(kind, path, result):
    """Write one output kind to ``path`` the way its command does (in-process)."""
    path = Path(path)
    if kind == "recording":
        return result.record(path)
    if kind in ("npz", "csv", "parquet"):
        return result.export(path)
    if kind == "png":
        return result.plot(path)
    if kind == "section-png":
        from rotframe.app.section_cli import run_section

        code = run_section("rectangle", [], png=str(path))
        if code != 0:
            raise OutputError("section --png failed")
        return path
    if kind == "bench-plot":
        from rotframe.app.bench.report import plot

        return plot(_bench_rows(), str(path.parent))
    if kind == "bench-json":
        from rotframe.app import bench

        args = argparse.Namespace(names=None, quick=True, json=True, plots=str(path.parent))
        orig = bench.run_bench, bench.plot
        bench.run_bench = lambda *a, **k: _bench_rows()
        bench.plot = lambda rows, folder: [str(Path(folder) / "bench-turntable-0.png")]  # bench.json alone
        try:
            return bench.main(args)
        finally:
            bench.run_bench, bench.plot = orig
    raise AssertionError(kind)


SUFFIX = {"recording": "out.rrd", "npz": "out.npz", "csv": "out.csv", "parquet": "out.parquet", "png": "out.png",
          "section-png": "out.png", "bench-plot": "bench-turntable-0.png", "bench-json": "bench.json"}
KINDS = list(SUFFIX)


def _skip_parquet(kind):
    if kind == "parquet":
        pytest.importorskip("pyarrow")


def test_every_writer_goes_through_the_door(tmp_path, result, monkeypatch, capsys):
    seen = []
    real = outputs.write_atomic

    def spy(final, write, what="file"):
        seen.append(Path(final).name)
        return real(final, write, what)

    from rotframe import files

    monkeypatch.setattr(outputs, "write_atomic", spy)
    monkeypatch.setattr(files, "write_atomic", spy)  # the one writer, which outputs re-exports
    for kind in KINDS:
        if kind == "parquet" and not _has_pyarrow():
            continue
        folder = tmp_path / kind
        folder.mkdir()
        write_kind(kind, folder / SUFFIX[kind], result)
        assert SUFFIX[kind] in seen, (kind, seen)
        assert (folder / SUFFIX[kind]).stat().st_size > 0
        assert not [p for p in folder.iterdir() if p.name.endswith(".tmp") or ".tmp." in p.name], kind
    capsys.readouterr()


def _has_pyarrow():
    try:
        import pyarrow  # noqa: F401
        return True
    except ImportError:
        return False


def _leftovers(folder, keep):
    return sorted(p.name for p in Path(folder).iterdir() if p.name not in keep)


# --- a full disk -------------------------------------------------------------------------------


class _FullFile:
    """A file that takes ``room`` bytes and then fails as a full disk does."""

    def __init__(self, f, room):
        self.f, self.room = f, room

    def write(self, data):
        n = len(memoryview(data).cast("B")) if not isinstance(data, str) else len(data)
        if n > self.room:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        self.room -= n
        return self.f.write(data)

    def __getattr__(self, name):
        return getattr(self.f, name)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.f.close()


@pytest.fixture
def full_folder(tmp_path, monkeypatch):
    """A folder on a full disk: a 64 KiB tmpfs filled up (as root), else ENOSPC injected after 4 KiB."""
    folder = tmp_path / "full"
    folder.mkdir()
    mounted = os.geteuid() == 0 and subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(folder)],
                                                   capture_output=True).returncode == 0
    if mounted:
        (folder / "out.png").write_bytes(GOOD)
        for name in KINDS:
            (folder / SUFFIX[name]).write_bytes(GOOD)
        try:
            with open(folder / "filler", "wb") as f:
                while True:
                    f.write(b"x" * 4096)
                    f.flush()
        except OSError:
            pass
    else:
        real_open = open

        def full_open(path, mode="r", *a, **k):
            f = real_open(path, mode, *a, **k)
            return _FullFile(f, 4096) if "w" in mode and Path(path).parent == folder else f

        monkeypatch.setattr(outputs, "open", full_open, raising=False)
    yield folder
    if mounted:
        subprocess.run(["umount", "-l", str(folder)], capture_output=True)


@pytest.mark.parametrize("kind", KINDS)
def test_a_full_disk_leaves_no_temporary_file_and_the_earlier_file_intact(full_folder, result, kind, capsys):
    _skip_parquet(kind)
    final = full_folder / SUFFIX[kind]
    final.write_bytes(GOOD)
    keep = {p.name for p in full_folder.iterdir()}
    with pytest.raises(RotframeError) as info:
        write_kind(kind, final, result)
    message = str(info.value)
    assert "\n" not in message and len(message) < 400, message
    if kind != "section-png":
        assert str(final) in message or final.name in message, message
    assert final.read_bytes() == GOOD
    assert _leftovers(full_folder, keep) == []
    capsys.readouterr()


# --- ulimit -f ------------------------------------------------------------------------------------

_FSIZE = r"""
import json, resource, signal, sys
from pathlib import Path
sys.path.insert(0, sys.argv[2])
import test_writer as tw
import rotframe
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
res = rotframe.run("turntable", samples=60, duration=0.5)
folder = Path(sys.argv[1])
out = {}
for kind in json.loads(sys.argv[3]):
    sub = folder / kind
    sub.mkdir()
    final = sub / tw.SUFFIX[kind]
    final.write_bytes(tw.GOOD)
    resource.setrlimit(resource.RLIMIT_FSIZE, (200, resource.RLIM_INFINITY))
    try:
        tw.write_kind(kind, final, res)
        out[kind] = "written"
    except rotframe.RotframeError as exc:
        out[kind] = str(exc)
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, (resource.RLIM_INFINITY, resource.RLIM_INFINITY))
print(json.dumps(out))
"""


def test_a_file_size_limit_leaves_no_temporary_file_and_the_earlier_file_intact(tmp_path):
    kinds = [k for k in KINDS if k != "parquet" or _has_pyarrow()]
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"), MPLBACKEND="Agg")
    proc = subprocess.run([sys.executable, "-c", _FSIZE, str(tmp_path), str(REPO / "tests"), json.dumps(kinds)],
                          capture_output=True, text=True, timeout=300, env=env)
    assert proc.returncode == 0, proc.stderr[-2000:]
    got = json.loads(proc.stdout.strip().splitlines()[-1])
    for kind in kinds:
        assert got[kind] != "written" and "\n" not in got[kind], (kind, got[kind])
        assert "File too large" in got[kind] or "cannot write" in got[kind] or "failed" in got[kind], got[kind]
        sub = tmp_path / kind
        assert (sub / SUFFIX[kind]).read_bytes() == GOOD, kind
        assert _leftovers(sub, {SUFFIX[kind]}) == [], kind


def test_the_command_line_under_ulimit_f_exits_2_with_one_line(tmp_path):
    import resource
    import signal

    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_DFL)  # as a shell leaves it: rotframe itself must ignore it
        resource.setrlimit(resource.RLIMIT_FSIZE, (4096, resource.RLIM_INFINITY))

    env = dict(os.environ, PYTHONPATH=str(REPO / "src"))
    (tmp_path / "x.csv").write_bytes(GOOD)
    proc = subprocess.run([sys.executable, "-m", "rotframe", "run", "turntable", "--no-record", "--export", "x.csv"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=300, env=env, preexec_fn=limit)
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "x.csv" in lines[0] and "Traceback" not in proc.stderr, proc.stderr
    assert (tmp_path / "x.csv").read_bytes() == GOOD
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.csv"]


# --- an unwritable folder ---------------------------------------------------------------------


@pytest.fixture
def readonly_folder(tmp_path):
    folder = tmp_path / "ro"
    folder.mkdir()
    (folder / "keep").write_bytes(GOOD)
    if os.geteuid() == 0:
        if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(folder)],
                          capture_output=True).returncode != 0:
            pytest.skip("root without mount: no folder is unwritable to it")
        (folder / "keep").write_bytes(GOOD)
        for kind in KINDS:
            (folder / SUFFIX[kind]).write_bytes(GOOD)
        subprocess.run(["mount", "-o", "remount,ro", str(folder)], check=True)
        yield folder
        subprocess.run(["umount", "-l", str(folder)], capture_output=True)
    else:
        for kind in KINDS:
            (folder / SUFFIX[kind]).write_bytes(GOOD)
        folder.chmod(0o555)
        yield folder
        folder.chmod(0o755)


@pytest.mark.parametrize("kind", KINDS)
def test_an_unwritable_folder_is_one_line_and_the_earlier_file_intact(readonly_folder, result, kind, capsys):
    _skip_parquet(kind)
    final = readonly_folder / SUFFIX[kind]
    keep = {p.name for p in readonly_folder.iterdir()}
    with pytest.raises(RotframeError) as info:
        write_kind(kind, final, result)
    assert "\n" not in str(info.value)
    assert final.read_bytes() == GOOD
    assert _leftovers(readonly_folder, keep) == []
    capsys.readouterr()


@pytest.mark.parametrize("kind", ["recording", "npz", "csv", "png"])
def test_a_path_under_a_file_or_onto_a_folder_is_a_rotframe_error_from_python(tmp_path, result, kind):
    (tmp_path / "file").write_bytes(GOOD)
    with pytest.raises(RotframeError):
        write_kind(kind, tmp_path / "file" / SUFFIX[kind], result)
    (tmp_path / SUFFIX[kind]).mkdir()
    with pytest.raises(RotframeError):
        write_kind(kind, tmp_path / SUFFIX[kind], result)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["file", SUFFIX[kind]])


# --- two writers at once ------------------------------------------------------------------------


def test_two_writers_of_one_path_at_once_each_publish_a_whole_file(tmp_path):
    final = tmp_path / "same.bin"
    barrier = threading.Barrier(2)
    payloads = [bytes([65 + k]) * (1 << 20) for k in range(2)]

    def writer(data):
        def write(f):
            barrier.wait()
            for start in range(0, len(data), 4096):  # interleave the two writers chunk by chunk
                f.write(data[start:start + 4096])
        outputs.write_atomic(final, write)

    threads = [threading.Thread(target=writer, args=(p,)) for p in payloads]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert final.read_bytes() in payloads
    assert sorted(p.name for p in tmp_path.iterdir()) == ["same.bin"]


def test_two_exports_of_one_path_at_once_give_one_whole_table(tmp_path):
    a = rotframe.run("turntable", samples=3000, duration=0.5)
    b = rotframe.run("turntable", samples=2000, duration=0.5, speed=0.7)
    final = tmp_path / "same.csv"
    solo = {}
    for name, res in (("a", a), ("b", b)):
        res.export(tmp_path / f"{name}.csv")
        solo[name] = (tmp_path / f"{name}.csv").read_bytes()
    for _ in range(3):
        threads = [threading.Thread(target=res.export, args=(final,)) for res in (a, b)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        assert final.read_bytes() in solo.values()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.csv", "b.csv", "same.csv"]
