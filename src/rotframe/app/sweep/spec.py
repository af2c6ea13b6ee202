"""What a sweep runs: the spec from the command line's pieces, and its rows of swept values.

A swept key is a numeric parameter or one component of a vector parameter
(``omega[0]``). Grid rows are the Cartesian product of ``--grid`` / ``--log-grid``
axes (last axis fastest); Monte Carlo rows are drawn from
``numpy.random.default_rng(seed)``, one ``--vary`` distribution after the other.
"""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import asdict, dataclass, field

import numpy as np

from rotframe.app.options import split_set
from rotframe.errors import ScenarioError

__all__ = ["Axis", "Vary", "SweepSpec", "SweptKey", "DISTRIBUTIONS", "parse_spec", "python_spec", "sweep_points", "points_of",
           "key_of", "apply_row"]


DISTRIBUTIONS = {"normal": ("MEAN", "SD"), "uniform": ("LO", "HI")}


@dataclass(frozen=True)
class Axis:
    """One grid axis: ``key`` swept over ``values`` (documented unit); ``log`` for a log-spaced grid."""

    key: str
    values: tuple
    log: bool = False


@dataclass(frozen=True)
class Vary:
    """One Monte Carlo distribution: ``normal(a=mean, b=sd)`` or ``uniform(a=lo, b=hi)``."""

    key: str
    dist: str
    a: float
    b: float


@dataclass
class SweepSpec:
    """What to sweep: validated by `parse_spec`, turned into rows by `sweep_points`.

    Attributes
    ----------
    scenario : str
        Scenario name or ``.toml`` path, as given.
    name : str
        The scenario's name (default output names).
    sets : dict
        ``--set`` values fixed for every row.
    axes : list of Axis
        Grid axes (empty for a Monte Carlo sweep).
    samples : int or None
        Monte Carlo sample count.
    vary : list of Vary
    seed : int
    method : str or None
    points : (rows, keys) float array or None
        Given points, one row each (``rotframe.sweep(points=...)``); their keys are ``point_keys``.
    point_keys : list of str
    """

    scenario: str
    name: str
    sets: dict
    axes: list = field(default_factory=list)
    samples: int | None = None
    vary: list = field(default_factory=list)
    seed: int = 0
    method: str | None = None
    points: object = None
    point_keys: list = field(default_factory=list)

    @property
    def keys(self) -> list:
        """Swept keys, in column order."""
        return [a.key for a in self.axes] + [v.key for v in self.vary] + list(self.point_keys)

    @property
    def log_keys(self) -> set:
        """Keys on a log-spaced grid (plotted on a log axis)."""
        return {a.key for a in self.axes if a.log}

    @property
    def n_rows(self) -> int:
        """Number of points."""
        if self.points is not None:
            return int(len(self.points))
        if self.axes:
            return int(np.prod([len(a.values) for a in self.axes]))
        return int(self.samples or 0)

    def describe(self) -> dict:
        """A JSON-able description, stored in every Parquet file of the sweep (given points by their digest)."""
        out = {"scenario": self.name, "sets": {k: _jsonable(v) for k, v in self.sets.items()},
               "axes": [[a.key, list(a.values), a.log] for a in self.axes], "samples": self.samples,
               "vary": [asdict(v) for v in self.vary], "seed": self.seed, "method": self.method,
               "keys": self.keys, "rows": self.n_rows}
        if self.points is not None:
            import hashlib

            data = np.ascontiguousarray(self.points, dtype=np.float64)
            out["points"] = {"keys": list(self.point_keys), "sha256": hashlib.sha256(data.tobytes()).hexdigest()}
        return out


def _jsonable(value):
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, (np.floating, np.integer)):
        return value.item()
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    return value if isinstance(value, (str, int, float, bool, type(None))) else str(value)


