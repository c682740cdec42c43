#!/usr/bin/python3
"""SE(2)-aligned ATE of a 2D run over all scans and over the scans before and from one index.

Usage: scripts/segment_ate_2d.py REFERENCE_TUM ESTIMATE_TUM FIRST_SCAN_OF_SECOND_PART

Each part is aligned on its own, so a single bad relative pose between the parts (in the estimate
or in the reference) shows as a large ATE over all scans with small ATEs within the parts. Used in
docs/planar.md for the fhw log, where our odometry loses 70-85 degrees in the spin at scans 40-65
(the break falls at scans 58 -> 59). Needs python3-numpy (Debian).
"""
import math
import sys

import numpy as np


def positions(path):
    rows = np.loadtxt(path, ndmin=2)
    if rows.shape[1] < 8:
        sys.exit(f"{path}: expected TUM rows (time x y z qx qy qz qw)")
    return rows[:, 1:3]


def aligned_rmse(estimate, reference):
    """RMSE after the rotation and translation that fit estimate onto reference best."""
    a = estimate - estimate.mean(0)
    b = reference - reference.mean(0)
    angle = math.atan2((a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]).sum(), (a * b).sum())
    c, s = math.cos(angle), math.sin(angle)
    moved = a @ np.array([[c, s], [-s, c]])
    return math.sqrt(((moved - b) ** 2).sum(1).mean()), math.degrees(angle)


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    reference, estimate = positions(sys.argv[1]), positions(sys.argv[2])
    if len(reference) != len(estimate):
        sys.exit(f"{len(reference)} reference poses but {len(estimate)} estimated")
    cut = int(sys.argv[3])
    if not 2 <= cut <= len(reference) - 2:
        sys.exit(f"the cut must leave two poses on each side (0..{len(reference)})")
    for name, part in (("all", slice(None)), (f"scans 0-{cut - 1}", slice(0, cut)),
                       (f"scans {cut}-{len(reference) - 1}", slice(cut, None))):
        rmse, angle = aligned_rmse(estimate[part], reference[part])
        print(f"{name}: ATE {rmse:.3f} m (aligned by {angle:.1f} deg)")


if __name__ == "__main__":
    main()
