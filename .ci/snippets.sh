#!/usr/bin/env bash
# CI: every fenced python and bash block of README.md and docs/guide, as a reader runs it: each
# page top to bottom in a fresh folder (Sybil, configured in conftest.py); a block that cannot
# run here is marked on its page with the reason, which pytest prints (-rs).
set -euo pipefail
cd "$(dirname "$0")/.."
python -m pytest -q -rs -n 0 -p no:cacheprovider README.md docs/guide