def parse_spec(scenario, *, sets=None, grid=(), log_grid=(), samples=None, vary=(), seed=0, method=None):
    """Validate the sweep's command-line pieces into a `SweepSpec`.

    Parameters
    ----------
    scenario : str
        Scenario name or ``.toml`` path.
    sets : dict, optional
        ``{key: value}`` fixed for every row (validated as ``rotframe run --set``).
    grid, log_grid : sequence of str
        ``KEY=START:STOP:N``: N linearly (logarithmically, both bounds > 0) spaced values, inclusive.
    samples : int, optional
        Monte Carlo sample count (with ``vary``).
    vary : sequence of str
        ``KEY=normal(MEAN,SD)`` or ``KEY=uniform(LO,HI)``.
    seed : int
    method : str, optional
        Integrator, checked against the scene's methods.

    Raises
    ------
    ScenarioError
        One line naming the option, key and value and what is allowed.
    """
    from rotframe.app import scenario as sc
    scn = sc.load(scenario)
    sets = dict(sets or {})
    base = scn.with_values(sets)
    _check_method(scn, method)
    axes = [_parse_axis(scn, base, text, log=False) for text in grid]
    axes += [_parse_axis(scn, base, text, log=True) for text in log_grid]
    varies = [_parse_vary(scn, base, text) for text in vary]
    _check_shape(axes, varies, samples)
    from rotframe import limits

    rows = math.prod(len(a.values) for a in axes) if axes else int(samples or 0)
    limits.check_rows(rows, what="sweep")
    spec = SweepSpec(scenario=str(scenario), name=scn.name, sets=sets, axes=axes, samples=samples,
                     vary=varies, seed=int(seed), method=method)
    _check_keys_once(spec)
    return spec


def python_spec(scenario, *, sets=None, grid=None, vary=None, points=None, samples=None, seed=None, method=None):
    """A `SweepSpec` from ``rotframe.sweep``'s arguments (Python values, not command-line text).

    ``grid``: key -> sequence of values (the product is taken, last key fastest); ``vary``: key ->
    a distribution string as on the command line (``"normal(1600,5)"``) with ``samples``; ``points``:
    a pandas DataFrame or a dict of equal-length arrays, one row each. One of the three.

    Raises
    ------
    ScenarioError
        One line naming the argument, the key and the value and what is allowed.
    """
    from rotframe.app import scenario as sc

    given = [n for n, v in (("grid", grid), ("vary", vary), ("points", points)) if v is not None and len(v)]
    if len(given) > 1:
        raise ScenarioError(f"sweep: give one of grid=, vary= (with samples=) or points=, not {' and '.join(given)}")
    if points is None or not len(points):
        if vary or samples is not None:
            return parse_spec(scenario, sets=sets, samples=samples, seed=0 if seed is None else seed, method=method,
                              vary=[f"{k}={v}" for k, v in (vary or {}).items()])
        return _grid_spec(scenario, sets, grid or {}, method)
    if samples is not None:
        raise ScenarioError("sweep: samples= goes with vary=, not with points= (whose length is the row count)")
    scn = sc.load(scenario)
    sets = dict(sets or {})
    base = scn.with_values(sets)
    _check_method(scn, method)
    names, cols = _point_columns(points)
    keys = [_parse_key(scn, "points", name) for name in names]
    for key, col in zip(keys, cols):
        if len(col) and not np.all(np.isfinite(col)):
            raise ScenarioError(f"points: column {key.text!r} has a non-finite value; allowed: finite numbers")
        if len(col):
            _check_value(scn, base, key, "points", key.text, col)
    from rotframe import limits

    limits.check_rows(len(cols[0]), what="sweep")
    spec = SweepSpec(scenario=str(scenario), name=scn.name, sets=sets, seed=0 if seed is None else int(seed),
                     method=method, points=np.stack(cols, axis=1), point_keys=[k.text for k in keys])
    _check_keys_once(spec)
    return spec


def _documented_unit(values, unit, key):
    """Grid values with any Quantity converted to the parameter's documented unit (never stripped)."""
    from rotframe.app.quantities import astropy_unit, holds_quantity, to_si

    if not holds_quantity(values):
        return values
    return to_si(values, astropy_unit(unit) if unit else "", key)


