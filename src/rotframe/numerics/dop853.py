"""Butcher tableau of Dormand-Prince 8(5,3), as published with Hairer's ``dop853.f``.

The explicit Runge-Kutta method of order 8 by Dormand and Prince (1980) with
the error estimators of Hairer, Norsett & Wanner, *Solving Ordinary
Differential Equations I* (2nd ed., Springer 1993), section II.10 and the
Fortran code ``dop853.f`` that accompanies it. The constants below are those
of ``dop853.f`` (30 significant digits), stored as decimal strings and rounded
to float64 once. See docs/physics/dop853.md for the layout, the error norm
and the checks (order conditions, observed order 8, the estimate tracking the
true error) in ``tests/test_i11b_dop853.py``.

Layout (0-based stage index ``i``; 12 stages, stage 11 is at ``c = 1``)::

    k_i = f(t + C[i] h, y + h sum_j A[i, j] k_j)
    y_new = y + h sum_i B[i] k_i                      (order 8)
    err5 = h sum_i E5[i] k_i                          (5th-order estimator, ``er`` of dop853.f)
    err3 = h sum_i E3[i] k_i                          (3rd-order estimator, B - ``bhh``)
    err  = |err5|^2 / sqrt(|err5|^2 + 0.01 |err3|^2)  (per component, scaled; see the kernel)

``E3`` and ``E5`` have 13 entries; the last one multiplies f(t + h, y_new)
(the first stage of the next step) and is zero.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from rotframe.numerics.compiled import jit_internal

__all__ = ["N_STAGES", "coefficients", "exact_tables", "dop853_error_norm"]

N_STAGES = 12

# nodes c_2 .. c_11 (c_1 = 0, c_12 = 1)
_C = ["0.526001519587677318785587544488e-01", "0.789002279381515978178381316732e-01",
      "0.118350341907227396726757197510", "0.281649658092772603273242802490",
      "0.333333333333333333333333333333", "0.25", "0.307692307692307692307692307692",
      "0.651282051282051282051282051282", "0.6", "0.857142857142857142857142857142"]

# rows of A: {stage (1-based): {column (1-based): a}}
_A = {
    2: {1: "5.26001519587677318785587544488e-2"},
    3: {1: "1.97250569845378994544595329183e-2", 2: "5.91751709536136983633785987549e-2"},
    4: {1: "2.95875854768068491816892993775e-2", 3: "8.87627564304205475450678981324e-2"},
    5: {1: "2.41365134159266685502369798665e-1", 3: "-8.84549479328286085344864962717e-1",
        4: "9.24834003261792003115737966543e-1"},
    6: {1: "3.7037037037037037037037037037e-2", 4: "1.70828608729473871279604482173e-1",
        5: "1.25467687566822425016691814123e-1"},
    7: {1: "3.7109375e-2", 4: "1.70252211019544039314978060272e-1", 5: "6.02165389804559606850219397283e-2",
        6: "-1.7578125e-2"},
    8: {1: "3.70920001185047927108779319836e-2", 4: "1.70383925712239993810214054705e-1",
        5: "1.07262030446373284651809199168e-1", 6: "-1.53194377486244017527936158236e-2",
        7: "8.27378916381402288758473766002e-3"},
    9: {1: "6.24110958716075717114429577812e-1", 4: "-3.36089262944694129406857109825",
        5: "-8.68219346841726006818189891453e-1", 6: "2.75920996994467083049415600797e1",
        7: "2.01540675504778934086186788979e1", 8: "-4.34898841810699588477366255144e1"},
    10: {1: "4.77662536438264365890433908527e-1", 4: "-2.48811461997166764192642586468",
         5: "-5.90290826836842996371446475743e-1", 6: "2.12300514481811942347288949897e1",
         7: "1.52792336328824235832596922938e1", 8: "-3.32882109689848629194453265587e1",
         9: "-2.03312017085086261358222928593e-2"},
    11: {1: "-9.3714243008598732571704021658e-1", 4: "5.18637242884406370830023853209",
         5: "1.09143734899672957818500254654", 6: "-8.14978701074692612513997267357",
         7: "-1.85200656599969598641566180701e1", 8: "2.27394870993505042818970056734e1",
         9: "2.49360555267965238987089396762", 10: "-3.0467644718982195003823669022"},
    12: {1: "2.27331014751653820792359768449", 4: "-1.05344954667372501984066689879e1",
         5: "-2.00087205822486249909675718444", 6: "-1.79589318631187989172765950534e1",
         7: "2.79488845294199600508499808837e1", 8: "-2.85899827713502369474065508674",
         9: "-8.87285693353062954433549289258", 10: "1.23605671757943030647266201528e1",
         11: "6.43392746015763530355970484046e-1"},
}

# weights of the order-8 solution: b_1, b_6 .. b_12 (b_2 .. b_5 = 0)
_B = {1: "5.42937341165687622380535766363e-2", 6: "4.45031289275240888144113950566",
      7: "1.89151789931450038304281599044", 8: "-5.8012039600105847814672114227",
      9: "3.1116436695781989440891606237e-1", 10: "-1.52160949662516078556178806805e-1",
      11: "2.01365400804030348374776537501e-1", 12: "4.47106157277725905176885569043e-2"}

# 3rd-order embedded weights bhh_1, bhh_2 (on stage 9), bhh_3 (on stage 12)
_BHH = {1: "0.244094488188976377952755905512", 9: "0.733846688281611857341361741547",
        12: "0.220588235294117647058823529412e-1"}

# 5th-order error estimator er_1, er_6 .. er_12
_ER = {1: "0.1312004499419488073250102996e-1", 6: "-0.1225156446376204440720569753e1",
       7: "-0.4957589496572501915214079952", 8: "0.1664377182454986536961530415e1",
       9: "-0.3503288487499736816886487290", 10: "0.3341791187130174790297318841",
       11: "0.8192320648511571246570742613e-1", 12: "-0.2235530786388629525884427845e-1"}


def exact_tables():
    """The tableau as ``fractions``-free decimal strings, for high-precision checks.

    Returns dicts ``(C, A, B, BHH, ER)`` keyed by 1-based stage numbers, with
    the values as the strings published in ``dop853.f`` (``C`` maps stage
    2 .. 12; ``C[12] = "1"``).
    """
    C = {i + 2: c for i, c in enumerate(_C)}
    C[12] = "1"
    return C, _A, _B, _BHH, _ER


@functools.cache
def coefficients():
    """(A (12, 12), B (12,), C (12,), E3 (13,), E5 (13,)) as contiguous float64 arrays."""
    n = N_STAGES
    A = np.zeros((n, n))
    for i, row in _A.items():
        for j, a in row.items():
            A[i - 1, j - 1] = float(a)
    B = np.zeros(n)
    for i, b in _B.items():
        B[i - 1] = float(b)
    C = np.zeros(n)
    C[1:11] = [float(c) for c in _C]
    C[11] = 1.0
    E5 = np.zeros(n + 1)
    for i, e in _ER.items():
        E5[i - 1] = float(e)
    E3 = np.zeros(n + 1)
    E3[:n] = B
    for i, b in _BHH.items():
        E3[i - 1] -= float(b)
    return tuple(np.ascontiguousarray(x, dtype=np.float64) for x in (A, B, C, E3, E5))


@jit_internal
def dop853_error_norm(K, h, y, y_new, rtol, atol, E3, E5):
    """Hairer's DOP853 error norm of one step: the 5th- and 3rd-order estimates combined.

    ``K`` (13, n) holds the stages of the step (the last one f(t + h, y_new),
    weighted zero), ``atol`` (n,) one absolute tolerance per component of ``y``;
    the scale of component j is ``atol[j] + rtol max(|y[j]|, |y_new[j]|)``. The
    particle and rigid-body kernels share this function (docs/physics/dop853.md).
    Compiled for compiled callers only (`rotframe.numerics.compiled.jit_internal`);
    from Python, call ``dop853_error_norm.py_func``.
    """
    n = y.shape[0]
    e5 = 0.0
    e3 = 0.0
    for j in range(n):
        a = y[j] if y[j] >= 0.0 else -y[j]  # max(|y|, |y_new|) as comparisons: no overloads to compile
        b = y_new[j] if y_new[j] >= 0.0 else -y_new[j]
        sc = atol[j] + rtol * (a if a >= b else b)
        s5 = 0.0
        s3 = 0.0
        for q in range(13):
            s5 += E5[q] * K[q, j]
            s3 += E3[q] * K[q, j]
        r5 = s5 / sc
        r3 = s3 / sc
        e5 += r5 * r5  # not ** 2: numba compiles an integer-power routine for that
        e3 += r3 * r3
    if e5 == 0.0 and e3 == 0.0:
        return 0.0
    return abs(h) * e5 / math.sqrt((e5 + 0.01 * e3) * n)
