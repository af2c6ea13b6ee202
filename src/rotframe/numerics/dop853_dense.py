"""Dense output of Dormand-Prince 8(5,3): three extra stages and the interpolant's weights.

The continuous extension of order 7 that accompanies Hairer's ``dop853.f`` (Hairer, Norsett
& Wanner, *Solving Ordinary Differential Equations I*, 2nd ed., II.6 and II.10, routine
``contd8``): after an accepted step with stages ``k_1 .. k_12`` and ``k_13 = f(t + h, y_new)``,
three more stages

    k_i = f(t + C[i] h, y + h sum_j A[i, j] k_j)     i = 14, 15, 16

and four rows of weights ``D`` give the coefficients of the interpolant (docs/physics/dop853.md;
`dense_coefficients` and `dense_value` evaluate it, for every DOP853 loop of rotframe). The constants are the decimal strings published
with ``dop853.f`` (as scipy's ``solve_ivp`` ships them), rounded to float64 once; the 12-stage
tableau itself is `rotframe.numerics.dop853`. Kept here rather than read from scipy so that
a first run does not import ``scipy.integrate`` (0.2 s).
"""

from __future__ import annotations

import functools

import numpy as np

from rotframe.numerics.compiled import jit_inline, jit_internal

__all__ = ["dense_tables", "extended_tableau", "dense_coefficients", "dense_value", "C_EXTRA"]

# rows 14..16 of A: {stage (1-based): {column (1-based): a}}
_A_EXTRA = {
    14: {1: "5.61675022830479523392909219681e-2", 7: "2.53500210216624811088794765333e-1",
         8: "-2.46239037470802489917441475441e-1", 9: "-1.24191423263816360469010140626e-1",
         10: "1.5329179827876569731206322685e-1", 11: "8.20105229563468988491666602057e-3",
         12: "7.56789766054569976138603589584e-3", 13: "-8.298e-3"},
    15: {1: "3.18346481635021405060768473261e-2", 6: "2.83009096723667755288322961402e-2",
         7: "5.35419883074385676223797384372e-2", 8: "-5.49237485713909884646569340306e-2",
         11: "-1.08347328697249322858509316994e-4", 12: "3.82571090835658412954920192323e-4",
         13: "-3.40465008687404560802977114492e-4", 14: "1.41312443674632500278074618366e-1"},
    16: {1: "-4.28896301583791923408573538692e-1", 6: "-4.69762141536116384314449447206",
         7: "7.68342119606259904184240953878", 8: "4.06898981839711007970213554331",
         9: "3.56727187455281109270669543021e-1", 13: "-1.39902416515901462129418009734e-3",
         14: "2.9475147891527723389556272149", 15: "-9.15095847217987001081870187138"},
}

# the interpolant's weights: {row (1-based): {stage (1-based): d}}
_D = {
    1: {1: "-0.84289382761090128651353491142e+1", 6: "0.56671495351937776962531783590",
         7: "-0.30689499459498916912797304727e+1", 8: "0.23846676565120698287728149680e+1",
         9: "0.21170345824450282767155149946e+1", 10: "-0.87139158377797299206789907490",
         11: "0.22404374302607882758541771650e+1", 12: "0.63157877876946881815570249290",
         13: "-0.88990336451333310820698117400e-1", 14: "0.18148505520854727256656404962e+2",
         15: "-0.91946323924783554000451984436e+1", 16: "-0.44360363875948939664310572000e+1"},
    2: {1: "0.10427508642579134603413151009e+2", 6: "0.24228349177525818288430175319e+3",
         7: "0.16520045171727028198505394887e+3", 8: "-0.37454675472269020279518312152e+3",
         9: "-0.22113666853125306036270938578e+2", 10: "0.77334326684722638389603898808e+1",
         11: "-0.30674084731089398182061213626e+2", 12: "-0.93321305264302278729567221706e+1",
         13: "0.15697238121770843886131091075e+2", 14: "-0.31139403219565177677282850411e+2",
         15: "-0.93529243588444783865713862664e+1", 16: "0.35816841486394083752465898540e+2"},
    3: {1: "0.19985053242002433820987653617e+2", 6: "-0.38703730874935176555105901742e+3",
         7: "-0.18917813819516756882830838328e+3", 8: "0.52780815920542364900561016686e+3",
         9: "-0.11573902539959630126141871134e+2", 10: "0.68812326946963000169666922661e+1",
         11: "-0.10006050966910838403183860980e+1", 12: "0.77771377980534432092869265740",
         13: "-0.27782057523535084065932004339e+1", 14: "-0.60196695231264120758267380846e+2",
         15: "0.84320405506677161018159903784e+2", 16: "0.11992291136182789328035130030e+2"},
    4: {1: "-0.25693933462703749003312586129e+2", 6: "-0.15418974869023643374053993627e+3",
         7: "-0.23152937917604549567536039109e+3", 8: "0.35763911791061412378285349910e+3",
         9: "0.93405324183624310003907691704e+2", 10: "-0.37458323136451633156875139351e+2",
         11: "0.10409964950896230045147246184e+3", 12: "0.29840293426660503123344363579e+2",
         13: "-0.43533456590011143754432175058e+2", 14: "0.96324553959188282948394950600e+2",
         15: "-0.39177261675615439165231486172e+2", 16: "-0.14972683625798562581422125276e+3"},
}


