"""The ``rotframe section`` command: properties of a cross-section.

::

    rotframe section SHAPE [--set KEY=VALUE]... [--png PATH] [--json]

SHAPE is one of `SHAPES`; each parameter has a default, so
``rotframe section i-beam`` alone describes the default I-beam. VALUE is a
number in metres or an astropy quantity string of dimension length
(``"120 mm"``, ``"4.5 inch"``, ``"0.5 ft"``). The polygon takes its vertices as
``"x1,y1;x2,y2;..."`` in the unit given by its ``unit`` key (default m), and
holes as the same separated by ``|``.

Output: an aligned table of the properties in SI units (m, m^2, m^4, deg) or,
with ``--json``, one JSON object on stdout and nothing else::

    {"shape": "rectangle", "params": {"width": 0.1, "height": 0.2},
     "properties": {"area": 0.02, ...}, "units": {"area": "m^2", ...},
     "png": null}

A PNG is written only when ``--png PATH`` is given (nothing is written
otherwise). Exit code 0 on success; 2 on bad input, with one line on stderr
naming the key, the value and what is allowed.
"""

from __future__ import annotations

import json
import math
import sys

import numpy as np

from rotframe.app.choices import did_you_mean
from rotframe.app.options import split_set
from rotframe.app.outputs import OutputError
from rotframe.app.quantities import NotAQuantity, WrongDimension, value_in
from rotframe.app.section_plot import plot_section
from rotframe.rigid.sections import (
    PROPERTY_UNITS,
    SectionError,
    angle,
    channel,
    circle,
    i_beam,
    polygon,
    rectangle,
    tube,
)

__all__ = ["SHAPES", "SHAPE_SUMMARIES", "run_section", "shapes_help"]

#: Shape name -> {parameter: (default as it would be typed after ``--set``, doc)}.
#: Lengths are in metres unless a unit is typed.
SHAPES: dict[str, dict[str, tuple[str, str]]] = {
    "rectangle": {
        "width": ("0.1", "width along x (length)"),
        "height": ("0.2", "height along y (length)"),
    },
    "circle": {
        "diameter": ("0.1", "diameter (length); exact circle"),
    },
    "tube": {
        "outer_diameter": ("0.1143", "outside diameter (length); exact circles"),
        "thickness": ("0.006", "wall thickness (length), at most outer_diameter/2"),
    },
    "i-beam": {
        "depth": ("0.2", "overall depth along y (length)"),
        "flange_width": ("0.1", "flange width along x (length)"),
        "flange_thickness": ("0.0085", "flange thickness (length), less than depth/2"),
        "web_thickness": ("0.0056", "web thickness (length), less than flange_width"),
    },
    "angle": {
        "height": ("0.15", "vertical leg length (length)"),
        "width": ("0.1", "horizontal leg length (length)"),
        "thickness": ("0.01", "leg thickness (length), less than both legs"),
    },
    "channel": {
        "depth": ("0.2", "overall depth along y (length)"),
        "flange_width": ("0.075", "flange width along x, web included (length)"),
        "flange_thickness": ("0.0115", "flange thickness (length), less than depth/2"),
        "web_thickness": ("0.0085", "web thickness (length), less than flange_width"),
    },
    "polygon": {
        "vertices": ("0,0;0.1,0;0,0.1", "outer boundary 'x1,y1;x2,y2;...' (either orientation, simple)"),
        "holes": ("", "holes 'x1,y1;...|x1,y1;...' strictly inside, disjoint (empty: none)"),
        "unit": ("m", "length unit of vertices and holes (astropy name: m, mm, inch, ...)"),
    },
}

