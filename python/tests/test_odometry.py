"""Odometry over simulated frames: the same poses and ATE as the command line on the same frames."""

import os
import subprocess
import tempfile
import unittest

import numpy as np

import scanmatch

# `scanmatch odometry sim:dynamic-outdoor-fast --frames 30 --seed 1` (ctf-icp, defaults) prints
# "ATE 0.039 m RMSE, 0.363 % of the 10.7 m path" (eval: rmse 0.0389 m); the Python run of the
# same frames must do as well. With SCANMATCH_CLI set to the built CLI (scripts/test_python does)
# the poses are also compared with the CLI's, number for number.
PRESET, FRAMES, SEED = "dynamic-outdoor-fast", 30, 1
CLI_ATE_RMSE = 0.039


class OdometrySimulated(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.sim = scanmatch.simulate(PRESET, frames=FRAMES, seed=SEED)
        cls.odometry = scanmatch.Odometry("ctf-icp")
        cls.returned = [cls.odometry.register_frame(frame, timestamp=t) for frame, t in cls.sim]

    def test_poses(self):
        poses = self.odometry.poses
        self.assertEqual(poses.shape, (FRAMES, 4, 4))
        # Frames 1-4 were returned under a provisional world anchor (it settles at frame 4);
        # poses holds them as settled.
        np.testing.assert_array_equal(poses[5:], np.stack(self.returned)[5:])
        for i in range(1, 5):
            np.testing.assert_allclose(poses[i], self.returned[i], atol=0.05)
        np.testing.assert_allclose(poses[0], np.eye(4), atol=1e-12)
        np.testing.assert_allclose(self.odometry.timestamps, self.sim.timestamps)
        self.assertEqual(len(self.odometry), FRAMES)
        self.assertFalse(any(s["bridged"] for s in self.odometry.stats))

    def test_ate_as_good_as_the_cli(self):
        ate = scanmatch.eval.ate(self.sim.poses, self.odometry.poses)
        self.assertEqual(ate["poses"], FRAMES)
        self.assertGreater(ate["path_length"], 10.0)  # a real drive, not a still sensor
        self.assertLess(ate["rmse"], CLI_ATE_RMSE)

    @unittest.skipUnless(os.environ.get("SCANMATCH_CLI"), "SCANMATCH_CLI not set")
    def test_same_poses_and_statistics_as_the_cli(self):
        with tempfile.TemporaryDirectory() as out:
            subprocess.run([os.environ["SCANMATCH_CLI"], "odometry", f"sim:{PRESET}", "--frames",
                            str(FRAMES), "--seed", str(SEED), "--out", out, "--quiet"], check=True)
            cli = np.loadtxt(os.path.join(out, "poses.txt")).reshape(-1, 3, 4)
            with open(os.path.join(out, "timing.csv")) as timing:
                columns = timing.readline().strip().split(",")
        np.testing.assert_allclose(self.odometry.poses[:, :3, :], cli, atol=1e-8)
        # One description gives both: the dictionary keys are timing.csv's columns, in order.
        self.assertEqual(columns[:2], ["index", "timestamp"])
        self.assertEqual(list(self.odometry.stats[0]), columns[2:])
        self.assertEqual(list(self.odometry.last_stats), columns[2:])

    def test_statistics_are_documented(self):
        doc = type(self.odometry).last_stats.__doc__
        for key in self.odometry.last_stats:
            self.assertIn(f"\n  {key}: ", doc)


class OdometryConfiguration(unittest.TestCase):
    def test_keywords_set_fields(self):
        odometry = scanmatch.Odometry("gicp", voxel_size=0.5, deskew=False, max_iterations=7,
                                      registration={"voxel_resolution": 0.75}, threads=2)
        config = odometry.config
        self.assertEqual(config["method"], "gicp")
        self.assertEqual(config["voxel_size"], 0.5)
        self.assertFalse(config["deskew"])
        self.assertEqual(config["registration.solver.max_iterations"], 7)
        self.assertEqual(config["registration.voxel_resolution"], 0.75)
        self.assertEqual(config["threads"], 2)
        self.assertEqual(scanmatch.odometry_options()["map_radius"], 50.0)
        self.assertIn("ctf-icp", scanmatch.odometry_methods())

    def test_bad_configuration(self):
        with self.assertRaisesRegex(TypeError, "unknown option 'voxel'"):
            scanmatch.Odometry(voxel=0.5)
        with self.assertRaisesRegex(TypeError, "'deskew' must be True or False"):
            scanmatch.Odometry(deskew="no")
        with self.assertRaisesRegex(ValueError, "merge_threshold' must be a non-negative"):
            scanmatch.Odometry(merge_threshold=-1)
        with self.assertRaises(scanmatch.Error):
            scanmatch.Odometry("no-such-method")

    def test_bad_frames(self):
        odometry = scanmatch.Odometry()
        frame = np.random.default_rng(2).uniform(-20, 20, size=(2000, 3))
        with self.assertRaisesRegex(ValueError, r"shape \(N, 3\)"):
            odometry.register_frame(frame[:, :2])
        bad = frame.copy()
        bad[5, 0] = np.nan
        with self.assertRaisesRegex(ValueError, "point 5 has a non-finite"):
            odometry.register_frame(bad)
        with self.assertRaisesRegex(ValueError, r"times: expected an array of shape \(2000,\)"):
            odometry.register_frame(frame, times=np.zeros(3))
        with self.assertRaisesRegex(ValueError, "timestamp must be finite"):
            odometry.register_frame(frame, timestamp=float("inf"))
        self.assertEqual(odometry.frames, 0)
        # An empty frame is bridged by the motion prior, not an error.
        odometry.register_frame(frame, times=np.linspace(0, 0.1, 2000))
        pose = odometry.register_frame(np.zeros((0, 3)))
        self.assertTrue(odometry.last_stats["bridged"])
        self.assertEqual(pose.shape, (4, 4))
        self.assertEqual(odometry.poses.shape, (2, 4, 4))
        np.testing.assert_allclose(odometry.timestamps, [0.0, 0.1])


if __name__ == "__main__":
    unittest.main()
