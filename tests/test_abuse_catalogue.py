"""An abuse catalogue of the newer surfaces (issue 27): the Python API, plugins, exports, pictures,
disk faults, signals in every phase and odd scenario files, as a careless or hostile user tries them.

The contract for every case, whatever the surface:

- from the command line: an allowed exit code (0 done, 2 bad input or a refused output, 3 a
  numerical failure, 130/143 a signal), no traceback, and an error in ONE line starting
  ``rotframe``, naming what was wrong (the ``fragment``);
- from Python: a :class:`rotframe.errors.RotframeError` (never a raw OSError, KeyError, ...), one
  line, or a good result;
- nothing half-written: no temporary file left, an earlier file under the final name untouched.

Cases are grouped by class (the door they go through), not by the examples of the issue. All run
in-process (signals too: a wrapped phase signals this process, whose handler the command installs).
"""

import errno
import os
import signal
from pathlib import Path

import numpy as np
import pytest

import rotframe
from cli_calls import call
from rotframe import scenes
from rotframe.errors import RotframeError

GOOD = b"an earlier good file\n"
SHORT = ["--set", "duration=0.2"]


def clean(code, out, err, allowed, fragment=None):
    assert code in allowed, (code, err[-600:])
    assert "Traceback" not in err and "Traceback" not in out, err[-2000:]
    assert "internal error" not in err, err
    if code != 0:
        lines = err.strip().splitlines()
        assert len(lines) == 1, err[-2000:]
        assert lines[0].startswith("rotframe"), lines[0]
        assert len(lines[0]) < 800, len(lines[0])
        if fragment:
            assert fragment.lower() in lines[0].lower(), (fragment, lines[0])


