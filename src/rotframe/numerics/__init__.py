"""Numerical building blocks shared by the particle and rigid-body layers.

Pure functions on float64 arrays, no physics of their own: Runge-Kutta tableaus
and error norms, composition weights, rotation primitives, sample decimation.
Nothing here imports from any other part of rotframe except [`rotframe.errors`][rotframe.errors].
"""