#: One-line description of each shape, for ``--help``.
SHAPE_SUMMARIES: dict[str, str] = {
    "rectangle": "solid rectangle [0, width] x [0, height]",
    "circle": "solid circle, exact (not a polygon)",
    "tube": "circular hollow section, exact",
    "i-beam": "doubly symmetric I-section, sharp corners (defaults: IPE 200 without fillets)",
    "angle": "L-section with unequal legs allowed, heel at the origin (default: L 150x100x10)",
    "channel": "C-section with parallel flanges, web on the left (defaults: UPN 200 dimensions)",
    "polygon": "any simple polygon with optional polygonal holes",
}

_LENGTH_ALLOWED = "a positive number in metres or a length quantity such as '120 mm'"
#: Lengths whose fourth power (a second moment) stays a normal double, with room to spare.
_MIN_LENGTH, _MAX_LENGTH = 1e-60, 1e60

_LABELS = {
    "area": "area A",
    "centroid_x": "centroid x_c",
    "centroid_y": "centroid y_c",
    "ixx": "Ixx (about centroid)",
    "iyy": "Iyy (about centroid)",
    "ixy": "Ixy = int x y dA (centroid)",
    "polar_moment": "polar moment Ixx + Iyy",
    "i_major": "I_major (strong axis)",
    "i_minor": "I_minor (weak axis)",
    "principal_angle_deg": "major axis angle from +x",
    "r_x": "radius of gyration r_x",
    "r_y": "radius of gyration r_y",
    "r_major": "radius of gyration r_major",
    "r_minor": "radius of gyration r_minor",
}


def run_section(shape: str, sets: list[str], png: str | None = None, as_json: bool = False) -> int:
    """Compute, print and optionally draw the properties of a section.

    Parameters
    ----------
    shape : str
        One of `SHAPES` (case and ``_``/``-`` are not significant).
    sets : list of str
        ``KEY=VALUE`` overrides of the shape's parameters.
    png : str or None
        Where to write a drawing of the section; nothing is drawn when None.
    as_json : bool
        Print one JSON object instead of the table.

    Returns
    -------
    int
        0 on success, 2 on bad input (one line on stderr).
    """
    try:
        name = _resolve_shape(shape)
        raw = _parse_sets(name, sets)
        with np.errstate(all="ignore"):
            params, section = _build(name, raw)
    except (_InputError, SectionError) as exc:
        return _fail(str(exc))
    except (ArithmeticError, ValueError) as exc:
        return _fail(f"{shape}: the values give no usable section ({' '.join(str(exc).split())}); "
                     f"allowed: {_LENGTH_ALLOWED}")

    written = None
    if png:
        from rotframe.app.plot import require_matplotlib
        from rotframe.errors import MissingExtraError

        try:
            require_matplotlib()
        except MissingExtraError as exc:
            return _fail(str(exc))
        try:
            written = str(plot_section(section, png, title=f"{name}: " + _params_text(params)))
        except OutputError as exc:  # the one writer's error: one line naming the path
            return _fail(f"--png {png!r}: {exc}")
        except OSError as exc:
            return _fail(f"--png {png!r}: cannot write the file ({exc.strerror or exc}); allowed: a writable path")

    try:
        props = _properties(name, params, section)
    except (SectionError, _InputError) as exc:
        return _fail(str(exc))
    if as_json:
        print(
            json.dumps(
                {"shape": name, "params": params, "properties": props, "units": PROPERTY_UNITS, "png": written}
            )
        )
    else:
        print(_table(name, params, props, written))
    return 0


def _properties(name: str, params: dict, section) -> dict:
    """``section.properties()`` as plain floats; a failure or an overflow names the shape and its values."""
    given = _params_text(params)
    try:
        with np.errstate(all="ignore"):
            props = {k: float(v) for k, v in section.properties().items()}
    except SectionError as exc:
        raise _InputError(f"{name}: {given}: {exc}") from None
    except (ArithmeticError, ValueError) as exc:
        raise _InputError(f"{name}: {given}: the properties cannot be computed ({exc})") from None
    bad = [k for k, v in props.items() if not math.isfinite(v)]
    if bad:
        raise _InputError(f"{name}: {given}: {', '.join(bad)} overflow double precision (over 1.8e308); "
                          "allowed: lengths below about 1e70 m")
    return props


