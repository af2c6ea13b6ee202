"""The README's speed table from ``rotframe bench --json`` (summary rows and the environment row).

    rotframe bench --json > /tmp/bench.json
    python tools/bench_table.py /tmp/bench.json     # Markdown on stdout

One row per problem and error level: the fastest rotframe run that reaches the level, the
fastest peer run that reaches it, their times and the ratio (peer time / rotframe time), and
what the bench says where the ratio is under its goal or not measurable.
"""

from __future__ import annotations

import json
import sys


def _ms(seconds):
    return "" if seconds is None else f"{seconds * 1e3:.3g} ms"


def table(rows) -> str:
    env = next((r for r in rows if r.get("kind") == "environment"), {})
    lines = ["| problem | level | rotframe (method, setting) | peer (method, setting) | ratio | note |",
             "|---|---|---|---|---|---|"]
    for r in rows:
        if r.get("kind") != "summary":
            continue
        ours = f"{r['rotframe_method']} {r['rotframe_setting']}: {_ms(r['wall_s'])}" if r.get("rotframe_method") else "-"
        peer = f"{r['peer']} {r['peer_setting']}: {_ms(r['peer_wall_s'])}" if r.get("peer") else "-"
        ratio = f"x{r['ratio']:.3g}" if r.get("ratio") else "-"
        note = r.get("note") or ""
        if r.get("shortfall"):
            note = f"short of x10 by {r['shortfall']:.2g}x: {r.get('reason', '')}".strip()
            if r.get("bound_ratio"):
                note += (f"; at most x{r['bound_ratio']:.2g} at our {r['s_per_eval'] * 1e9:.2g} ns an evaluation "
                         f"with the fewest any method needs ({r['fewest_nfev']:.3g}, {r['fewest_nfev_method']})")
        lines.append(f"| {r['scenario']} ({r.get('horizon', '')}) | {r['level']:.0e} | {ours} | {peer} | {ratio} | {note} |")
    # the scenes' first runs (the problem-of-your-own rows and diffrax's beside them are a table of their own)
    startup = [r for r in rows if r.get("scenario") == "startup" and "beyond_imports_s" in r
               and str(r.get("method", "")).startswith("rotframe run ")]
    if startup:
        lines += ["", "| first run | warm cache (goal 1 s in all) | empty cache (goal 3 s beyond imports) |",
                  "|---|---|---|"]
        by_name = {}
        for r in startup:
            name = r.get("run") or r["method"].split()[2]  # older JSON files have no "run"
            by_name.setdefault(name, {})["cold" if r["setting"].startswith("first") else "warm"] = r
        for name, pair in by_name.items():
            cells = []
            for key in ("warm", "cold"):
                r = pair.get(key)
                cells.append("-" if r is None else
                             f"{r['wall_s']:.2f} s (imports {r['import_s']:.2f}, beyond them "
                             f"{r['beyond_imports_s']:.2f}): {'met' if r['goal_met'] else 'not met'}")
            lines.append(f"| `rotframe run {name}` | {cells[0]} | {cells[1]} |")
    versions = ", ".join(f"{k} {env[k]}" for k in ("python", "numpy", "scipy", "numba", "jax", "diffrax") if k in env)
    machine = f"{env.get('cpus', '?')} cores, {env.get('processor', env.get('machine', '?'))}"
    return "\n".join(lines) + f"\n\nMeasured in one run on {machine}; {versions}.\n"


if __name__ == "__main__":
    with open(sys.argv[1]) as f:
        print(table(json.load(f)), end="")
