#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "apps/commands.hpp"
#include "scanmatch/eval/metrics.hpp"
#include "scanmatch/eval/metrics_json.hpp"
#include "scanmatch/io/trajectory.hpp"

namespace scanmatch::cli {
namespace {

struct EvalOptions {
  std::string ground_truth, estimate, align = "none";
  bool allow_partial = false, json = false;
  std::size_t rpe_frames = 1;
  double rpe_distance = 0.0;
  double max_time_gap = 0.01;
};

nlohmann::ordered_json rpe_json(const RpeResult& r) {
  return {{"pairs", r.pairs},
          {"translation_rmse_m", r.translation_rmse},
          {"translation_mean_m", r.translation_mean},
          {"translation_median_m", r.translation_median},
          {"rotation_rmse_deg", r.rotation_rmse},
          {"rotation_mean_deg", r.rotation_mean}};
}

void run_eval(const EvalOptions& o) {
  const Trajectory gt = read_trajectory(o.ground_truth);
  const Trajectory est = read_trajectory(o.estimate);
  const Association pairs = associate(gt, est, o.allow_partial, o.max_time_gap);
  const AteResult ate = compute_ate(pairs.ground_truth, pairs.estimate, parse_alignment(o.align));
  const RpeResult rpe = compute_rpe_frames(pairs.ground_truth, pairs.estimate, o.rpe_frames);
  const bool with_distance_rpe = o.rpe_distance > 0.0;
  const RpeResult rpe_distance =
      with_distance_rpe ? compute_rpe_distance(pairs.ground_truth, pairs.estimate, o.rpe_distance)
                        : RpeResult{};
  const KittiDriftResult kitti = compute_kitti_drift(pairs.ground_truth, pairs.estimate);

  if (o.json) {
    nlohmann::ordered_json j = {
        {"ground_truth", o.ground_truth},
        {"estimate", o.estimate},
        {"association", pairs.description},
        {"alignment", o.align},
        {"ate", ate_json(ate)},
        {"rpe_frames", {{"delta_frames", o.rpe_frames}, {"result", rpe_json(rpe)}}},
        {"kitti",
         {{"segments", kitti.segments},
          {"translation_percent", kitti.translation_percent},
          {"rotation_deg_per_100m", kitti.rotation_deg_per_100m},
          {"lengths_m", kitti.lengths_used}}}};
    if (with_distance_rpe)
      j["rpe_distance"] = {{"delta_m", o.rpe_distance}, {"result", rpe_json(rpe_distance)}};
    fmt::print("{}\n", j.dump(2));
    return;
  }
  fmt::print("association: {}\nalignment: {}\n", pairs.description, o.align);
  fmt::print("ATE: rmse {:.4f} m, mean {:.4f} m, median {:.4f} m, max {:.4f} m over {} poses\n",
             ate.rmse, ate.mean, ate.median, ate.max, ate.poses);
  if (ate.path_length > 0.0)
    fmt::print("ATE: {:.3f} % of the {:.2f} m ground-truth path\n", ate.rmse_percent_of_path,
               ate.path_length);
  else
    fmt::print("still sensor: final drift {:.4f} m, maximum drift {:.4f} m\n", ate.final_drift,
               ate.max);
  if (ate.alignment.scale != 1.0) fmt::print("sim3 scale: {:.6f}\n", ate.alignment.scale);
  fmt::print(
      "RPE over {} frame(s): translation rmse {:.4f} m, rotation rmse {:.4f} deg ({} pairs)\n",
      o.rpe_frames, rpe.translation_rmse, rpe.rotation_rmse, rpe.pairs);
  if (with_distance_rpe)
    fmt::print(
        "RPE over {:.2f} m: translation rmse {:.4f} m, rotation rmse {:.4f} deg ({} pairs)\n",
        o.rpe_distance, rpe_distance.translation_rmse, rpe_distance.rotation_rmse,
        rpe_distance.pairs);
  if (kitti.segments > 0)
    fmt::print("KITTI drift: {:.3f} % translation, {:.4f} deg/100 m rotation ({} segments)\n",
               kitti.translation_percent, kitti.rotation_deg_per_100m, kitti.segments);
  else
    fmt::print("KITTI drift: path shorter than 100 m, not computed\n");
}

}  // namespace

void add_eval_command(CLI::App& app) {
  auto options = std::make_shared<EvalOptions>();
  auto* cmd = app.add_subcommand(
      "eval", "Compare an estimated trajectory with ground truth (ATE, RPE, KITTI drift)");
  cmd->add_option("--gt", options->ground_truth, "Ground-truth trajectory (KITTI or TUM)")
      ->required();
  cmd->add_option("--est", options->estimate, "Estimated trajectory (KITTI or TUM)")->required();
  cmd->add_option("--align", options->align, "Alignment before ATE: none, se3 or sim3")
      ->capture_default_str();
  cmd->add_option("--rpe-frames", options->rpe_frames, "RPE frame delta")->capture_default_str();
  cmd->add_option("--rpe-distance", options->rpe_distance,
                  "Also compute RPE over this distance delta in metres (0: off)");
  cmd->add_option("--max-time-gap", options->max_time_gap,
                  "Largest timestamp difference for association, s")
      ->capture_default_str();
  cmd->add_flag("--allow-partial", options->allow_partial,
                "Evaluate the matched poses when the trajectories differ in length");
  cmd->add_flag("--json", options->json, "Print JSON");
  cmd->callback([options] { run_eval(*options); });
}

}  // namespace scanmatch::cli
