#!/usr/bin/env bash
# CI: the numpydoc Examples sections of the public modules run as doctests.
set -euo pipefail
cd "$(dirname "$0")/.."
python -m pytest -q --doctest-modules -p no:cacheprovider \
    src/rotframe/api.py src/rotframe/units.py src/rotframe/frames.py src/rotframe/inertia.py \
    src/rotframe/rigid.py src/rotframe/principal.py src/rotframe/record.py src/rotframe/sections.py \
    src/rotframe/export.py src/rotframe/errors.py
