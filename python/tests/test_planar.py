"""2D: register2d recovers a simulated room-2d offset; Mapper2D chains a short simulated run."""

import unittest

import numpy as np

import scanmatch


def planar(pose):
    """The 3x3 planar part (x, y, yaw) of a 4x4 pose of a 2D preset."""
    return np.array([[pose[0, 0], pose[0, 1], pose[0, 3]],
                     [pose[1, 0], pose[1, 1], pose[1, 3]],
                     [0.0, 0.0, 1.0]])


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


if __name__ == "__main__":
    unittest.main()
