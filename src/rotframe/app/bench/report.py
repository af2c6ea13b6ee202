"""The bench's outputs: the text table, work-precision plots, JSON rows and the machine description."""

from __future__ import annotations

import math
import os

import numpy as np

from rotframe.app import outputs
from rotframe.app.bench.summary import is_peer, problem_keys

__all__ = ["environment", "plot", "table", "json_rows"]


def environment():
    """Machine and versions, for the record."""
    import platform

    import numba
    import scipy

    out = {"python": platform.python_version(), "numpy": np.__version__, "scipy": scipy.__version__,
           "numba": numba.__version__, "machine": platform.machine(), "cpus": os.cpu_count(),
           "processor": platform.processor() or platform.machine()}
    try:
        import diffrax
        import jax

        out["jax"], out["diffrax"] = jax.__version__, diffrax.__version__
    except Exception:  # noqa: BLE001
        pass
    return out


def plot(rows, folder):
    """One work-precision diagram per problem: log error against log wall time, and against log
    evaluations (the work a method needs, whatever one costs); returns the paths."""
    import matplotlib
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    os.makedirs(folder, exist_ok=True)
    paths = []
    keys = problem_keys(rows)
    for scenario, horizon in keys:
        fig = Figure(figsize=(12, 5))
        FigureCanvasAgg(fig)
        by_time, by_work = fig.subplots(1, 2, sharey=True)
        sel = [r for r in rows if r["scenario"] == scenario and r.get("horizon") == horizon and r.get("kind") != "summary"]
        colours = matplotlib.colormaps["tab20"].colors  # one colour a method (the default cycle has ten)
        for k, method in enumerate(dict.fromkeys(r["method"] for r in sel)):
            mine = [r for r in sel if r["method"] == method and r["error"] is not None and np.isfinite(r["error"])
                    and r["error"] > 0]
            peer = bool(mine) and is_peer(mine[0])
            for ax, x_of in ((by_time, lambda r: r["wall_s"]), (by_work, lambda r: r.get("nfev") or 0)):
                pts = sorted((x_of(r), r["error"]) for r in mine if x_of(r) > 0)
                if pts:
                    x, y = zip(*pts)
                    ax.loglog(x, y, "--" if peer else "-", marker="s" if peer else "o", ms=3, label=method,
                              color=colours[(2 * k) % 20 + (k // 10) % 2])
        by_time.set_xlabel("wall time per run (s)")
        by_work.set_xlabel("force evaluations per run (nfev)")
        by_time.set_ylabel("final error")
        fig.suptitle(f"{scenario}: {horizon}\n{sel[0]['error_kind']}", fontsize=9)
        for ax in (by_time, by_work):
            ax.grid(True, which="both", alpha=0.3)
        by_time.legend(fontsize=7)
        path = os.path.join(folder, f"bench-{scenario}-{len(paths)}.png")
        outputs.write_atomic(path, lambda f, fig=fig: fig.savefig(f, dpi=110, bbox_inches="tight", format="png"),
                     what="bench plot")
        paths.append(path)
    return paths


def _fmt_setting(v):
    return v if isinstance(v, str) else ("-" if v is None else f"{v:.0e}")


def table(rows, speed) -> str:
    body = [r for r in rows if r.get("kind") not in ("summary", "note")]
    lines = [f"{'scenario':<12} {'horizon':<22} {'method':<22} {'setting':>9} {'wall s':>10} {'error':>10} "
             f"{'invariant':>10} {'nfev':>10} {'compile s':>9}"]
    for r in body:
        inv = r.get("invariant_error")
        extra = ""
        if "particle_steps_per_s" in r:
            extra = f"  {r['particle_steps_per_s']:.3g} particle-steps/s"
            if "goal_ratio" in r:
                extra += (f", {r['parallel_efficiency']:.2f} of cores x single-core "
                          f"({r['goal_ratio']:.2f} of the 0.7 goal; the ceiling's scaling x {r['scaling_vs_ceiling']:.2f}), "
                          f"{r['of_ceiling']:.2f} of the ceiling, "
                          f"bitwise identical to 1 thread: {r['bitwise_identical_to_1_thread']}")
            if "of_integrate_ensemble" in r:  # the engine's door (the sweeps'), beside the scenes' kernels' door
                extra += (f", {r['of_ceiling']:.2f} of the ceiling, {r['of_integrate_ensemble']:.2f} of "
                          f"integrate_ensemble's rate")
            if "of_ceiling" in r and "ceiling_goal" in r:
                jax = r.get("vs_jax_vmap")
                alone = r.get("kernel_of_ceiling")
                extra += (f", {r['of_ceiling']:.2f} of the hand-written kernel (goal {r['ceiling_goal']:g}"
                          + (f"; the kernels alone {alone:.2f}" if alone else "") + "), "
                          + (f"x{jax:.3g} JAX vmap (goal x{r['jax_goal']:g})" if jax else "no JAX ratio")
                          + (f"; {r['notes']}" if r.get("notes") else ""))
            if "same_work" in r and (r["method"].startswith("hand-written prange") or r["scenario"] == "gpu-ensemble"):
                extra += f"; {r['same_work_note']}"
        if "rows_per_s" in r:
            extra = f"  {r['rows_per_s']:.3g} rows/s"
            if "scaling" in r:
                extra += f", {r['scaling']:.2f} x one worker (cluster start and warm-up {r['cluster_start_s']:.2g} s apart)"
        if "import_s" in r:
            cold = r["setting"].startswith("first")
            extra = (f"  (imports {r['import_s']:.2f} s, beyond them {r['beyond_imports_s']:.2f} s; goal "
                     f"{r['goal_s']:g} s {'beyond imports' if cold else 'in all'}: "
                     f"{'met' if r['goal_met'] else 'not met'})")
        if r.get("error_kind") == "start-up" and r.get("family") == "peer":  # diffrax beside a problem of your own
            extra = f"  ({r['note']})"
        err = r["error"]
        comp = r.get("compile_s")
        lines.append(f"{r['scenario']:<12} {str(r.get('horizon', '')):<22} {r['method'][:22]:<22} "
                     f"{_fmt_setting(r['setting']):>9} {r['wall_s']:>10.3g} "
                     f"{(err if err is not None else math.nan):>10.2e} {('-' if inv is None else f'{inv:.1e}'):>10} "
                     f"{r['nfev']:>10} {('' if comp is None else f'{comp:.2g}'):>9}{extra}")
    summ = [r for r in rows if r.get("kind") == "summary"]
    if summ:
        lines.append("")
        lines.append("at equal final error: fastest rotframe run, fastest peer run (scipy, scipy + numba, diffrax), "
                     "ratio (peer time / rotframe time); compile time of the peer apart")
        lines.append(f"{'scenario':<12} {'horizon':<22} {'error <=':>8} {'rotframe':>24} {'s':>9} {'peer':>24} "
                     f"{'s':>9} {'compile s':>9} {'ratio':>8}")
        for r in summ:
            mine = f"{r['rotframe_method']} {_fmt_setting(r['rotframe_setting'])}" if r["rotframe_method"] else "-"
            peer = f"{r['peer']} {_fmt_setting(r['peer_setting'])}" if r["peer"] else "-"
            pc = r.get("peer_compile_s")
            lines.append(f"{r['scenario']:<12} {str(r['horizon']):<22} {r['level']:>8.0e} {mine[:24]:>24} "
                         f"{(r['wall_s'] or math.nan):>9.2g} {peer[:24]:>24} {(r['peer_wall_s'] or math.nan):>9.2g} "
                         f"{('' if pc is None else f'{pc:.2g}'):>9} "
                         f"{('x' + format(r['ratio'], '.1f')) if r['ratio'] else '-':>8}"
                         + (f"  {r['note']}" if r.get("note") else ""))
    if speed:
        lines.append("")
        lines.append("speed at equal final error (best rotframe method / fastest plain scipy method):")
        for key, s in speed.items():
            lines.append(f"  {key:<40} x{s['speedup']:8.1f} at error {s['error']:.1e}: {s['rotframe']} "
                         f"({s['rotframe_wall_s']:.2g} s) vs {s['scipy']} rtol {s['scipy_rtol']:.0e} "
                         f"({s['scipy_wall_s']:.2g} s)")
    notes = [r["note"] for r in rows if r.get("kind") == "note"]
    if notes:
        lines.append("")
        lines.extend(f"note: {n}" for n in notes)
    return "\n".join(lines)


def json_rows(rows):
    def clean(v):
        if isinstance(v, float) and not math.isfinite(v):
            return None
        if isinstance(v, (np.floating, np.integer, np.bool_)):
            return clean(v.item())
        return v

    return [{k: clean(v) for k, v in r.items()} for r in rows]
