// Trajectory metrics (eval/metrics.hpp); python/scanmatch/eval.py re-exports them as
// scanmatch.eval.ate and scanmatch.eval.rpe.

#include "bindings.hpp"
#include "convert.hpp"
#include "scanmatch/eval/metrics.hpp"

namespace scanmatch::python {

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
}

}  // namespace scanmatch::python
