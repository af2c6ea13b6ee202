"""How scenarios and results show themselves: a short repr, and tables for Jupyter.

``repr(scenario)`` is one line (name, scene, parameter count, method);
``_repr_markdown_`` and ``_repr_html_`` give tables that Jupyter shows when a
`Scenario` or a `Result` is the last expression of a cell: the parameters
with unit, default, bounds and meaning; a run's metrics beside their theory
with units, and its warnings.
"""

from __future__ import annotations

import html
import math

__all__ = ["scenario_repr", "scenario_rows", "result_rows", "markdown", "html_table"]


def _fmt(value) -> str:
    if isinstance(value, bool) or value is None:
        return str(value)
    if isinstance(value, float):
        return "nan" if math.isnan(value) else f"{value:.6g}"
    if isinstance(value, (list, tuple)):
        return "(" + ", ".join(_fmt(v) for v in value) + ")"
    return str(value)


def scenario_repr(scn) -> str:
    """``<rotframe.Scenario foucault: scene foucault, 8 parameters, method dop853>``."""
    method = scn.run.get("method")
    return (f"<rotframe.Scenario {scn.name}: scene {scn.scene}, {len(scn.parameters)} parameters, "
            f"{'method ' + method if method else 'the scene' + chr(39) + 's default method'}>")


def scenario_rows(scn) -> tuple[str, list[str], list[list[str]]]:
    """Title, header and rows of a scenario's parameter table."""
    rows = [[name, _fmt(p.default), p.unit, p.bounds_text(), p.doc] for name, p in scn.parameters.items()]
    title = f"{scn.name}: {scn.title}" if getattr(scn, "title", "") else scn.name
    return title, ["parameter", "default", "unit", "allowed", "meaning"], rows


def result_rows(result) -> tuple[str, list[str], list[list[str]], list[str]]:
    """Title, header, rows (metrics beside theory) and warnings of a result."""
    units = result.units
    rows = [[key, _fmt(value), _fmt(result.theory.get(key, "")) if key in result.theory else "", units.get(key, "")]
            for key, value in result.metrics.items()]
    state = "" if result.complete else ", incomplete"
    title = f"{result.scenario.name} ({result.method}{state})"
    return title, ["metric", "measured", "theory", "unit"], rows, result.warnings


def markdown(title: str, header: list[str], rows: list[list[str]], warnings=()) -> str:
    """A Markdown table under a bold title, with warnings listed after it."""
    def cell(text):
        return str(text).replace("|", "\\|").replace("\n", " ")

    lines = [f"**{cell(title)}**", "", "| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(cell(c) for c in row) + " |" for row in rows]
    if warnings:
        lines += [""] + [f"- warning: {cell(w)}" for w in warnings]
    return "\n".join(lines) + "\n"


def html_table(title: str, header: list[str], rows: list[list[str]], warnings=()) -> str:
    """An HTML table under a bold title, with warnings listed after it."""
    esc = html.escape
    head = "".join(f"<th style='text-align:left'>{esc(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td style='text-align:left'>{esc(str(c))}</td>" for c in row) + "</tr>"
                   for row in rows)
    out = f"<p><b>{esc(title)}</b></p><table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"
    if warnings:
        out += "<ul>" + "".join(f"<li><b>warning:</b> {esc(w)}</li>" for w in warnings) + "</ul>"
    return out
