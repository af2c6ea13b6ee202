"""The GPU ensemble table (Markdown) from ``rotframe bench gpu --json``.

    rotframe bench gpu --json > docs/bench/gpu.json
    python tools/gpu_table.py docs/bench/gpu.json

One row per method and event: rotframe's GPU door, the hand-written kernels and JAX, in
particle-steps per second, with rotframe's ratio to the faster hand-written kernel and to JAX.
"""

from __future__ import annotations

import json
import sys


def table(rows) -> str:
    body = [r for r in rows if r.get("scenario") == "gpu-ensemble"]
    if not body:
        return "no gpu-ensemble rows\n"
    lines = [f"GPU: {body[0]['gpu']}{' (numba CUDA simulator: no timing of meaning)' if body[0]['simulator'] else ''}",
             "", "| case | rotframe | hand-written numba CUDA | hand-written CUDA C | JAX jit(vmap) | "
             "of the ceiling (goal 0.5) | x JAX (goal 10) | same work | kernels alone: rotframe, hand-written "
             "(ratio) |", "|---|---|---|---|---|---|---|---|---|"]
    cases = {}
    for r in body:
        cases.setdefault((r["integrator"], r["event"]), []).append(r)
    for (method, event), rs in cases.items():
        def rate(prefix):
            hit = [r for r in rs if r["method"].startswith(prefix)]
            return f"{hit[0]['particle_steps_per_s']:.3g}" if hit else "-"
        mine = rs[0]
        jax = mine.get("vs_jax_vmap")
        alone = "-"
        if "kernel_of_ceiling" in mine:
            alone = (f"{rate('rotframe kernel alone')}, {rate('hand-written numba CUDA kernel alone')} "
                     f"({mine['kernel_of_ceiling']:.2f})")
        lines.append(f"| {method}{' + ground event' if event else ''} | {rate('rotframe')} | "
                     f"{rate('hand-written numba')} | {rate('hand-written CUDA C')} | {rate('JAX')} | "
                     f"{mine['of_ceiling']:.2f} | {'-' if jax is None else f'x{jax:.3g}'} | "
                     f"{all(r['same_work'] for r in rs if 'same_work' in r)} | {alone} |")
    lines.append("")
    lines.append(f"Particle-steps per second; {body[0]['setting'].split(', ', 2)[-1]}. The ceiling is the faster "
                 "hand-written kernel. Kernels alone: launched on arrays already on the GPU (no transfers).")
    users = [r for r in body if "of_scene_gpu" in r]
    if users:
        lines += ["", "Your own problem on the GPU: `rotframe.simulate(device='gpu')` with gravity as a force of your own "
                  "(and the ground as an event of your own), beside the scenes' ensemble of the same terms (gravity, "
                  "Coriolis, centrifugal: simulate always models the frame's centrifugal term), and the same problem "
                  "with the built-in terms (`rotframe.forces.gravity`, the built-in crossing) and one sample, which "
                  "the engine gives to the scenes' GPU kernel (`rotframe.problem.steady`; '-' where not run).", "",
                  "| case | rotframe.simulate, user force | integrate_ensemble, same terms | ratio | same work "
                  "| simulate, built-in terms, samples=1 | ratio |",
                  "|---|---|---|---|---|---|---|"]
        for u in users:
            def of_case(key, prefix=None, u=u):
                return next((r for r in body if r["integrator"] == u["integrator"] and r["event"] == u["event"]
                             and (key in r if prefix is None else r["method"].startswith(prefix))), None)
            twin = of_case(None, "rotframe integrate_ensemble(device='gpu'), +")
            b = of_case("builtin_of_scene_gpu")
            built = "- | -" if b is None else (f"{b['particle_steps_per_s']:.3g} | {b['builtin_of_scene_gpu']:.2f}"
                                               + ("" if b["same_work"] else " (not the same work)"))
            lines.append(f"| {u['integrator']}{' + ground event' if u['event'] else ''} | "
                         f"{u['particle_steps_per_s']:.3g} | {twin['particle_steps_per_s']:.3g} | "
                         f"{u['of_scene_gpu']:.2f} | {u['same_work']} ({u['same_work_max_rel']:.1e}) | {built} |")
    notes = sorted({r["notes"] for r in body if r.get("notes")})
    lines.extend(f"Note: {n}." for n in notes)
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    with open(sys.argv[1]) as f:
        print(table(json.load(f)), end="")
