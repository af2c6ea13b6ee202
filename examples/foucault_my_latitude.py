"""Foucault's pendulum at your own latitude: the swing plane turns at Omega sin(latitude).

    python examples/foucault_my_latitude.py --latitude "52d12m N" --length 20 --duration "2 h"

Latitudes as numbers (degrees, north positive) or strings such as "33d52m S";
lengths and durations as numbers (m, s) or with units ("65 ft", "2 h").
"""

import argparse

import rotframe

parser = argparse.ArgumentParser(description="Foucault's pendulum at your latitude")
parser.add_argument("--latitude", default="51d28m N", help="your latitude (default Greenwich)")
parser.add_argument("--length", default="20 m", help="string length")
parser.add_argument("--duration", default="1 h", help="simulated time")
args = parser.parse_args()

r = rotframe.run("foucault", latitude=args.latitude, length=args.length, duration=args.duration)
rate, theory = r.metrics["precession_rate_deg_per_hour"], r.theory["precession_rate_deg_per_hour"]
sense = "clockwise" if rate > 5e-4 else "anticlockwise" if rate < -5e-4 else "(not measurably)"
print(f"latitude {r.params['latitude']:.4f} deg, string {r.params['length']:g} m, period {r.metrics['period_s']:.3f} s")
omega_sin = r.diagnostics["omega_sin_latitude_deg_per_hour"]
print(f"the swing plane turns {abs(rate):.3f} deg/h {sense} seen from above "
      f"(theory {abs(theory):.3f} deg/h: Omega sin(lat) = {abs(omega_sin):.3f} less Airy's finite-swing correction)")
if abs(rate) > 5e-4:
    print(f"a full turn takes {360 / abs(rate):.1f} h")
