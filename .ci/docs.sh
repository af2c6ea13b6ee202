#!/usr/bin/env bash
# CI: build the documentation (user guide + API reference from the docstrings); any warning fails.
# Needs the docs extra: python -m pip install -e ".[docs]"
set -euo pipefail
cd "$(dirname "$0")/.."
site="$(mktemp -d)"
trap 'rm -rf "$site"' EXIT
python -m mkdocs build --strict --site-dir "$site"