def _grid_spec(scenario, sets, grid, method):
    from rotframe.app import scenario as sc

    scn = sc.load(scenario)
    base = scn.with_values(dict(sets or {}))
    axes = []
    for name, values in grid.items():
        key = _parse_key(scn, "grid", str(name))
        values = _documented_unit(values, scn.parameters[key.param].unit, f"grid: {name!r}")
        try:
            arr = np.atleast_1d(np.asarray(values, dtype=np.float64))
        except (TypeError, ValueError):
            raise ScenarioError(f"grid: {name!r} = {str(values)[:80]!r}: not a sequence of numbers") from None
        if arr.ndim != 1 or not len(arr) or not np.all(np.isfinite(arr)):
            raise ScenarioError(f"grid: {name!r}: allowed: a non-empty sequence of finite numbers")
        _check_value(scn, base, key, "grid", str(name), arr)
        axes.append(Axis(key.text, tuple(float(x) for x in arr)))
    spec = parse_spec(scenario, sets=sets, method=method, grid=[], samples=None, vary=[]) if not axes else None
    if spec is not None:
        return spec  # (parse_spec's own "nothing to sweep" error)
    from rotframe import limits

    limits.check_rows(math.prod(len(a.values) for a in axes), what="sweep")
    _check_method(scn, method)
    spec = SweepSpec(scenario=str(scenario), name=scn.name, sets=dict(sets or {}), axes=axes, method=method)
    _check_keys_once(spec)
    return spec


def _point_columns(points):
    """(names, float columns) of a DataFrame or a dict of equal-length arrays."""
    try:
        names = [str(c) for c in points.keys()]
        cols = [np.asarray(points[c], dtype=np.float64).ravel() for c in points.keys()]
    except (AttributeError, TypeError, ValueError) as exc:
        raise ScenarioError(f"points: {type(points).__name__}: allowed: a pandas DataFrame or a dict of "
                            f"equal-length arrays of numbers ({str(exc)[:80]})") from None
    if not cols or len({len(c) for c in cols}) != 1 or not len(cols[0]):
        raise ScenarioError("points: the columns must be non-empty and of equal length "
                            f"(got {', '.join(f'{n}: {len(c)}' for n, c in zip(names, cols))})")
    return names, cols


def sweep_points(spec: SweepSpec) -> np.ndarray:
    """The swept values, one row per point: a (rows, keys) float array in `SweepSpec.keys` order.

    Grid rows are the Cartesian product of the axes (last axis fastest); Monte Carlo
    rows are drawn from ``default_rng(seed)``, one distribution after the other, so the
    same spec always gives the same rows.
    """
    if spec.points is not None:
        return np.asarray(spec.points, dtype=np.float64)
    if spec.axes:
        grid = list(itertools.product(*[a.values for a in spec.axes]))
        return np.array(grid, dtype=np.float64).reshape(len(grid), len(spec.axes))
    rng = np.random.default_rng(spec.seed)
    cols = [rng.normal(v.a, v.b, spec.samples) if v.dist == "normal" else rng.uniform(v.a, v.b, spec.samples)
            for v in spec.vary]
    return np.stack(cols, axis=1).astype(np.float64)


def points_of(spec: SweepSpec, rows) -> np.ndarray:
    """The swept values of the given ``rows`` only (as `sweep_points` would give them).

    Grid points are computed from their row index, so a large grid is never held
    whole; Monte Carlo rows are drawn in order from the seed.
    """
    rows = np.asarray(rows, dtype=np.int64)
    if spec.points is not None:
        return np.asarray(spec.points, dtype=np.float64)[rows]
    if spec.axes:
        shape = tuple(len(a.values) for a in spec.axes)
        idx = np.unravel_index(rows, shape) if len(rows) else [np.zeros(0, np.int64)] * len(shape)
        cols = [np.asarray(a.values, dtype=np.float64)[i] for a, i in zip(spec.axes, idx)]
        return np.stack(cols, axis=1) if cols else np.zeros((len(rows), 0))
    return sweep_points(spec)[rows]


