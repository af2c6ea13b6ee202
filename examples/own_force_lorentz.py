"""Your own force: a proton gyrating in a uniform magnetic field, seen from a rotating frame.

The Lorentz force per unit mass, (q/m) v_inertial x B, is written as a plain function and
rotframe compiles it with numba; the frame turns at omega about z (think of a planet's
co-rotating magnetosphere). In the frame, v_inertial = v + omega x r. The gyration radius
m v / (q B) is checked at the end.

    python examples/own_force_lorentz.py --omega 2.0
"""

import argparse

import numpy as np

import rotframe


def lorentz(t, r, v, q_over_m, bz, wz):
    """(q/m) (v + w x r) x B with B = (0, 0, bz) and w = (0, 0, wz), frame axes (B is along the spin axis)."""
    vx = v[0] - wz * r[1]
    vy = v[1] + wz * r[0]
    return q_over_m * vy * bz, -q_over_m * vx * bz, 0.0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--omega", type=float, default=2.0, help="frame rotation rate, rad/s")
    args = parser.parse_args()
    q_over_m, bz = 9.58e7, 1e-6  # a proton in one microtesla: gyro-frequency 95.8 rad/s
    speed = 1.0e4
    wz = args.omega
    r0 = np.array([speed / (q_over_m * bz), 0.0, 0.0])  # on the gyro-circle about the origin
    v_in = np.array([0.0, -speed, 0.0])
    v0 = v_in - np.cross([0, 0, wz], r0)  # the frame sees the inertial velocity less omega x r
    res = rotframe.simulate(omega=[0, 0, wz], r0=r0, v0=v0, duration=1.0, forces=[lorentz],
                            params=(q_over_m, bz, wz), rtol=1e-11, samples=2000)
    radius = np.linalg.norm(res.trajectory.r[:, 0, :2], axis=1)
    print(f"gyration radius {radius.mean():.6f} m (theory m v / (q B) = {speed / (q_over_m * bz):.6f} m), "
          f"spread {radius.max() - radius.min():.2e} m, in a frame turning at {wz} rad/s")


if __name__ == "__main__":
    main()
