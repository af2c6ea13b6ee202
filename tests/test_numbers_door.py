"""Door 4 and the small ones of door 6 (issue 27): every number checked for what it will become.

- a subnormal step or rtol (1e-310) is refused where run settings are parsed (file, --set, the
  Python API, a sweep's --set) before any run; a tiny normal step gives the work-limit refusal,
  never an OverflowError from a count beyond a float;
- a scenario file is refused by its size before it is read (a sparse file of gigabytes);
- every RotframeError message is cut to a readable length (errors.readable);
- --json to a full device and a broken pyarrow import are one line, exit 2.
"""

import builtins
import os
import subprocess
import sys
from pathlib import Path

import pytest

import rotframe
from cli_calls import assert_clean, call
from rotframe.errors import MAX_MESSAGE, RotframeError, ScenarioError

REPO = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("argv", [
    ["run", "turntable", "--method", "rk4", "--set", "step=1e-310"],
    ["run", "foucault", "--method", "splitting", "--set", "step=5e-324"],
    ["run", "heavy-top", "--method", "top-splitting", "--set", "step=1e-310"],
    ["run", "dzhanibekov", "--method", "rk4", "--set", "step=2e-309"],
    ["run", "heavy-top", "--method", "dop853", "--set", "rtol=1e-310"],
    ["run", "foucault", "--method", "splitting", "--set", "step=1e-300"],
    ["run", "dzhanibekov", "--method", "rk4", "--set", "step=1e-300"],
    ["run", "heavy-top", "--method", "top-splitting", "--set", "step=1e-300"],
    ["run", "turntable", "--method", "rk4", "--set", "step=1e-300", "--set", "duration=1e300"],
    ["sweep", "tower-drop", "--method", "rk4", "--set", "step=1e-310", "--grid", "latitude=0:90:3"],
])
def test_a_tiny_step_is_exit_2_not_an_overflow(tmp_path, monkeypatch, capsys, argv):
    monkeypatch.chdir(tmp_path)
    code, out, err = call(capsys, *argv, *(["--no-record"] if argv[0] == "run" else ["--out", "s.parquet"]))
    assert_clean(code, out, err, allowed=(2,))
    assert "step" in err or "rtol" in err
    assert not list(tmp_path.iterdir())  # refused up front: no table, no part, no recording


@pytest.mark.parametrize("key,value", [("step", 1e-310), ("rtol", 5e-324), ("step", 1e-300)])
def test_the_python_api_refuses_a_tiny_step_with_a_rotframe_error(key, value):
    method = "rk4" if key == "step" else "dop853"
    with pytest.raises(RotframeError):
        rotframe.run("turntable", method=method, **{key: value})


@pytest.mark.parametrize("body", [False, True])
def test_your_own_problem_refuses_a_step_count_beyond_any_integer_by_the_limit(body):
    """A fixed step so far below the run's length that the count overflows an integer is over the work limit (one
    line naming the steps), never an OverflowError: the count is a float until it is checked."""
    from rotframe.limits import LimitError

    kw = dict(duration=1e300, method="rk4", step=1e-300)
    with pytest.raises(LimitError, match="integration steps"):
        if body:
            rotframe.simulate_body(inertia=[1.0, 2.0, 3.0], L0=[1.0, 0.0, 0.0], q0=[0.0, 0.0, 0.0, 1.0], **kw)
        else:
            rotframe.simulate(omega=[0.0, 0.0, 1.0], r0=[1.0, 0.0, 0.0], v0=[0.0, 1.0, 0.0], **kw)


@pytest.mark.parametrize("method", ["dop853", "exact"])
def test_too_many_samples_of_a_method_without_a_fixed_step_name_the_samples(method):
    """A sample is no step: an adaptive or exact run over the sample limit is refused for its samples."""
    from rotframe.limits import LimitError

    with pytest.raises(LimitError, match="output samples"):
        rotframe.simulate(omega=[0.0, 0.0, 1.0], r0=[1.0, 0.0, 0.0], v0=[0.0, 1.0, 0.0], duration=1.0,
                          method=method, samples=10**12)


