"""A nearly spherical free top (I3/I1 - 1 = 1e-12) keeps its body precession to round-off (issue 27).

``1/I3 - 1/I1`` of the two rounded inverses cancels and lost five digits; the rate is computed
as ``(I1 - I3) / (I1 I3)``. The oracle: mpmath at 50 digits from the same float moments.
"""


import mpmath
import numpy as np
import pytest

from rotframe.rigid import dynamics as rigid

I1 = 2.0
I3 = 2.0 * (1 + 1e-12)
L0 = np.array([0.3, 0.0, 5.0])


def _k_mp():
    with mpmath.workdps(50):
        return mpmath.mpf(L0[2]) * (1 / mpmath.mpf(I3) - 1 / mpmath.mpf(I1))


def test_elliptic_period_of_a_nearly_spherical_top_against_mpmath():
    with mpmath.workdps(50):
        ref = float(2 * mpmath.pi / abs(_k_mp()))
    got = rigid.elliptic_period([I1, I1, I3], L0)
    assert got == pytest.approx(ref, rel=1e-14)


@pytest.mark.parametrize("method", ["exact", "lie-poisson4"])
def test_body_rotation_of_a_nearly_spherical_top_against_mpmath(method):
    # the body components (L1, L2) turn at -k about e3; over t they turn by -k t: compare the angle
    t = 1e12
    with mpmath.workdps(50):
        angle = -_k_mp() * t
        ref = np.array([float(mpmath.mpf(L0[0]) * mpmath.cos(angle)), float(mpmath.mpf(L0[0]) * mpmath.sin(angle))])
    q0 = np.array([0.0, 0.0, 0.0, 1.0])
    if method == "exact":
        L, _ = rigid.free_body_exact([I1, I1, I3], L0, q0, [t])
        L = L[-1]
    else:
        Ls, _, _ = rigid.lie_poisson([I1, I1, I3], L0, q0, t / 10, 10, order=4)  # the symmetric sub-flows are exact
        L = Ls[-1]
    # an angle of 2.5 rad known to ~1e-15 relative; 1/I3 - 1/I1 of rounded inverses was off by ~1e-4
    assert np.allclose(L[:2], ref, rtol=0, atol=1e-12 * abs(L0[0])), (L[:2], ref)
