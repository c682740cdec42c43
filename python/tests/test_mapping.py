"""Loop closure over odometries that drift in a known way: LoopClosure2D on simulated room-2d
scans, LoopClosure3D around the simulated campus block."""

import unittest

import numpy as np

import scanmatch


def planar(x, y, theta):
    return np.array([[np.cos(theta), -np.sin(theta), x],
                     [np.sin(theta), np.cos(theta), y], [0.0, 0.0, 1.0]])


def planar_of(pose):
    """x, y and yaw of a 4x4 pose of a 2D preset, as a 3x3 pose."""
    return planar(pose[0, 3], pose[1, 3], np.arctan2(pose[1, 0], pose[0, 0]))


def orthonormal(pose):
    return planar(pose[0, 2], pose[1, 2], np.arctan2(pose[1, 0], pose[0, 0]))


def rmse(truth, estimate):
    """Position RMSE after a rigid 2D alignment of estimate onto truth (m)."""
    a, b = estimate[:, :2, 2], truth[:, :2, 2]
    ca, cb = a.mean(axis=0), b.mean(axis=0)
    u, _, vt = np.linalg.svd((a - ca).T @ (b - cb))
    d = np.diag([1.0, np.sign(np.linalg.det(vt.T @ u.T))])
    rotation = vt.T @ d @ u.T
    return float(np.sqrt((((a - ca) @ rotation.T + cb - b) ** 2).sum(axis=1).mean()))


