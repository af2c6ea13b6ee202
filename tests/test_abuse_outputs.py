"""Outputs under abuse: races, write errors, impossible paths, damaged files.

A file under its final name is complete and is the data of the run that wrote
it; a write error ends the run with one line and leaves no temporary file; an
output that cannot be written is refused before any computing starts.
"""

import errno
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from rotframe.app.cli import main

REPO = Path(__file__).resolve().parents[1]


def rotframe(*args, cwd, timeout=300, preexec_fn=None):
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"))
    return subprocess.run([sys.executable, "-m", "rotframe", *args], cwd=cwd, capture_output=True, text=True,
                          timeout=timeout, env=env, preexec_fn=preexec_fn)


def one_line(text):
    lines = text.strip().splitlines()
    assert len(lines) == 1, text
    assert "Traceback" not in text
    return lines[0]


def puck_positions(path):
    """The puck's recorded positions (rerun's own reader)."""
    from rerun.chunk import RrdReader

    rows = []
    for chunk in RrdReader(str(path)).stream():
        if chunk.entity_path == "/world/puck" and not chunk.is_static:
            col = chunk.to_record_batch().column("Points3D:positions")
            rows.extend(np.asarray(v, dtype=float).ravel() for v in col.to_pylist())
    return rows


def test_two_runs_started_together_on_one_out_each_write_their_own_file(tmp_path):
    out = tmp_path / "same.rrd"
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"))
    # compile the kernels first, so the two runs overlap in their recording phase
    assert rotframe("run", "turntable", "--no-record", "--set", "duration=0.1", cwd=tmp_path).returncode == 0
    procs = [subprocess.Popen([sys.executable, "-m", "rotframe", "run", "turntable", "--out", str(out), "--set",
                               f"speed={speed}", "--set", "samples=300"], cwd=tmp_path, env=env,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
             for speed in (0.5, 1.5)]
    results = [p.communicate(timeout=300) + (p.returncode,) for p in procs]
    assert [r[2] for r in results] == [0, 0], results
    assert sorted(p.name for p in tmp_path.iterdir() if p.name != "recordings") == ["same.rrd"]  # no temp files
    # the file is complete and is exactly one of the two runs: its first positions are that run's
    rows = puck_positions(out)
    assert len(rows) == 301
    alone = []
    for speed in (0.5, 1.5):
        single = tmp_path / f"alone-{speed}.rrd"
        assert rotframe("run", "turntable", "--out", str(single), "--set", f"speed={speed}", "--set",
                        "samples=300", cwd=tmp_path).returncode == 0
        alone.append(puck_positions(single))
    matches = [all(np.array_equal(a, b) for a, b in zip(rows, ref)) for ref in alone]
    assert sum(matches) == 1


def _limit_file_size():
    resource.setrlimit(resource.RLIMIT_FSIZE, (20_000, 20_000))


def test_a_file_size_limit_ends_the_run_with_one_line_and_no_file(tmp_path):
    t0 = time.monotonic()
    res = rotframe("run", "turntable", "--set", "samples=2000", cwd=tmp_path, timeout=120,
                   preexec_fn=_limit_file_size)
    assert time.monotonic() - t0 < 120
    assert res.returncode == 2, res.stderr
    line = one_line(res.stderr)
    assert "cannot write the recording" in line and "too large" in line.lower()
    assert not list((tmp_path / "recordings").iterdir())  # no temporary, no truncated file


def test_a_full_disk_ends_the_run_with_one_line_and_no_file(tmp_path, capsys, monkeypatch):
    from rotframe.app import outputs
    def full(fd):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(outputs.os, "fsync", full)
    out = tmp_path / "r" / "t.rrd"
    code = main(["run", "turntable", "--out", str(out), "--set", "samples=100"])
    _, err = capsys.readouterr()
    assert code == 2
    assert "No space left on device" in one_line(err)
    assert not list(out.parent.iterdir())


@pytest.mark.parametrize("setup,argv,fragment", [
    (lambda d: (d / "dir.rrd").mkdir(), ["run", "turntable", "--out", "dir.rrd"], "folder"),
    (lambda d: (d / "f").write_text("x"), ["run", "turntable", "--out", "f/x.rrd"], "is a file"),
    (lambda d: None, ["run", "turntable", "--out", "x.txt"], ".rrd"),
    (lambda d: None, ["run", "turntable", "--out", "sub/"], "folder"),
    (lambda d: (d / "recordings").write_text("x"), ["run", "turntable"], "is a file"),
    (lambda d: (d / "t.parquet").mkdir(), ["sweep", "tower-drop", "--grid", "latitude=0:1:2", "--out", "t.parquet"],
     "folder"),
    (lambda d: (d / "t.parquet.parts").write_text("x"),
     ["sweep", "tower-drop", "--grid", "latitude=0:1:2", "--out", "t.parquet"], ".parts"),
    (lambda d: (d / "plots").write_text("x"), ["bench", "--quick", "--plots", "plots/x"], "is a file"),
    (lambda d: (d / "plots").write_text("x"), ["bench", "--quick", "--plots", "plots"], "not a folder"),
])
def test_impossible_outputs_are_refused_before_computing(tmp_path, capsys, monkeypatch, setup, argv, fragment):
    monkeypatch.chdir(tmp_path)
    setup(tmp_path)

    def no_compute(*a, **k):
        raise AssertionError("computing started before the output was checked")

    from rotframe.app import bench

    from rotframe.app import runner

    from rotframe.app import sweep
    monkeypatch.setattr(runner, "simulate", no_compute)
    monkeypatch.setattr(sweep, "run_sweep", no_compute)
    monkeypatch.setattr(bench, "main", no_compute)
    code = main(argv)
    _, err = capsys.readouterr()
    assert code == 2
    assert fragment in one_line(err)


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_a_read_only_folder_is_refused_before_computing(tmp_path, capsys):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        code = main(["run", "turntable", "--out", str(ro / "x.rrd")])
        _, err = capsys.readouterr()
        assert code == 2 and "not writable" in one_line(err)
    finally:
        ro.chmod(0o755)


@pytest.mark.parametrize("content,fragment", [
    (b"not a recording", "not a rerun recording"),
    (None, "damaged or truncated"),
])
def test_view_checks_the_file_before_starting_the_viewer(tmp_path, capsys, monkeypatch, content, fragment):
    import subprocess as sp

    monkeypatch.setattr(sp, "call", lambda *a, **k: pytest.fail("viewer started on a bad file"))
    path = tmp_path / "x.rrd"
    if content is None:
        good = tmp_path / "good.rrd"
        assert main(["run", "turntable", "--out", str(good), "--set", "samples=100"]) == 0
        capsys.readouterr()
        path.write_bytes(good.read_bytes()[:1500])
    else:
        path.write_bytes(content)
    code = main(["view", str(path)])
    _, err = capsys.readouterr()
    assert code == 2 and fragment in one_line(err)


def test_view_starts_the_viewer_on_loopback(tmp_path, capsys, monkeypatch):
    import subprocess as sp

    seen = []
    monkeypatch.setattr(sp, "call", lambda argv, **k: seen.append(argv) or 0)
    monkeypatch.setenv("DISPLAY", ":0")  # a display, so that view starts the viewer (without one it summarises)
    good = tmp_path / "good.rrd"
    assert main(["run", "turntable", "--out", str(good), "--set", "samples=100"]) == 0
    assert main(["view", str(good)]) == 0
    assert seen and seen[0][seen[0].index("--bind") + 1] == "127.0.0.1"


@pytest.mark.parametrize("damage", ["garbage", "truncated"])
def test_resume_over_a_damaged_table_is_one_line(tmp_path, capsys, damage):
    out = tmp_path / "s.parquet"
    argv = ["sweep", "tower-drop", "--grid", "latitude=0:90:3", "--out", str(out)]
    assert main(argv) == 0
    capsys.readouterr()
    data = out.read_bytes()
    out.write_bytes(b"\x00garbage" * 10 if damage == "garbage" else data[: len(data) // 2])
    code = main(argv + ["--resume"])
    _, err = capsys.readouterr()
    assert code == 2 and "--resume" in one_line(err)


def test_a_sweeps_plots_do_not_depend_on_pyplots_open_figures(tmp_path):
    # pyplot warns once a process holds more than 20 figures (an error in this suite): a sweep's pictures are
    # Figures of their own, so a notebook or an earlier test that left pyplot's figures open does not fail it
    plt = pytest.importorskip("matplotlib.pyplot")
    figures = [plt.figure() for _ in range(20)]  # the most pyplot holds without a warning
    try:
        assert main(["sweep", "tower-drop", "--grid", "latitude=0:90:3", "--out", str(tmp_path / "s.parquet")]) == 0
    finally:
        for fig in figures:
            plt.close(fig)


def test_json_stdout_is_guarded_at_the_file_descriptor(tmp_path):
    # LAPACK's xerbla writes to fd 1 (a NaN fit): with --json it must land on stderr, not in the JSON
    code = ("import numpy as np\nfrom rotframe.app.cli import _JsonStdout\nwith _JsonStdout(True):\n"
            "    try:\n        np.polyfit(np.array([0.0, 1.0]), np.array([np.nan, 1.0]), 1)\n"
            "    except Exception:\n        pass\n    print('{\"ok\": 1}')\n")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path,
                         env=dict(os.environ, PYTHONPATH=str(REPO / "src")))
    assert res.stdout == '{"ok": 1}\n', (res.stdout, res.stderr)