@pytest.fixture(autouse=True)
def in_tmp(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    saved = dict(scenes.SCENES), dict(scenes.SCENARIO_FILES), set(scenes._PLUGINS_LOADED)
    monkeypatch.delenv("ROTFRAME_PLUGINS", raising=False)
    yield tmp_path
    scenes.SCENES.clear()
    scenes.SCENES.update(saved[0])
    scenes.SCENARIO_FILES.clear()
    scenes.SCENARIO_FILES.update(saved[1])
    scenes._PLUGINS_LOADED.clear()
    scenes._PLUGINS_LOADED.update(saved[2])


def no_temporaries(folder):
    left = [p.name for p in Path(folder).rglob("*") if ".tmp" in p.name or p.name.endswith("~")]
    assert not left, left


# --- 1. odd scenario files (the scenario door: rotframe.app.scenario.load) ----------------------------

FILES = {
    "empty": (b"", "scene"),
    "bom": ("\ufeffscene = 'turntable'\n".encode("utf-8"), None),
    "binary": (bytes(range(256)) * 4, "not a text file"),
    "latin1": ("name = 'caf\xe9'\n".encode("latin-1"), "utf-8"),
    "not-toml": (b"this is not = = toml", "toml"),
    "nested-deep": (b"x = " + b"[" * 5000 + b"]" * 5000, None),
    "unknown-top-key": (b'scene = "turntable"\ncolour = "red"\n', "colour"),
    "scene-missing": (b'name = "x"\n', "scene"),
    "scene-unknown": (b'scene = "turntabel"\n', "turntable"),
    "scene-not-string": (b"scene = 3\n", "scene"),
    "name-slash": (b'scene = "turntable"\nname = "../evil"\n', "name"),
    "name-dots": (b'scene = "turntable"\nname = ".."\n', "name"),
    "name-long": (b'scene = "turntable"\nname = "' + b"a" * 300 + b'"\n', "name"),
    "model-unknown-term": (b'scene = "tower-drop"\nmodel = ["gravity", "antigravity"]\n', "antigravity"),
    "model-not-list": (b'scene = "tower-drop"\nmodel = "gravity"\n', "model"),
    "parameters-list": (b'scene = "turntable"\nparameters = [1, 2]\n', "parameters"),
    "run-string": (b'scene = "turntable"\nrun = "fast"\n', "run"),
    "run-unknown-key": (b'scene = "turntable"\n[run]\nspeed = 2\n', "speed"),
    "run-method-unknown": (b'scene = "turntable"\n[run]\nmethod = "euler-forward"\n', "method"),
    "run-method-number": (b'scene = "turntable"\n[run]\nmethod = 4\n', "method"),
    "run-step-negative": (b'scene = "turntable"\n[run]\nstep = -1e-3\n', "step"),
    "run-step-subnormal": (b'scene = "turntable"\n[run]\nmethod = "rk4"\nstep = 1e-320\n', "step"),
    "run-rtol-zero": (b'scene = "turntable"\n[run]\nrtol = 0\n', "rtol"),
    "run-samples-fraction": (b'scene = "turntable"\n[run]\nsamples = 2.5\n', "samples"),
    "run-samples-huge": (b'scene = "turntable"\n[run]\nsamples = 1e15\n', "samples"),
    "run-samples-bool": (b'scene = "turntable"\n[run]\nsamples = true\n', "samples"),
    "param-typo": (b'scene = "tower-drop"\n[parameters.hieght]\ndefault = 3.0\n', "hieght"),
    "param-no-default": (b'scene = "tower-drop"\n[parameters.height]\nunit = "m"\n', None),
    "param-bool-for-number": (b'scene = "tower-drop"\n[parameters.height]\ndefault = true\n', "height"),
    "param-nan": (b'scene = "tower-drop"\n[parameters.height]\ndefault = nan\n', "height"),
    "param-inf": (b'scene = "tower-drop"\n[parameters.height]\ndefault = inf\n', "height"),
    "param-negative": (b'scene = "tower-drop"\n[parameters.height]\ndefault = -5.0\n', "height"),
    "param-wrong-dimension-string": (b'scene = "tower-drop"\n[parameters.height]\ndefault = "3 s"\n', "height"),
    "param-unit-seconds": (b'scene = "tower-drop"\n[parameters.height]\ndefault = 0.1\nunit = "s"\n', "unit"),
    "param-unit-garbage": (b'scene = "tower-drop"\n[parameters.height]\ndefault = 0.1\nunit = "parsecz"\n', "unit"),
    "param-unit-number": (b'scene = "tower-drop"\n[parameters.height]\ndefault = 0.1\nunit = 5\n', "unit"),
    "param-min-string": (b'scene = "tower-drop"\n[parameters.height]\ndefault = 1.0\nmin = "low"\n', "min"),
    "param-max-inf": (b'scene = "tower-drop"\n[parameters.height]\ndefault = 1.0\nmax = inf\n', "max"),
    "param-vector-short": (b'scene = "dzhanibekov"\n[parameters.omega]\ndefault = [1.0, 2.0]\n', "omega"),
    "param-vector-strings": (b'scene = "dzhanibekov"\n[parameters.omega]\ndefault = ["a", "b", "c"]\n', "omega"),
    "param-choice-unknown": (b'scene = "tower-drop"\n[parameters.g_model]\ndefault = "moon"\n', "g_model"),
    "param-datetime": (b'scene = "tower-drop"\n[parameters.height]\ndefault = 1979-05-27\n', "height"),
    "param-huge-int": (b'scene = "tower-drop"\n[parameters.height]\ndefault = 9223372036854775807\n', None),
    "param-table-value": (b'scene = "tower-drop"\n[parameters.height]\ndefault = {a = 1}\n', "height"),
    "param-shape-huge": (b'scene = "dzhanibekov"\n[parameters.omega]\ndefault = [1.0, 2.0, 3.0]\nshape = 10000\n',
                         "shape"),
    "reserved-name": (b'scene = "turntable"\n[parameters.step]\ndefault = 1.0\n', "step"),
    "km-converted": (b'scene = "tower-drop"\n[parameters.height]\ndefault = 0.01\nunit = "km"\n', None),
}


@pytest.mark.parametrize("case", list(FILES))
def test_odd_scenario_file(in_tmp, capsys, case):
    content, fragment = FILES[case]
    path = in_tmp / f"{case}.toml"
    path.write_bytes(content)
    code, out, err = call(capsys, "run", path, "--no-record", *SHORT)
    clean(code, out, err, (0, 2) if fragment is None else (2,), fragment)
    try:
        rotframe.run(str(path), duration=0.2)
    except RotframeError as exc:
        assert "\n" not in str(exc)


PATHS = {
    "missing": ("nope.toml", "does not exist"),
    "a-folder": ("folder.toml", None),
    "nul-byte": ("a\x00b.toml", None),
    "too-long": ("x" * 5000 + ".toml", None),
    "name-escape": ("../etc/passwd", "scenario"),
    "empty-name": ("", None),
}


@pytest.mark.parametrize("case", list(PATHS))
def test_odd_scenario_path(in_tmp, capsys, case):
    text, fragment = PATHS[case]
    if case == "a-folder":
        (in_tmp / "folder.toml").mkdir()
    code, out, err = call(capsys, "run", text, "--no-record")
    clean(code, out, err, (2,), fragment)
    with pytest.raises(RotframeError):
        rotframe.run(text)


def test_sparse_scenario_file_of_gigabytes(in_tmp, capsys):
    path = in_tmp / "big.toml"
    with open(path, "wb") as f:
        f.truncate(3 * 10**9)
    code, out, err = call(capsys, "run", path, "--no-record")
    clean(code, out, err, (2,), "too large")


# --- 2. the Python API's values (the same parsers as the command line) ---------------------------------

API = {
    "none-value": dict(height=None),
    "list-for-scalar": dict(height=[1.0, 2.0]),
    "dict-value": dict(height={"a": 1}),
    "complex": dict(height=1 + 2j),
    "nan": dict(height=float("nan")),
    "inf": dict(height=float("inf")),
    "negative": dict(height=-1.0),
    "bool": dict(height=True),
    "huge-int": dict(height=10**400),
    "numpy-array": dict(height=np.array([1.0, 2.0])),
    "wrong-unit": dict(height="3 kg"),
    "garbage-string": dict(height="tall"),
    "unknown-key": dict(hieght=3.0),
    "method-unknown": dict(method="leapfrog"),
    "method-number": dict(method=4),
    "samples-zero": dict(samples=0),
    "samples-negative": dict(samples=-5),
    "samples-fraction": dict(samples=2.5),
    "samples-huge": dict(samples=1e15),
    "step-zero": dict(step=0.0, method="rk4"),
    "step-subnormal": dict(step=5e-324, method="rk4"),
    "step-tiny": dict(step=1e-300, method="rk4"),
    "rtol-negative": dict(rtol=-1e-9, method="dop853"),
    "rtol-subnormal": dict(rtol=1e-310, method="dop853"),
    "latitude-out-of-range": dict(latitude=91.0),
    "latitude-wrong-letter": dict(latitude="50d N E"),
    "height-overflow": dict(height=1e308),
    "height-subnormal": dict(height=1e-310),
    "drag-dop853-forever": dict(drag=1e-4, height=1e20),
}


@pytest.mark.parametrize("case", list(API))
def test_python_api_bad_value(case):
    kw = dict(API[case])
    with pytest.raises(RotframeError) as info:
        rotframe.run("tower-drop", **kw)
    assert "\n" not in str(info.value) and len(str(info.value)) < 800


@pytest.mark.parametrize("name,kw", [
    ("foucault", dict(duration=1e20)),
    ("foucault", dict(duration=1e15, method="rk4")),
    ("heavy-top", dict(duration=1e15)),
    ("free-top", dict(samples=1e9)),
    ("dzhanibekov", dict(omega="1e300,1e300,1e300")),
    ("inertial-oscillation", dict(duration=1e25, method="dop853")),
])
def test_python_api_work_beyond_the_limits_is_refused_up_front(name, kw):
    with pytest.raises(RotframeError, match="limit|too|must|allowed|overflow|finite"):
        rotframe.run(name, **kw)


@pytest.mark.parametrize("scenario", [3, None, "", "no-such-scene", "../x", b"turntable"])
def test_python_api_bad_scenario_argument(scenario):
    with pytest.raises((RotframeError, TypeError)) as info:
        rotframe.run(scenario)
    if isinstance(info.value, TypeError):
        assert "scenario" in str(info.value)


# --- 3. outputs from Python and the command line (door 1: rotframe.app.outputs.write_atomic) ----------

@pytest.fixture(scope="module")
def result():
    return rotframe.run("turntable", samples=40, duration=0.3)


OUTPUTS = {
    "export-no-suffix": ("export", "out"),
    "export-txt": ("export", "out.txt"),
    "export-folder": ("export", "adir.csv"),
    "export-under-file": ("export", "afile/out.csv"),
    "export-empty": ("export", ""),
    "export-nul": ("export", "a\x00.csv"),
    "plot-folder": ("plot", "adir.png"),
    "plot-under-file": ("plot", "afile/out.png"),
    "record-txt": ("record", "out.txt"),
    "record-folder": ("record", "adir.rrd"),
    "record-under-file": ("record", "afile/out.rrd"),
}


@pytest.mark.parametrize("case", list(OUTPUTS))
def test_python_output_to_an_impossible_path(in_tmp, result, case):
    method, path = OUTPUTS[case]
    (in_tmp / "adir.csv").mkdir()
    (in_tmp / "adir.png").mkdir()
    (in_tmp / "adir.rrd").mkdir()
    (in_tmp / "afile").write_bytes(GOOD)
    with pytest.raises(RotframeError) as info:
        getattr(result, method)(path)
    assert "\n" not in str(info.value)
    assert (in_tmp / "afile").read_bytes() == GOOD
    no_temporaries(in_tmp)


@pytest.mark.parametrize("name", ["out.npz", "out.csv", "with space.csv", "ünïcode.npz", "deep/er/out.csv",
                                  "out.CSV", "out.parquet"])
def test_python_export_to_an_ordinary_path_reads_back(in_tmp, result, name):
    if name.endswith(".parquet"):
        pytest.importorskip("pyarrow")
    path = result.export(in_tmp / name)
    assert path.is_file() and path.stat().st_size > 0
    if name.endswith(".npz"):
        with np.load(path) as data:
            assert np.array_equal(data["times"], result.trajectory.times)
    no_temporaries(in_tmp)


@pytest.mark.parametrize("argv,fragment", [
    (["run", "turntable", "--export", "x.txt"], "--export"),
    (["run", "turntable", "--export", "adir"], "--export"),
    (["run", "turntable", "--export", "afile/x.csv"], "afile"),
    (["run", "turntable", "--png", "x.jpg"], "--png"),
    (["run", "turntable", "--png", "afile/x.png"], "afile"),
    (["run", "turntable", "--png", "adir/"], "--png"),
    (["run", "turntable", "--out", "x.txt"], "--out"),
    (["run", "turntable", "--out", "afile/x.rrd"], "afile"),
    (["section", "rectangle", "--png", "afile/x.png"], "x.png"),
    (["section", "rectangle", "--png", "adir"], "adir"),
    (["bench", "--plots", "afile"], "--plots"),
])
def test_cli_output_to_an_impossible_path(in_tmp, capsys, argv, fragment):
    (in_tmp / "adir").mkdir()
    (in_tmp / "afile").write_bytes(GOOD)
    extra = ["--no-record"] if argv[0] == "run" and "--out" not in argv else []
    code, out, err = call(capsys, *argv, *extra, *(SHORT if argv[0] == "run" else []))
    clean(code, out, err, (2,), fragment)
    assert (in_tmp / "afile").read_bytes() == GOOD
    no_temporaries(in_tmp)


# --- 4. disk faults on every output (door 1) --------------------------------------------------------

class _Full:
    def __init__(self, f, room):
        self.f, self.room = f, room

    def write(self, data):
        n = len(data) if isinstance(data, str) else memoryview(data).nbytes
        if n > self.room:
            raise OSError(self.errno_, os.strerror(self.errno_))
        self.room -= n
        return self.f.write(data)

    def __getattr__(self, name):
        return getattr(self.f, name)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.f.close()


def _inject(monkeypatch, err_no, room=1024):
    from rotframe import files as outputs  # the one writer

    real = open

    def faulty(path, mode="r", *a, **k):
        f = real(path, mode, *a, **k)
        if "w" in mode:
            wrapped = _Full(f, room)
            wrapped.errno_ = err_no
            return wrapped
        return f

    monkeypatch.setattr(outputs, "open", faulty, raising=False)


FAULT_KINDS = [("run", ["--export", "x.csv"], "x.csv"), ("run", ["--export", "x.npz"], "x.npz"),
               ("run", ["--png", "x.png"], "x.png"), ("run", ["--out", "x.rrd"], "x.rrd"),
               ("section", ["--png", "x.png"], "x.png")]


@pytest.mark.parametrize("err_no", [errno.ENOSPC, errno.EFBIG, errno.EIO, errno.EDQUOT])
@pytest.mark.parametrize("command,opts,target", FAULT_KINDS)
def test_a_disk_fault_on_every_output(in_tmp, capsys, monkeypatch, err_no, command, opts, target):
    (in_tmp / target).write_bytes(GOOD)
    _inject(monkeypatch, err_no)
    argv = ["run", "turntable", *SHORT, *(["--no-record"] if "--out" not in opts else []), *opts] \
        if command == "run" else ["section", "rectangle", *opts]
    code, out, err = call(capsys, *argv)
    clean(code, out, err, (2,), target)
    assert (in_tmp / target).read_bytes() == GOOD
    no_temporaries(in_tmp)


# --- 5. signals in every phase, in-process (door 2: the command's InterruptScope) ----------------------

PHASES = [
    ("rotframe.app.runner", "simulate"),
    ("rotframe.app.runner", "summarize"),
    ("rotframe.app.runner", "record_result"),
    ("rotframe.app.export", "write_trajectory"),
    ("rotframe.app.plot", "plot_result"),
    ("rotframe.particles.chunked", "KernelSetup.warm_up"),
    ("rotframe.particles.linear", "ExactFlow.states"),
]


@pytest.mark.parametrize("sig,code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
@pytest.mark.parametrize("module,attr", PHASES)
def test_a_signal_in_every_phase(in_tmp, capsys, monkeypatch, module, attr, sig, code):
    import importlib

    owner = importlib.import_module(module)
    parts = attr.split(".")
    for part in parts[:-1]:
        owner = getattr(owner, part)
    real = getattr(owner, parts[-1])

    def signalled(*a, **k):
        os.kill(os.getpid(), sig)
        return real(*a, **k)

    monkeypatch.setattr(owner, parts[-1], signalled)
    method = ["--method", "rk4"] if "KernelSetup" in attr else []
    argv = ["run", "turntable", *SHORT, *method, "--export", "x.csv", "--png", "x.png", "--out", "x.rrd"]
    got, out, err = call(capsys, *argv)
    clean(got, out, err, (code, 0))
    if got == 0:  # a phase this run does not go through: no signal was sent
        return
    assert ("terminated" if sig == signal.SIGTERM else "interrupted") in err
    no_temporaries(in_tmp)


# --- 6. plugins (door 3: rotframe.scenes._import_plugin and register) ------------------------------

PLUGIN_CASES = {
    "raises": ("raise ValueError('boom')\n", "plugin_raises.py"),
    "syntax": ("x = (\n", "plugin_syntax.py"),
    "keyboard-import": ("import no_module_xyz\n", "plugin_keyboard_import.py"),
    "exits": ("raise SystemExit(0)\n", "plugin_exits.py"),
    "recursion": ("def f():\n    return f()\nf()\n", "plugin_recursion.py"),
    "clash": ("import rotframe, rotframe.scenes.foucault as f\nrotframe.register_scene('foucault', f)\n",
              "foucault"),
    "non-scene": ("import rotframe\nrotframe.register_scene('mine', object())\n", "mine"),
    "bad-toml": ("import rotframe, pathlib, rotframe.scenes.turntable as t\n"
                 "p = pathlib.Path(__file__).with_name('bad.toml'); p.write_text('= nope')\n"
                 "rotframe.register_scene('mine', t, scenario=p)\n", "bad.toml"),
}


@pytest.mark.parametrize("case", list(PLUGIN_CASES))
def test_a_faulty_plugin(in_tmp, capsys, monkeypatch, case):
    source, fragment = PLUGIN_CASES[case]
    plugin = in_tmp / f"plugin_{case.replace('-', '_')}.py"
    plugin.write_text(source, encoding="utf-8")
    monkeypatch.setenv("ROTFRAME_PLUGINS", str(plugin))
    code, out, err = call(capsys, "run", "turntable", "--no-record", *SHORT)
    clean(code, out, err, (2,), fragment)


@pytest.mark.parametrize("value", ["no_such_mod", "./missing.py", ",,,", "rotframe.errors"])
def test_odd_plugin_lists(in_tmp, capsys, monkeypatch, value):
    monkeypatch.setenv("ROTFRAME_PLUGINS", value)
    code, out, err = call(capsys, "run", "turntable", "--no-record", *SHORT)
    clean(code, out, err, (0, 2))


@pytest.mark.parametrize("args", [("", "rotframe.scenes.turntable"), ("a/b", "rotframe.scenes.turntable"),
                                  (3, "rotframe.scenes.turntable"), ("mine", "no.such.module"),
                                  ("mine", "json"), ("mine", 42), ("heavy-top", "rotframe.scenes.turntable")])
def test_register_scene_refusals(args):
    with pytest.raises(RotframeError) as info:
        rotframe.register_scene(*args)
    assert "\n" not in str(info.value)


# --- 7. numbers that become something else (door 4) -------------------------------------------------

@pytest.mark.parametrize("argv,fragment", [
    (["run", "dzhanibekov", "--set", "omega=" + ",".join(["1"] * 200000)], "omega"),
    (["run", "tower-drop", "--set", "height=" + "9" * 5000], "height"),
    (["run", "tower-drop", "--set", "latitude=" + "d" * 5000], "latitude"),
    (["run", "heavy-top", "--set", "theta0=1e-310"], "theta0"),
    (["run", "heavy-top", "--method", "top-splitting8", "--set", "step=1e-309"], "step"),
    (["run", "turntable", "--set", "samples=1e400"], "samples"),
    (["run", "turntable", "--set", "duration=1e-320"], "duration"),
    (["run", "foucault", "--set", "duration=1e20"], "--max-steps"),
    (["run", "foucault", "--set", "duration=1e9", "--max-steps", "1e3"], "--max-steps"),
    (["run", "turntable", "--max-samples", "0"], "max-samples"),
])
def test_numbers_checked_for_what_they_become(in_tmp, capsys, argv, fragment):
    code, out, err = call(capsys, *argv, "--no-record")
    clean(code, out, err, (2,), fragment)
