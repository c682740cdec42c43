// Trajectory metrics (eval/metrics.hpp) and their 2D forms with the revisit consistency of a 2D
// map (eval/metrics2d.hpp); python/scanmatch/eval.py re-exports them as scanmatch.eval.ate, rpe,
// ate_2d, rpe_2d, all_pairs_error_2d and revisit_consistency_2d. 2D poses and scans come in as
// the 2D bindings take them (bind_planar.cpp): 3x3 matrices or (x, y, theta), (N, 2) x y arrays.

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "convert.hpp"
#include "scanmatch/eval/metrics.hpp"
#include "scanmatch/eval/metrics2d.hpp"

namespace scanmatch::python {
namespace {

double degrees_of(double radians) {
  return radians * 180.0 / M_PI;
}

py::dict relative_error_dict(const RelativeError2D& r) {
  py::dict d;
  d["step"] = r.step;
  d["pairs"] = r.pairs;
  d["translation_mean"] = r.mean_translation;
  d["translation_median"] = r.median_translation;
  d["translation_max"] = r.max_translation;
  d["rotation_mean_deg"] = degrees_of(r.mean_rotation);
  d["rotation_median_deg"] = degrees_of(r.median_rotation);
  d["rotation_max_deg"] = degrees_of(r.max_rotation);
  d["failure_rate"] = r.failure_rate;
  return d;
}

// The failure thresholds of the relative errors: in m and degrees, not negative (inf: never).
std::pair<double, double> failure_thresholds(double translation, double rotation_deg,
                                             const std::string& function) {
  if (!(translation >= 0.0))
    throw py::value_error(function + ": failure_translation must be at least 0 m, got " +
                          std::to_string(translation));
  if (!(rotation_deg >= 0.0))
    throw py::value_error(function + ": failure_rotation_deg must be at least 0, got " +
                          std::to_string(rotation_deg));
  return {translation, rotation_deg * M_PI / 180.0};
}

}  // namespace

void bind_eval(py::module_& m) {
  m.def(
      "ate",
      [](py::handle ground_truth, py::handle estimate, const std::string& alignment) {
        const std::vector<Pose> gt = poses_from_array(ground_truth, "gt_poses");
        const std::vector<Pose> est = poses_from_array(estimate, "est_poses");
        const Alignment align = parse_alignment(alignment);
        const AteResult r = compute_ate(gt, est, align);
        py::dict d;
        d["poses"] = r.poses;
        d["rmse"] = r.rmse;
        d["mean"] = r.mean;
        d["median"] = r.median;
        d["max"] = r.max;
        d["path_length"] = r.path_length;
        d["rmse_percent_of_path"] = r.rmse_percent_of_path;
        d["final_drift"] = r.final_drift;
        d["alignment"] = pose_to_array(r.alignment.transform);
        d["scale"] = r.alignment.scale;
        return d;
      },
      py::arg("gt_poses"), py::arg("est_poses"), py::arg("alignment") = "none", R"doc(
ate(gt_poses, est_poses, alignment="none") -> dict

Absolute trajectory error of associated poses (pose i with pose i), both (N, 4, 4). alignment:
none, se3 or sim3 (Umeyama on the positions). Keys: rmse, mean, median, max (m), path_length
(m), rmse_percent_of_path, final_drift (m), poses, alignment (4x4 applied to the estimate),
scale. Different lengths raise scanmatch.Error.)doc");

  m.def(
      "rpe",
      [](py::handle ground_truth, py::handle estimate, std::size_t delta) {
        const std::vector<Pose> gt = poses_from_array(ground_truth, "gt_poses");
        const std::vector<Pose> est = poses_from_array(estimate, "est_poses");
        if (delta == 0) throw py::value_error("rpe: delta must be at least 1");
        const RpeResult r = compute_rpe_frames(gt, est, delta);
        py::dict d;
        d["pairs"] = r.pairs;
        d["translation_rmse"] = r.translation_rmse;
        d["translation_mean"] = r.translation_mean;
        d["translation_median"] = r.translation_median;
        d["rotation_rmse_deg"] = r.rotation_rmse;
        d["rotation_mean_deg"] = r.rotation_mean;
        return d;
      },
      py::arg("gt_poses"), py::arg("est_poses"), py::arg("delta") = 1, R"doc(
rpe(gt_poses, est_poses, delta=1) -> dict

Relative pose error between poses `delta` frames apart: translation_rmse/mean/median (m),
rotation_rmse_deg/mean_deg.)doc");

  m.def(
      "ate_2d",
      [](py::handle reference, py::handle estimate) {
        const std::vector<Pose2> ref = poses2_from_array(reference, "reference_poses");
        const std::vector<Pose2> est = poses2_from_array(estimate, "estimated_poses");
        const AbsoluteError2D r = absolute_trajectory_error_2d(ref, est);
        py::dict d;
        d["poses"] = r.poses;
        d["rmse"] = r.rmse;
        d["mean"] = r.mean;
        d["max"] = r.max;
        d["alignment"] = pose2_to_array(r.alignment);
        return d;
      },
      py::arg("reference_poses"), py::arg("estimated_poses"), R"doc(
ate_2d(reference_poses, estimated_poses) -> dict

Absolute trajectory error of associated 2D poses (pose i with pose i) after the rigid 2D motion
(rotation and translation, least squares on the positions) that best aligns the estimate onto
the reference. Poses: (N, 3, 3) as Mapper2D.poses and LoopClosure2D.poses give them, or (N, 3)
rows of x y theta. Keys: poses, rmse, mean, max (m, of the positions after the alignment),
alignment (3x3 that maps estimated positions onto the reference). Fewer than two poses give zero
error and the identity. Different lengths raise scanmatch.Error.)doc");

  m.def(
      "rpe_2d",
      [](py::handle reference, py::handle estimate, std::size_t step, double failure_translation,
         double failure_rotation_deg) {
        const std::vector<Pose2> ref = poses2_from_array(reference, "reference_poses");
        const std::vector<Pose2> est = poses2_from_array(estimate, "estimated_poses");
        const auto [t, a] = failure_thresholds(failure_translation, failure_rotation_deg, "rpe_2d");
        return relative_error_dict(relative_pose_error_2d(ref, est, step, t, a));
      },
      py::arg("reference_poses"), py::arg("estimated_poses"), py::arg("step") = 1,
      py::arg("failure_translation") = 0.2, py::arg("failure_rotation_deg") = 5.0, R"doc(
rpe_2d(reference_poses, estimated_poses, step=1, failure_translation=0.2,
       failure_rotation_deg=5.0) -> dict

Relative pose error of 2D trajectories: the motion from pose k to pose k + step of the estimate
against that of the reference, for every k. Poses as for ate_2d. Keys: step, pairs,
translation_mean/median/max (m), rotation_mean_deg/median_deg/max_deg, failure_rate (share of
pairs off by more than failure_translation m or failure_rotation_deg degrees). Different lengths
or step 0 raise scanmatch.Error.)doc");

  m.def(
      "all_pairs_error_2d",
      [](py::handle reference, py::handle estimate, std::size_t max_poses,
         double failure_translation, double failure_rotation_deg) {
        const std::vector<Pose2> ref = poses2_from_array(reference, "reference_poses");
        const std::vector<Pose2> est = poses2_from_array(estimate, "estimated_poses");
        if (max_poses < 2)
          throw py::value_error("all_pairs_error_2d: max_poses must be at least 2, got " +
                                std::to_string(max_poses));
        const auto [t, a] =
            failure_thresholds(failure_translation, failure_rotation_deg, "all_pairs_error_2d");
        RelativeError2D r;
        {
          py::gil_scoped_release release;
          r = all_pairs_relative_error_2d(ref, est, max_poses, t, a);
        }
        return relative_error_dict(r);
      },
      py::arg("reference_poses"), py::arg("estimated_poses"), py::arg("max_poses") = 1500,
      py::arg("failure_translation") = 0.2, py::arg("failure_rotation_deg") = 5.0, R"doc(
all_pairs_error_2d(reference_poses, estimated_poses, max_poses=1500, failure_translation=0.2,
                   failure_rotation_deg=5.0) -> dict

The relative error over all pairs of poses j > k (Kuemmerle et al. 2009, every pair a
relation), with the keys of rpe_2d and step 0. Longer trajectories are first thinned evenly to
max_poses poses (the pairs grow with the square). Different lengths raise scanmatch.Error.)doc");

  m.def(
      "revisit_consistency_2d",
      [](py::handle scans, py::handle poses, std::size_t revisit_gap, double max_distance,
         std::size_t max_queries, bool circular) {
        // A list of scans, or an (M, N, 2) array of scans of as many beams.
        if (!py::isinstance<py::sequence>(scans) ||
            (py::isinstance<py::array>(scans) &&
             py::reinterpret_borrow<py::array>(scans).ndim() != 3))
          throw py::type_error(
              "revisit_consistency_2d: scans must be a sequence of (N, 2) arrays, one per scan");
        const py::sequence items = py::reinterpret_borrow<py::sequence>(scans);
        std::vector<Scan2D> laser;
        laser.reserve(items.size());
        for (std::size_t i = 0; i < items.size(); ++i)
          laser.push_back(
              scan_from_arrays(items[i], py::none(), circular, "scans[" + std::to_string(i) + "]"));
        const std::vector<Pose2> p = poses2_from_array(poses, "poses");
        if (!std::isfinite(max_distance))
          throw py::value_error("revisit_consistency_2d: max_distance must be finite");
        if (max_queries == 0)
          throw py::value_error("revisit_consistency_2d: max_queries must be at least 1");
        RevisitConsistency2D r;
        {
          py::gil_scoped_release release;
          r = revisit_consistency_2d(laser, p, revisit_gap, max_distance, max_queries);
        }
        py::dict d;
        d["points"] = r.points;
        d["revisited"] = r.revisited;
        d["revisited_share"] =
            r.points > 0 ? static_cast<double>(r.revisited) / static_cast<double>(r.points) : 0.0;
        d["mean"] = r.mean;
        d["median"] = r.median;
        d["p90"] = r.p90;
        return d;
      },
      py::arg("scans"), py::arg("poses"), py::arg("revisit_gap") = 20,
      py::arg("max_distance") = 0.5, py::arg("max_queries") = 200000, py::arg("circular") = false,
      R"doc(
revisit_consistency_2d(scans, poses, revisit_gap=20, max_distance=0.5, max_queries=200000,
                       circular=False) -> dict

How far apart the walls of revisits lie, a 2D map's quality without a reference (map2d's
revisit_consistency). scans: a sequence of (N, 2) arrays of x y in the laser frame, in beam
order, as register2d and Mapper2D take them, or one (M, N, 2) array (circular: the scans cover
360 degrees); poses[i] is the pose of scans[i], as for ate_2d. Each point (every n-th, to look
at most at max_queries) is compared with the nearest point of a scan at least revisit_gap scans
away: its distance to that scan's surface (the segments to its beam neighbours), capped at
max_distance (m). Keys: points (looked at), revisited (with another visit's point within
max_distance), revisited_share, and mean, median, p90 (m, over the revisited points). Non-finite
poses or points raise ValueError; different lengths, revisit_gap 0 or max_distance <= 0
scanmatch.Error.)doc");
}

}  // namespace scanmatch::python
