"""Aerospace yaw, pitch, roll to a direction-cosine matrix and an angular velocity.

Yaw psi about z (down), pitch theta about the new y, roll phi about the newest x: the
intrinsic sequence "ZYX". ``rotframe.frames`` gives the passive matrix A (navigation frame
components -> body components) and the body rates (p, q, r) from the Euler-angle rates.
Checked here against the textbook formulas (Stevens & Lewis, eq. 1.3-22).

    python examples/aerospace_ypr.py --ypr 30,10,5 --rates 2,0,1
"""

import argparse

import numpy as np

from rotframe import frames

parser = argparse.ArgumentParser(description="yaw-pitch-roll -> DCM and body rates")
parser.add_argument("--ypr", default="30,10,5", help="yaw, pitch, roll in degrees")
parser.add_argument("--rates", default="2,0,1", help="yaw, pitch, roll rates in deg/s")
args = parser.parse_args()

ypr = np.array([float(x) for x in args.ypr.split(",")])
rates = np.array([float(x) for x in args.rates.split(",")])
A = frames.euler_to_dcm(ypr, seq="ZYX", degrees=True)  # navigation -> body
print("direction-cosine matrix (navigation -> body):\n", np.array2string(A, precision=6, suppress_small=True))
pqr = frames.euler_rates_to_omega(ypr, rates, seq="ZYX", frame="body", degrees=True)
print("body rates p, q, r (deg/s):", np.array2string(pqr, precision=6))

# the same from the textbook: p = phidot - psidot sin(theta), q = thetadot cos(phi) + psidot cos(theta) sin(phi),
# r = -thetadot sin(phi) + psidot cos(theta) cos(phi)
psi, theta, phi = np.radians(ypr)
psid, thetad, phid = rates
book = np.array([phid - psid * np.sin(theta),
                 thetad * np.cos(phi) + psid * np.cos(theta) * np.sin(phi),
                 -thetad * np.sin(phi) + psid * np.cos(theta) * np.cos(phi)])
assert np.allclose(pqr, book, atol=1e-12), (pqr, book)
back = frames.dcm_to_euler(A, seq="ZYX", degrees=True)
assert np.allclose(back, ypr, atol=1e-9)
print("round trip yaw, pitch, roll (deg):", np.array2string(back, precision=6))
