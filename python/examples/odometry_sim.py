"""LiDAR odometry on a simulated drive, from Python.

Run it with the venv the README's Python section sets up (Debian's numpy and matplotlib come in
through --system-site-packages):

    .venv/bin/python python/examples/odometry_sim.py [--frames 100] [--out odometry_sim.png]

It prints the absolute trajectory error and saves a plot of the estimate against the ground
truth.
"""

# %% [markdown]
# We start with the imports. matplotlib is told to draw into files (the Agg backend) before
# pyplot is imported, so the script also runs on a machine without a display.

# %%
import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import scanmatch  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--preset", default="dynamic-outdoor-fast", help="a simulator preset")
parser.add_argument("--frames", type=int, default=100, help="frames to simulate")
parser.add_argument("--method", default="ctf-icp", help="an odometry method")
parser.add_argument("--out", default="odometry_sim.png", help="where to save the plot")
args = parser.parse_args()

# %% [markdown]
# The simulator renders each frame of a preset: a scene, a sensor and a motion. Here it is a
# Livox MID-360 on a robot driving fast around a campus block. Every frame is a PointCloud in the
# sensor frame, and each point carries its own measurement time: the sensor moves while it
# scans, so the frames are motion-distorted, as real ones are. The simulator also knows exactly
# where the sensor was: `sim.poses` is the ground truth, one 4x4 pose per frame.

# %%
sim = scanmatch.simulate(args.preset, frames=args.frames, seed=1)
print(f"{sim}: {len(sim.frames[0])} points in the first frame, "
      f"fields x y z intensity ring time")

# %% [markdown]
# Odometry registers the frames one after the other. ctf-icp is the coarse-to-fine pipeline:
# NDT against the previous frame, then a fine registration against the global Gaussian map,
# with deskewing from the point times. Each call returns the sensor pose at the frame start;
# keyword arguments of `Odometry` set any field of the configuration
# (`scanmatch.odometry_options()` lists them). The frames are passed as PointCloud objects, which
# the library uses in place, without copying.

# %%
odometry = scanmatch.Odometry(args.method)
for frame, timestamp in sim:
    odometry.register_frame(frame, timestamp=timestamp)
total_ms = [s["total_ms"] for s in odometry.stats]
print(f"{args.method}: {odometry.frames} frames, {np.mean(total_ms):.1f} ms per frame on average")

# %% [markdown]
# The absolute trajectory error compares each estimated position with the true one. Both
# trajectories start at the identity, so no alignment is needed; `alignment="se3"` would fit
# one first.

# %%
ate = scanmatch.eval.ate(sim.poses, odometry.poses)
print(f"ATE {ate['rmse']:.3f} m RMSE (max {ate['max']:.3f} m), "
      f"{ate['rmse_percent_of_path']:.2f} % of the {ate['path_length']:.1f} m path")

# %% [markdown]
# Finally the plot: the path seen from above, estimate against ground truth, and the position
# error along the drive.

# %%
truth, estimate = sim.poses[:, :3, 3], odometry.poses[:, :3, 3]
error = np.linalg.norm(estimate - truth, axis=1)
fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.5))
left.plot(truth[:, 0], truth[:, 1], "k-", label="ground truth")
left.plot(estimate[:, 0], estimate[:, 1], "C1--", label=args.method)
left.set_xlabel("x (m)")
left.set_ylabel("y (m)")
left.set_aspect("equal", adjustable="datalim")
left.legend()
left.set_title(f"{sim.preset}, {len(sim)} frames")
right.plot(sim.timestamps, error * 100, "C1-")
right.set_xlabel("time (s)")
right.set_ylabel("position error (cm)")
right.set_title(f"ATE {ate['rmse'] * 100:.1f} cm RMSE")
fig.tight_layout()
fig.savefig(args.out, dpi=120)
print(f"plot saved to {args.out}")
