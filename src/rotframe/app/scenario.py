"""Scenario files: TOML in ``scenarios/``, loaded, validated and resolved to SI.

A scenario file is meant to be read by a physicist who never saw the code::

    name = "tower-drop"
    title = "Reich's drop, Freiberg 1831"
    description = "..."
    scene = "tower-drop"            # which rotframe scene builds the model
    model = ["gravity", "coriolis"] # the terms the scene includes by default

    [parameters.height]
    default = 158.5
    unit = "m"
    min = 0
    doc = "drop height above the ground"

    [run]
    method = "exact"    # default integrator (``rotframe run --method`` overrides)
    step = 1e-3         # s, fixed-step methods
    rtol = 1e-10        # adaptive methods
    samples = 2000      # samples recorded

Values on the command line (``--set KEY=VALUE``) and in the file are numbers in
the parameter's documented unit (SI; angles in degrees), astropy quantity
strings of the right dimension (``"520 ft"``, ``"50d54m"``, ``"48d50m46s N"``)
or, for vectors, comma-separated numbers. Every value is checked: unknown keys
get a did-you-mean, wrong dimensions and impossible values are refused with a
[`ScenarioError`][rotframe.errors.ScenarioError] naming the file, key, value and what is
allowed. This module imports astropy only when a string has to be parsed, so
listing scenarios stays instant.
"""

from __future__ import annotations

import math
import re
import sys
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from rotframe.app.choices import did_you_mean as _did_you_mean
from rotframe.app.quantities import NotAQuantity, WrongDimension, first_line, value_in
from rotframe.errors import ScenarioError
from rotframe.scenes.run_settings import RUN_DEFAULTS

__all__ = ["Scenario", "Parameter", "load", "find", "names", "scenario_dir", "RUN_KEYS", "RUN_DEFAULTS",
           "parse_run_value"]

_TOP_KEYS = ("name", "title", "description", "scene", "model", "optional_terms", "parameters", "run")
_PARAM_KEYS = ("default", "unit", "doc", "min", "max", "exclusive_min", "exclusive_max", "shape", "choices", "type")
#: Settings under ``[run]`` that ``--set`` may change too.
RUN_KEYS = {"method": str, "step": float, "rtol": float, "samples": int}
#: Run settings of a scenario whose ``[run]`` table leaves them out: the one table of run defaults
#: (``method`` None: the scene's default method; ``step`` None: the scene's own step rule).
#: Model terms of rigid-body scenes (particle terms are in rotframe.particles.model.TERMS).
RIGID_TERMS = ("free-rigid-body", "gravity-torque")


def scenario_dir() -> Path:
    """The ``scenarios/`` folder: ``$ROTFRAME_SCENARIOS``, else the checkout's, else the installed package's.

    In a source checkout (``src/rotframe`` beside ``pyproject.toml``) the
    top-level ``scenarios/`` is the source; a wheel ships the same files as
    package data in ``rotframe/scenarios/``.
    """
    import os

    env = os.environ.get("ROTFRAME_SCENARIOS")
    if env:
        return Path(env)
    package = Path(__file__).resolve().parents[1]  # rotframe/
    repo = package.parents[1]
    if (repo / "pyproject.toml").is_file() and (repo / "scenarios").is_dir():
        return repo / "scenarios"
    return package / "scenarios"


def names() -> list[str]:
    """Names of the scenarios in `scenario_dir`, sorted."""
    return sorted(p.stem for p in scenario_dir().glob("*.toml"))


def find(name_or_path: str) -> Path:
    """Resolve a scenario name (inside ``scenarios/``) or a path to a ``.toml`` file.

    A bare name may not escape ``scenarios/``: ``../x`` or ``a/b`` are refused;
    a path must end in ``.toml`` and exist.
    """
    text = str(name_or_path)
    if text.endswith(".toml"):
        path = Path(text)
        try:
            found = path.is_file()
        except (OSError, ValueError) as exc:  # a name too long, a NUL byte
            raise ScenarioError(f"scenario file {text[:80]!r}{'...' if len(text) > 80 else ''}: cannot be "
                                f"read ({first_line(exc)[:80]}); allowed: a path to a .toml file") from None
        if not found:
            raise ScenarioError(f"scenario file {text!r} does not exist")
        return path
    from rotframe.scenes import SCENARIO_FILES, load_plugins

    load_plugins()
    if text in SCENARIO_FILES:  # registered with rotframe.register_scene
        return SCENARIO_FILES[text]
    valid = names()
    if "/" in text or "\\" in text or text.startswith(".") or not text:
        raise ScenarioError(f"scenario {text!r}: not a scenario name; use one of {', '.join(valid)} "
                            "or a path ending in .toml")
    path = scenario_dir() / f"{text}.toml"
    try:
        found = path.is_file()
    except (OSError, ValueError):  # a name too long, a NUL byte: no such scenario
        found = False
    if not found:
        raise ScenarioError(f"unknown scenario {text!r}{_did_you_mean(text, valid)}; available: {', '.join(valid)}")
    return path


