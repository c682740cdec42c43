// `scanmatch register SOURCE TARGET --method NAME`: the transform that maps SOURCE into TARGET;
// with --global, found with no initial guess (registration/global_registration.hpp).

#include <fmt/format.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <sstream>

#include "apps/commands.hpp"
#include "apps/config_options.hpp"
#include "scanmatch/core/error.hpp"
#include "scanmatch/geometry/voxel_filter.hpp"
#include "scanmatch/io/carmen.hpp"
#include "scanmatch/io/cloud_io.hpp"
#include "scanmatch/registration/global_registration.hpp"
#include "scanmatch/registration/methods.hpp"
#include "scanmatch/registration/planar/registration2d.hpp"

namespace scanmatch::cli {
namespace {

struct RegisterCommand {
  std::string source, target, init;
  bool planar = false;
  Registration2DOptions planar_options;
  bool json = false;
  PairRegistrationOptions pair;
  const CLI::Option *method = nullptr, *max_distance = nullptr;  ///< given: they apply to --2d
  bool global = false;
  GlobalRegistrationOptions global_options;
  const CLI::Option *voxel = nullptr, *max_iterations = nullptr;  ///< given: they apply to --global
};

std::vector<std::vector<double>> matrix_rows(const Pose& T) {
  const Eigen::Matrix4d M = to_matrix(T);
  std::vector<std::vector<double>> rows(4, std::vector<double>(4));
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) rows[i][j] = M(i, j);
  return rows;
}

// --global: no initial guess; the global stage's evidence, and a non-zero exit when it cannot.
void run_global(RegisterCommand& c, const PointCloud& source, const PointCloud& target) {
  GlobalRegistrationOptions o = c.global_options;
  // The refinement: --method and the registration flags when given, else the global defaults.
  const RegistrationOptions defaults = o.refinement;
  o.refinement = c.pair.registration;
  if (c.method->count() == 0) o.refinement.method = defaults.method;
  if (c.max_iterations->count() == 0)
    o.refinement.solver.max_iterations = defaults.solver.max_iterations;
  if (c.voxel->count() > 0) o.refine_voxel_size = c.pair.voxel_size;
  o.num_threads = c.pair.registration.solver.num_threads;
  const auto start = std::chrono::steady_clock::now();
  const GlobalRegistrationResult r = register_global(source, target, o);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (c.json) {
    nlohmann::ordered_json j;
    j["success"] = r.success;
    if (!r.success) j["failure"] = r.failure;
    j["transform"] = matrix_rows(r.transform);
    j["coarse_transform"] = matrix_rows(r.coarse_transform);
    j["refinement_method"] = o.refine ? o.refinement.method : "none";
    j["source_keypoints"] = r.source_keypoints;
    j["target_keypoints"] = r.target_keypoints;
    j["correspondences"] = r.correspondences;
    j["clique_size"] = r.clique_size;
    j["inliers"] = r.inliers;
    j["inlier_ratio"] = r.inlier_ratio;
    j["second_inliers"] = r.second_inliers;
    j["ambiguity"] = r.ambiguity;
    j["overlap"] = r.overlap;
    j["fitness"] = r.fitness;
    j["iterations"] = r.refinement.iterations;
    j["feature_ms"] = r.feature_ms;
    j["matching_ms"] = r.matching_ms;
    j["refine_ms"] = r.refine_ms;
    j["time_ms"] = ms;
    fmt::print("{}\n", j.dump(2));
  } else if (r.success) {
    const Eigen::Matrix4d M = to_matrix(r.transform);
    for (int i = 0; i < 4; ++i)
      fmt::print("{:12.8f} {:12.8f} {:12.8f} {:12.8f}\n", M(i, 0), M(i, 1), M(i, 2), M(i, 3));
    fmt::print("global: {}\n", r.summary());
    fmt::print(
        "refined by {} ({} iterations); features {:.0f} ms, matching {:.0f} ms, refinement "
        "{:.0f} ms, {:.0f} ms in all\n",
        o.refine ? o.refinement.method : "nothing", r.refinement.iterations, r.feature_ms,
        r.matching_ms, r.refine_ms, ms);
  }
  if (!r.success)
    throw Error("cannot register " + c.source + " onto " + c.target + " globally: " + r.failure +
                " (evidence: " + r.summary() + ")");
}

// "16 numbers" (row-major 4x4) or "x,y,z,roll,pitch,yaw" (metres and degrees).
Pose parse_initial_guess(const std::string& text) {
  std::string s = text;
  for (char& c : s)
    if (c == ',' || c == ';') c = ' ';
  std::istringstream in(s);
  std::vector<double> v;
  std::string token;
  while (in >> token) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(token, &used));
      if (used != token.size()) throw std::invalid_argument(token);
    } catch (const std::exception&) {
      throw Error("--init: not a number: '" + token + "'");
    }
  }
  for (double x : v)
    if (!std::isfinite(x)) throw Error("--init: the initial guess contains a non-finite value");
  if (v.size() == 6)
    return from_xyz_rpy(v[0], v[1], v[2], v[3] * M_PI / 180, v[4] * M_PI / 180, v[5] * M_PI / 180);
  if (v.size() == 16) {
    Eigen::Matrix4d M;
    for (int i = 0; i < 16; ++i) M(i / 4, i % 4) = v[static_cast<std::size_t>(i)];
    if (!is_valid_pose(M, 1e-3)) throw Error("--init: the 4x4 matrix is not a rigid transform");
    return from_matrix(M);
  }
  throw Error(
      "--init: expected 16 numbers (a 4x4 matrix) or 6 (x,y,z,roll,pitch,yaw in degrees), got " +
      std::to_string(v.size()));
}