def test_a_scenario_file_in_a_file_refuses_a_subnormal_step(tmp_path, capsys):
    path = tmp_path / "tiny.toml"
    path.write_text('scene = "turntable"\n[run]\nmethod = "rk4"\nstep = 1e-310\n', encoding="utf-8")
    code, out, err = call(capsys, "run", path, "--no-record")
    assert_clean(code, out, err, allowed=(2,))
    assert "tiny.toml" in err and "step" in err


def test_a_huge_scenario_file_is_refused_by_its_size_before_it_is_read(tmp_path, capsys, monkeypatch):
    path = tmp_path / "huge.toml"
    with open(path, "wb") as f:  # sparse: 5 GB that take no disk
        f.truncate(5 * 10**9)
    read = []
    real = Path.read_bytes
    monkeypatch.setattr(Path, "read_bytes", lambda self: read.append(self) or real(self))
    code, out, err = call(capsys, "run", path, "--no-record")
    assert_clean(code, out, err, allowed=(2,))
    assert "huge.toml" in err and "too large" in err
    assert path not in read
    with pytest.raises(ScenarioError, match="too large"):
        rotframe.run(str(path))


def test_a_scenario_file_a_little_over_a_page_still_reads(tmp_path):
    path = tmp_path / "long.toml"
    path.write_text('scene = "turntable"\n' + "# a comment line of a long file\n" * 2000, encoding="utf-8")
    assert rotframe.run(str(path), duration=0.2).complete


@pytest.mark.parametrize("n", [10**4, 10**6])
def test_an_error_about_a_huge_value_is_cut_to_a_readable_line(capsys, n):
    value = ",".join(["1"] * n)
    code, out, err = call(capsys, "run", "dzhanibekov", "--set", f"omega={value}", "--no-record")
    assert_clean(code, out, err, allowed=(2,))
    assert len(err) < MAX_MESSAGE + 100, len(err)
    assert "omega" in err and "characters cut" in err
    with pytest.raises(ScenarioError) as info:
        rotframe.run("dzhanibekov", omega=value)
    assert len(str(info.value)) <= MAX_MESSAGE + 60


def test_readable_keeps_short_messages_and_cuts_long_ones_in_the_middle():
    from rotframe.errors import readable

    assert readable("short") == "short"
    long = "head " + "x" * 5000 + " tail"
    cut = readable(long)
    assert cut.startswith("head ") and cut.endswith(" tail") and len(cut) < MAX_MESSAGE + 60


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full")
@pytest.mark.parametrize("argv", [["run", "turntable", "--no-record", "--json", "--set", "duration=0.2"],
                                  ["list", "--json"], ["list"]])
def test_json_to_a_full_device_is_one_line_and_exit_2(tmp_path, argv):
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"))
    with open("/dev/full", "w") as full:
        proc = subprocess.run([sys.executable, "-m", "rotframe", *argv], cwd=tmp_path, stdout=full,
                              stderr=subprocess.PIPE, text=True, timeout=120, env=env)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr and "No space" in lines[0], proc.stderr


@pytest.mark.parametrize("error", [ImportError("no module named pyarrow"), RuntimeError("ABI mismatch"),
                                   AttributeError("module 'numpy' has no attribute 'x'")])
def test_a_missing_or_broken_pyarrow_names_the_export_extra(tmp_path, monkeypatch, error):
    res = rotframe.run("turntable", duration=0.2, samples=20)
    real = builtins.__import__

    def broken(name, *a, **k):
        if name == "pyarrow" or name.startswith("pyarrow."):
            raise error
        return real(name, *a, **k)

    for mod in [m for m in sys.modules if m == "pyarrow" or m.startswith("pyarrow.")]:
        monkeypatch.delitem(sys.modules, mod)
    monkeypatch.setattr(builtins, "__import__", broken)
    with pytest.raises(ScenarioError, match=r"rotframe\[export\]") as info:
        res.export(tmp_path / "x.parquet")
    assert "\n" not in str(info.value)
    assert list(tmp_path.iterdir()) == []
