"""2D: register2d recovers a simulated room-2d offset; Mapper2D chains a short simulated run; the
2D metrics (scanmatch.eval.ate_2d, rpe_2d, all_pairs_error_2d, revisit_consistency_2d) give known
answers and, with SCANMATCH_CLI set, the numbers of map2d's summary.json."""

import json
import os
import subprocess
import tempfile
import unittest

import numpy as np

import scanmatch


def planar(pose):
    """The 3x3 planar part (x, y, yaw) of a 4x4 pose of a 2D preset."""
    return np.array([[pose[0, 0], pose[0, 1], pose[0, 3]],
                     [pose[1, 0], pose[1, 1], pose[1, 3]],
                     [0.0, 0.0, 1.0]])


def xy_theta(poses):
    """(N, 3) rows of x y yaw of (N, 4, 4) poses. (The 2D presets' poses tilt a little, so their
    planar block is not quite a rotation; the 2D metrics take x y theta, as map2d reads them.)"""
    poses = np.asarray(poses)
    return np.column_stack([poses[:, 0, 3], poses[:, 1, 3],
                            np.arctan2(poses[:, 1, 0], poses[:, 0, 0])])


def matrices(rows):
    """(N, 3, 3) homogeneous matrices of (N, 3) rows of x y theta."""
    out = np.tile(np.eye(3), (len(rows), 1, 1))
    c, s = np.cos(rows[:, 2]), np.sin(rows[:, 2])
    out[:, 0, 0], out[:, 0, 1], out[:, 1, 0], out[:, 1, 1] = c, -s, s, c
    out[:, :2, 2] = rows[:, :2]
    return out


def read_tum_2d(path):
    """x y yaw of each line of a TUM trajectory (t x y z qx qy qz qw) of planar poses."""
    tum = np.loadtxt(path, ndmin=2)
    return np.column_stack([tum[:, 1], tum[:, 2], 2.0 * np.arctan2(tum[:, 6], tum[:, 7])])


