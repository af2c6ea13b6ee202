"""Your own torque: a tumbling satellite with magnetic-style damping, tau = -c omega.

The torque is a plain function of (t, L, q) in body axes, compiled by numba. With
tau = -c I^-1 L the energy decays and the spin settles; for a symmetric damping each body
rate decays like exp(-c t / I_k) about a principal axis, which is checked on a single-axis spin.

    python examples/own_torque_damping.py --c 0.05
"""

import argparse

import numpy as np

import rotframe


def damping(t, L, q, c, i1, i2, i3):
    return -c * L[0] / i1, -c * L[1] / i2, -c * L[2] / i3


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--c", type=float, default=0.05, help="damping coefficient, N m s")
    args = parser.parse_args()
    inertia = (1.0, 2.0, 3.0)
    res = rotframe.simulate_body(inertia=inertia, L0=[0.0, 0.0, 3.0], q0=[0, 0, 0, 1], duration=20.0,
                                 torque=damping, params=(args.c, *inertia), rtol=1e-12, samples=100)
    L3 = res.trajectory.L[-1, 2]
    exact = 3.0 * np.exp(-args.c * 20.0 / inertia[2])
    print(f"spin about axis 3 decays to L3 = {L3:.9f} kg m^2/s (exact 3 exp(-c t / I3) = {exact:.9f})")
    tumbling = rotframe.simulate_body(inertia=inertia, L0=[0.5, 2.0, 0.3], q0=[0, 0, 0, 1], duration=20.0,
                                      torque=damping, params=(args.c, *inertia), samples=100)
    L = tumbling.trajectory.L
    print(f"a tumbling body: |L| {np.linalg.norm(L[0]):.3f} -> {np.linalg.norm(L[-1]):.3f} kg m^2/s")


if __name__ == "__main__":
    main()
