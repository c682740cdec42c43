"""Shared helpers of the Python tests (plain unittest; run with `python -m unittest discover`)."""

import numpy as np


def pose_error(truth, estimate):
    """Translation (m) and rotation (deg) of truth^-1 * estimate."""
    delta = np.linalg.inv(truth) @ estimate
    cos = np.clip((np.trace(delta[:3, :3]) - 1.0) / 2.0, -1.0, 1.0)
    return float(np.linalg.norm(delta[:3, 3])), float(np.degrees(np.arccos(cos)))
