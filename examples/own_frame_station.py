"""Your own frame: a ball let go inside a space station that spins up.

The station's angular velocity is a function of time, omega(t) = (0, 0, alpha t) (spinning
up at alpha rad/s^2 from rest); rotframe derives omega'(t) for the Euler force. The ball,
let go at t = 0, 20 m from the axis, while the station is still at rest, stays at rest in
space; in the station's axes it falls behind as the station turns by alpha t^2 / 2, pushed
by the Euler, centrifugal and Coriolis forces. We check that against the inertial answer.

    python examples/own_frame_station.py --alpha 0.01
"""

import argparse

import numpy as np

import rotframe


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--alpha", type=float, default=0.01, help="spin-up rate, rad/s^2")
    parser.add_argument("--duration", type=float, default=10.0, help="seconds")
    args = parser.parse_args()
    alpha, T = args.alpha, args.duration
    omega = lambda t: (0.0, 0.0, alpha * t)  # noqa: E731 (a user's one-liner)
    r0 = np.array([20.0, 0.0, 0.0])
    res = rotframe.simulate(omega=omega, r0=r0, v0=[0.0, 0.0, 0.0], duration=T, rtol=1e-11, samples=200)
    # inertial: the ball stays at rest at (20, 0, 0); the station has turned by alpha t^2 / 2
    t = res.trajectory.times
    angle = 0.5 * alpha * t * t
    exact = np.stack([20 * np.cos(angle), -20 * np.sin(angle), 0 * t], axis=1)
    err = np.max(np.linalg.norm(res.trajectory.r[:, 0] - exact, axis=1))
    print(f"after {T:g} s the station turned {np.degrees(angle[-1]):.1f} deg; the ball, at rest in space, is "
          f"{np.degrees(angle[-1]):.1f} deg behind in the station's axes; error against the inertial line {err:.1e} m")


if __name__ == "__main__":
    main()