// "LOG" (its first scan) or "LOG:INDEX" (a CARMEN log; .gz allowed).
LaserScan2D read_scan_2d(const std::string& spec) {
  std::string path = spec;
  std::size_t index = 0;
  const auto colon = spec.rfind(':');
  if (colon != std::string::npos && colon + 1 < spec.size() &&
      spec.find_first_not_of("0123456789", colon + 1) == std::string::npos) {
    path = spec.substr(0, colon);
    index = std::stoul(spec.substr(colon + 1));
  }
  const CarmenLog log = read_carmen_log(path);
  if (index >= log.scans.size())
    throw Error(path + ": scan " + std::to_string(index) + " requested, the log has " +
                std::to_string(log.scans.size()));
  return log.scans[index];
}

void run_2d(RegisterCommand& c) {
  Pose2 initial = Pose2::Identity();
  if (!c.init.empty()) initial = planar_pose(parse_initial_guess(c.init));
  const Scan2D source = scan_from_laser(read_scan_2d(c.source));
  const Scan2D target = scan_from_laser(read_scan_2d(c.target));
  const auto start = std::chrono::steady_clock::now();
  const Registration2DResult r = register_scans(source, target, c.planar_options, initial);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  const double x = r.transform.translation().x(), y = r.transform.translation().y();
  const double theta = pose2_angle(r.transform);
  if (c.json) {
    nlohmann::ordered_json j;
    j["method"] = c.planar_options.method;
    j["x"] = x;
    j["y"] = y;
    j["theta_deg"] = theta * 180 / M_PI;
    j["iterations"] = r.iterations;
    j["converged"] = r.converged;
    j["pairs"] = r.pairs;
    j["error_m"] = r.error;
    j["time_ms"] = ms;
    fmt::print("{}\n", j.dump(2));
    return;
  }
  fmt::print("x {:.4f} m, y {:.4f} m, theta {:.3f} deg\n", x, y, theta * 180 / M_PI);
  fmt::print("method {}: {} iterations, {}, {} pairs, mean pair distance {:.4f} m, {:.2f} ms\n",
             c.planar_options.method, r.iterations, r.converged ? "converged" : "not converged",
             r.pairs, r.error, ms);
}

