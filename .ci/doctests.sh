#!/usr/bin/env bash
# CI: the numpydoc Examples sections of the public modules run as doctests.
set -euo pipefail
cd "$(dirname "$0")/.."
python -m pytest -q --doctest-modules -p no:cacheprovider \
    src/rotframe/errors.py src/rotframe/frames src/rotframe/validation.py \
    src/rotframe/numerics src/rotframe/rigid src/rotframe/app/api.py src/rotframe/app/units.py \
    src/rotframe/app/record.py src/rotframe/app/export.py src/rotframe/app/section_plot.py \
    src/rotframe/app/choices.py src/rotframe/app/options.py src/rotframe/app/quantities.py \
    src/rotframe/particles/advice.py src/rotframe/scenes/run_settings.py src/rotframe/method_registry.py src/rotframe/forces.py src/rotframe/torques.py src/rotframe/events.py src/rotframe/problem/callables.py src/rotframe/app/problems.py src/rotframe/app/sweep/api.py \
    src/rotframe/problem/prepared.py src/rotframe/problem/prepared_body.py
