"""One run record for 2D and 3D: Python's dictionaries have the keys of the run folder's files,
because both come from one description each (timing.csv's columns from Scan2DStats' and
FrameStats', summary.json's loop-closure counts from mapping/loop_counts.hpp). Needs SCANMATCH_CLI
(scripts/test_python sets it) for the run folders."""

import json
import os
import subprocess
import tempfile
import unittest

import numpy as np

import scanmatch

SCANS = 40


@unittest.skipUnless(os.environ.get("SCANMATCH_CLI"), "SCANMATCH_CLI not set")
class RunRecord2D(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        with tempfile.TemporaryDirectory() as out:
            subprocess.run([os.environ["SCANMATCH_CLI"], "map2d", "sim:room-2d", "--scans",
                            str(SCANS), "--no-motion-distortion", "--seed", "1", "--loop-closure",
                            "--out", out, "--quiet"], check=True)
            with open(os.path.join(out, "timing.csv")) as f:
                cls.columns = f.readline().strip().split(",")
            with open(os.path.join(out, "summary.json")) as f:
                cls.summary = json.load(f)
            cls.cli_poses = np.loadtxt(os.path.join(out, "poses_tum.txt"))
        sim = scanmatch.Simulator("room-2d", frames=SCANS, seed=1, motion_distortion=False)
        cls.mapper = scanmatch.Mapper2D()
        for i in range(SCANS):
            points, circular = sim.scan2d(i)
            cls.mapper.add_scan(points, circular=circular, timestamp=sim.timestamps[i])

    def test_a_run_folder_says_what_it_is(self):
        self.assertEqual(self.summary["kind"], "map2d")

    def test_scan_statistics_have_timing_csvs_keys(self):
        self.assertEqual(self.columns[:2], ["index", "timestamp"])
        self.assertEqual(list(self.mapper.stats[0]), self.columns[2:])
        self.assertIn("error_m", self.mapper.last_stats)
        self.assertIn("weak_fit", self.mapper.last_stats)
        doc = type(self.mapper).last_stats.__doc__
        for key in self.mapper.last_stats:
            self.assertIn(f"\n  {key}: ", doc)

    def test_mapper2d_has_the_defaults_of_map2d(self):
        # One default for the correlative search: the library's, so Python maps as map2d does.
        self.assertEqual(self.mapper.config["registration.search_window"], 1.3)
        xy = self.mapper.poses[:, :2, 2]
        np.testing.assert_allclose(xy, self.cli_poses[:, 1:3], atol=1e-6)

    def test_loop_counts_have_summary_jsons_keys(self):
        run_keys = ["accepted", "ms_per_scan", "thread", "wait_ms_per_scan"]
        counts = list(scanmatch.LoopClosure2D().counts)
        self.assertEqual(counts + run_keys, list(self.summary["loop_closure"]))
        self.assertIn("rejected_as_outliers", counts)


@unittest.skipUnless(os.environ.get("SCANMATCH_CLI"), "SCANMATCH_CLI not set")
class RunRecord3D(unittest.TestCase):
    def test_a_run_folder_says_what_it_is_and_loop_counts_have_its_keys(self):
        with tempfile.TemporaryDirectory() as out:
            subprocess.run([os.environ["SCANMATCH_CLI"], "odometry", "sim:dynamic-outdoor-fast",
                            "--frames", "4", "--loop-closure", "--out", out, "--quiet"],
                           check=True)
            with open(os.path.join(out, "summary.json")) as f:
                summary = json.load(f)
        self.assertEqual(summary["kind"], "odometry")
        run_keys = ["accepted", "ms_per_frame", "thread", "wait_ms_per_frame"]
        counts = list(scanmatch.LoopClosure3D().counts)
        self.assertEqual(counts + run_keys, list(summary["loop_closure"]))
        doc = scanmatch.LoopClosure3D.counts.__doc__
        for key in counts:
            self.assertIn(f"\n  {key}: ", doc)


if __name__ == "__main__":
    unittest.main()
