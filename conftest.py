"""The snippets of README.md and docs/guide run as a reader runs them (Sybil; ``.ci/snippets.sh``).

Each page runs top to bottom in a fresh folder of its own, one Python namespace a page (a
block that continues an earlier one says so in its first line), and each ``bash`` block runs in
that folder with ``set -e``, as a reader pastes it into a shell. A block that cannot run here
(an install, a window, minutes of work) is marked on the page with ``<!-- skip: next "why" -->``,
and pytest reports the reason. The main suite does not collect these pages (its ``testpaths`` is
``tests``); ``python -m pytest README.md docs/guide`` does.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

try:
    from sybil import Sybil
    from sybil.parsers.markdown import CodeBlockParser, PythonCodeBlockParser, SkipParser
except ImportError:  # the test extra brings Sybil; without it the pages are simply not collected
    Sybil = None

#: The longest a shell block may run (s): the pages' commands are short runs.
SHELL_TIMEOUT_S = 300


#: The checkout: a page's folder links its examples and tools, as a reader in a clone has them.
ROOT = Path(__file__).resolve().parent


def _enter_folder(namespace):
    """A page starts in a fresh temporary folder (what it writes stays out of the checkout)."""
    folder = tempfile.TemporaryDirectory(prefix="rotframe-page-")
    for name in ("examples", "tools"):
        (Path(folder.name) / name).symlink_to(ROOT / name, target_is_directory=True)
    namespace["_page_folder"] = folder
    namespace["_page_cwd"] = os.getcwd()
    os.chdir(folder.name)
    os.environ["MPLBACKEND"] = "Agg"  # a figure is drawn, never shown in a window


def _leave_folder(namespace):
    os.chdir(namespace["_page_cwd"])
    namespace["_page_folder"].cleanup()


def _run_shell(example):
    """A ``bash`` block, in the page's folder, with the interpreter running the tests first on PATH."""
    env = dict(os.environ, PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}")
    done = subprocess.run(["bash", "-e", "-c", example.parsed], capture_output=True, text=True,
                          timeout=SHELL_TIMEOUT_S, env=env)
    if done.returncode != 0:
        return f"exit {done.returncode}\n--- stdout\n{done.stdout[-3000:]}\n--- stderr\n{done.stderr[-3000:]}"
    return None


if Sybil is not None:
    pytest_collect_file = Sybil(
        parsers=[PythonCodeBlockParser(), CodeBlockParser("bash", evaluator=_run_shell), SkipParser()],
        patterns=["README.md", "*.md"],
        excludes=["CHANGELOG.md"],
        setup=_enter_folder,
        teardown=_leave_folder,
    ).pytest()
