"""The run summary as text: what ``rotframe run`` prints without ``--json``.

Each metric beside its theory and their relative difference, each theory named,
each note and warning on its own line; an unresolved diagnostic (None or NaN)
prints as null, as in the JSON.
"""

from __future__ import annotations

import math

__all__ = ["format_summary", "is_number", "short"]


def format_summary(scn, s) -> str:
    """The run summary as a text table; each theory is named and each warning has its own line."""
    lines = [f"{scn.name}: {scn.title}"]
    params = ", ".join(f"{k}={short(v)}{(' ' + scn.parameters[k].unit) if k in scn.parameters and scn.parameters[k].unit else ''}"
                       for k, v in s["params"].items())
    lines.append(f"  parameters  {params}")
    lines.append(f"  model       {', '.join(s['model'])}")
    lines.append(f"  method      {s['method']} ({s['steps']} steps)")
    lines.append("  metric                          simulated        theory    rel. diff")
    for key, value in s["metrics"].items():
        theory = s["theory"].get(key)
        shown = short(value) if is_number(value) else "null"
        if is_number(theory) and is_number(value):
            diff = abs(value - theory) / abs(theory) if theory else abs(value - theory)
            lines.append(f"  {key:<30} {value:>11.6g}  {theory:>12.6g}  {diff:>10.2g}")
        elif is_number(theory):
            lines.append(f"  {key:<30} {shown:>11}  {theory:>12.6g}")
        else:
            lines.append(f"  {key:<30} {shown:>11}")
    for key, value in s["diagnostics"].items():
        unresolved = value is None or (isinstance(value, float) and value != value)  # None or NaN: JSON's null
        lines.append(f"  {key:<30} {'null' if unresolved else short(value):>11}")
    for key, what in s.get("theory_notes", {}).items():
        if key in s["theory"]:
            lines.append(f"  theory of {key}: {what}")
    for note in s.get("notes", []):
        lines.append(f"  note: {note}")
    for warning in s.get("warnings", []):
        lines.append(f"  warning: {warning}")
    if "audit" in s:
        lines.append(s["audit"]["text"])
    t = s["timing"]
    lines.append(f"  timing      simulate {t['simulate_s']:.3f} s (+ {t.get('compile_s', 0):.3f} s loading or "
                 f"compiling kernels), record {t['record_s']:.3f} s, total {t['total_s']:.3f} s")
    lines.append(f"  recording   {s['recording'] or '(none)'}")
    return "\n".join(lines)


def is_number(v) -> bool:
    """A finite int or float (not a bool): what the table prints as a number."""
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def short(v):
    """A value as the table shows it: floats to 6 significant digits, vectors comma-separated."""
    if isinstance(v, float):
        return f"{v:.6g}"
    if isinstance(v, list):
        return ",".join(short(x) for x in v)
    return str(v)