@dataclass
class Parameter:
    """One scenario parameter: default, unit, bounds and documentation."""

    name: str
    default: object
    unit: str = ""
    doc: str = ""
    min: float | None = None
    max: float | None = None
    exclusive_min: bool = False
    exclusive_max: bool = False
    shape: int = 0  # 0 scalar, 3 vector
    choices: tuple = ()
    type: str = "float"  # float, int, bool, str, vector

    def bounds_text(self) -> str:
        """What the value may be: ``">= 0, < 90"``, ``"one of a, b"``, or ``""`` where anything goes."""
        lo = [] if self.min is None else [(">" if self.exclusive_min else ">=") + f" {self.min:g}"]
        hi = [] if self.max is None else [("<" if self.exclusive_max else "<=") + f" {self.max:g}"]
        of = ["one of " + ", ".join(map(str, self.choices))] if self.choices else []
        return ", ".join(lo + hi + of)

    def describe(self) -> str:
        bounds, unit = self.bounds_text(), (f" {self.unit}" if self.unit else "")
        return f"{_fmt(self.default)}{unit}" + (f" ({bounds})" if bounds else "")

    @property
    def bounds(self) -> tuple:
        """``(min, max)`` in `unit`, None where unbounded; ``exclusive_min``/``exclusive_max`` say if excluded."""
        return (self.min, self.max)


@dataclass
class Scenario:
    """A loaded, validated scenario: what the scene is, not where it is."""

    name: str
    path: Path
    title: str
    description: str
    scene: str
    model: list
    optional_terms: list
    parameters: dict
    run: dict
    values: dict = field(default_factory=dict)

    def __repr__(self) -> str:
        from rotframe.app.display import scenario_repr
        return scenario_repr(self)

    def _repr_markdown_(self) -> str:
        from rotframe.app.display import markdown, scenario_rows
        return markdown(*scenario_rows(self))

    def _repr_html_(self) -> str:
        from rotframe.app.display import html_table, scenario_rows
        return html_table(*scenario_rows(self))

    def with_values(self, sets: dict | None = None) -> dict:
        """Parameter values (documented units) after applying ``--set`` overrides.

        Run settings (`RUN_KEYS`) may be set the same way; they are
        returned under the key ``"run"``.
        """
        values = {k: p.default for k, p in self.parameters.items()}
        run = dict(self.run)
        for key, raw in (sets or {}).items():
            if key in self.parameters:
                values[key] = parse_value(self.parameters[key], raw, source="--set")
            elif key in RUN_KEYS:
                run[key] = parse_run_value(key, raw, source="--set", scene=self.scene)
            else:
                allowed = list(self.parameters) + list(RUN_KEYS)
                raise ScenarioError(f"--set: unknown key {key!r} for scenario {self.name!r}"
                                    f"{_did_you_mean(key, allowed)}; allowed: {', '.join(allowed)}")
        values["run"] = run
        return values


#: A scenario name: it names the recording ``recordings/<name>.rrd``, so it is a slug.
_SLUG = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,63}")
_TYPES = ("float", "int", "bool", "str", "vector")


#: The largest scenario file read (bytes): a scenario is a page of text; a bigger file is refused by its size
#: before it is read (a sparse file of gigabytes would fill the memory).
MAX_SCENARIO_BYTES = 1 << 20


def _read_toml(path: Path, src: str) -> dict:
    try:
        size = path.stat().st_size
        if size > MAX_SCENARIO_BYTES:
            raise ScenarioError(f"{src}: {size} bytes, too large for a scenario file; allowed: at most "
                                f"{MAX_SCENARIO_BYTES} bytes (a scenario is a page of TOML)")
        raw = path.read_bytes()
    except OSError as exc:
        raise ScenarioError(f"{src}: cannot read the file ({exc.strerror or exc})") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ScenarioError(f"{src}: not a text file (byte {exc.start} is not UTF-8); allowed: a TOML "
                            "scenario file in UTF-8") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{src}: not valid TOML: {exc}") from None
    except RecursionError:  # arrays or inline tables nested thousands deep
        raise ScenarioError(f"{src}: nested too deeply to read; allowed: a scenario file "
                            "(tables of values, a few levels deep)") from None


