"""register(): a simulated pair with an exactly known offset, options and error handling."""

import unittest

import numpy as np

import scanmatch
from helpers import pose_error


class RegisterSimulatedPair(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        # Frames 0 and 5 of the fast campus drive, without motion distortion: the true offset is
        # the simulator's ground truth, 0.56 m and a few degrees.
        sim = scanmatch.simulate("dynamic-outdoor-fast", frames=6, seed=1, motion_distortion=False)
        cls.source, cls.target = sim.frames[5], sim.frames[0]
        cls.truth = np.linalg.inv(sim.poses[0]) @ sim.poses[5]

    def test_gicp_recovers_the_true_offset(self):
        self.assertGreater(np.linalg.norm(self.truth[:3, 3]), 0.5)  # a real offset to recover
        result = scanmatch.register(self.source, self.target, max_correspondence_distance=2.0)
        self.assertEqual(result.method, "gicp")
        self.assertTrue(result.converged)
        translation, rotation = pose_error(self.truth, result.transform)
        self.assertLess(translation, 0.01)
        self.assertLess(rotation, 0.1)
        self.assertEqual(result.transform.shape, (4, 4))
        self.assertGreater(result.inliers, 1000)
        self.assertGreater(result.fitness, 0.0)
        self.assertEqual(result.information.shape, (6, 6))
        self.assertEqual(set(result.as_dict()) >= {"transform", "iterations", "converged"}, True)

    def test_arrays_and_clouds_give_the_same_result(self):
        from_clouds = scanmatch.register(self.source, self.target, method="ndt")
        from_arrays = scanmatch.register(np.asarray(self.source.points, dtype=np.float64),
                                         self.target.points, method="ndt")
        np.testing.assert_array_equal(from_clouds.transform, from_arrays.transform)
        translation, _ = pose_error(self.truth, from_clouds.transform)
        self.assertLess(translation, 0.01)

    def test_initial_guess_and_options(self):
        # One iteration from the truth stays at the truth; solver options by flat key and dict.
        result = scanmatch.register(self.source, self.target, method="point-to-plane",
                                    initial=self.truth, max_iterations=1)
        self.assertEqual(result.iterations, 1)
        self.assertLess(pose_error(self.truth, result.transform)[0], 0.02)
        result = scanmatch.register(self.source, self.target, method="point-to-plane",
                                    solver={"max_iterations": 2, "kernel": "huber"})
        self.assertLessEqual(result.iterations, 2)
        result = scanmatch.register(self.source, self.target, method="vgicp",
                                    **{"solver.max_iterations": 3, "voxel_resolution": 0.5})
        self.assertLessEqual(result.iterations, 3)

    def test_every_method_is_listed_and_options_have_defaults(self):
        methods = scanmatch.registration_methods()
        for name in ("icp", "gicp", "vgicp", "ndt", "point-to-plane", "ctf-fine", "loam"):
            self.assertIn(name, methods)
        options = scanmatch.registration_options()
        self.assertEqual(options["max_correspondence_distance"], 1.0)
        self.assertEqual(options["solver.kernel"], "none")
        self.assertIn("voxel_resolution", scanmatch.registration_options(help=True))


class RegisterErrors(unittest.TestCase):
    def setUp(self):
        rng = np.random.default_rng(1)
        self.cloud = rng.uniform(-5, 5, size=(500, 3)).astype(np.float32)

    def test_unknown_option_and_wrong_types(self):
        with self.assertRaisesRegex(TypeError, "unknown option 'max_distance'.*valid:"):
            scanmatch.register(self.cloud, self.cloud, max_distance=1.0)
        with self.assertRaisesRegex(TypeError, "'solver.max_iterations' must be an integer"):
            scanmatch.register(self.cloud, self.cloud, max_iterations=2.5)
        with self.assertRaisesRegex(TypeError, "must be True or False"):
            scanmatch.register(self.cloud, self.cloud, levenberg_marquardt=1)
        with self.assertRaisesRegex(ValueError, "kernel"):
            scanmatch.register(self.cloud, self.cloud, kernel="nope")
        with self.assertRaisesRegex(TypeError, "takes a dict"):
            scanmatch.register(self.cloud, self.cloud, solver=3)

    def test_unknown_method_is_a_scanmatch_error(self):
        with self.assertRaisesRegex(scanmatch.Error, "unknown registration method 'nope'"):
            scanmatch.register(self.cloud, self.cloud, method="nope")
        self.assertTrue(issubclass(scanmatch.Error, ValueError))

    def test_non_finite_coordinates(self):
        bad = self.cloud.copy()
        bad[17, 1] = np.nan
        with self.assertRaisesRegex(ValueError, "source: point 17 has a non-finite"):
            scanmatch.register(bad, self.cloud)
        bad[17, 1] = np.inf
        with self.assertRaisesRegex(ValueError, "target: point 17"):
            scanmatch.register(self.cloud, bad)
        cloud = scanmatch.PointCloud(bad, keep_non_finite=True)
        with self.assertRaisesRegex(ValueError, "point 17"):
            scanmatch.register(cloud, self.cloud)
        with self.assertRaisesRegex(ValueError, "non-finite"):
            scanmatch.PointCloud(bad)

    def test_shapes_and_dtypes(self):
        with self.assertRaisesRegex(ValueError, r"shape \(N, 3\).*\(500, 2\)"):
            scanmatch.register(self.cloud[:, :2], self.cloud)
        with self.assertRaisesRegex(ValueError, r"\(1500,\)"):
            scanmatch.register(self.cloud.ravel(), self.cloud)
        with self.assertRaisesRegex(TypeError, "real-valued"):
            scanmatch.register(self.cloud.astype(np.complex64), self.cloud)
        with self.assertRaisesRegex(TypeError, "real-valued"):
            scanmatch.register(np.array([["a", "b", "c"]]), self.cloud)
        with self.assertRaises(TypeError):
            scanmatch.register(None, self.cloud)
        with self.assertRaisesRegex(ValueError, "4x4"):
            scanmatch.register(self.cloud, self.cloud, initial=np.eye(3))
        with self.assertRaisesRegex(ValueError, "not a rotation"):
            scanmatch.register(self.cloud, self.cloud, initial=np.diag([2.0, 1, 1, 1]))
        # Integer and Fortran-ordered arrays are converted.
        result = scanmatch.register(np.asfortranarray(self.cloud), self.cloud.astype(np.int64),
                                    method="icp", max_iterations=1)
        self.assertEqual(result.transform.shape, (4, 4))

    def test_too_few_points_is_a_scanmatch_error(self):
        with self.assertRaises(scanmatch.Error):
            scanmatch.register(self.cloud[:3], self.cloud)
        with self.assertRaises(scanmatch.Error):
            scanmatch.register(np.zeros((0, 3)), self.cloud)


if __name__ == "__main__":
    unittest.main()
