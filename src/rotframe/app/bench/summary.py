"""What the bench rows mean: at each error level the fastest rotframe and peer runs, and speed-ups over scipy."""

from __future__ import annotations

import numpy as np

__all__ = ["LEVELS", "GOAL", "is_peer", "problem_keys", "level_summary", "shortfall_reason", "at_level",
           "work_bound", "speedups"]


#: error levels of the summary
LEVELS = (1e-3, 1e-6, 1e-9)
#: the speed ratio over the fastest peer that rotframe aims at; a summary row below it says by how much and why
GOAL = 10.0


def is_peer(r):
    return r.get("family") == "peer" or r["method"].startswith(("scipy", "diffrax"))


def problem_keys(rows):
    """The (scenario, horizon) of each benchmarked problem, in order of first appearance."""
    keys = []
    for r in rows:
        k = (r["scenario"], r.get("horizon"))
        if r.get("horizon") and r.get("kind") != "summary" and k not in keys:
            keys.append(k)
    return keys


def level_summary(rows, levels=LEVELS):
    """Summary rows: per (scenario, horizon) and error level, the fastest rotframe and peer runs and their ratio.

    A run counts for a level when its final error is at most the level. A
    rotframe row with zero error counts only for an ``exact`` method, plain or
    prepared (a reference that is that flow). ``ratio`` = peer time / rotframe time; ``note``
    says why a level has no ratio.
    """
    out = []
    keys = problem_keys(rows)
    for scenario, horizon in keys:
        sel = [r for r in rows if (r["scenario"], r.get("horizon")) == (scenario, horizon)
               and r.get("kind") != "summary" and r["error"] is not None and np.isfinite(r["error"])]
        mine = [r for r in sel if not is_peer(r) and (r["error"] > 0 or r["method"].startswith("exact"))]
        theirs = [r for r in sel if is_peer(r)]
        ref_error = max((r.get("reference_error") or 0.0 for r in sel), default=0.0)
        for level in levels:
            if level < ref_error:
                out.append({"scenario": scenario, "method": "summary", "setting": level, "wall_s": None,
                            "error": None, "error_kind": sel[0]["error_kind"], "nfev": 0, "horizon": horizon,
                            "kind": "summary", "level": level, "rotframe_method": None, "rotframe_setting": None,
                            "peer": None, "peer_setting": None, "peer_wall_s": None, "peer_error": None,
                            "peer_compile_s": None, "ratio": None,
                            "note": f"not measurable: the reference itself is good to {ref_error:.0e} only"})
                continue
            m = [r for r in mine if r["error"] <= level]
            t = [r for r in theirs if r["error"] <= level]
            best_m = min(m, key=lambda r: r["wall_s"]) if m else None
            best_t = min(t, key=lambda r: r["wall_s"]) if t else None
            row = {"scenario": scenario, "method": "summary", "setting": level,
                   "wall_s": best_m["wall_s"] if best_m else None, "error": best_m["error"] if best_m else None,
                   "error_kind": sel[0]["error_kind"] if sel else "", "nfev": best_m["nfev"] if best_m else 0,
                   "horizon": horizon, "kind": "summary", "level": level,
                   "rotframe_method": best_m["method"] if best_m else None,
                   "rotframe_setting": best_m["setting"] if best_m else None,
                   "peer": best_t["method"] if best_t else None, "peer_setting": best_t["setting"] if best_t else None,
                   "peer_wall_s": best_t["wall_s"] if best_t else None, "peer_error": best_t["error"] if best_t else None,
                   "peer_compile_s": _compile_of(rows, best_t) if best_t else None,
                   "ratio": (best_t["wall_s"] / best_m["wall_s"]) if (best_m and best_t) else None}
            notes = []
            if not best_m:
                finest = min((r["error"] for r in mine), default=None)
                notes.append("no rotframe run reached this error" +
                             (f" (smallest {finest:.1e})" if finest is not None else ""))
            if not best_t:
                finest = min((r["error"] for r in theirs), default=None)
                notes.append("no peer run reached this error" +
                             (f" (smallest {finest:.1e})" if finest is not None else " (no peer rows)"))
            if row["ratio"] is not None and row["ratio"] < GOAL:
                row["shortfall"] = GOAL / row["ratio"]
                row["reason"] = shortfall_reason(best_m, best_t)
                notes.append(f"below the {GOAL:g}x goal by a factor {row['shortfall']:.1f}: {row['reason']}")
                bound = work_bound(sel, level, best_m)
                if bound is not None:
                    row.update(bound)
                    notes.append(_bound_note(bound))
            if notes:
                row["note"] = "; ".join(notes)
            out.append(row)
    return out


