"""The progress line: on a terminal only, never with --json, rate and time left, erased at the end."""

import io

from rotframe.app.progress import Progress


class FakeTTY(io.StringIO):
    def isatty(self):
        return True


def test_progress_draws_rate_and_time_left_on_a_terminal():
    stream = FakeTTY()
    bar = Progress("sweep", "rows", delay=0.0, interval=0.0, stream=stream)
    bar.update(10, 100)
    bar.update(50, 100)
    text = stream.getvalue()
    assert "50/100 rows" in text and "rows/s" in text and "left" in text
    bar.close()
    assert stream.getvalue().endswith("\r")


def test_progress_is_silent_off_a_terminal_and_when_disabled():
    plain = io.StringIO()
    Progress("run", delay=0.0, interval=0.0, stream=plain).update(1, 2)
    assert plain.getvalue() == ""
    tty = FakeTTY()
    Progress("run", delay=0.0, interval=0.0, stream=tty, enabled=False).update(1, 2)
    assert tty.getvalue() == ""


def test_progress_as_a_fraction_callback():
    stream = FakeTTY()
    bar = Progress("run", "%", delay=0.0, interval=0.0, stream=stream)
    bar(0.25)
    assert "25.0%" in stream.getvalue()


def test_json_runs_never_show_progress(tmp_path, capsys, monkeypatch):
    from rotframe.app.cli import main

    monkeypatch.setattr("sys.stderr.isatty", lambda: True, raising=False)
    assert main(["run", "tower-drop", "--no-record", "--json"]) == 0
    out, err = capsys.readouterr()
    assert err == "" and out.startswith("{")