class LoopClosure2D(unittest.TestCase):
    def test_loop_closure_2d_removes_a_known_drift(self):
        sim = scanmatch.Simulator("room-2d", frames=500, seed=1, motion_distortion=False)
        truth = np.stack([planar_of(sim.pose(i)) for i in range(len(sim))])
        # The true steps, 1 % too long and turned by 0.04 deg each: an odometry that drifts.
        odometry = [truth[0]]
        for i in range(1, len(truth)):
            step = np.linalg.inv(truth[i - 1]) @ truth[i]
            step[:2, 2] *= 1.01
            odometry.append(orthonormal(odometry[-1] @ step @ planar(0, 0, np.radians(0.04))))
        odometry = np.stack(odometry)
        closure = scanmatch.LoopClosure2D(skip_recent=30, verification={"min_paired_fraction": 0.65})
        keyframes = 0
        for i in range(len(sim)):
            points, circular = sim.scan2d(i)
            keyframes += closure.add_scan(points, odometry[i], circular=circular)
        closure.finish()
        self.assertEqual(len(closure), 500)
        self.assertEqual(closure.poses.shape, (500, 3, 3))
        self.assertEqual(closure.counts["keyframes"], keyframes)
        # Steps along the hallway (plain walls, doors every 5 m) are left open by the scans; the
        # rooms' are not.
        self.assertGreater(closure.counts["open_odometry_edges"], 0)
        self.assertLess(closure.counts["open_odometry_edges"], keyframes // 2)
        before, after = rmse(truth, odometry), rmse(truth, closure.poses)
        self.assertGreater(before, 0.3)
        self.assertLess(after, 0.5 * before)
        self.assertGreater(len(closure.loops), 0)
        for loop in closure.loops:  # every accepted loop agrees with the truth
            if loop["outlier"]:
                continue
            true_relative = np.linalg.inv(truth[loop["from_scan"]]) @ truth[loop["to_scan"]]
            error = loop["relative"][:2, 2] - true_relative[:2, 2]
            if loop["sliding"]:  # it holds nothing along its open direction
                axis = loop["relative"][:2, :2] @ np.array(loop["slide_direction"])
                self.assertAlmostEqual(np.linalg.norm(axis), 1.0, places=6)
                error -= axis * (axis @ error)
            self.assertLess(np.linalg.norm(error), 0.15)

    def test_a_weak_step_is_tested_for_its_rotation(self):
        # corridor-2d over 800 scans turns 90 deg between scans 81 and 82, where going straight on
        # fits about as well: a step the odometry registered poorly (Mapper2D's weak_fit) takes
        # the rotation test though it turned less than rotation_open_min_turn.
        sim = scanmatch.Simulator("corridor-2d", frames=800)
        before, after = sim.scan2d(81)[0], sim.scan2d(82)[0]

        def open_edges(weak_fit):
            closure = scanmatch.LoopClosure2D(keyframe_distance=0.5)
            closure.add_scan(before, (0.0, 0.0, 0.0))
            self.assertTrue(closure.add_scan(after, (0.81, 0.15, 0.0), weak_fit=weak_fit))
            return closure.counts["rotation_open_odometry_edges"]

        self.assertEqual(open_edges(False), 0)
        self.assertEqual(open_edges(True), 1)

    def test_options_and_errors(self):
        options = scanmatch.loop_closure_2d_options()
        self.assertIn("verification.min_paired_fraction", options)
        self.assertEqual(options["odometry_spread_window"], 1.5)
        self.assertEqual(options["graph.loop_kernel"], "cauchy")
        with self.assertRaisesRegex(TypeError, "no_such_option"):
            scanmatch.LoopClosure2D(no_such_option=1)
        with self.assertRaisesRegex(ValueError, "kernel"):
            scanmatch.LoopClosure2D(graph={"loop_kernel": "tukey"})
        with self.assertRaisesRegex(ValueError, "standard deviations"):
            scanmatch.LoopClosure2D(loop_sigma_xy=0.0)
        closure = scanmatch.LoopClosure2D()
        with self.assertRaisesRegex(ValueError, "non-finite"):
            closure.add_scan(np.array([[1.0, np.nan], [2.0, 0.0]]), (0.0, 0.0, 0.0))
        # A scan too small to verify is kept as a keyframe without loops, never an error.
        self.assertTrue(closure.add_scan(np.zeros((0, 2)), (0.0, 0.0, 0.0)))
        self.assertEqual(closure.poses.shape, (1, 3, 3))


if __name__ == "__main__":
    unittest.main()


def drifting(truth, yaw_per_m):
    """Each true step 0.2 % too long and turned by a yaw bias per metre: an odometry that drifts."""
    odometry = [truth[0]]
    for i in range(1, len(truth)):
        step = np.linalg.inv(truth[i - 1]) @ truth[i]
        length = np.linalg.norm(step[:3, 3])
        step[:3, 3] *= 1.002
        yaw = yaw_per_m * length
        turn = np.eye(4)
        turn[:2, :2] = [[np.cos(yaw), -np.sin(yaw)], [np.sin(yaw), np.cos(yaw)]]
        odometry.append(odometry[-1] @ step @ turn)
    return np.stack(odometry)


class LoopClosure3D(unittest.TestCase):
    def test_loop_closure_3d_closes_the_campus_loop(self):
        # dynamic-outdoor-fast: 1000 frames go once around the campus block; every second one.
        sim = scanmatch.Simulator("dynamic-outdoor-fast", frames=1000, seed=1,
                                  motion_distortion=False)
        indices = range(0, len(sim), 2)
        truth = np.stack([sim.pose(i) for i in indices])
        odometry = drifting(truth, np.radians(0.01))
        closure = scanmatch.LoopClosure3D()
        for k, i in enumerate(indices):
            closure.add_frame(sim.frame(i), odometry[k])
        closure.finish()
        self.assertEqual(closure.poses.shape, (len(truth), 4, 4))
        before = scanmatch.eval.ate(truth, odometry)["rmse"]
        after = scanmatch.eval.ate(truth, closure.poses)["rmse"]
        self.assertGreater(before, 1.0)
        self.assertLess(after, before / 3)
        self.assertGreater(len(closure.loops), 0)
        for loop in closure.loops:
            if loop["outlier"]:
                continue
            expected = np.linalg.inv(truth[loop["from_frame"]]) @ truth[loop["to_frame"]]
            self.assertLess(np.linalg.norm(loop["relative"][:3, 3] - expected[:3, 3]), 0.3)

    def test_options_and_errors(self):
        options = scanmatch.loop_closure_3d_options()
        self.assertEqual(options["verification.fine_method"], "gicp")
        with self.assertRaisesRegex(TypeError, "no_such_option"):
            scanmatch.LoopClosure3D(no_such_option=1)
        with self.assertRaisesRegex(ValueError, "LoopClosure3D"):
            scanmatch.LoopClosure3D(verification={"fine_method": "no-such-method"})
        closure = scanmatch.LoopClosure3D()
        with self.assertRaisesRegex(ValueError, "non-finite|finite"):
            closure.add_frame(np.array([[1.0, np.nan, 0.0]]), np.eye(4))
        self.assertTrue(closure.add_frame(np.zeros((0, 3)), np.eye(4)))  # empty: kept, no loops
        self.assertEqual(closure.poses.shape, (1, 4, 4))
