"""A sweep's pictures: one PNG per metric against each swept key (matplotlib, Agg)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from rotframe.app.sweep.spec import SweepSpec
from rotframe.app.sweep.store import column, metric_columns
from rotframe.numerics.sampling import decimate

__all__ = ["write_plots"]


def write_plots(table, spec: SweepSpec, stem) -> list:
    """One PNG per metric, ``<stem>-<metric>.png``, against each swept key (matplotlib Agg).

    A one-axis grid is drawn as a line, anything else as a scatter; ``theory_<metric>``
    is overlaid when present; log-grid keys get a log x axis. A Monte Carlo sweep adds
    the metric's histogram (its dispersion: mean and standard deviation in the legend).
    """
    # a pyplot-free Figure (as `rotframe.app.plot.new_figure`): pyplot keeps every figure it makes in a process-wide
    # list, and once a process has more than 20 open it warns, which the suite makes an error
    from matplotlib.figure import Figure

    paths = []
    for metric in metric_columns(table, spec):
        y = column(table, metric)
        if not np.any(np.isfinite(y)):
            continue
        theory = column(table, "theory_" + metric) if "theory_" + metric in table.column_names else None
        panels = len(spec.keys) + (1 if spec.vary else 0)
        fig = Figure(figsize=(5.5 * panels, 4.2))
        axs = fig.subplots(1, panels, squeeze=False)
        for ax, key in zip(axs[0], spec.keys):
            _plot_one(ax, column(table, key), y, theory, key, metric, spec)
        if spec.vary:
            _histogram(axs[0][-1], y, metric)
        fig.suptitle(f"{spec.name}: {metric} ({table.num_rows} runs)")
        fig.tight_layout()
        path = Path(f"{stem}-{_safe(metric)}.png")
        from rotframe.app.outputs import atomic_path

        with atomic_path(path, "plot") as tmp:
            fig.savefig(tmp, dpi=110, format="png")
        paths.append(path)
    return paths


def _plot_one(ax, x, y, theory, key, metric, spec):
    ok = np.isfinite(x) & np.isfinite(y)
    line = len(spec.axes) == 1
    order = np.argsort(x[ok], kind="stable")
    xs, ys = x[ok][order], y[ok][order]
    if line:
        ax.plot(xs, ys, "o-", ms=3.5, lw=1.2, label="simulated")
    else:
        pick = decimate(len(xs), 20000)
        ax.plot(xs[pick], ys[pick], ".", ms=2.0, alpha=0.5, rasterized=True, label="simulated")
    if theory is not None and np.any(np.isfinite(theory[ok])):
        th = theory[ok][order]
        if line:
            ax.plot(xs, th, "-", color="k", lw=0.9, alpha=0.7, label="theory")
        else:
            pick = decimate(len(xs), 20000)
            ax.plot(xs[pick], th[pick], ".", ms=1.0, color="k", alpha=0.4, rasterized=True, label="theory")
    if key in spec.log_keys:
        ax.set_xscale("log")
    ax.set_xlabel(_label(spec, key))
    ax.set_ylabel(metric)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)


def _histogram(ax, y, metric):
    y = y[np.isfinite(y)]
    bins = int(np.clip(np.sqrt(len(y)), 10, 100))
    ax.hist(y, bins=bins, color="C0", alpha=0.8,
            label=f"mean {np.mean(y):.6g}\nsd {np.std(y, ddof=1) if len(y) > 1 else 0.0:.3g}")
    ax.set_xlabel(metric)
    ax.set_ylabel("runs")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)


def _label(spec, key):
    from rotframe.app import scenario as sc
    param = key.split("[")[0]
    p = sc.load(spec.scenario).parameters.get(param)
    return f"{key} [{p.unit}]" if p is not None and p.unit else key


def _safe(name):
    return re.sub(r"[^\w.-]+", "_", name)
