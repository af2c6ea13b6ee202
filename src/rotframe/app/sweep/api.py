"""``rotframe.sweep``: a sweep from Python, returning a pandas DataFrame.

The same implementation as ``rotframe sweep`` (`rotframe.app.sweep.execute.run_sweep`):
the same rows, batches, parts and resume, and bitwise the same table whether it runs
in this process or on a ``distributed.Client`` of the caller's.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

__all__ = ["sweep"]


def sweep(name_or_path, *, grid=None, vary=None, points=None, samples=None, seed=None, client=None, out=None,
          threads=None, device=None, **fixed):
    """Run a scenario once per point and return one row per run.

    Parameters
    ----------
    name_or_path : str or path
        A scenario name (``rotframe.scenarios()``) or a ``.toml`` scenario file.
    grid : dict, optional
        Parameter -> sequence of values; the Cartesian product is swept (last key fastest).
        A vector component is named ``"omega[0]"``.
    vary : dict, optional
        Parameter -> a distribution as on the command line, ``"normal(MEAN,SD)"`` or
        ``"uniform(LO,HI)"``, with ``samples`` draws from ``numpy.random.default_rng(seed)``.
    points : pandas.DataFrame or dict of arrays, optional
        Given points, one row each (for example from ``scipy.stats.qmc``); the columns
        are parameter names.
    samples : int, optional
        Monte Carlo sample count (with ``vary``).
    seed : int, optional
        Seed of the Monte Carlo draws (default 0).
    client : distributed.Client, optional
        Run the batches on this Dask cluster (not closed here); default this process.
    out : path-like, optional
        Also write the table to this ``.parquet`` file (its finished batches go to
        ``<out>.parts/`` as they finish). Default: nothing is written.
    threads : int, optional
        Threads of each vectorised ensemble batch (as ``--threads``; default every core,
        shared out over a local cluster's workers). The table does not depend on it.
    device : {"cpu", "gpu"}, optional
        Where the ensemble batches run (as ``--device``; carried to Dask workers too).
        ``"gpu"`` without a CUDA GPU raises ScenarioError.
    **fixed
        Parameter values fixed for every row (numbers in the documented unit, strings
        such as ``"520 ft"`` or astropy quantities), the run settings ``step``,
        ``rtol`` and ``samples``, and ``method``.

    Returns
    -------
    pandas.DataFrame
        ``row``, the swept values (documented units), every metric, ``theory_<metric>``
        where the scene has a closed form, and ``error`` (empty where the run was fine).

    Raises
    ------
    rotframe.errors.ScenarioError
        Bad input, in one line naming the argument, key and value.
    rotframe.app.sweep.cluster.SweepLost
        The Dask scheduler went away (the finished batches stay in ``<out>.parts/``).
    KeyboardInterrupt
        Ctrl-C (a `SweepInterrupted` saying what was kept).

    Examples
    --------
    >>> import rotframe
    >>> df = rotframe.sweep("tower-drop", grid={"height": [50, 100, 150]}, latitude=45)
    >>> list(df["height"])
    [50.0, 100.0, 150.0]
    """
    from rotframe.app.optional import need
    from rotframe.particles.ensemble import device_scope, threads_scope

    need("pandas", "rotframe.sweep")
    _check_arguments(grid, vary, points, samples, seed, client)
    with threads_scope(threads), device_scope(device):
        return _sweep(name_or_path, grid, vary, points, samples, seed, client, out, fixed)


def _sweep(name_or_path, grid, vary, points, samples, seed, client, out, fixed):
    from rotframe.app.sweep.execute import run_sweep
    from rotframe.app.sweep.spec import python_spec

    method = fixed.pop("method", None)
    sets = {k: _plain(v) for k, v in fixed.items()}
    spec = python_spec(str(name_or_path), sets=sets, grid=grid, vary=vary, points=points, samples=samples, seed=seed,
                       method=method)
    if out is not None:
        return run_sweep(spec, out, client=client, plots=False, recording=False).table.to_pandas()
    with tempfile.TemporaryDirectory(prefix="rotframe-sweep-") as tmp:
        return run_sweep(spec, Path(tmp) / f"{spec.name}.parquet", client=client, plots=False,
                         recording=False).table.to_pandas()


def _check_arguments(grid, vary, points, samples, seed, client):
    """Every argument of `sweep` checked at the door: one ScenarioError line naming it, the value and what is allowed."""
    from rotframe.errors import ScenarioError

    for name, value in (("grid", grid), ("vary", vary)):
        if value is not None and not isinstance(value, dict):
            raise ScenarioError(f"{name}={str(value)[:60]!r}: a dict, parameter -> "
                                + ("a sequence of values" if name == "grid" else "a distribution string"))
    for key, values in (grid or {}).items():
        if isinstance(values, (str, bytes)) or not hasattr(values, "__len__") or isinstance(values, dict):
            raise ScenarioError(f"grid: {key!r} = {str(values)[:60]!r}: a sequence of values, such as [50, 100] "
                                f"(one value: pass {key}=... instead)")
    for key, value in (vary or {}).items():
        if not isinstance(value, str):
            raise ScenarioError(f"vary: {key!r} = {str(value)[:60]!r}: a distribution string, \"normal(MEAN,SD)\" "
                                "or \"uniform(LO,HI)\"")
    if points is not None and not (isinstance(points, dict) or hasattr(points, "columns")):
        raise ScenarioError(f"points={str(points)[:60]!r}: a pandas DataFrame or a dict of equal-length arrays")
    for name, value, least in (("samples", samples, 1), ("seed", seed, 0)):
        if value is None:
            continue
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < least:
            raise ScenarioError(f"{name}={value!r}: a whole number >= {least}")
    if client is not None:
        _check_client(client)


def _check_client(client):
    from rotframe.errors import ScenarioError

    try:
        from distributed import Client
    except Exception:  # distributed missing or broken: no client can be one of its Clients
        Client = None
    if Client is None or not isinstance(client, Client):
        raise ScenarioError(f"client={str(client)[:60]!r}: a distributed.Client (for an address, "
                            "use rotframe sweep --scheduler ADDRESS, or Client(ADDRESS))")
    status = str(getattr(client, "status", "running"))
    if status not in ("running", "connecting", "newly-created"):
        raise ScenarioError(f"client: the distributed.Client is {status}; give an open one")


def _plain(value):
    """An astropy quantity as the text the scenario parser reads (``"520.0 ft"``); anything else as it is."""
    if hasattr(value, "unit") and hasattr(value, "value") and getattr(value, "ndim", 0) == 0:
        return f"{float(value.value)!r} {value.unit.to_string()}"
    return value
