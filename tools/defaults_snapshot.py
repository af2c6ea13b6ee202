"""Save or check the JSON summary of every built-in scenario run with its defaults.

Used to prove that a refactor changes no number::

    python tools/defaults_snapshot.py save /tmp/before     # on the old tree
    python tools/defaults_snapshot.py check /tmp/before    # on the new tree

``check`` compares model, method, steps, metrics, theory and diagnostics of each
scenario; numbers must agree to ``--rel`` (default 1e-12, bitwise in practice).
Exit status 1 lists every difference.
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
from pathlib import Path

KEYS = ("model", "method", "steps", "metrics", "theory", "diagnostics", "warnings")


def summary(name: str) -> dict:
    out = subprocess.run([sys.executable, "-m", "rotframe", "run", name, "--json", "--no-record"],
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def differences(before, after, rel: float, where: str = ""):
    if isinstance(before, dict) and isinstance(after, dict):
        for key in sorted(set(before) | set(after)):
            yield from differences(before.get(key, "<missing>"), after.get(key, "<missing>"), rel, f"{where}.{key}")
    elif isinstance(before, (int, float)) and isinstance(after, (int, float)) and not isinstance(before, bool):
        if not math.isclose(before, after, rel_tol=rel, abs_tol=1e-300):
            yield f"{where}: {before!r} -> {after!r}"
    elif before != after:
        yield f"{where}: {before!r} -> {after!r}"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("action", choices=("save", "check"))
    parser.add_argument("folder", type=Path)
    parser.add_argument("--rel", type=float, default=1e-12)
    args = parser.parse_args(argv)
    from rotframe import scenarios

    bad = 0
    for name in scenarios():
        name = getattr(name, "name", name)
        path = args.folder / f"{name}.json"
        if args.action == "check" and not path.is_file():
            print(f"{name}: new (no snapshot to compare with)")
            continue
        now = {k: v for k, v in summary(name).items() if k in KEYS}
        if args.action == "save":
            args.folder.mkdir(parents=True, exist_ok=True)
            path.write_text(json.dumps(now, indent=1, sort_keys=True))
            continue
        before = {k: v for k, v in json.loads(path.read_text()).items() if k in KEYS}
        found = list(differences(before, now, args.rel, name))
        bad += len(found)
        print(f"{name}: {'same' if not found else f'{len(found)} differences'}")
        for line in found:
            print("   ", line)
    return 1 if bad else 0


if __name__ == "__main__":
    raise SystemExit(main())
