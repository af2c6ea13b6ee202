"""A sweep from Python with a plot: Foucault's precession rate against latitude.

One ``rotframe.sweep`` call runs every latitude (one row each, a pandas DataFrame: the
command line's sweep, with ``client=`` for a Dask cluster); the curve behind is
Omega sin(latitude).

    python examples/sweep_latitude.py --points 13 --out foucault-latitude.png
"""

import argparse
import os
import tempfile

import matplotlib

matplotlib.use("Agg")  # write a file, open no window
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import rotframe  # noqa: E402

parser = argparse.ArgumentParser(description="Foucault rate against latitude")
parser.add_argument("--points", default=9, type=int, help="latitudes from -90 to 90")
parser.add_argument("--duration", default=1800.0, type=float, help="simulated seconds per run")
parser.add_argument("--out", default=os.path.join(tempfile.gettempdir(), "foucault-latitude.png"), help="PNG path")
args = parser.parse_args()

latitudes = np.linspace(-90, 90, args.points)
table = rotframe.sweep("foucault", grid={"latitude": latitudes}, method="exact", duration=args.duration,
                       small_angle=True)
rates = table["precession_rate_deg_per_hour"].to_numpy()
theory = table["theory_precession_rate_deg_per_hour"].to_numpy()

fine = np.linspace(-90, 90, 181)
peak = max(abs(t) for t in theory)  # Omega in deg/h
fig, ax = plt.subplots(figsize=(6, 4))
ax.plot(fine, peak * np.sin(np.radians(fine)), color="0.7", label="Omega sin(latitude)")
ax.plot(latitudes, rates, "o", label="simulated")
ax.set_xlabel("latitude (deg)")
ax.set_ylabel("precession, clockwise (deg/h)")
ax.legend()
fig.tight_layout()
fig.savefig(args.out, dpi=100)
worst = max(abs(a - b) for a, b in zip(rates, theory))
print(f"{len(latitudes)} runs; largest difference from theory {worst:.2e} deg/h; plot in {args.out}")
