"""Door 2 (issue 27): a signal in every phase gives 130 / 143, one line and the partial result.

Each test waits for a sign that the phase began (tests/signs.py), then signals from outside:
a long ``dop853`` heavy-top run (the engine's compiled calls are sized in time), the exact propagator
with its sample limit raised, and numba compiling a kernel from an empty cache.
"""

import signal

import pytest

from signs import start, wait_for


def finish(proc, bound=120):
    out, err = proc.communicate(timeout=bound)  # a bound that turns a hang into a failure, not a timing assertion
    lines = err.strip().splitlines()
    assert "Traceback" not in err and "internal error" not in err, err
    assert len(lines) == 1, err
    return proc.returncode, lines[0]


def test_sigterm_stops_a_long_heavy_top_dop853_run_with_its_partial_recording(tmp_path):
    proc, sign = start(tmp_path, "rotframe.problem.engine", "advance", 3, "run", "heavy-top",
                       "--method", "dop853", "--set", "duration=2e5", "--set", "samples=2000")
    wait_for(sign, proc)
    proc.send_signal(signal.SIGTERM)
    code, line = finish(proc)
    assert code == 143 and "terminated" in line and "simulated time" in line, line
    assert (tmp_path / "recordings" / "heavy-top.partial.rrd").is_file()


def test_sigterm_in_the_exact_propagator_keeps_the_partial_result(tmp_path):
    proc, sign = start(tmp_path, "rotframe.particles.linear", "ExactFlow.states", 1, "run", "tower-drop",
                       "--set", "samples=4e6", "--max-samples", "1e8", "--no-record")
    wait_for(sign, proc)
    proc.send_signal(signal.SIGTERM)
    code, line = finish(proc)
    assert code == 143 and "terminated" in line, line


@pytest.mark.parametrize("sig,code", [("SIGINT", 130), ("SIGTERM", 143)])
def test_a_signal_while_numba_compiles_is_the_signal_not_an_internal_error(tmp_path, sig, code):
    # an empty numba cache: the kernel is compiled in this run, and the signal arrives while it is
    proc, sign = start(tmp_path, "rotframe.particles.chunked", "KernelSetup.warm_up", 1, "run", "foucault",
                       "--set", "duration=1", "--no-record",
                       env={"NUMBA_CACHE_DIR": str(tmp_path / "numba-cache")})
    wait_for(sign, proc)
    proc.send_signal(getattr(signal, sig))
    got, line = finish(proc)
    assert got == code, line
    assert ("terminated" if sig == "SIGTERM" else "interrupted") in line


@pytest.mark.parametrize("name,sets", [
    ("foucault", {"duration": "1e20"}),
    ("foucault", {"duration": "1e12", "length": "0.01", "amplitude": "0.001"}),
    ("tower-drop", {"drag": "1e-4", "height": "1e20"}),
    ("inertial-oscillation", {"duration": "1e20"}),
])
def test_work_beyond_the_limits_is_refused_from_closed_forms_before_any_compiled_work(name, sets, capsys,
                                                                                       monkeypatch):
    import rotframe
    from cli_calls import assert_clean, call
    from rotframe.limits import LimitError
    from rotframe.particles import chunked

    def no_compiled_work(*a, **k):
        raise AssertionError("compiled work started before the limit was checked")

    monkeypatch.setattr(chunked.KernelSetup, "warm_up", no_compiled_work)
    monkeypatch.setattr(chunked.KernelSetup, "call", no_compiled_work)
    method = ["--method", "dop853"]
    argv = ["run", name, *method, "--no-record"] + [x for k, v in sets.items() for x in ("--set", f"{k}={v}")]
    code, out, err = call(capsys, *argv)
    assert_clean(code, out, err, allowed=(2,))
    assert "limit" in err and "--max-steps" in err
    with pytest.raises(LimitError):
        rotframe.run(name, method="dop853", **{k: float(v) for k, v in sets.items()})