def shapes_help() -> str:
    """Text listing every shape with its parameters and defaults, for ``--help``."""
    lines = ["shapes and parameters (--set KEY=VALUE; lengths in m or e.g. '120 mm'):"]
    for name, spec in SHAPES.items():
        lines.append(f"  {name}: {SHAPE_SUMMARIES[name]}")
        for key, (default, doc) in spec.items():
            shown = repr(default) if default == "" else default
            lines.append(f"      {key} = {shown}  ({doc})")
    return "\n".join(lines)


# --------------------------------------------------------------------------
# Helpers
# --------------------------------------------------------------------------


class _InputError(ValueError):
    """Bad command-line input; the message is the one line shown."""


def _fail(message: str) -> int:
    print("rotframe section: " + " ".join(message.split()), file=sys.stderr)
    return 2


def _resolve_shape(shape: str) -> str:
    name = str(shape).strip().lower().replace("_", "-")
    if name in SHAPES:
        return name
    raise _InputError(f"unknown shape {shape!r}{_did_you_mean(name, SHAPES)}; allowed: {', '.join(SHAPES)}")


def _parse_sets(shape: str, sets) -> dict[str, str]:
    spec = SHAPES[shape]
    raw = {key: default for key, (default, _) in spec.items()}
    seen = set()
    for item in sets or []:
        key, value = split_set(item) or ("", "")
        key = key.replace("-", "_")
        if not key:
            raise _InputError(f"--set {item!r} is not KEY=VALUE; allowed keys for {shape}: {', '.join(spec)}")
        if key not in spec:
            raise _InputError(
                f"{shape}: unknown key {key!r} (value {value!r}){_did_you_mean(key, spec)}; "
                f"allowed: {', '.join(spec)}"
            )
        if key in seen:
            raise _InputError(f"{shape}: key {key!r} is set twice (last value {value!r}); allowed: once each")
        seen.add(key)
        raw[key] = value.strip()
    return raw


def _build(shape: str, raw: dict[str, str]):
    if shape == "polygon":
        scale = _parse_unit(raw["unit"])
        outer = _parse_points("vertices", raw["vertices"], scale)
        holes = [
            _parse_points(f"holes (hole {k})", text, scale)
            for k, text in enumerate(raw["holes"].split("|"), start=1)
            if text.strip()
        ]
        params = {"vertices": outer, "holes": holes, "unit": raw["unit"]}
        try:
            return params, polygon(outer, holes)
        except SectionError as exc:
            given = f"vertices = {raw['vertices']!r}" + (f", holes = {raw['holes']!r}" if holes else "")
            raise _InputError(f"polygon: {given}: {exc}") from None
    params = {key: _parse_length(shape, key, text) for key, text in raw.items()}
    builder = {
        "rectangle": rectangle,
        "circle": circle,
        "tube": tube,
        "i-beam": i_beam,
        "angle": angle,
        "channel": channel,
    }[shape]
    return params, builder(**params)


def _parse_length(shape: str, key: str, text: str) -> float:
    """A length in metres from a number (m) or an astropy quantity string."""
    try:
        value = float(text)
    except ValueError:
        value = _quantity_to_metres(shape, key, text)
    if not math.isfinite(value):
        raise _InputError(f"{shape}: {key} = {text!r} is not finite; allowed: {_LENGTH_ALLOWED}")
    if value <= 0.0:
        raise _InputError(f"{shape}: {key} = {text!r} is not positive; allowed: {_LENGTH_ALLOWED}")
    if not _MIN_LENGTH <= value <= _MAX_LENGTH:
        raise _InputError(f"{shape}: {key} = {text!r} ({value:g} m) is out of range; allowed: "
                          f"{_MIN_LENGTH:g} m to {_MAX_LENGTH:g} m (second moments, length^4, must fit a double)")
    return value


