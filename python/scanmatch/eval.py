"""Trajectory accuracy (the library's eval/metrics.hpp, as ``scanmatch eval`` on the command line).

Both trajectories are (N, 4, 4) arrays of associated poses: pose i of one belongs with pose i of
the other (e.g. ``Odometry.poses`` against ``Simulation.poses``).
"""

from ._scanmatch import ate, rpe

__all__ = ["ate", "rpe"]
