"""Two runs of ``rotframe bench --json`` compared: each summary row's ratio to its fastest peer, and each ensemble
row's share of the ceiling, the first run against the second.

    python tools/bench_compare.py docs/bench/latest.json new.json [--within 0.1]

For issue 32's "What must not move": every summary row keeps its ratio within ``--within`` (10 %) of the file's.
Each row prints its new ratio over the old one, rotframe's wall time in both runs and the peer's: a ratio that moved
while rotframe's own time did not is the peer's doing (a µs-long solve moves with the peer's dispatch from run to
run), which the two walls show. Then every ``of_ceiling`` of the ensemble rows (goal 0.7), old and new. Exits 1 where
a summary row fell below ``1 - within`` of the old ratio, so that a script can tell; the printed walls say why.
"""

from __future__ import annotations

import argparse
import json
import sys


def _summaries(rows):
    return {(r["scenario"], r.get("horizon"), r.get("level")): r for r in rows if r.get("kind") == "summary"}


def _ceilings(rows):
    return {(r["method"], str(r.get("setting"))): r["of_ceiling"] for r in rows if "of_ceiling" in r}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("old")
    parser.add_argument("new")
    parser.add_argument("--within", type=float, default=0.1)
    args = parser.parse_args(argv)
    with open(args.old) as f:
        old = json.load(f)
    with open(args.new) as f:
        new = json.load(f)
    o, n = _summaries(old), _summaries(new)
    moved = []
    for key in sorted(o, key=str):
        if key not in n:
            print(f"only in {args.old}: {key}")
            continue
        a, b = o[key], n[key]
        if not (a.get("ratio") and b.get("ratio")):
            continue
        share = b["ratio"] / a["ratio"]
        flag = "  below" if share < 1.0 - args.within else ""
        print(f"{share:6.3f}  {key[0]} ({key[1]}) at {key[2]:g}: {a['ratio']:.3g} -> {b['ratio']:.3g}; rotframe "
              f"{a['wall_s']:.3g} -> {b['wall_s']:.3g} s ({b.get('rotframe_method')}), {b.get('peer')} "
              f"{a['peer_wall_s']:.3g} -> {b['peer_wall_s']:.3g} s{flag}")
        if flag:
            moved.append(key)
    oc, nc = _ceilings(old), _ceilings(new)
    for key in sorted(oc):
        print(f"of_ceiling {oc[key]:.3f} -> {nc.get(key, float('nan')):.3f}  {key[0]}")
    print(f"{len(moved)} summary rows below {1.0 - args.within:g} of their old ratio")
    return 1 if moved else 0


if __name__ == "__main__":
    sys.exit(main())