@dataclass(frozen=True)
class SweptKey:
    """A swept key: a parameter, or one component of a vector parameter (``omega[0]``)."""

    text: str
    param: str
    index: int | None = None


def _parse_key(scn, option, text):
    m = re.fullmatch(r"\s*([A-Za-z_][\w-]*)\s*(?:\[\s*(\d+)\s*\])?\s*", text)
    allowed = _sweepable(scn)
    if not m or m.group(1) not in scn.parameters:
        word = m.group(1) if m else text
        raise ScenarioError(f"{option}: unknown key {text!r} for scenario {scn.name!r}"
                            f"{_did_you_mean(word, allowed)}; sweepable: {', '.join(allowed)}")
    p = scn.parameters[m.group(1)]
    if p.type == "vector":
        size = p.shape or len(p.default)
        if m.group(2) is None or int(m.group(2)) >= size:
            raise ScenarioError(f"{option}: {text!r} is a vector of {size}; sweep one component, "
                                f"{m.group(1)}[0] to {m.group(1)}[{size - 1}]")
        return SweptKey(f"{m.group(1)}[{int(m.group(2))}]", m.group(1), int(m.group(2)))
    if p.type not in ("float", "int") or m.group(2) is not None:
        raise ScenarioError(f"{option}: {text!r} is not a numeric parameter ({p.type}); "
                            f"sweepable: {', '.join(allowed)}")
    return SweptKey(m.group(1), m.group(1))


def _sweepable(scn):
    out = []
    for name, p in scn.parameters.items():
        if p.type in ("float", "int"):
            out.append(name)
        elif p.type == "vector":
            out.append(f"{name}[i]")
    return out


def _parse_axis(scn, base, text, log):
    option = "--log-grid" if log else "--grid"
    key_text, spec = _split_assignment(option, text, "KEY=START:STOP:N")
    key = _parse_key(scn, option, key_text)
    parts = spec.split(":")
    if len(parts) != 3:
        raise ScenarioError(f"{option} {text!r}: expected KEY=START:STOP:N (N values from START to STOP)")
    n = _parse_count(option, text, parts[2])
    from rotframe import limits

    limits.check_rows(n, what=f"{option} {text!r}")
    lo, hi = (_parse_number(scn, key, option, text, s) for s in parts[:2])
    if log and not (lo > 0 and hi > 0):
        raise ScenarioError(f"{option} {text!r}: START and STOP must both be > 0 for a logarithmic grid")
    values = np.geomspace(lo, hi, n) if log else np.linspace(lo, hi, n)
    if key.index is None and scn.parameters[key.param].type == "int":
        values = np.unique(np.round(values))
    _check_value(scn, base, key, option, text, values)
    return Axis(key.text, tuple(float(x) for x in values), log)


def _parse_vary(scn, base, text):
    key_text, spec = _split_assignment("--vary", text, "KEY=normal(MEAN,SD) or KEY=uniform(LO,HI)")
    key = _parse_key(scn, "--vary", key_text)
    m = re.fullmatch(r"\s*([A-Za-z_]\w*)\s*\(\s*([^,()]+?)\s*,\s*([^,()]+?)\s*\)\s*", spec)
    allowed = "normal(MEAN,SD), uniform(LO,HI)"
    if not m:
        raise ScenarioError(f"--vary {text!r}: expected KEY=normal(MEAN,SD) or KEY=uniform(LO,HI)")
    dist = m.group(1)
    if dist not in DISTRIBUTIONS:
        raise ScenarioError(f"--vary {text!r}: unknown distribution {dist!r}"
                            f"{_did_you_mean(dist, list(DISTRIBUTIONS))}; allowed: {allowed}")
    a, b = (_parse_number(scn, key, "--vary", text, s) for s in m.groups()[1:])
    if dist == "normal" and b < 0:
        raise ScenarioError(f"--vary {text!r}: SD = {b:g} must be >= 0")
    if dist == "uniform" and b < a:
        raise ScenarioError(f"--vary {text!r}: LO = {a:g} must not exceed HI = {b:g}")
    centre = np.array([a if dist == "normal" else 0.5 * (a + b)])
    _check_value(scn, base, key, "--vary", text, centre)
    return Vary(key.text, dist, a, b)


