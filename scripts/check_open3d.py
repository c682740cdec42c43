#!/usr/bin/python3
"""Checks that Open3D (Debian's python3-open3d, optional) reads frames written by
`scanmatch simulate` with the same points as scanmatch.

usage: scripts/check_open3d.py DATASET   (exit 0 and a line per frame when they agree)
"""
import os
import subprocess
import sys

import numpy as np

try:
    import open3d as o3d
except ImportError:
    print("open3d not installed (apt-get install python3-open3d); skipped")
    sys.exit(0)

dataset = sys.argv[1]
cli = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "build", "scanmatch")
frames = sorted(os.listdir(os.path.join(dataset, "frames")))[:3]
for name in frames:
    path = os.path.join(dataset, "frames", name)
    cloud = o3d.io.read_point_cloud(path)
    points = np.asarray(cloud.points)
    info = subprocess.run([cli, "info", "--json", path], capture_output=True, text=True, check=True).stdout
    count = int(next(l for l in info.splitlines() if '"points":' in l).split(":")[1].strip(" ,"))
    ok = len(points) == count and np.all(np.isfinite(points))
    print(f"{name}: open3d {len(points)} points, scanmatch {count}: {'ok' if ok else 'MISMATCH'}")
    if not ok:
        sys.exit(1)
