#!/usr/bin/python3
"""Registers the real pairs in ../shared/data/3d with every method of `scanmatch register` and
prints a Markdown table of the error against each pair's reference transform.

usage: scripts/real_pairs.py [--cli build/scanmatch] [--voxel 0.1]
"""
import argparse
import json
import os
import subprocess

import numpy as np

METHODS = ["icp", "icp-gn", "point-to-plane", "point-to-line", "gicp", "vgicp", "ndt", "ctf-fine",
           "loam", "loam-edge", "loam-plane"]


def car_reference(folder):
    for line in open(os.path.join(folder, "carCloudList.csv")):
        cells = [c.strip() for c in line.split(",")]
        if cells[0] == "car_cloud401.csv":
            return np.array([float(v) for v in cells[1:17]]).reshape(4, 4)
    raise SystemExit("no reference for car_cloud401.csv")


def error(reference, estimate):
    delta = np.linalg.inv(reference) @ estimate
    angle = np.degrees(np.arccos(np.clip((np.trace(delta[:3, :3]) - 1) / 2, -1, 1)))
    return np.linalg.norm(delta[:3, 3]), angle


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", default="build/scanmatch")
    ap.add_argument("--voxel", default="0.1")
    args = ap.parse_args()
    shared = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared", "data", "3d")
    pairs = [
        ("hdl32_pair", os.path.join(shared, "hdl32_pair", "source.ply"), os.path.join(shared, "hdl32_pair", "target.ply"),
         np.loadtxt(os.path.join(shared, "hdl32_pair", "T_target_source.txt"))),
        ("car_pair", os.path.join(shared, "car_pair", "car_cloud401.csv"), os.path.join(shared, "car_pair", "car_cloud400.csv"),
         car_reference(os.path.join(shared, "car_pair"))),
    ]
    print("| pair | method | translation error (m) | rotation error (deg) | iterations | time (ms) |")
    print("|---|---|---|---|---|---|")
    for name, source, target, reference in pairs:
        for method in METHODS:
            run = subprocess.run([args.cli, "register", source, target, "--method", method, "--voxel", args.voxel,
                                  "--max-iterations", "60", "--json"], capture_output=True, text=True)
            if run.returncode != 0:
                print(f"| {name} | {method} | failed: {run.stderr.strip()} | | | |")
                continue
            result = json.loads(run.stdout)
            t, r = error(reference, np.array(result["transform"]))
            print(f"| {name} | {method} | {t:.3f} | {r:.2f} | {result['iterations']} | {result['time_ms']:.0f} |")


if __name__ == "__main__":
    main()