def _split_assignment(option, text, form):
    pair = split_set(text)
    if pair is None:
        raise ScenarioError(f"{option} {text!r}: expected {form}")
    return pair


def _parse_count(option, text, raw):
    try:
        n = int(raw.strip())
    except ValueError:
        raise ScenarioError(f"{option} {text!r}: N = {raw.strip()!r} must be a whole number >= 1") from None
    if n < 1:
        raise ScenarioError(f"{option} {text!r}: N = {n} must be >= 1")
    return n


def _parse_number(scn, key, option, text, raw):
    """A number (or quantity string) in the parameter's unit; bounds are checked later."""
    from rotframe.app.scenario import Parameter, parse_value

    p = Parameter(name=key.text, default=0.0, unit=scn.parameters[key.param].unit)
    try:
        return float(parse_value(p, raw.strip(), source=f"{option} {text!r}"))
    except ScenarioError as exc:
        raise ScenarioError(str(exc)) from None


def _check_value(scn, base, key, option, text, values):
    """The extreme grid values (or the distribution's centre) must be valid values of the parameter."""
    for x in {float(np.min(values)), float(np.max(values))}:
        try:
            apply_row(scn, dict(base), [key], [x])
        except ScenarioError as exc:
            raise ScenarioError(f"{option} {text!r}: {exc}") from None


def _check_shape(axes, varies, samples):
    if axes and (varies or samples is not None):
        raise ScenarioError("sweep: give either --grid/--log-grid or --samples with --vary, not both")
    if samples is not None and samples < 1:
        raise ScenarioError(f"--samples {samples}: must be >= 1")
    if varies and samples is None:
        raise ScenarioError("--vary needs --samples N (the number of Monte Carlo samples)")
    if samples is not None and not varies:
        raise ScenarioError(f"--samples {samples}: give at least one --vary KEY=normal(MEAN,SD)|uniform(LO,HI)")
    if not axes and not varies:
        raise ScenarioError("sweep: nothing to sweep; give --grid KEY=START:STOP:N, --log-grid or --samples N "
                            "with --vary")


def _check_keys_once(spec):
    seen = set()
    for key in spec.keys:
        if key in seen:
            raise ScenarioError(f"sweep: key {key!r} is swept twice")
        seen.add(key)
        param = key.split("[")[0]
        if param in spec.sets and "[" not in key:
            raise ScenarioError(f"sweep: key {key!r} is both fixed by --set and swept")


def _check_method(scn, method):
    if method is None:
        return
    from rotframe import scenes
    from rotframe.particles.integrators import METHOD_NAMES

    allowed = getattr(scenes.get(scn.scene), "METHODS", None) or list(METHOD_NAMES)
    if method not in allowed:
        raise ScenarioError(f"--method {method!r}: allowed for {scn.name}: {', '.join(allowed)}"
                            f"{_did_you_mean(method, list(allowed))}")


def _did_you_mean(word, options):
    from rotframe.app.choices import did_you_mean as suggest

    plain = [o.split("[")[0] for o in options]
    return suggest(word, plain) or suggest(word, list(options))


def key_of(text):
    m = re.fullmatch(r"(.+)\[(\d+)\]", text)
    return SweptKey(text, m.group(1), int(m.group(2))) if m else SweptKey(text, text)


def apply_row(scn, values, keys, row):
    """``values`` with the swept keys set to ``row`` (validated); vector components replace one entry."""
    from rotframe.app.scenario import parse_value

    for key, x in zip(keys, row):
        p = scn.parameters[key.param]
        if key.index is None:
            values[key.param] = parse_value(p, float(x))
        else:
            vec = list(values[key.param])
            vec[key.index] = float(x)
            values[key.param] = parse_value(p, vec)
    return values
