"""read_cloud/write_cloud round trips, zero-copy views, and the trajectory metrics."""

import gc
import gzip
import os
import tempfile
import unittest

import numpy as np

import scanmatch


class CloudIo(unittest.TestCase):
    def setUp(self):
        rng = np.random.default_rng(3)
        self.points = rng.uniform(-50, 50, size=(1000, 3)).astype(np.float32)
        self.intensity = rng.uniform(0, 255, size=1000).astype(np.float32)
        self.ring = rng.integers(0, 64, size=1000).astype(np.uint16)
        self.time = np.linspace(0, 0.1, 1000, dtype=np.float32)
        self.dir = tempfile.TemporaryDirectory()

    def tearDown(self):
        self.dir.cleanup()

    def path(self, name):
        return os.path.join(self.dir.name, name)

    def test_round_trip_every_format(self):
        for name, encoding in [("a.pcd", "binary"), ("b.pcd", "ascii"),
                               ("c.pcd", "binary_compressed"), ("d.ply", "binary"),
                               ("e.ply", "ascii")]:
            with self.subTest(file=name):
                scanmatch.write_cloud(self.path(name), self.points, intensity=self.intensity,
                                      ring=self.ring, time=self.time, encoding=encoding)
                cloud = scanmatch.read_cloud(self.path(name))
                self.assertEqual(len(cloud), 1000)
                tol = 1e-4 if encoding == "ascii" else 0
                np.testing.assert_allclose(cloud.points, self.points, atol=tol * 100)
                np.testing.assert_allclose(cloud.intensity, self.intensity, atol=tol * 1000)
                np.testing.assert_array_equal(cloud.ring, self.ring)
                np.testing.assert_allclose(cloud.time, self.time, atol=tol)
        # Reading decompresses .gz transparently.
        with open(self.path("a.pcd"), "rb") as f, gzip.open(self.path("a.pcd.gz"), "wb") as g:
            g.write(f.read())
        np.testing.assert_array_equal(scanmatch.read_cloud(self.path("a.pcd.gz")).points,
                                      self.points)
        scanmatch.write_cloud(self.path("g.bin"), self.points, intensity=self.intensity)
        cloud = scanmatch.read_cloud(self.path("g.bin"))
        np.testing.assert_array_equal(cloud.points, self.points)
        self.assertIsNone(cloud.ring)

    def test_pointcloud_round_trip_in_place(self):
        cloud = scanmatch.PointCloud(self.points, intensity=self.intensity)
        scanmatch.write_cloud(self.path("x.pcd"), cloud)
        again = scanmatch.read_cloud(self.path("x.pcd"))
        np.testing.assert_array_equal(again.points, self.points)
        np.testing.assert_array_equal(again.intensity, self.intensity)
        self.assertIsNone(again.time)
        with self.assertRaisesRegex(ValueError, "not both"):
            scanmatch.write_cloud(self.path("y.pcd"), cloud, time=self.time)

    def test_views_share_memory_and_keep_the_cloud_alive(self):
        cloud = scanmatch.PointCloud(self.points, time=self.time)
        points = cloud.points
        self.assertEqual(points.dtype, np.float32)
        self.assertEqual(points.shape, (1000, 3))
        self.assertFalse(points.flags.writeable)
        self.assertTrue(np.shares_memory(points, cloud.points))  # the same buffer each time
        self.assertTrue(np.shares_memory(np.asarray(cloud), points))
        self.assertFalse(np.shares_memory(points, self.points))  # construction copied once
        del cloud
        gc.collect()
        np.testing.assert_array_equal(points, self.points)  # still valid: the view owns the cloud

    def test_errors(self):
        with self.assertRaisesRegex(scanmatch.Error, "missing.pcd"):
            scanmatch.read_cloud(self.path("missing.pcd"))
        with self.assertRaisesRegex(scanmatch.Error, "unknown point cloud format '.foo'"):
            scanmatch.write_cloud(self.path("x.foo"), self.points)
        with self.assertRaisesRegex(ValueError, "unknown encoding"):
            scanmatch.write_cloud(self.path("x.pcd"), self.points, encoding="zip")
        with self.assertRaisesRegex(ValueError, r"intensity: expected an array of shape \(1000,\)"):
            scanmatch.write_cloud(self.path("x.pcd"), self.points, intensity=self.intensity[:9])
        with self.assertRaisesRegex(ValueError, "ring index"):
            scanmatch.write_cloud(self.path("x.pcd"), self.points, ring=self.ring - 1.5)
        with open(self.path("broken.pcd"), "w") as f:
            f.write("VERSION 0.7\nFIELDS x y\n")
        with self.assertRaises(scanmatch.Error):
            scanmatch.read_cloud(self.path("broken.pcd"))


class TrajectoryMetrics(unittest.TestCase):
    def setUp(self):
        self.gt = np.tile(np.eye(4), (10, 1, 1))
        self.gt[:, 0, 3] = np.arange(10.0)  # 9 m straight along x

    def test_ate_known_answers(self):
        self.assertEqual(scanmatch.eval.ate(self.gt, self.gt)["rmse"], 0.0)
        shifted = self.gt.copy()
        shifted[:, 1, 3] += 1.0
        ate = scanmatch.eval.ate(self.gt, shifted)
        self.assertAlmostEqual(ate["rmse"], 1.0)
        self.assertAlmostEqual(ate["path_length"], 9.0)
        self.assertAlmostEqual(ate["rmse_percent_of_path"], 100.0 / 9.0)
        aligned = scanmatch.eval.ate(self.gt, shifted, alignment="se3")
        self.assertAlmostEqual(aligned["rmse"], 0.0, places=9)
        self.assertAlmostEqual(aligned["alignment"][1, 3], -1.0, places=9)
        rpe = scanmatch.eval.rpe(self.gt, shifted)
        self.assertEqual(rpe["pairs"], 9)
        self.assertAlmostEqual(rpe["translation_rmse"], 0.0)

    def test_errors(self):
        with self.assertRaises(scanmatch.Error):
            scanmatch.eval.ate(self.gt, self.gt[:5])
        with self.assertRaises(scanmatch.Error):
            scanmatch.eval.ate(self.gt, self.gt, alignment="affine")
        with self.assertRaisesRegex(ValueError, r"\(N, 4, 4\)"):
            scanmatch.eval.ate(self.gt[:, :3, :], self.gt)
        bad = self.gt.copy()
        bad[3, 0, 0] = np.nan
        with self.assertRaisesRegex(ValueError, r"est_poses\[3\]: .*non-finite"):
            scanmatch.eval.ate(self.gt, bad)


if __name__ == "__main__":
    unittest.main()