class Planar(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.sim = scanmatch.Simulator("room-2d", frames=40, seed=1, motion_distortion=False)
        cls.scans = [cls.sim.scan2d(i) for i in range(len(cls.sim))]
        cls.truth = np.stack([planar(cls.sim.pose(i)) for i in range(len(cls.sim))])

    def test_register2d_recovers_the_true_offset(self):
        (reference, circular), (current, _) = self.scans[0], self.scans[5]
        self.assertTrue(circular)
        truth = np.linalg.inv(self.truth[0]) @ self.truth[5]
        self.assertGreater(np.linalg.norm(truth[:2, 2]), 0.2)
        for method in ("sparse-icp", "pl-icp"):
            with self.subTest(method=method):
                result = scanmatch.register2d(current, reference, method=method, circular=True)
                self.assertTrue(result.converged)
                self.assertEqual(result.transform.shape, (3, 3))
                self.assertLess(np.linalg.norm(result.transform[:2, 2] - truth[:2, 2]), 0.01)
                angle = np.arctan2(truth[1, 0], truth[0, 0])
                self.assertLess(abs(result.theta - angle), np.radians(0.5))
                searched = scanmatch.register2d(current, reference, method=method, circular=True,
                                                search_window=1.0)
                # A clean pair: the method refines the search's pose, which is not kept.
                self.assertFalse(searched.search_pose_kept)
                self.assertLess(np.linalg.norm(searched.transform[:2, 2] - truth[:2, 2]), 0.01)
        # An initial guess as (x, y, theta) and as a matrix give the same result.
        a = scanmatch.register2d(current, reference, initial=(0.2, 0.0, 0.15), circular=True)
        b = scanmatch.register2d(current, reference, circular=True,
                                 initial=[[np.cos(0.15), -np.sin(0.15), 0.2],
                                          [np.sin(0.15), np.cos(0.15), 0.0], [0, 0, 1]])
        np.testing.assert_allclose(a.transform, b.transform, atol=1e-9)

    def test_mapper2d_follows_the_ground_truth(self):
        mapper = scanmatch.Mapper2D("sparse-icp", keyframe_distance=0.0, max_iterations=50)
        for (points, circular), t in zip(self.scans, self.sim.timestamps):
            mapper.add_scan(points, circular=circular, timestamp=t)
        self.assertEqual(mapper.poses.shape, (40, 3, 3))
        error = np.linalg.norm(mapper.poses[:, :2, 2] - self.truth[:, :2, 2], axis=1)
        self.assertGreater(np.linalg.norm(self.truth[-1, :2, 2]), 2.0)  # it did move
        self.assertLess(error.max(), 0.25)
        self.assertEqual(mapper.config["registration.max_iterations"], 50)
        # room-2d's scans determine every step: the motion prior never has to choose.
        self.assertFalse(any(s["open_step_from_prior"] for s in mapper.stats))
        self.assertEqual(mapper.config["open_step_window"], 1.5)

    def test_errors(self):
        points, _ = self.scans[0]
        with self.assertRaisesRegex(ValueError, r"shape \(N, 2\)"):
            scanmatch.register2d(np.zeros((10, 3)), points)
        bad = points.copy()
        bad[4, 1] = np.nan
        with self.assertRaisesRegex(ValueError, "current: point 4 has a non-finite"):
            scanmatch.register2d(bad, points)
        with self.assertRaises(scanmatch.Error):
            scanmatch.register2d(points, points, method="nope")
        with self.assertRaises(scanmatch.Error):
            scanmatch.register2d(points[:3], points)
        with self.assertRaisesRegex(TypeError, "unknown option 'foo'"):
            scanmatch.register2d(points, points, foo=1)
        with self.assertRaisesRegex(TypeError, "unknown option 'foo'"):
            scanmatch.Mapper2D(foo=1)
        with self.assertRaisesRegex(ValueError, "not a 2D laser"):
            scanmatch.Simulator("dynamic-indoor", frames=1).scan2d(0)
        with self.assertRaisesRegex(ValueError, "3x3 matrix or"):
            scanmatch.register2d(points, points, initial=np.eye(4))


class PlanarMetrics(unittest.TestCase):
    def setUp(self):
        # 5 poses, the estimate 1.1 m per step where the reference moves 1.0 m.
        self.reference = np.array([[k * 1.0, 0.0, 0.0] for k in range(5)])
        self.estimate = np.array([[k * 1.1, 0.0, 0.0] for k in range(5)])

    def test_ate_2d_recovers_a_rigid_motion(self):
        k = np.arange(20.0)
        reference = np.column_stack([2.0 * np.cos(0.2 * k), np.sin(0.3 * k) + 0.1 * k, 0.15 * k])
        # The estimate is the reference in another frame: moved by G = (1.5, -2.0, 0.7 rad).
        g = matrices(np.array([[1.5, -2.0, 0.7]]))[0]
        estimate = g @ matrices(reference)
        ate = scanmatch.eval.ate_2d(matrices(reference), estimate)
        self.assertEqual(ate["poses"], 20)
        self.assertLess(ate["rmse"], 1e-9)
        self.assertLess(ate["max"], 1e-9)
        self.assertEqual(ate["alignment"].shape, (3, 3))
        np.testing.assert_allclose(ate["alignment"] @ g, np.eye(3), atol=1e-9)  # G undone
        # (N, 3) rows of x y theta are the same poses.
        rows = np.column_stack([estimate[:, 0, 2], estimate[:, 1, 2],
                                np.arctan2(estimate[:, 1, 0], estimate[:, 0, 0])])
        again = scanmatch.eval.ate_2d(reference, rows)
        np.testing.assert_allclose(again["alignment"], ate["alignment"], atol=1e-12)
        # Headings do not count, positions do.
        turned = reference.copy()
        turned[:, 2] += 0.3
        self.assertLess(scanmatch.eval.ate_2d(reference, turned)["rmse"], 1e-12)
        self.assertEqual(scanmatch.eval.ate_2d(reference[:1], reference[:1] + 5.0)["rmse"], 0.0)

    def test_ate_2d_of_an_offset_on_half_the_poses(self):
        # 8 poses along x; poses 0, 3, 4 and 7 (placed symmetrically, so that no rotation helps)
        # 0.6 m off in y: the best alignment moves the estimate 0.3 m back and every pose is then
        # 0.3 m off.
        reference = np.column_stack([np.arange(8.0), np.zeros(8), np.zeros(8)])
        estimate = reference.copy()
        estimate[[0, 3, 4, 7], 1] += 0.6
        ate = scanmatch.eval.ate_2d(reference, estimate)
        self.assertAlmostEqual(ate["rmse"], 0.3, places=12)
        self.assertAlmostEqual(ate["mean"], 0.3, places=12)
        self.assertAlmostEqual(ate["max"], 0.3, places=12)
        np.testing.assert_allclose(ate["alignment"], [[1, 0, 0], [0, 1, -0.3], [0, 0, 1]],
                                   atol=1e-12)
        # The second half off instead: the alignment also turns. Its rmse against the best of a
        # fine search over the angle (the translation at each: the centroids'), done here.
        estimate = reference.copy()
        estimate[4:, 1] += 0.6
        angle = np.linspace(-0.2, 0.2, 400001)[:, None]
        centred = estimate[:, :2] - estimate[:, :2].mean(axis=0)
        x = np.cos(angle) * centred[:, 0] - np.sin(angle) * centred[:, 1]
        y = np.sin(angle) * centred[:, 0] + np.cos(angle) * centred[:, 1]
        target = reference[:, :2] - reference[:, :2].mean(axis=0)
        best = np.sqrt(np.mean((x - target[:, 0]) ** 2 + (y - target[:, 1]) ** 2, axis=1)).min()
        ate = scanmatch.eval.ate_2d(reference, estimate)
        self.assertLess(ate["rmse"], 0.29)  # the turn helps
        self.assertAlmostEqual(ate["rmse"], best, places=9)

    def test_relative_errors_of_a_known_drift(self):
        one = scanmatch.eval.rpe_2d(self.reference, self.estimate)
        self.assertEqual((one["step"], one["pairs"]), (1, 4))
        self.assertAlmostEqual(one["translation_mean"], 0.1, places=12)
        self.assertAlmostEqual(one["translation_median"], 0.1, places=12)
        self.assertAlmostEqual(one["translation_max"], 0.1, places=12)
        self.assertEqual(one["rotation_max_deg"], 0.0)
        self.assertEqual(one["failure_rate"], 0.0)
        two = scanmatch.eval.rpe_2d(matrices(self.reference), matrices(self.estimate), step=2)
        self.assertEqual((two["step"], two["pairs"]), (2, 3))
        self.assertAlmostEqual(two["translation_mean"], 0.2, places=12)
        # Off by 0.3 m over three steps: past a 0.25 m failure threshold, within 0.35 m.
        self.assertEqual(scanmatch.eval.rpe_2d(self.reference, self.estimate, step=3,
                                               failure_translation=0.25)["failure_rate"], 1.0)
        self.assertEqual(scanmatch.eval.rpe_2d(self.reference, self.estimate, step=3,
                                               failure_translation=0.35)["failure_rate"], 0.0)
        # Pose 1 turned by 10 degrees: the pairs 0-1 and 1-2 are off by 10 degrees, in degrees.
        turned = self.reference.copy()
        turned[1, 2] = np.radians(10.0)
        rotation = scanmatch.eval.rpe_2d(self.reference, turned)
        self.assertAlmostEqual(rotation["rotation_max_deg"], 10.0, places=9)
        self.assertAlmostEqual(rotation["rotation_mean_deg"], 5.0, places=9)
        self.assertAlmostEqual(rotation["failure_rate"], 0.5)  # 10 degrees > 5 (the default)
        self.assertEqual(scanmatch.eval.rpe_2d(self.reference, turned,
                                               failure_rotation_deg=11.0)["failure_rate"], 0.0)

    def test_all_pairs_error_of_a_known_drift(self):
        # The ten pairs k < j are off by 0.1 (j - k) m: j - k = 1 four times, 2 three times, 3
        # twice, 4 once: mean 0.2 m, median 0.2 m, largest 0.4 m.
        every = scanmatch.eval.all_pairs_error_2d(self.reference, self.estimate)
        self.assertEqual((every["step"], every["pairs"]), (0, 10))
        self.assertAlmostEqual(every["translation_mean"], 0.2, places=12)
        self.assertAlmostEqual(every["translation_median"], 0.2, places=12)
        self.assertAlmostEqual(every["translation_max"], 0.4, places=12)
        # 0.3 m twice and 0.4 m once pass a 0.25 m failure threshold.
        self.assertAlmostEqual(scanmatch.eval.all_pairs_error_2d(
            self.reference, self.estimate, failure_translation=0.25)["failure_rate"], 0.3)
        # Thinned to 3 poses (0, 2, 4): pairs off by 0.2, 0.2 and 0.4 m.
        thinned = scanmatch.eval.all_pairs_error_2d(self.reference, self.estimate, max_poses=3)
        self.assertEqual(thinned["pairs"], 3)
        self.assertAlmostEqual(thinned["translation_mean"], 0.8 / 3, places=12)

    def test_revisit_consistency_on_a_simulated_return(self):
        # room-2d ends where it started: its first 40 and last 40 scans see the same room. With a
        # gap of 40 among these 80 scans every point's other visit is the other end of the run.
        sim = scanmatch.Simulator("room-2d", seed=1, motion_distortion=False, noise=False)
        visits = list(range(40)) + list(range(len(sim) - 40, len(sim)))
        scans = [sim.scan2d(i) for i in visits]
        self.assertTrue(all(circular for _, circular in scans))
        points = [p for p, _ in scans]
        truth = xy_theta([sim.pose(i) for i in visits])
        # Each pose of the return lies within 0.2 m of one of the first visit's.
        apart = np.linalg.norm(truth[40:, None, :2] - truth[None, :40, :2], axis=2)
        self.assertLess(apart.min(axis=1).max(), 0.2)

        def measure(poses, revisit_gap=40, **options):
            return scanmatch.eval.revisit_consistency_2d(points, poses, revisit_gap=revisit_gap,
                                                         circular=True, **options)

        exact = measure(truth)
        self.assertEqual(exact["points"], sum(len(p) for p in points))
        self.assertGreater(exact["revisited_share"], 0.95)
        self.assertAlmostEqual(exact["revisited_share"], exact["revisited"] / exact["points"])
        # Noiseless scans from the true poses: the walls coincide (but at corners and behind
        # furniture, where the other visit's nearest surface is another one).
        self.assertLess(exact["median"], 0.001)
        self.assertLess(exact["p90"], 0.001)
        self.assertLess(exact["mean"], 0.012)
        # The return visit placed 3 cm off in y: the rooms' walls along x lie 3 cm apart, and
        # they are most of what the scans see.
        moved = truth.copy()
        moved[40:, 1] += 0.03
        off = measure(moved)
        self.assertGreater(off["median"], 0.026)
        self.assertLess(off["median"], 0.031)
        self.assertLessEqual(off["p90"], 0.031)
        self.assertGreater(off["mean"], exact["mean"] + 0.015)
        # Within 2 cm the shifted walls no longer pair; no revisit past the sequence; a query
        # budget looks at every n-th point.
        self.assertLess(measure(moved, max_distance=0.02)["revisited"], exact["revisited"] / 2)
        self.assertEqual(measure(truth, revisit_gap=80)["revisited"], 0)
        stride = -(-exact["points"] // 1000)  # every n-th point, n rounded up
        self.assertEqual(measure(truth, max_queries=1000)["points"], -(-exact["points"] // stride))
        # With the range noise of the preset the true poses still score a few mm.
        noisy = scanmatch.Simulator("room-2d", seed=1, motion_distortion=False)
        noisy_points = [noisy.scan2d(i)[0] for i in visits]
        noisy_exact = scanmatch.eval.revisit_consistency_2d(noisy_points, truth, 40,
                                                            circular=True)
        noisy_off = scanmatch.eval.revisit_consistency_2d(noisy_points, moved, 40, circular=True)
        self.assertLess(noisy_exact["median"], 0.01)
        self.assertGreater(noisy_off["median"], 2 * noisy_exact["median"])

    def test_errors(self):
        with self.assertRaisesRegex(scanmatch.Error, "4 estimated poses against 5 reference"):
            scanmatch.eval.ate_2d(self.reference, self.estimate[:4])
        with self.assertRaisesRegex(scanmatch.Error, "4 estimated poses against 5 reference"):
            scanmatch.eval.rpe_2d(self.reference, self.estimate[:4])
        with self.assertRaisesRegex(scanmatch.Error, "4 estimated poses against 5 reference"):
            scanmatch.eval.all_pairs_error_2d(self.reference, self.estimate[:4])
        with self.assertRaisesRegex(scanmatch.Error, "step must be at least 1"):
            scanmatch.eval.rpe_2d(self.reference, self.estimate, step=0)
        with self.assertRaisesRegex(ValueError, "max_poses must be at least 2"):
            scanmatch.eval.all_pairs_error_2d(self.reference, self.estimate, max_poses=1)
        with self.assertRaisesRegex(ValueError, "failure_translation must be at least 0"):
            scanmatch.eval.rpe_2d(self.reference, self.estimate, failure_translation=np.nan)
        with self.assertRaisesRegex(ValueError, r"reference_poses: expected .*\(N, 3, 3\) or "
                                                r"\(N, 3\)"):
            scanmatch.eval.ate_2d(np.tile(np.eye(4), (5, 1, 1)), self.estimate)
        bad = self.estimate.copy()
        bad[3, 2] = np.inf
        with self.assertRaisesRegex(ValueError, r"estimated_poses\[3\]: .*must be finite"):
            scanmatch.eval.rpe_2d(self.reference, bad)
        sheared = matrices(self.estimate)
        sheared[2, 0, 1] = 0.5
        with self.assertRaisesRegex(ValueError, r"estimated_poses\[2\]: .*not a rotation"):
            scanmatch.eval.ate_2d(matrices(self.reference), sheared)
        with self.assertRaises(TypeError):
            scanmatch.eval.ate_2d(self.reference.astype(bool), self.estimate)

        scans = [np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]])] * 5
        with self.assertRaisesRegex(scanmatch.Error, "4 poses for 5 scans"):
            scanmatch.eval.revisit_consistency_2d(scans, self.reference[:4])
        with self.assertRaisesRegex(scanmatch.Error, "gap must be at least 1"):
            scanmatch.eval.revisit_consistency_2d(scans, self.reference, revisit_gap=0)
        with self.assertRaisesRegex(scanmatch.Error, "distance must be positive"):
            scanmatch.eval.revisit_consistency_2d(scans, self.reference, max_distance=0.0)
        with self.assertRaisesRegex(ValueError, "max_distance must be finite"):
            scanmatch.eval.revisit_consistency_2d(scans, self.reference, max_distance=np.inf)
        with self.assertRaisesRegex(ValueError, "max_queries must be at least 1"):
            scanmatch.eval.revisit_consistency_2d(scans, self.reference, max_queries=0)
        broken = [s.copy() for s in scans]
        broken[2][1, 0] = np.nan
        with self.assertRaisesRegex(ValueError, "scans\\[2\\]: point 1 has a non-finite"):
            scanmatch.eval.revisit_consistency_2d(broken, self.reference)
        with self.assertRaisesRegex(ValueError, r"scans\[0\]: expected an array of shape \(N, 2\)"):
            scanmatch.eval.revisit_consistency_2d([np.zeros((4, 3))] * 5, self.reference)
        with self.assertRaisesRegex(TypeError, "sequence of \\(N, 2\\) arrays"):
            scanmatch.eval.revisit_consistency_2d(scans[0], self.reference[:3])
        # One (M, N, 2) array is M scans.
        self.assertEqual(scanmatch.eval.revisit_consistency_2d(np.stack(scans), self.reference,
                                                               revisit_gap=1)["points"], 15)


# With SCANMATCH_CLI set (scripts/test_python does), the metrics of a map2d run, recomputed here
# from its poses and the same simulated scans, are the numbers of its summary.json.
@unittest.skipUnless(os.environ.get("SCANMATCH_CLI"), "SCANMATCH_CLI not set")
class PlanarMetricsAsTheCli(unittest.TestCase):
    def test_same_numbers_as_map2d(self):
        with tempfile.TemporaryDirectory() as out:
            subprocess.run([os.environ["SCANMATCH_CLI"], "map2d", "sim:room-2d", "--scans", "40",
                            "--no-motion-distortion", "--seed", "1", "--out", out, "--quiet"],
                           check=True)
            with open(os.path.join(out, "summary.json")) as f:
                summary = json.load(f)
            estimate = read_tum_2d(os.path.join(out, "poses_tum.txt"))
            reference = read_tum_2d(os.path.join(out, "poses_reference_tum.txt"))
        sim = scanmatch.Simulator("room-2d", frames=40, seed=1, motion_distortion=False)
        np.testing.assert_allclose(reference, xy_theta([sim.pose(i) for i in range(40)]),
                                   atol=1e-9)
        ate = scanmatch.eval.ate_2d(reference, estimate)
        self.assertEqual(ate["poses"], summary["ate"]["poses"])
        for key in ("rmse", "mean", "max"):
            self.assertAlmostEqual(ate[key], summary["ate"][key + "_m"], places=9)
        for name, error in [("relative_error_1", scanmatch.eval.rpe_2d(reference, estimate)),
                            ("relative_error_10",
                             scanmatch.eval.rpe_2d(reference, estimate, step=10)),
                            ("relative_error_all_pairs",
                             scanmatch.eval.all_pairs_error_2d(reference, estimate))]:
            cli = summary[name]
            with self.subTest(name=name):
                self.assertEqual((error["step"], error["pairs"]), (cli["step"], cli["pairs"]))
                for key in ("mean", "median", "max"):
                    self.assertAlmostEqual(1000 * error["translation_" + key],
                                           cli[key + "_translation_mm"], places=6)
                for key in ("mean", "median"):
                    self.assertAlmostEqual(error[f"rotation_{key}_deg"],
                                           cli[key + "_rotation_deg"], places=6)
                self.assertEqual(error["failure_rate"], cli["failure_rate"])
        points = [sim.scan2d(i)[0] for i in range(40)]
        for name, poses in [("revisit_consistency", estimate),
                            ("revisit_consistency_reference", reference)]:
            mine = scanmatch.eval.revisit_consistency_2d(points, poses, circular=True)
            cli = summary[name]
            with self.subTest(name=name):
                self.assertEqual(mine["points"], cli["points"])
                self.assertAlmostEqual(mine["revisited_share"], cli["revisited_share"], places=12)
                for key in ("mean", "median", "p90"):
                    self.assertAlmostEqual(mine[key], cli[key + "_m"], places=6)


if __name__ == "__main__":
    unittest.main()