def shortfall_reason(mine, peer):
    """Why the fastest rotframe run ``mine`` is less than `GOAL` times faster than the ``peer`` row.

    The time ratio is split into the work ratio (``nfev``: right-hand-side
    evaluations, or steps of a fixed-step method) and the cost of one unit of
    work; the larger shortfall names the reason.
    """
    n_m, n_p = mine.get("nfev") or 0, peer.get("nfev") or 0
    if not (n_m > 0 and n_p > 0 and mine["wall_s"] and peer["wall_s"]):
        return "no work count to compare (a closed form or an unmeasured peer)"
    work = n_p / n_m  # > 1: the peer does more work
    unit = (peer["wall_s"] / n_p) / (mine["wall_s"] / n_m)  # > 1: each of the peer's units costs more
    if work < 1 and 1 / work >= GOAL / unit:  # less work is the larger of the two shortfalls
        return (f"the peer needs {1 / work:.2g}x less work ({n_p} vs {n_m} nfev at "
                f"{peer['method']} {peer.get('setting')}): its method suits this error level better")
    compiled = " (also compiled: the whole solve is one jax.jit call)" if peer["method"].startswith("diffrax") else ""
    return (f"the peer's evaluation costs only {unit:.2g}x ours{compiled} and it does {work:.2g}x our work "
            f"({n_p} vs {n_m} nfev)")


def at_level(ladder, level):
    """The work and time one method needs for a final error of exactly ``level``, from its ladder.

    ``ladder``: the rows of one method (``nfev`` > 0, finite positive errors). Between the
    two neighbouring rows whose errors bracket ``level``, log ``nfev`` and log ``wall_s``
    are interpolated linearly in log error (a power law, as the error of a method of
    fixed order is on the work). Where even the cheapest row is below ``level``, that row
    is returned (an upper bound). Returns ``(nfev, wall_s)``, or None where no row
    reaches ``level``.
    """
    pts = sorted((r["nfev"], r["wall_s"], r["error"]) for r in ladder
                 if (r.get("nfev") or 0) > 0 and r["wall_s"] and r["error"] is not None and r["error"] > 0)
    best = None
    for k, (n, w, e) in enumerate(pts):
        if e > level:
            continue
        cand = (float(n), float(w))
        for n0, w0, e0 in pts[:k][::-1]:  # the nearest cheaper row above the level
            if e0 > level:
                f = np.log(e0 / level) / np.log(e0 / e)
                cand = (float(np.exp(np.log(n0) + f * np.log(n / n0))), float(np.exp(np.log(w0) + f * np.log(w / w0))))
                break
        if best is None or cand[0] < best[0]:
            best = cand
    return best


