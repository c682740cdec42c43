#include "scanmatch/benchmark/benchmark2d.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>

#include "scanmatch/core/error.hpp"
#include "scanmatch/core/progress.hpp"
#include "scanmatch/eval/metrics.hpp"
#include "scanmatch/eval/metrics2d.hpp"
#include "scanmatch/io/carmen.hpp"
#include "scanmatch/io/file_util.hpp"
#include "scanmatch/registration/planar/registration2d.hpp"
#include "scanmatch/sim/scan_pairs.hpp"

namespace scanmatch {
namespace {

struct ScanPair {
  Scan2D current, reference;
  Pose2 truth;  ///< maps current into reference
};

std::vector<ScanPair> simulated_pairs(std::size_t count, double max_translation,
                                      double max_rotation) {
  sim::PlanarPairOptions options;
  options.count = count;
  options.max_translation = max_translation;
  options.max_rotation = max_rotation;
  std::vector<ScanPair> pairs;
  for (const sim::PlanarScanPair& p : sim::planar_scan_pairs(options))
    pairs.push_back({scan_from_laser(p.current), scan_from_laser(p.reference), p.truth});
  return pairs;
}

struct Spread {
  double mean = 0, std = 0;
};
Spread spread(const std::vector<double>& v) {
  Spread s;
  if (v.empty()) return s;
  s.mean = mean_of(v);
  for (double x : v) s.std += (x - s.mean) * (x - s.mean);
  s.std = std::sqrt(s.std / static_cast<double>(v.size()));
  return s;
}

std::string pair_table(const std::vector<ScanPair>& pairs, const Benchmark2DOptions& o) {
  std::string md = fmt::format(
      "### Simulated Neato scan pairs (2D paper, Table 1)\n\n{} pairs of Neato scans at random "
      "places in the rooms of room-2d, offset by up to {:.0f} mm and {:.0f} deg (mean {:.0f} mm, "
      "{:.1f} deg), 1 % range noise, 1 % dropouts, no motion distortion; every method from the "
      "identity.\n\n"
      "| method | error mm, mean | std | median | rotation error deg, mean | iterations, mean | "
      "std | pairs/s |\n|---|---:|---:|---:|---:|---:|---:|---:|\n",
      pairs.size(), 1000 * o.max_translation, o.max_rotation_deg,
      spread([&] {
        std::vector<double> v;
        for (const auto& p : pairs) v.push_back(1000 * p.truth.translation().norm());
        return v;
      }())
          .mean,
      spread([&] {
        std::vector<double> v;
        for (const auto& p : pairs) v.push_back(std::abs(pose2_angle(p.truth)) * 180 / M_PI);
        return v;
      }())
          .mean);
  ProgressReporter progress("bench2d pairs", pairs.size() * o.methods.size(), "pairs", o.quiet);
  std::size_t done = 0;
  for (const std::string& method : o.methods) {
    const Registration2DOptions options = benchmark2d_method(method);
    std::vector<double> errors, rotations, iterations;
    double seconds = 0.0;
    for (const ScanPair& p : pairs) {
      const auto start = std::chrono::steady_clock::now();
      const Registration2DResult r = register_scans(p.current, p.reference, options);
      seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const Pose2 error = p.truth.inverse() * r.transform;
      errors.push_back(1000 * error.translation().norm());
      rotations.push_back(std::abs(pose2_angle(error)) * 180 / M_PI);
      iterations.push_back(r.iterations);
      progress.update(++done);
    }
    std::vector<double> sorted = errors;
    std::sort(sorted.begin(), sorted.end());
    const Spread e = spread(errors), it = spread(iterations);
    md += fmt::format("| {} | {:.2f} | {:.2f} | {:.2f} | {:.3f} | {:.1f} | {:.1f} | {:.0f} |\n",
                      method, e.mean, e.std, sorted[sorted.size() / 2], spread(rotations).mean,
                      it.mean, it.std, static_cast<double>(pairs.size()) / seconds);
  }
  progress.finish();
  return md;
}

std::string log_table(const std::string& path, const Benchmark2DOptions& o) {
  const CarmenLog log = read_carmen_log(path);
  if (log.scans.size() < 12) throw Error(path + ": too few scans for the 10-step error");
  std::vector<Scan2D> scans;
  std::vector<Pose2> reference;
  for (const LaserScan2D& s : log.scans) {
    scans.push_back(scan_from_laser(s));
    reference.push_back(pose2(s.pose));
  }
  std::string md = fmt::format(
      "### {} ({} scans)\n\nRelative pose error against the corrected poses of the log, over 1 and "
      "10 scan steps; failures: steps off by more than 0.2 m or 5 deg.\n\n"
      "| method | initial guess | 1-step mm, mean | median | deg, mean | failures % | "
      "10-step mm, mean | median | deg, mean | scans/s |\n"
      "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
      std::filesystem::path(path).filename().string(), scans.size());
  struct Variant {
    std::string method, label;
    bool constant_velocity;
    double search;
  };
  std::vector<Variant> variants;
  for (const std::string& m : o.methods)
    for (const bool cv : {false, true})
      variants.push_back({m, cv ? "constant velocity" : "identity", cv, 0.0});
  if (o.search_window > 0.0)
    for (const std::string& m : o.methods)
      variants.push_back(
          {m, fmt::format("identity + search {:.1f} m", o.search_window), false, o.search_window});
  ProgressReporter progress("bench2d " + std::filesystem::path(path).filename().string(),
                            variants.size() * scans.size(), "scans", o.quiet);
  std::size_t done = 0;
  for (const Variant& v : variants) {
    Mapper2DConfig config;
    config.registration = benchmark2d_method(v.method);
    config.registration.search_window = v.search;
    config.constant_velocity = v.constant_velocity;
    Mapper2D mapper(config);
    std::vector<Pose2> estimate;
    double ms = 0.0;
    for (const Scan2D& s : scans) {
      estimate.push_back(mapper.add_scan(s));
      ms += mapper.last_stats().ms;
      progress.update(++done);
    }
    const RelativeError2D one = relative_pose_error_2d(reference, estimate, 1),
                          ten = relative_pose_error_2d(reference, estimate, 10);
    md += fmt::format(
        "| {} | {} | {:.0f} | {:.0f} | {:.2f} | {:.1f} | {:.0f} | {:.0f} | {:.2f} | {:.0f} |\n",
        v.method, v.label, 1000 * one.mean_translation, 1000 * one.median_translation,
        one.mean_rotation * 180 / M_PI, 100 * one.failure_rate, 1000 * ten.mean_translation,
        1000 * ten.median_translation, ten.mean_rotation * 180 / M_PI,
        1000.0 * static_cast<double>(scans.size() - 1) / std::max(ms, 1e-9));
  }
  progress.finish();
  return md;
}

}  // namespace

Registration2DOptions benchmark2d_method(const std::string& name) {
  if (name != kSparseIcpPaper && name != kPlIcpFitted) check_registration_2d_method(name);
  Registration2DOptions o;
  o.method = name;
  if (name == kSparseIcpPaper) {
    o.method = "sparse-icp";
    o.coarse_translation = true;
    o.histogram_min_segment = 0.0;
    o.subsample_projection = false;
    o.sparse_step = "svd";
    o.path_rules = PathRules{};
    o.sparse_keep_fraction = 1.0;
    o.sparse_min_pairs = 0.0;
  } else if (name == kPlIcpFitted) {
    o.method = "pl-icp";
    o.pl_line_radius = o.sparse_line_radius;
  }
  return o;
}

std::string run_benchmark2d(Benchmark2DOptions o,
                            const std::function<void(const std::string&)>& on_table) {
  if (o.methods.empty()) {
    o.methods = registration_2d_method_names();
    o.methods.insert(o.methods.begin() + 1, kSparseIcpPaper);
    o.methods.push_back(kPlIcpFitted);
  }
  for (const auto& m : o.methods) benchmark2d_method(m);
  std::string md;
  const auto done = [&](const std::string& table) {
    md += table;
    if (on_table) on_table(table);
  };
  if (o.pairs > 0)
    done(pair_table(simulated_pairs(o.pairs, o.max_translation, o.max_rotation_deg * M_PI / 180),
                    o) +
         "\n");
  for (const std::string& log : o.logs) done(log_table(log, o) + "\n");
  if (!o.out.empty()) {
    std::filesystem::create_directories(o.out);
    write_file_atomic((std::filesystem::path(o.out) / "planar_tables.md").string(), md);
  }
  return md;
}

}  // namespace scanmatch
