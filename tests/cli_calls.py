"""Helpers for tests that drive the command line in-process: one call, and what a clean outcome is."""

from rotframe.app.cli import main


def call(capsys, *argv):
    """``rotframe ARGV...`` in this process; returns (exit code, stdout, stderr)."""
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def assert_clean(code, out, err, allowed=(0, 2, 3)):
    """An allowed exit, no traceback, and an error (if any) in one line starting 'rotframe'."""
    assert code in allowed, (code, out, err)
    assert "Traceback" not in err and "Traceback" not in out
    if code != 0:
        lines = err.strip().splitlines()
        assert len(lines) == 1, err
        assert lines[0].startswith("rotframe"), err