def work_bound(sel, level, mine):
    """How fast rotframe could be at ``level`` at all, at its own cost of one evaluation.

    A work-precision argument: the fewest evaluations that any method of the bench
    (rotframe's or a peer's) needs for an error of ``level`` (`at_level`, along each
    method's ladder), times the cost of one of rotframe's evaluations (``mine``: its
    fastest run at this level), against the fastest peer's time at that error. If even
    that bound is under `GOAL`, no method in the bench reaches the goal without a
    cheaper evaluation; ``needed_s_per_eval`` says how cheap one would have to be.
    Returns None where ``mine`` has no work count (a closed form).
    """
    if not (mine.get("nfev") or 0) > 0 or not mine["wall_s"]:
        return None
    by_method = {}
    for r in sel:
        by_method.setdefault(r["method"], []).append(r)
    fewest, peer_time = None, None
    for method, ladder in by_method.items():
        got = at_level(ladder, level)
        if got is None:
            continue
        if fewest is None or got[0] < fewest[0]:
            fewest = (got[0], method)
        if is_peer(ladder[0]) and (peer_time is None or got[1] < peer_time[0]):
            peer_time = (got[1], method)
    if fewest is None or peer_time is None:
        return None
    per_eval = mine["wall_s"] / mine["nfev"]
    return {"fewest_nfev": fewest[0], "fewest_nfev_method": fewest[1], "s_per_eval": per_eval,
            "peer_wall_at_level": peer_time[0], "peer_at_level": peer_time[1],
            "bound_ratio": peer_time[0] / (fewest[0] * per_eval),
            "needed_s_per_eval": peer_time[0] / (GOAL * fewest[0])}


def _bound_note(b):
    verdict = ("so no method of the bench reaches the goal at our cost of an evaluation"
               if b["bound_ratio"] < GOAL else "so a method with fewer evaluations could reach it")
    return (f"at this error the fewest evaluations of any method are about {b['fewest_nfev']:.3g} "
            f"({b['fewest_nfev_method']}) and the fastest peer takes about {b['peer_wall_at_level'] * 1e3:.3g} ms "
            f"({b['peer_at_level']}; both along the ladders, at the level); at {b['s_per_eval'] * 1e9:.3g} ns "
            f"an evaluation the bound is x{b['bound_ratio']:.2g}, {verdict} "
            f"(x{GOAL:g} needs {b['needed_s_per_eval'] * 1e9:.3g} ns)")


def _compile_of(rows, r):
    """The compile time reported with the first row of ``r``'s method."""
    for s in rows:
        if (s["scenario"], s.get("horizon"), s["method"]) == (r["scenario"], r.get("horizon"), r["method"]) \
                and "compile_s" in s:
            return s["compile_s"]
    return None


def speedups(rows, max_error=1e-2):
    """Per (scenario, horizon): speed ratio of the best rotframe method over the fastest scipy method.

    For each rotframe row, the fastest scipy row whose final error is at least
    as small is found; the ratio of their wall times is reported at the
    rotframe row that maximises it, with the error where it holds. Rows with
    error above ``max_error`` are not accuracy and are left out, and so are rows
    with zero error (a method compared with itself as the reference).
    """
    out = {}
    keys = {(r["scenario"], r["horizon"]) for r in rows if r.get("horizon") and r.get("kind") != "summary"}
    for key in sorted(keys):
        def usable(r):
            return (r["scenario"], r.get("horizon")) == key and r.get("kind") != "summary" and \
                r["error"] is not None and np.isfinite(r["error"]) and 0 < r["error"] <= max_error

        mine = [r for r in rows if usable(r) and not is_peer(r)]
        theirs = [r for r in rows if usable(r) and r["method"].startswith("scipy")]
        if not mine or not theirs:
            continue
        best = None
        for r in mine:
            candidates = [s["wall_s"] for s in theirs if s["error"] <= r["error"]]
            if not candidates:
                continue
            ratio = min(candidates) / r["wall_s"]
            if best is None or ratio > best[0]:
                fastest = min((s for s in theirs if s["error"] <= r["error"]), key=lambda s: s["wall_s"])
                best = (ratio, r, fastest)
        if best:
            ratio, r, s = best
            out[f"{key[0]} ({key[1]})"] = {"speedup": ratio, "error": r["error"], "rotframe": r["method"],
                                           "rotframe_setting": r["setting"], "rotframe_wall_s": r["wall_s"],
                                           "scipy": s["method"], "scipy_rtol": s["setting"], "scipy_wall_s": s["wall_s"]}
    return out