def _builtin_for_scene(scene: str, path: Path) -> dict | None:
    """The built-in scenario file of ``scene`` (its own name first), as TOML data; None if there is none.

    A scene registered with ``rotframe.register_scene(..., scenario=FILE)`` has FILE as its built-in.
    """
    from rotframe.scenes import SCENARIO_FILES

    folder = scenario_dir()
    candidates = [folder / f"{scene}.toml", *SCENARIO_FILES.values()] + sorted(folder.glob("*.toml"))
    for cand in candidates:
        try:
            if not cand.is_file() or cand.resolve() == path.resolve() or cand.stat().st_size > MAX_SCENARIO_BYTES:
                continue
            data = tomllib.loads(cand.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
            continue
        if data.get("scene") == scene:
            return data
    return None


def _expect(value, kinds, src: str, where: str, allowed: str):
    if isinstance(value, bool) and bool not in kinds or not isinstance(value, kinds):
        raise ScenarioError(f"{src}: {where} = {value!r}: expected {allowed}")
    return value


def _check_top_types(data: dict, src: str):
    for key in ("name", "title", "description", "scene"):
        if key in data:
            _expect(data[key], (str,), src, key, "a string")
    for key in ("model", "optional_terms"):
        if key in data:
            _expect(data[key], (list,), src, key, "a list of term names, e.g. [\"gravity\", \"coriolis\"]")
            for term in data[key]:
                _expect(term, (str,), src, f"{key} item", "a term name (a string)")
    if "parameters" in data:
        _expect(data["parameters"], (dict,), src, "parameters", "a table: [parameters.NAME] with default = ...")
    if "run" in data:
        _expect(data["run"], (dict,), src, "run", "a table: [run] with method, step, rtol or samples")


def _parameter(key: str, spec: dict, src: str) -> Parameter:
    where = f"parameters.{key}"
    for k in ("min", "max"):
        if spec.get(k) is not None:
            _expect(spec[k], (int, float), src, f"{where}.{k}", "a number")
            if not math.isfinite(float(spec[k])):
                raise ScenarioError(f"{src}: {where}.{k} = {spec[k]!r}: expected a finite number")
    for k in ("unit", "doc"):
        if k in spec:
            _expect(spec[k], (str,), src, f"{where}.{k}", "a string")
    for k in ("exclusive_min", "exclusive_max"):
        if k in spec:
            _expect(spec[k], (bool,), src, f"{where}.{k}", "true or false")
    if "shape" in spec:
        _expect(spec["shape"], (int,), src, f"{where}.shape", "a whole number of components (0 or 3)")
        if not 0 <= spec["shape"] <= 16:
            raise ScenarioError(f"{src}: {where}.shape = {spec['shape']!r}: expected 0 (scalar) to 16 components")
    if "choices" in spec:
        _expect(spec["choices"], (list,), src, f"{where}.choices", "a list of allowed strings")
    kind = spec.get("type", None)
    if kind is not None:
        _expect(kind, (str,), src, f"{where}.type", f"one of {', '.join(_TYPES)}")
        if kind not in _TYPES:
            raise ScenarioError(f"{src}: {where}.type = {kind!r}: allowed {', '.join(_TYPES)}"
                                f"{_did_you_mean(kind, list(_TYPES))}")
    unit = spec.get("unit", "")
    p = Parameter(name=key, default=None, unit=unit, doc=spec.get("doc", ""),
                  min=spec.get("min"), max=spec.get("max"),
                  exclusive_min=bool(spec.get("exclusive_min", False)),
                  exclusive_max=bool(spec.get("exclusive_max", False)),
                  shape=int(spec.get("shape", 0)), choices=tuple(spec.get("choices", ())),
                  type=kind or _infer_type(spec))
    p.default = parse_value(p, spec["default"], source=src)
    return p


def _in_scene_unit(key: str, spec: dict, base: dict, src: str) -> dict:
    """``spec`` (a file's redeclaration of the scene's parameter ``key``) with its numbers in the scene's unit.

    The scene reads every value in the unit of its own scenario file; a file that
    declares another unit (``unit = "km"`` where the scene has ``"m"``) has its
    ``default``, ``min`` and ``max`` converted (astropy). A unit of another
    dimension, or one astropy does not know, is refused naming the file, the
    key, the unit and the scene's unit.
    """
    unit, scene_unit = spec.get("unit"), base.get("unit", "")
    if unit is None or not isinstance(unit, str) or not isinstance(scene_unit, str) or unit == scene_unit:
        return spec
    import astropy.units as u
    from astropy.units import imperial

    with imperial.enable():
        try:
            factor = float(u.Unit(unit or "").to(u.Unit(scene_unit) if scene_unit else u.dimensionless_unscaled))
        except (ValueError, TypeError, u.UnitsError) as exc:
            raise ScenarioError(f"{src}: parameters.{key}.unit = {unit!r}: the scene's {key} is in "
                                f"{scene_unit or 'no unit'!r} and {unit!r} does not convert to it "
                                f"({first_line(exc)[:120]}); allowed: a unit of the same dimension") from None
    out = dict(spec, unit=scene_unit)

    def scaled(value):
        if isinstance(value, bool):
            return value
        if isinstance(value, (int, float)):
            return value * factor
        if isinstance(value, str):
            try:
                return float(value) * factor
            except ValueError:
                return value  # a quantity string carries its own unit
        if isinstance(value, list):
            return [scaled(v) for v in value]
        return value

    for k in ("default", "min", "max"):
        if k in spec:
            out[k] = scaled(spec[k])
    return out


def load(name_or_path: str) -> Scenario:
    """Load and validate a scenario by name or path.

    A file that names a built-in scene but leaves out some of that scene's
    parameters (or its ``model``, ``optional_terms`` or ``[run]``) takes them from
    the built-in scenario of the same scene, so a file may declare only what it
    changes.
    """
    path = find(name_or_path)
    src = path.name
    data = _read_toml(path, src)
    _check_keys(data, _TOP_KEYS, src, "top level")
    _check_top_types(data, src)
    if "scene" not in data:
        raise ScenarioError(f"{src}: missing 'scene'")
    from rotframe.scenes import SCENES, load_plugins

    load_plugins()
    scene = data["scene"]
    if scene not in SCENES:
        raise ScenarioError(f"{src}: scene {scene!r} unknown{_did_you_mean(scene, list(SCENES))}; "
                            f"available: {', '.join(SCENES)} (a scene of your own: rotframe.register_scene, "
                            "and ROTFRAME_PLUGINS=module for the command line)")
    name = data.get("name", path.stem)
    if not _SLUG.fullmatch(name) or name in (".", ".."):
        raise ScenarioError(f"{src}: name = {name!r}: not allowed; a name is 1 to 64 letters, digits, '-', '_' "
                            "or '.', starting with a letter or digit (it names the recording file)")
    builtin = _builtin_for_scene(scene, path) or {}
    specs = dict(builtin.get("parameters", {}))
    specs.update(data.get("parameters", {}))
    if not specs:
        raise ScenarioError(f"{src}: missing 'parameters'")
    params = {}
    for key, spec in specs.items():
        if not isinstance(spec, dict):
            spec = {"default": spec}
        base = builtin.get("parameters", {}).get(key)
        if key in data.get("parameters", {}) and isinstance(base, dict):
            # a file may override only the default; the scene's parameter keeps its kind and its unit
            spec = {"type": _infer_type(base), **base, **_in_scene_unit(key, spec, base, src)}
        _check_keys(spec, _PARAM_KEYS, src, f"parameters.{key}")
        if "default" not in spec:
            raise ScenarioError(f"{src}: parameters.{key} has no default")
        params[key] = _parameter(key, spec, src)
    clash = set(params) & set(RUN_KEYS)
    if clash:
        raise ScenarioError(f"{src}: parameter names {sorted(clash)} are reserved for [run]")
    run = dict(RUN_DEFAULTS)
    run_data = data["run"] if "run" in data else builtin.get("run", {})
    for key, raw in run_data.items():
        if key not in RUN_KEYS:
            raise ScenarioError(f"{src}: unknown key 'run.{key}'{_did_you_mean(key, list(RUN_KEYS))}; "
                                f"allowed: {', '.join(RUN_KEYS)}")
        run[key] = parse_run_value(key, raw, source=src, scene=scene)
    model = list(data["model"] if "model" in data else builtin.get("model", []))
    optional = list(data["optional_terms"] if "optional_terms" in data else builtin.get("optional_terms", []))
    from rotframe.particles.model import TERMS

    known = TERMS + RIGID_TERMS
    for term in model + optional:
        if term not in known:
            raise ScenarioError(f"{src}: model term {term!r} unknown{_did_you_mean(term, list(known))}; "
                                f"allowed: {', '.join(known)}")
    return Scenario(name=name, path=path, title=data.get("title", ""),
                    description=data.get("description", "").strip(), scene=scene, model=model,
                    optional_terms=optional, parameters=params, run=run)


# ---------------------------------------------------------------------------
# values
# ---------------------------------------------------------------------------


def parse_value(p: Parameter, raw, source: str = ""):
    """Parse and check one value for parameter ``p``; returns it in ``p.unit``."""
    where = f"{source}: " if source else ""
    if p.type == "bool":
        if isinstance(raw, bool):
            return raw
        text = str(raw).strip().lower()
        if text in ("true", "1", "yes", "on"):
            return True
        if text in ("false", "0", "no", "off"):
            return False
        raise ScenarioError(f"{where}{p.name} = {raw!r}: expected true or false")
    if p.type == "str":
        if not isinstance(raw, (str, int, float)):
            raise ScenarioError(f"{where}{p.name} = {raw!r}: expected a string"
                                + (f"; allowed {', '.join(map(str, p.choices))}" if p.choices else ""))
        value = str(raw)
        if p.choices and value not in p.choices:
            raise ScenarioError(f"{where}{p.name} = {value!r}: allowed {', '.join(map(str, p.choices))}"
                                f"{_did_you_mean(value, list(map(str, p.choices)))}")
        return value
    if p.type == "vector":
        items = raw if isinstance(raw, (list, tuple)) else str(raw).split(",")
        try:
            vec = [_to_float(p, x, where) for x in items]
        except ScenarioError:
            raise
        if not vec or (p.shape and len(vec) != p.shape):
            raise ScenarioError(f"{where}{p.name} = {raw!r}: expected {p.shape or 'one or more'} comma-separated numbers "
                                f"in {p.unit or 'the documented unit'}")
        return vec
    value = _to_float(p, raw, where)
    if p.type == "int":
        if value != int(value):
            raise ScenarioError(f"{where}{p.name} = {raw!r}: expected a whole number")
        value = int(value)
    _check_bounds(p, value, raw, where)
    return value


def _to_float(p: Parameter, raw, where: str) -> float:
    if isinstance(raw, bool):
        raise ScenarioError(f"{where}{p.name} = {raw!r}: expected a number in {p.unit or 'the documented unit'}")
    if isinstance(raw, (int, float)):
        try:
            value = float(raw)
        except OverflowError:  # an integer beyond a float's range
            value = math.inf
    elif isinstance(raw, str):
        value = _parse_quantity(p, raw.strip(), where)
    else:
        raise ScenarioError(f"{where}{p.name} = {raw!r}: expected a number or a quantity string")
    if not math.isfinite(value):
        raise ScenarioError(f"{where}{p.name} = {raw!r}: must be a finite number")
    return value


def _parse_quantity(p: Parameter, text: str, where: str) -> float:
    unit = p.unit or ""
    try:
        return _angle_value(p, text, unit) if unit in ("deg", "rad") else value_in(text, unit)
    except ScenarioError as exc:  # an angle with a letter it does not take, or a sign and a letter
        raise ScenarioError(f"{where}{exc}") from None
    except WrongDimension as exc:
        raise ScenarioError(f"{where}{p.name} = {text!r}: wrong dimension; expected a value in "
                            f"{unit or 'no unit'} ({exc})") from None
    except NotAQuantity as exc:
        example = p.default if isinstance(p.default, (int, float)) and not isinstance(p.default, bool) else 1
        raise ScenarioError(f"{where}{p.name} = {text!r}: not a number or quantity; expected e.g. "
                            f"'{_fmt(example)}{(' ' + unit) if unit else ''}' ({exc})") from None


def _angle_value(p: Parameter, text: str, unit: str) -> float:
    """An angle in ``unit`` (deg or rad): a number, or what [`rotframe.earth.read_angle_text`][rotframe.earth.read_angle_text] reads."""
    try:
        return float(text)
    except ValueError:
        pass
    import astropy.units as u
    from astropy.units import imperial

    with imperial.enable():
        try:
            from rotframe.earth import angle_kind, read_angle_text

            return float(read_angle_text(text, p.name, angle_kind(p.name)).to_value(unit))
        except ScenarioError:
            raise
        except (u.UnitConversionError, u.UnitTypeError) as exc:
            raise WrongDimension(first_line(exc), None) from None
        except (ValueError, TypeError, ArithmeticError) as exc:
            raise NotAQuantity(first_line(exc)) from None


def _check_bounds(p: Parameter, value: float, raw, where: str):
    bad = None
    if p.min is not None and (value < p.min or (p.exclusive_min and value == p.min)):
        bad = ("> " if p.exclusive_min else ">= ") + f"{p.min:g}"
    if p.max is not None and (value > p.max or (p.exclusive_max and value == p.max)):
        bad = ("< " if p.exclusive_max else "<= ") + f"{p.max:g}"
    if bad:
        unit = f" {p.unit}" if p.unit else ""
        shown = raw if isinstance(raw, str) else f"{value:g}"
        raise ScenarioError(f"{where}{p.name} = {shown}: out of range; allowed {bad}{unit}")


_RUN_EXAMPLES = {"step": 1e-3, "rtol": 1e-10, "samples": 2000}


def methods_for(scene: str | None) -> tuple:
    """Integrator names a ``[run] method`` or ``--set method=`` may take for ``scene``.

    One source: the scene module's ``METHODS`` (a
    `rotframe.scenes.base.MethodNames`, whose ``in`` accepts the old names
    too), else every particle integrator; for ``scene=None`` every name of the
    built-in scenes. The scene module is imported here (a run imports it anyway).
    """
    from rotframe import scenes
    from rotframe.scenes.base import MethodNames, particle_methods

    if scene is None:
        found = [methods_for(name) for name, target in scenes.SCENES.items() if isinstance(target, str)]
        return MethodNames(tuple(dict.fromkeys(m for names in found for m in names)),
                           {a: c for names in found for a, c in getattr(names, "aliases", {}).items()})
    methods = getattr(scenes.get(scene), "METHODS", None) if scene in scenes.SCENES else None
    return methods if methods is not None else particle_methods()


def parse_run_value(key, raw, source, scene=None):
    """Parse and check one run setting (a `RUN_KEYS` key) from a file, ``--set`` or the Python API.

    ``method`` must be one of `methods_for` ``(scene)``; ``step`` (s), ``rtol`` and ``samples``
    (a whole number) must be finite and > 0.
    """
    kind = RUN_KEYS[key]
    where = f"{source}: " if source else ""
    if kind is str:
        allowed = methods_for(scene)
        raw = raw.lower() if isinstance(raw, str) else raw  # any case: scipy's "DOP853" is dop853
        if not isinstance(raw, str) or raw not in allowed:
            raise ScenarioError(f"{where}method = {raw!r}: allowed {', '.join(allowed)}"
                                f"{_did_you_mean(str(raw), list(allowed))}")
        return raw
    p = Parameter(name=key, default=_RUN_EXAMPLES[key], unit="s" if key == "step" else "", min=0.0,
                  exclusive_min=True)
    value = _to_float(p, raw, where)
    _check_bounds(p, value, raw, where)
    if 0.0 < value < sys.float_info.min:  # a subnormal keeps too few digits; every count from it overflows
        raise ScenarioError(f"{where}{key} = {raw!r}: below the smallest normal float64 ({sys.float_info.min:.4g}), "
                            f"too small to compute with; allowed: {key} >= {sys.float_info.min:.4g}")
    if kind is int:
        if value != int(value):
            raise ScenarioError(f"{where}{key} = {raw!r}: expected a whole number")
        return int(value)
    return value


# ---------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------


def _infer_type(spec) -> str:
    d = spec.get("default")
    if spec.get("shape"):
        return "vector"
    if isinstance(d, bool):
        return "bool"
    if isinstance(d, list):
        return "vector"
    if isinstance(d, str) and spec.get("choices"):
        return "str"
    if isinstance(d, int) and not spec.get("unit"):
        return "int"
    return "float"


def _check_keys(data: dict, allowed, src: str, where: str):
    for key in data:
        if key not in allowed:
            raise ScenarioError(f"{src}: unknown key {key!r} in {where}{_did_you_mean(key, list(allowed))}; "
                                f"allowed: {', '.join(allowed)}")


def _fmt(value) -> str:
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, list):
        return ",".join(_fmt(v) for v in value)
    return str(value)
