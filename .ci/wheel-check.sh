#!/usr/bin/env bash
# CI: build a wheel, install it outside the checkout, and run rotframe from there.
# Uses the current python (the CI venv, whose packages are rotframe's dependencies): the
# wheel is installed with --no-deps into a fresh target folder that is put first on the
# path, and the check runs from a folder outside the checkout, after proving that
# `import rotframe` resolves to the installed copy (not to src/ or an editable install).
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
py="${PYTHON:-python}"
work="$(mktemp -d "${TMPDIR:-/tmp}/rotframe-wheel.XXXXXX")"
trap 'rm -rf "$work"' EXIT
# an isolated build (pip fetches the build backend from the package registry)
"$py" -m pip wheel --no-deps -q -w "$work/dist" "$repo"
wheel="$(ls "$work"/dist/rotframe-*.whl)"
# every module of the source tree and every scenario file is in the wheel (a package missing
# from pyproject's list would not be); read in Python, not through a pipe that grep -q may cut
"$py" - "$wheel" "$repo/src" <<'PY'
import pathlib, sys, zipfile
names = set(zipfile.ZipFile(sys.argv[1]).namelist())
src = pathlib.Path(sys.argv[2])
missing = [str(p.relative_to(src)) for p in src.rglob("rotframe/**/*.py") if str(p.relative_to(src)) not in names]
# the built-in scenarios, shipped as package data from the top-level scenarios/ folder
missing += [f"rotframe/scenarios/{p.name}" for p in (src.parent / "scenarios").glob("*.toml")
            if f"rotframe/scenarios/{p.name}" not in names]
if missing:
    sys.exit(f"wheel-check: the wheel lacks {', '.join(sorted(missing))}")
PY
"$py" -m pip install -q --no-deps --target "$work/site" "$wheel"
mkdir -p "$work/run"
cd "$work/run"
export PYTHONPATH="$work/site"
unset ROTFRAME_SCENARIOS || true
where="$("$py" -c 'import rotframe, os; print(os.path.dirname(rotframe.__file__))')"
[ "$where" = "$work/site/rotframe" ] \
  || { echo "wheel-check: import rotframe resolved to $where, not the installed wheel" >&2; exit 1; }
listed="$("$py" -m rotframe list)"
echo "$listed"
for name in $(ls "$repo/scenarios" | sed 's/\.toml$//'); do
  grep -q "$name" <<<"$listed" || { echo "wheel-check: scenario $name missing from 'rotframe list'" >&2; exit 1; }
done
# every built-in scenario runs from the installed copy
for name in $(ls "$repo/scenarios" | sed 's/\.toml$//'); do
  "$py" -m rotframe run "$name" --no-record --json >"$work/out.json"
  "$py" -c 'import json, sys; d = json.load(open(sys.argv[1])); assert d["metrics"], d' "$work/out.json"
  echo "wheel-check: $name ran"
done
echo "wheel-check: ok ($(basename "$wheel"))"
