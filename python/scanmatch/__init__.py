"""scanmatch: LiDAR registration, odometry, simulation and evaluation from Python.

The C++ library does the work (scanmatch._scanmatch, built with pybind11); arrays go in and out
as numpy arrays:

* ``register(source, target, method="gicp", initial=None, **options)`` -> RegistrationResult
* ``Odometry(method="ctf-icp", **config)`` with ``register_frame(points, times, timestamp)``
  and ``poses`` (N x 4 x 4)
* ``simulate(preset, frames=..., seed=...)`` -> Simulation (frames, timestamps, ground truth)
* ``read_cloud(path)`` / ``write_cloud(path, points, ...)``
* ``eval.ate(gt_poses, est_poses)`` / ``eval.rpe(...)``; in 2D ``eval.ate_2d``, ``eval.rpe_2d``,
  ``eval.all_pairs_error_2d`` and ``eval.revisit_consistency_2d``
* 2D: ``register2d(current, reference, ...)`` and ``Mapper2D``
* loop closure: ``LoopClosure2D(**options)`` with ``add_scan(points, odometry_pose)``, ``finish()``,
  ``poses`` (optimized, N x 3 x 3) and ``loops``; ``LoopClosure3D`` likewise with
  ``add_frame(points, odometry_pose)`` and N x 4 x 4 poses

Copies: arrays passed in are copied once into the library's layout (a ``PointCloud`` is used in
place, so convert once for repeated use); clouds coming out (``read_cloud``, simulated frames)
are ``PointCloud`` objects whose ``points``/``intensity``/``ring``/``time`` are read-only numpy
views without a copy; poses and matrices are small float64 copies.

Errors: the library's errors (bad files, unknown methods, too few points) raise
``scanmatch.Error``, a subclass of ValueError; bad shapes and NaN/inf coordinates ValueError;
unknown option keywords and wrong types TypeError.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Iterator, List, Optional, Tuple

import numpy as np

from . import _scanmatch
from ._scanmatch import (
    Error,
    LoopClosure2D,
    LoopClosure3D,
    Mapper2D,
    Odometry,
    PointCloud,
    Registration2DResult,
    RegistrationResult,
    Simulator,
    loop_closure_2d_options,
    loop_closure_3d_options,
    mapper2d_options,
    odometry_options,
    presets,
    read_cloud,
    register,
    register2d,
    registration_2d_methods,
    registration_2d_options,
    registration_methods,
    registration_options,
    write_cloud,
)
from . import eval  # noqa: A004  (scanmatch.eval, as the CLI's `scanmatch eval`)

__version__ = _scanmatch.__version__

# Shown as scanmatch.X in messages and reprs (they live in the compiled scanmatch._scanmatch).
for _cls in (Error, LoopClosure2D, LoopClosure3D, Mapper2D, Odometry, PointCloud,
             Registration2DResult, RegistrationResult, Simulator):
    _cls.__module__ = __name__
del _cls

__all__ = [
    "Error",
    "LoopClosure2D",
    "LoopClosure3D",
    "Mapper2D",
    "Odometry",
    "PointCloud",
    "Registration2DResult",
    "RegistrationResult",
    "Simulation",
    "Simulator",
    "eval",
    "loop_closure_2d_options",
    "loop_closure_3d_options",
    "mapper2d_options",
    "odometry_methods",
    "odometry_options",
    "presets",
    "read_cloud",
    "register",
    "register2d",
    "registration_2d_methods",
    "registration_2d_options",
    "registration_methods",
    "registration_options",
    "simulate",
    "write_cloud",
]


def odometry_methods() -> List[str]:
    """The odometry's methods: ctf-icp and every registration method."""
    return [name.strip() for name in _scanmatch.odometry_methods().split(",")]


@dataclass
class Simulation:
    """A simulated sequence: ``frames[i]`` is a PointCloud (x y z intensity ring time, in the
    sensor frame, each point's time since the frame start), ``timestamps[i]`` its start time (s)
    and ``poses[i]`` the exact ground truth (4x4 sensor pose at the frame start, world frame of
    frame 0). Iterating yields ``(frame, timestamp)``."""

    preset: str
    sensor: str
    rate_hz: float
    frames: List[PointCloud]
    timestamps: np.ndarray
    poses: np.ndarray
    path_length: float = 0.0
    seed: int = 1
    options: dict = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.frames)

    def __iter__(self) -> Iterator[Tuple[PointCloud, float]]:
        return iter(zip(self.frames, (float(t) for t in self.timestamps)))

    def __repr__(self) -> str:
        return (f"<scanmatch.Simulation {self.preset} ({self.sensor}), {len(self.frames)} frames, "
                f"{self.path_length:.1f} m>")


def simulate(preset: str = "dynamic-outdoor", frames: Optional[int] = None, seed: int = 1,
             sensor: str = "", motion_distortion: bool = True, noise: bool = True) -> Simulation:
    """Renders a simulator preset (``presets()`` lists them) into memory.

    ``frames`` truncates the preset (None: all its frames; mind the memory of long presets, or
    use ``Simulator`` to render frame by frame). The same preset, frame count and seed give the
    same frames as ``scanmatch odometry sim:PRESET --frames N --seed S`` on the command line.
    Each frame's arrays are views into its PointCloud (no copy); ground-truth poses are an
    (N, 4, 4) float64 array."""
    if frames is not None and (isinstance(frames, bool) or int(frames) != frames or frames < 0):
        raise ValueError(f"simulate: frames must be a non-negative integer, got {frames!r}")
    simulator = Simulator(preset, None if frames is None else int(frames), seed, sensor,
                          motion_distortion, noise)
    clouds = [simulator.frame(i) for i in range(len(simulator))]
    return Simulation(
        preset=simulator.preset,
        sensor=simulator.sensor,
        rate_hz=simulator.rate_hz,
        frames=clouds,
        timestamps=simulator.timestamps,
        poses=simulator.poses,
        path_length=simulator.path_length,
        seed=seed,
        options={"motion_distortion": motion_distortion, "noise": noise},
    )
