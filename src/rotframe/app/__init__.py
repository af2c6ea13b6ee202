"""The application layer: scenario files, runner, recordings, CLI, sweeps, bench.

Everything here may do I/O, print and read units; it imports the layers below
(scenes, particles, rigid, earth, analytic, frames) and none of them imports it.

Within the layer, what several commands share lives in small standard-library
modules at the bottom: :mod:`~rotframe.app.messages` (exit codes, the one-line
error), :mod:`~rotframe.app.options` (``--set`` pairs, JSON-safe values),
:mod:`~rotframe.app.choices` (did-you-mean) and :mod:`~rotframe.app.quantities`
(a value with a unit). :mod:`~rotframe.app.cli` imports the commands
(:mod:`~rotframe.app.sweep`, :mod:`~rotframe.app.bench`, ...); they never import it.
"""
