"""Trajectory accuracy (the library's eval/metrics.hpp, as ``scanmatch eval`` on the command line)
and its 2D forms (eval/metrics2d.hpp, as ``scanmatch map2d`` reports them).

3D: both trajectories are (N, 4, 4) arrays of associated poses: pose i of one belongs with pose i
of the other (e.g. ``Odometry.poses`` against ``Simulation.poses``); ``ate`` and ``rpe``.

2D: poses as the 2D classes give and take them, (N, 3, 3) homogeneous matrices (e.g.
``Mapper2D.poses``, ``LoopClosure2D.poses``) or (N, 3) rows of x y theta; scans as (N, 2) x y
arrays in beam order, as ``register2d`` and ``Mapper2D.add_scan`` take them:

* ``ate_2d(reference_poses, estimated_poses)``: rmse, mean, max (m) after the best rigid 2D
  alignment, which comes back as a 3x3 matrix (``alignment``)
* ``rpe_2d(reference_poses, estimated_poses, step=1)`` and
  ``all_pairs_error_2d(reference_poses, estimated_poses, max_poses=1500)``: translation (m) and
  rotation (degrees) errors of relative motions, and the share of failed pairs
* ``revisit_consistency_2d(scans, poses, revisit_gap=20, max_distance=0.5)``: how far apart the
  walls of revisits lie (m), without a reference
"""

from ._scanmatch import all_pairs_error_2d, ate, ate_2d, revisit_consistency_2d, rpe, rpe_2d

__all__ = ["all_pairs_error_2d", "ate", "ate_2d", "revisit_consistency_2d", "rpe", "rpe_2d"]
