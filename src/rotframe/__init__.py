"""rotframe: dynamics seen from rotating frames.

The centre of the package is the transport theorem,
``(d/dt)_space = (d/dt)_body + omega x``. Importing :mod:`rotframe` is cheap:
subpackages that need astropy, numba or rerun are imported only when used.
"""

__version__ = "0.1.0"
