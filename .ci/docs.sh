#!/usr/bin/env bash
# CI: build the documentation (user guide, examples, the quick-start notebook executed by
# mkdocs-jupyter, API reference from the docstrings); any warning or failing cell fails.
# Then check what a reader sees: no raw Sphinx role (mkdocstrings renders Markdown, so
# `:class:`X`` would print literally; tools/fix_roles.py converts them) in the built pages.
# Needs the docs extra: python -m pip install -e ".[docs]"
set -euo pipefail
cd "$(dirname "$0")/.."
site="$(mktemp -d)"
trap 'rm -rf "$site"' EXIT
python -m mkdocs build --strict --site-dir "$site"
if grep -rlE ':(class|func|meth|mod):' "$site" --include='*.html'; then
    echo "docs: raw Sphinx roles in the pages above (run: PYTHONPATH=src python tools/fix_roles.py)" >&2
    exit 1
fi
python tools/fix_roles.py --check
test -s "$site/notebooks/quickstart/index.html"
echo "docs: built with --strict, notebook executed, no raw roles"