def _quantity_to_metres(shape: str, key: str, text: str) -> float:
    try:
        return value_in(text, "m")
    except NotAQuantity:
        raise _InputError(
            f"{shape}: {key} = {text!r} is neither a number nor a quantity; allowed: {_LENGTH_ALLOWED}"
        ) from None
    except WrongDimension as exc:
        raise _InputError(
            f"{shape}: {key} = {text!r} has unit {exc.unit.to_string()!r} ({exc.unit.physical_type}), "
            f"not a length; allowed: {_LENGTH_ALLOWED}"
        ) from None


def _parse_unit(text: str) -> float:
    """Metres per unit of a polygon's coordinates."""
    if text.strip() in ("", "m"):
        return 1.0
    import astropy.units as u
    from astropy.units import imperial

    allowed = "a length unit such as m, mm, cm, inch, ft"
    with imperial.enable():
        try:
            unit = u.Unit(text.strip())
        except (TypeError, ValueError):
            raise _InputError(f"polygon: unit = {text!r} is not a unit; allowed: {allowed}") from None
        if not unit.is_equivalent(u.m):
            raise _InputError(
                f"polygon: unit = {text!r} is a {unit.physical_type}, not a length; allowed: {allowed}"
            )
        return float(unit.to(u.m))


def _parse_points(key: str, text: str, scale: float) -> list[list[float]]:
    allowed = "'x1,y1;x2,y2;...' with at least 3 pairs of finite numbers"
    points = []
    for k, pair in enumerate(p for p in text.split(";") if p.strip()):
        parts = pair.split(",")
        try:
            if len(parts) != 2:
                raise ValueError
            x, y = float(parts[0]), float(parts[1])
        except ValueError:
            raise _InputError(
                f"polygon: {key} = {text!r}: pair {k + 1} {pair.strip()!r} is not x,y; allowed: {allowed}"
            ) from None
        if not (math.isfinite(x) and math.isfinite(y)):
            raise _InputError(
                f"polygon: {key} = {text!r}: pair {k + 1} {pair.strip()!r} is not finite; allowed: {allowed}"
            )
        x, y = x * scale, y * scale
        if max(abs(x), abs(y)) > _MAX_LENGTH:
            raise _InputError(f"polygon: {key} = {text!r}: pair {k + 1} {pair.strip()!r} is out of range; "
                              f"allowed: coordinates up to {_MAX_LENGTH:g} m")
        points.append([x, y])
    if len(points) < 3:
        raise _InputError(f"polygon: {key} = {text!r} has {len(points)} vertices; allowed: {allowed}")
    return points


def _did_you_mean(word: str, choices) -> str:
    """Shape and key names are short: a looser match (0.5) than scenario keys' default (0.6)."""
    return did_you_mean(word, choices, cutoff=0.5)


def _params_text(params: dict) -> str:
    if "vertices" in params:
        return f"{len(params['vertices'])} vertices, {len(params['holes'])} holes"
    return ", ".join(f"{k}={v:.6g} m" for k, v in params.items())


def _table(shape: str, params: dict, props: dict, png: str | None) -> str:
    rows = [(_LABELS[k], f"{v:.6g}", PROPERTY_UNITS[k]) for k, v in props.items()]
    w0 = max(len(r[0]) for r in rows + [("quantity", "", "")])
    w1 = max(len(r[1]) for r in rows + [("", "value", "")])
    lines = [f"section {shape}: {_params_text(params)}", f"{'quantity':<{w0}}  {'value':>{w1}}  unit"]
    lines += [f"{a:<{w0}}  {b:>{w1}}  {c}" for a, b, c in rows]
    lines.append("(second moments about centroidal axes; angle counter-clockwise from +x in (-90, 90])")
    if png:
        lines.append(f"drawing: {png}")
    return "\n".join(lines)