@functools.cache
def dense_tables():
    """(A_extra (3, 16), D (4, 16)): rows 14..16 of the extended tableau and the weights, float64."""
    A = np.zeros((3, 16))
    for i, row in _A_EXTRA.items():
        for j, a in row.items():
            A[i - 14, j - 1] = float(a)
    D = np.zeros((4, 16))
    for i, row in _D.items():
        for j, d in row.items():
            D[i - 1, j - 1] = float(d)
    return A, D


#: the nodes of the three dense-output stages (dop853.f's c14, c15, c16)
C_EXTRA = (0.1, 0.2, 0.777777777777777777777777777778)


@functools.cache
def extended_tableau():
    """(A (16, 16), C (16,), D (4, 16)): the step's stages and the dense output's, in one stage loop.

    Rows 0..11 of ``A`` are the stages of `rotframe.numerics.dop853.coefficients`, row 12 its
    order-8 weights ``B`` (so that "stage 12" forms ``y_new = y + h sum B_q k_q``, and ``k_12`` is
    ``f(t + h, y_new)``), rows 13..15 the dense output's stages. ``C`` their nodes (``C[12] = 1``).
    Read-only arrays, made once.
    """
    from rotframe.numerics.dop853 import coefficients

    A12, B, C12, _, _ = coefficients()
    A_extra, D = dense_tables()
    A = np.zeros((16, 16))
    A[:12, :12] = A12
    A[12, :12] = B
    A[13:] = A_extra
    C = np.zeros(16)
    C[:12] = C12
    C[12] = 1.0
    C[13:] = C_EXTRA
    for x in (A, C, D):
        x.flags.writeable = False
    return A, C, D


@jit_internal
def dense_coefficients(y, y_new, K, h, D, F):
    """The interpolant's coefficients ``F`` (7, n) of an accepted step, Hairer's ``contd8`` form.

    ``K`` (16, n) holds the step's stages, ``K[12] = f(t + h, y_new)`` and the dense output's
    three stages ``K[13..15]`` (rows 13..15 of `extended_tableau`); ``D`` as `extended_tableau`.
    """
    for j in range(y.shape[0]):
        dy = y_new[j] - y[j]
        F[0, j] = dy
        F[1, j] = h * K[0, j] - dy
        F[2, j] = 2 * dy - h * (K[12, j] + K[0, j])
        for r in range(4):
            acc = 0.0
            for q in range(16):
                acc += D[r, q] * K[q, j]
            F[3 + r, j] = h * acc


@jit_inline
def dense_value(F, y, x, j):
    """Component ``j`` of the interpolant at ``t + x h`` (``0 <= x <= 1``): order 7 in the step.

    ``y + x (F0 + (1-x) (F1 + x (F2 + (1-x) (F3 + x (F4 + (1-x) (F5 + x F6))))))``, from the
    innermost term out (``contd8`` of dop853.f).
    """
    v = 0.0
    for i in range(7):
        v += F[6 - i, j]
        v *= x if i % 2 == 0 else 1.0 - x
    return y[j] + v
