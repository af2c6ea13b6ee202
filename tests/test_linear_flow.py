"""The exact linear flow expm(M t) against mpmath at 40 digits, over long times.

``rotframe.particles.linear.flow_at`` takes scipy's ``expm`` of a similarity-scaled M t,
so that the kinematic r' = v and the constant force b do not add squarings (and their
round-off) that the motion does not need. The oracle is mpmath's own ``expm`` on the
same M, written out here from the model's rates (not from rotframe's ``flow_matrix``),
in 40-digit arithmetic. Plain ``expm(M t)`` misses these tolerances wherever the kinematic
coupling or the force set its norm: 3e-14 after 248 s with the centrifugal term, 7e-14 after
1e4 s with drag, 8e-12 after 1e5 s and 1e-10 after 6e5 s for gravity and Coriolis.
"""

import math

import mpmath as mp
import numpy as np
import pytest

from rotframe.particles.integrators import Event, integrate_particles
from rotframe.particles.linear import flow_at, flow_matrix
from rotframe.particles.model import OmegaSchedule, ParticleModel

LAT = math.radians(49.6)
OMEGA = 7.2921159e-5
W = OMEGA * np.array([0.0, math.cos(LAT), math.sin(LAT)])
G = np.array([0.0, 0.0, -9.81])

MODELS = {
    "gravity, Coriolis": (ParticleModel(("gravity", "coriolis"), omega=OmegaSchedule.constant(W), g=G),
                          dict(gravity=True)),
    "and centrifugal": (ParticleModel(("gravity", "coriolis", "centrifugal"), omega=OmegaSchedule.constant(W), g=G),
                        dict(gravity=True, centrifugal=True)),
    "f-plane": (ParticleModel(("coriolis",), omega=OmegaSchedule.constant([0.0, 0.0, 1.1e-4])), {}),
    "drag": (ParticleModel(("gravity", "coriolis", "linear-drag"), omega=OmegaSchedule.constant(W), g=G,
                           k_linear=2e-6), dict(gravity=True, drag=2e-6)),
    "spring": (ParticleModel(("coriolis", "spring"), omega=OmegaSchedule.constant(W), spring=1e-7),
               dict(spring=1e-7)),
}


def mp_flow(model, spec, t):
    """expm(M t) in mpmath at 40 digits, M from r'' = b - 2 w x v - w x (w x r) - k v - s r_h written out here (r_h: x and y)."""
    with mp.workdps(40):
        w = [mp.mpf(float(x)) for x in model.omega.vector(0.0)]
        M = mp.zeros(7, 7)
        for i in range(3):
            M[i, 3 + i] = 1
        hat = mp.matrix([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
        hat2 = hat * hat
        for i in range(3):
            for j in range(3):
                M[3 + i, 3 + j] = -2 * hat[i, j] - (mp.mpf(spec["drag"]) if "drag" in spec and i == j else 0)
                M[3 + i, j] = (-hat2[i, j] if spec.get("centrifugal") else 0) - (
                    mp.mpf(spec["spring"]) if "spring" in spec and i == j < 2 else 0)
            M[3 + i, 6] = mp.mpf(float(G[i])) if spec.get("gravity") else 0
        return mp.expm(M * mp.mpf(t))


@pytest.mark.parametrize("name", MODELS)
@pytest.mark.parametrize("t, tol", [(5.0, 1e-14), (248.0, 1e-14), (1e4, 1e-14), (1e5, 2e-14), (6e5, 2e-12)])
def test_flow_at_against_mpmath(name, t, tol):
    model, spec = MODELS[name]
    s0 = np.array([1.0, -2.0, 3.0, 100.0, 50.0, 800.0, 1.0])
    got = flow_at(flow_matrix(model), t) @ s0
    with mp.workdps(40):
        ref = np.array([float(x) for x in mp_flow(model, spec, t) * mp.matrix(s0.tolist())])
    for block in (slice(0, 3), slice(3, 6)):
        err = np.max(np.abs(got[block] - ref[block])) / np.max(np.abs(ref[block]))
        assert err < tol, (name, t, block, err)
    assert got[6] == 1.0


def test_flow_at_zero_time_is_the_identity():
    model, _ = MODELS["gravity, Coriolis"]
    assert np.array_equal(flow_at(flow_matrix(model), 0.0), np.eye(7))


def test_exact_runs_land_a_long_shot_to_round_off():
    """integrate_particles(method="exact"): ground crossing and landing point against mpmath's flow and root."""
    model, spec = MODELS["gravity, Coriolis"]
    v0 = 1600.0 * np.array([math.cos(math.radians(50)) * math.sin(math.radians(232)),
                            math.cos(math.radians(50)) * math.cos(math.radians(232)), math.sin(math.radians(50))])
    traj = integrate_particles(model, np.zeros(3), v0, 400.0, method="exact", samples=2000,
                               events=[Event("ground", "r", 2, 0.0, -1, True)])
    t_hit = float(traj.event_times["ground"][0][0])
    with mp.workdps(40):
        s0 = mp.matrix([0, 0, 0] + [mp.mpf(float(x)) for x in v0] + [1])
        t_ref = mp.findroot(lambda t: (mp_flow(model, spec, t) * s0)[2], mp.mpf(t_hit))
        r_ref = np.array([float(x) for x in (mp_flow(model, spec, t_ref) * s0)[0:3]])
    assert abs(t_hit - float(t_ref)) < 4e-15 * float(t_ref)
    r_hit = traj.event_states["ground"][0][0][:3]
    assert np.max(np.abs(r_hit - r_ref)) < 4e-15 * np.max(np.abs(r_ref))


def test_a_steady_force_free_run_stays_on_its_inertial_line_over_many_turns():
    """Coriolis and centrifugal at 1 rad/s for 160 turns: the inertial straight line, seen turning (written here).

    This model is linear, but its M is defective (double eigenvalues +-i w) and expm's
    round-off grows like the square of the turns (6e-10 relative here); the exact run takes the
    force-free closed form instead.
    """
    w = 1.0
    model = ParticleModel(("coriolis", "centrifugal"), omega=OmegaSchedule.constant([0.0, 0.0, w]))
    r0, v0 = np.array([2.0, 0.0, 0.5]), np.array([-1.0, 0.3, 0.2])
    traj = integrate_particles(model, r0, v0, 1000.0, method="exact", samples=4000)
    t = traj.times
    u = v0 + np.cross([0.0, 0.0, w], r0)  # inertial velocity
    line = r0[None] + t[:, None] * u[None]
    c, s = np.cos(w * t), np.sin(w * t)  # the frame has turned by w t: rotate back by -w t
    seen = np.stack([c * line[:, 0] + s * line[:, 1], -s * line[:, 0] + c * line[:, 1], line[:, 2]], axis=1)
    err = np.max(np.linalg.norm(traj.r[:, 0] - seen, axis=1) / np.maximum(1.0, np.linalg.norm(seen, axis=1)))
    assert err < 1e-13, err
