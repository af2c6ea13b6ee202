"""The application layer: scenario files, runner, recordings, CLI, sweeps, bench.

Everything here may do I/O, print and read units; it imports the layers below
(scenes, particles, rigid, earth, analytic, frames) and none of them imports it.

Within the layer, what several commands share lives in small standard-library
modules at the bottom: `messages` (exit codes, the one-line
error), `options` (``--set`` pairs, JSON-safe values),
`choices` (did-you-mean) and `quantities`
(a value with a unit). `cli` imports the commands
(`sweep`, `bench`, ...); they never import it.
"""
