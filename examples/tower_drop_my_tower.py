"""Drop a ball from your own tower: how far east of the foot does it land?

    python examples/tower_drop_my_tower.py --height "828 m" --latitude "25d11m N"   # Burj Khalifa

To first order the ball lands (1/3) Omega g t^3 cos(latitude) east of the foot; the
simulation solves the equations exactly (gravity and Coriolis; add drag with --drag).
"""

import argparse

import rotframe

parser = argparse.ArgumentParser(description="eastward deflection of a dropped ball")
parser.add_argument("--height", default="324 m", help="drop height (default the Eiffel tower)")
parser.add_argument("--latitude", default="48d51m30s N", help="latitude of the tower")
parser.add_argument("--drag", default=0.0, type=float, help="quadratic drag k (1/m); 0 = vacuum")
args = parser.parse_args()

r = rotframe.run("tower-drop", height=args.height, latitude=args.latitude, drag=args.drag)
east, north = r.metrics["east_deflection_m"], r.metrics["north_deflection_m"]
print(f"height {r.params['height']:.1f} m at latitude {r.params['latitude']:.3f} deg: "
      f"falls {r.metrics['fall_time_s']:.2f} s")
print(f"lands {1000 * east:.1f} mm east (first-order theory {1000 * r.theory['east_deflection_m']:.1f} mm) "
      f"and {1000 * abs(north):.3f} mm {'south' if north < 0 else 'north'}")
# the path itself: r.trajectory.r[:, 0] is (samples, 3) in metres, x east, y north, z up
