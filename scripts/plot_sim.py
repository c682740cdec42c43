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


def plot_planar(dataset, out, title, every):
    """2D data sets: ROBOTLASER1 scans placed at their ground-truth poses."""
    points, path = [], []
    with open(os.path.join(dataset, "scans.log")) as f:
        for i, line in enumerate(l for l in f if l.startswith("ROBOTLASER1")):
            v = line.split()
            start, step, n = float(v[2]), float(v[4]), int(v[8])
            ranges = np.array([float(x) for x in v[9:9 + n]])
            nr = int(v[9 + n])
            x, y, th = (float(a) for a in v[10 + n + nr:13 + n + nr])
            path.append((x, y))
            if i % every:
                continue
            ok = ranges < float(v[5])
            a = start + step * np.arange(n) + th
            points.append(np.stack([x + ranges[ok] * np.cos(a[ok]), y + ranges[ok] * np.sin(a[ok])], 1))
    pts, path = np.concatenate(points), np.array(path)
    fig, ax = plt.subplots(figsize=(9, 4.5))
    ax.scatter(pts[:, 0], pts[:, 1], s=0.3, c="k")
    ax.plot(path[:, 0], path[:, 1], "r-", lw=1, label="ground truth path")
    ax.set_aspect("equal")
    ax.set_title(f"{title}: scans placed at their ground-truth poses")
    ax.legend(loc="upper right")
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dataset")
    ap.add_argument("out")
    ap.add_argument("--every", type=int, default=10)
    ap.add_argument("--title", default="")
    ap.add_argument("--pattern", action="store_true")
    ap.add_argument("--max-z", type=float, default=None, help="top view: drop points above (ceilings)")
    args = ap.parse_args()
    info = json.load(open(os.path.join(args.dataset, "dataset.json")))
    title = args.title or f"{info['preset']} ({info['sensor']})"
    if os.path.exists(os.path.join(args.dataset, "scans.log")):
        plot_planar(args.dataset, args.out, title, args.every)
        return
    frames = sorted(os.listdir(os.path.join(args.dataset, "frames")))
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
    below = cloud if args.max_z is None else cloud[cloud[:, 2] < args.max_z]
    order = np.argsort(below[:, 2])
    top.scatter(below[order, 0], below[order, 1], c=below[order, 2], s=0.05, cmap="viridis")
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
