"""Generated source of the frame's evaluators: omega(t), omega'(t) and a0(t) for the compiled drivers.

Each form of `rotframe.problem.frame.FrameSpec` has its evaluator written out here as
source text, so that a generated driver (`rotframe.problem.codegen`) compiles only the
form its problem uses. The numpy twins used for analysis are in `rotframe.problem.frame`;
``tests/test_simulate.py`` checks both against each other and against closed forms.
"""

from __future__ import annotations

__all__ = ["SEARCH_SOURCE", "vector_source", "central_difference_step"]

#: h of the fourth-order central difference for omega' of a function, in units of min(1 s, 1 / |omega(0)|)
#: (frame.derivative_step computes it; the drivers read it from F[0][0])
central_difference_step = 2.0 ** -9

#: the interval search shared by the table and body forms
SEARCH_SOURCE = '''

@jit
def interval(knots, t):
    """The index i of the interval [knots[i], knots[i + 1]] holding t (clipped to the ends)."""
    n = knots.shape[0]
    if t <= knots[0]:
        return 0
    if t >= knots[n - 1]:
        return n - 2
    lo = 0
    hi = n - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if knots[mid] <= t:
            lo = mid
        else:
            hi = mid
    return lo

'''


def vector_source(name: str, kind: str, derivative: bool, fn: str = "", fn_dot: str = "") -> str:
    """Source of ``name(t, F)`` returning a 3-vector's components (and its derivative's, if ``derivative``).

    ``kind`` is a `rotframe.problem.frame.KINDS` form or ``"zero"``; ``fn``/``fn_dot`` name
    the bound user functions of the ``function`` form (``fn_dot`` empty: derived).
    """
    ret = "x, y, z, dx, dy, dz" if derivative else "x, y, z"
    lines = ["", "@jit", f"def {name}(t, F):"]
    if kind == "zero":
        lines.append("    return " + ", ".join(["0.0"] * (6 if derivative else 3)))
    elif kind == "constant":
        lines += ["    w = F[0]", "    x = w[0]", "    y = w[1]", "    z = w[2]", "    dx = 0.0", "    dy = 0.0",
                  "    dz = 0.0", f"    return {ret}"]
    elif kind == "table":
        lines += ["    knots = F[0]", "    coef = F[1]", "    i = interval(knots, t)", "    s = t - knots[i]"]
        for k, c in enumerate("xyz"):
            lines.append(f"    {c} = ((coef[i, 0, {k}] * s + coef[i, 1, {k}]) * s + coef[i, 2, {k}]) * s + coef[i, 3, {k}]")
            lines.append(f"    d{c} = (3.0 * coef[i, 0, {k}] * s + 2.0 * coef[i, 1, {k}]) * s + coef[i, 2, {k}]")
        lines.append(f"    return {ret}")
    elif kind == "body":
        lines += ["    times = F[0]", "    w = F[1]", "    wd = F[2]", "    wdd = F[3]", "    i = interval(times, t)",
                  "    h = times[i + 1] - times[i]", "    s = (t - times[i]) / h",
                  "    s2 = s * s", "    s3 = s2 * s", "    s4 = s3 * s", "    s5 = s4 * s",
                  "    h0 = 1.0 - 10.0 * s3 + 15.0 * s4 - 6.0 * s5",
                  "    h1 = s - 6.0 * s3 + 8.0 * s4 - 3.0 * s5",
                  "    h2 = 0.5 * (s2 - 3.0 * s3 + 3.0 * s4 - s5)",
                  "    h3 = 10.0 * s3 - 15.0 * s4 + 6.0 * s5",
                  "    h4 = -4.0 * s3 + 7.0 * s4 - 3.0 * s5",
                  "    h5 = 0.5 * (s3 - 2.0 * s4 + s5)",
                  "    d0 = -30.0 * s2 + 60.0 * s3 - 30.0 * s4",
                  "    d1 = 1.0 - 18.0 * s2 + 32.0 * s3 - 15.0 * s4",
                  "    d2 = 0.5 * (2.0 * s - 9.0 * s2 + 12.0 * s3 - 5.0 * s4)",
                  "    d3 = 30.0 * s2 - 60.0 * s3 + 30.0 * s4",
                  "    d4 = -12.0 * s2 + 28.0 * s3 - 15.0 * s4",
                  "    d5 = 0.5 * (3.0 * s2 - 8.0 * s3 + 5.0 * s4)"]
        for k, c in enumerate("xyz"):
            lines.append(f"    {c} = (h0 * w[i, {k}] + h1 * h * wd[i, {k}] + h2 * h * h * wdd[i, {k}] + h3 * w[i + 1, {k}]"
                         f" + h4 * h * wd[i + 1, {k}] + h5 * h * h * wdd[i + 1, {k}])")
            lines.append(f"    d{c} = (d0 * w[i, {k}] + d1 * h * wd[i, {k}] + d2 * h * h * wdd[i, {k}] + d3 * w[i + 1, {k}]"
                         f" + d4 * h * wd[i + 1, {k}] + d5 * h * h * wdd[i + 1, {k}]) / h")
        lines.append(f"    return {ret}")
    elif kind == "function":
        lines += [f"    w = {fn}(t)", "    x = w[0]", "    y = w[1]", "    z = w[2]"]
        if derivative:
            if fn_dot:
                lines += [f"    e = {fn_dot}(t)", "    dx = e[0]", "    dy = e[1]", "    dz = e[2]"]
            else:
                lines += ["    hh = (t + F[0][0]) - t",  # the step of frame.derivative_step, exact in floats
                          f"    a = {fn}(t - 2.0 * hh)", f"    b = {fn}(t - hh)", f"    c = {fn}(t + hh)",
                          f"    d = {fn}(t + 2.0 * hh)",
                          "    dx = (a[0] - 8.0 * b[0] + 8.0 * c[0] - d[0]) / (12.0 * hh)",
                          "    dy = (a[1] - 8.0 * b[1] + 8.0 * c[1] - d[1]) / (12.0 * hh)",
                          "    dz = (a[2] - 8.0 * b[2] + 8.0 * c[2] - d[2]) / (12.0 * hh)"]
        lines.append(f"    return {ret}")
    else:
        raise ValueError(f"unknown vector form {kind!r}")
    return "\n".join(lines) + "\n"
