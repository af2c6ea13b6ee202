"""Model only what a scene needs, and show it: toggle each optional term and measure.

``rotframe run NAME --audit`` runs the scene again once per optional term of
the scenario (``optional_terms`` in its file), with that term switched on if
the scene leaves it off and off if it has it, and reports for each term the
peak size of its acceleration along the base path and how much each metric
moves. A term whose effect is far below the metric's accuracy of interest can
be left out with a clear conscience; one that moves the answer cannot.
"""

from __future__ import annotations

import numpy as np

from rotframe.particles.model import term_accelerations

__all__ = ["audit"]


def audit(scn, values, base_result, base_summary, method=None):
    """Toggle each optional term of the finished run ``base_result``; returns ``{"terms": ..., "text": table}``."""
    from rotframe.app import runner
    model = base_result.extras.get("model")
    traj = base_result.trajectory
    peaks = {}
    if model is not None:
        accel = term_accelerations(model, traj.times, traj.r[:, 0], traj.v[:, 0])
        peaks = {k: float(np.max(a)) if np.size(a) else 0.0 for k, a in accel.items()}
    rows = {}
    for term in scn.optional_terms:
        terms = list(base_result.terms)
        switched = "off" if term in terms else "on"
        terms = [t for t in terms if t != term] if switched == "off" else terms + [term]
        result = runner.simulate(scn, values, method=method, terms=terms)
        summary = runner.summarize(scn, values, result, {})
        changes = {}
        for key, base in base_summary["metrics"].items():
            new = summary["metrics"].get(key)
            if isinstance(base, float) and isinstance(new, float):
                changes[key] = {"change": new - base, "relative": (new - base) / abs(base) if base else None}
        rows[term] = {"switched": switched, "peak_acceleration_m_s2": peaks.get(term), "metrics": changes}
    return {"terms": rows, "text": _table(rows, base_summary)}


def _table(rows, base_summary) -> str:
    metric_names = list(base_summary["metrics"])
    lines = ["  audit: each optional term toggled, peak acceleration along the base path, change of each metric"]
    head = f"    {'term':<18} {'switched':<8} {'peak |a| m/s^2':>14}  " + "  ".join(f"{m:>26}" for m in metric_names)
    lines.append(head)
    for term, row in rows.items():
        peak = row["peak_acceleration_m_s2"]
        cells = []
        for m in metric_names:
            ch = row["metrics"].get(m)
            if ch is None:
                cells.append(f"{'-':>26}")
            else:
                rel = f" ({ch['relative']:+.1e})" if ch["relative"] is not None else ""
                cells.append(f"{ch['change']:>+14.3e}{rel:>12}")
        peak_s = f"{peak:14.3e}" if peak is not None else f"{'(no force)':>14}"
        lines.append(f"    {term:<18} {row['switched']:<8} {peak_s}  " + "  ".join(cells))
    return "\n".join(lines)
