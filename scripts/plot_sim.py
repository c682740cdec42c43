#!/usr/bin/python3
"""Top and side views of a simulated data set's accumulated map (frames moved by ground truth).

usage: scripts/plot_sim.py DATASET OUT.png [--every N] [--title TEXT] [--pattern]
--pattern plots the first frame's ray pattern (azimuth/elevation) instead of a map.
"""
import argparse
import json
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read_pcd(path):
    with open(path, "rb") as f:
        data = f.read()
    header_end = data.index(b"DATA binary\n") + len(b"DATA binary\n")
    header = data[:header_end].decode().split("\n")
    fields = next(l for l in header if l.startswith("FIELDS")).split()[1:]
    sizes = [int(s) for s in next(l for l in header if l.startswith("SIZE")).split()[1:]]
    types = next(l for l in header if l.startswith("TYPE")).split()[1:]
    kinds = {("F", 4): "<f4", ("U", 2): "<u2", ("F", 8): "<f8", ("U", 1): "u1"}
    dtype = np.dtype([(n, kinds[(t, s)]) for n, t, s in zip(fields, types, sizes)])
    return np.frombuffer(data[header_end:], dtype=dtype)


def read_kitti(path):
    rows = np.loadtxt(path, ndmin=2)
    poses = np.tile(np.eye(4), (len(rows), 1, 1))
    poses[:, :3, :] = rows.reshape(-1, 3, 4)
    return poses


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dataset")
    ap.add_argument("out")
    ap.add_argument("--every", type=int, default=10)
    ap.add_argument("--title", default="")
    ap.add_argument("--pattern", action="store_true")
    args = ap.parse_args()
    info = json.load(open(os.path.join(args.dataset, "dataset.json")))
    frames = sorted(os.listdir(os.path.join(args.dataset, "frames")))
    title = args.title or f"{info['preset']} ({info['sensor']})"
    if args.pattern:
        fig, axes = plt.subplots(1, 2, figsize=(12, 3.6))
        for ax, count in zip(axes, [1, 5]):
            for i in range(count):
                p = read_pcd(os.path.join(args.dataset, "frames", frames[i]))
                r = np.sqrt(p["x"] ** 2 + p["y"] ** 2 + p["z"] ** 2)
                az = np.degrees(np.arctan2(p["y"], p["x"]))
                el = np.degrees(np.arcsin(p["z"] / np.maximum(r, 1e-6)))
                ax.scatter(az, el, s=0.2, alpha=0.6, label=f"frame {i}")
            ax.set_xlabel("azimuth (deg)")
            ax.set_ylabel("elevation (deg)")
            ax.set_title(f"{title}: {count} frame(s)")
        fig.tight_layout()
        fig.savefig(args.out, dpi=110)
        return
    poses = read_kitti(os.path.join(args.dataset, "poses_gt.txt"))
    clouds = []
    for i in range(0, len(frames), args.every):
        p = read_pcd(os.path.join(args.dataset, "frames", frames[i]))
        xyz = np.stack([p["x"], p["y"], p["z"]], axis=1).astype(np.float64)
        clouds.append(xyz @ poses[i][:3, :3].T + poses[i][:3, 3])
    cloud = np.concatenate(clouds)
    fig, (top, side) = plt.subplots(1, 2, figsize=(13, 5), gridspec_kw={"width_ratios": [1.3, 1]})
    order = np.argsort(cloud[:, 2])
    top.scatter(cloud[order, 0], cloud[order, 1], c=cloud[order, 2], s=0.05, cmap="viridis")
    top.plot(poses[:, 0, 3], poses[:, 1, 3], "r-", lw=1, label="ground truth path")
    top.set_aspect("equal")
    top.set_title(f"{title}: top view, {len(clouds)} frames accumulated")
    top.legend(loc="upper right", markerscale=10)
    side.scatter(cloud[:, 0], cloud[:, 2], s=0.05, c="k", alpha=0.3)
    side.set_title("side view (x, z)")
    side.set_aspect("equal")
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)


if __name__ == "__main__":
    main()