void run(RegisterCommand& c) {
  if (c.planar) {
    if (c.method->count() > 0) c.planar_options.method = c.pair.registration.method;
    if (c.max_distance->count() > 0)
      c.planar_options.max_correspondence_distance =
          c.pair.registration.max_correspondence_distance;
    check_registration_2d_method(c.planar_options.method);
    return run_2d(c);
  }
  if (c.global && !c.init.empty()) throw Error("--global takes no initial guess: leave out --init");
  const Pose initial = c.init.empty() ? Pose::Identity() : parse_initial_guess(c.init);
  PointCloud source = read_cloud(c.source), target = read_cloud(c.target);
  if (source.empty()) throw Error(c.source + ": the cloud is empty");
  if (target.empty()) throw Error(c.target + ": the cloud is empty");
  if (c.global) return run_global(c, source, target);
  if (c.pair.voxel_size > 0.0) {
    source = voxel_downsample(source, c.pair.voxel_size);
    target = voxel_downsample(target, c.pair.voxel_size);
  }
  const auto start = std::chrono::steady_clock::now();
  const RegistrationResult r = register_clouds(source, target, c.pair.registration, initial);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::size_t matched = 0;
  const double fitness = fitness_score(source, target, r.transform,
                                       c.pair.registration.max_correspondence_distance, &matched);
  const Eigen::Matrix4d M = to_matrix(r.transform);
  if (c.json) {
    nlohmann::ordered_json j;
    j["method"] = c.pair.registration.method;
    j["transform"] = std::vector<std::vector<double>>{{M(0, 0), M(0, 1), M(0, 2), M(0, 3)},
                                                      {M(1, 0), M(1, 1), M(1, 2), M(1, 3)},
                                                      {M(2, 0), M(2, 1), M(2, 2), M(2, 3)},
                                                      {M(3, 0), M(3, 1), M(3, 2), M(3, 3)}};
    j["iterations"] = r.iterations;
    j["converged"] = r.converged;
    j["stop_reason"] = r.stop_reason;
    j["time_ms"] = ms;
    j["fitness"] = fitness;
    j["correspondences"] = r.inliers;
    j["condition_number"] = std::isfinite(r.condition_number) ? r.condition_number : -1.0;
    j["source_points"] = source.size();
    j["target_points"] = target.size();
    fmt::print("{}\n", j.dump(2));
    return;
  }
  for (int i = 0; i < 4; ++i)
    fmt::print("{:12.8f} {:12.8f} {:12.8f} {:12.8f}\n", M(i, 0), M(i, 1), M(i, 2), M(i, 3));
  fmt::print(
      "method {}: {} iterations, {}, {:.1f} ms\n", c.pair.registration.method, r.iterations,
      r.converged ? "converged (" + r.stop_reason + ")" : "not converged (" + r.stop_reason + ")",
      ms);
  fmt::print("fitness {:.6g} m^2 over {} of {} points; condition number {:.4g}\n", fitness, matched,
             source.size(), r.condition_number);
}

}  // namespace

void add_register_command(CLI::App& app) {
  auto c = std::make_shared<RegisterCommand>();
  auto* cmd = app.add_subcommand(
      "register",
      "Register SOURCE onto TARGET; prints the 4x4 transform mapping SOURCE into TARGET");
  cmd->add_option("SOURCE", c->source, "Source cloud")->required();
  cmd->add_option("TARGET", c->target, "Target cloud")->required();
  c->method = cmd->add_option("--method", c->pair.registration.method,
                              "One of: " + registration_method_list())
                  ->capture_default_str();
  cmd->add_option("--init", c->init,
                  "Initial guess: 16 numbers (row-major 4x4) or x,y,z,roll,pitch,yaw (m, deg)");
  cmd->add_option("--threads", c->pair.registration.solver.num_threads, "Threads for linearisation")
      ->capture_default_str();
  add_config_options(cmd, c->pair);
  c->max_distance = cmd->get_option("--max-distance");
  c->voxel = cmd->get_option("--voxel");
  c->max_iterations = cmd->get_option("--max-iterations");
  cmd->add_flag("--global", c->global,
                "No initial guess: FPFH features, a maximum consistent set of matches, then "
                "--method (default vgicp) from there; exits non-zero when the evidence is weak");
  auto& g = c->global_options;
  cmd->add_option("--feature-voxel", g.feature_voxel_size, "--global: keypoint voxel size, m")
      ->capture_default_str();
  cmd->add_option("--feature-radius", g.fpfh.radius, "--global: FPFH neighbourhood radius, m")
      ->capture_default_str();
  cmd->add_option("--noise-bound", g.noise_bound,
                  "--global: largest distance error of a correct feature match, m")
      ->capture_default_str();
  cmd->add_option("--min-inliers", g.min_inliers,
                  "--global: feature matches the best motion must explain")
      ->capture_default_str();
  cmd->add_option("--max-ambiguity", g.max_ambiguity,
                  "--global: fail when another motion explains this share of the best's matches")
      ->capture_default_str();
  cmd->add_flag("--json", c->json, "Print JSON");
  cmd->add_flag("--2d", c->planar,
                "2D laser scans: SOURCE and TARGET are CARMEN logs, LOG or LOG:INDEX; methods " +
                    registration_2d_method_list() + " (default " + Registration2DOptions{}.method +
                    ")");
  cmd->add_option("--search-window", c->planar_options.search_window,
                  "2D: correlative coarse search over +- this many m first (0: off)");
  std::string methods = "3D methods (what each builds first):\n";
  for (const auto& m : registration_methods())
    methods += fmt::format("  {:<15} {} ({})\n", m.name, m.summary, m.builds);
  cmd->footer(methods);
  cmd->callback([c] { run(*c); });
}

}  // namespace scanmatch::cli
