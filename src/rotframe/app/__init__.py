"""The application layer: scenario files, runner, recordings, CLI, sweeps, bench.

Everything here may do I/O, print and read units; it imports the layers below
(scenes, particles, rigid, earth, analytic, frames) and none of them imports it.
"""
