// Global registration: FPFH, the consistency clique and `register --global` with no initial
// guess, from any yaw and a 10 m offset, on simulated and real pairs; and a clear failure where
// there is nothing to match.

#include <gtest/gtest.h>

#include <fmt/format.h>

#include <fstream>
#include <random>
#include <sstream>

#include "scanmatch/core/error.hpp"
#include "scanmatch/core/stopwatch.hpp"
#include "scanmatch/features/fpfh.hpp"
#include "scanmatch/geometry/voxel_filter.hpp"
#include "scanmatch/io/cloud_io.hpp"
#include "scanmatch/registration/global_registration.hpp"
#include "scanmatch/sim/simulator.hpp"
#include "test_helpers.hpp"

namespace scanmatch {
namespace {

struct CloudPair {
  PointCloud source, target;
  Pose truth;  ///< T_target_source
};

PointCloud transformed(const PointCloud& cloud, const Pose& T) {
  PointCloud out = cloud;
  for (Point& p : out.points) p = (T * p.cast<double>()).cast<float>();
  return out;
}

// The source seen from a frame `yaw_deg` and 10 m away from its own: the truth becomes
// truth * P^-1, and the source's sensor sits at P's translation.
struct Perturbed {
  CloudPair pair;
  Eigen::Vector3d source_viewpoint;
};
Perturbed perturb(const CloudPair& pair, double yaw_deg, double direction_deg) {
  const double d = direction_deg * M_PI / 180;
  const Pose P = from_xyz_rpy(10 * std::cos(d), 10 * std::sin(d), 0, 0, 0, yaw_deg * M_PI / 180);
  return {{transformed(pair.source, P), pair.target, pair.truth * P.inverse()}, P.translation()};
}

void expect_recovered(const Perturbed& p, const std::string& label, double metres = 0.05,
                      double degrees = 0.5) {
  GlobalRegistrationOptions o;
  o.source_viewpoint = p.source_viewpoint;
  const Stopwatch time;
  const GlobalRegistrationResult r = register_global(p.pair.source, p.pair.target, o);
  const Pose error = p.pair.truth.inverse() * r.transform;
  const Pose coarse = p.pair.truth.inverse() * r.coarse_transform;
  const std::string report =
      fmt::format("{}: {:.3f} m {:.3f} deg (coarse {:.3f} m {:.2f} deg), {:.0f} ms; {}", label,
                  error.translation().norm(), rotation_angle(error) * kDegreesPerRadian,
                  coarse.translation().norm(), rotation_angle(coarse) * kDegreesPerRadian,
                  time.ms(), r.summary()) +
      (r.success ? "" : "; failed: " + r.failure);
  std::cout << report << "\n";
  ASSERT_TRUE(r.success) << report;
  EXPECT_LT(error.translation().norm(), metres) << report;
  EXPECT_LT(rotation_angle(error) * kDegreesPerRadian, degrees) << report;
  EXPECT_GE(r.inliers, o.min_inliers);
  EXPECT_LE(r.ambiguity, o.max_ambiguity);
}

Pose read_matrix(std::istream& in) {
  Eigen::Matrix4d M;
  for (int i = 0; i < 16; ++i) in >> M(i / 4, i % 4);
  return from_matrix(M);
}

// car_cloud401 onto car_cloud400: carCloudList.csv's row of 401 (400's row is the identity).
std::optional<Pose> car_reference(const std::string& folder) {
  std::ifstream in(folder + "/carCloudList.csv");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("car_cloud401.csv", 0) != 0) continue;
    std::string values = line.substr(line.find(',') + 1);
    for (char& c : values)
      if (c == ',') c = ' ';
    std::istringstream row(values);
    return read_matrix(row);
  }
  return std::nullopt;
}

TEST(Fpfh, PairAnglesAreTheSameFromEitherEnd) {
  const Eigen::Vector3d p(0, 0, 0), q(1, 0.5, 0.2);
  const Eigen::Vector3d n = Eigen::Vector3d(0.1, 0.2, 1).normalized();
  const Eigen::Vector3d m = Eigen::Vector3d(0.5, -0.3, 1).normalized();
  Eigen::Vector3d a, b;
  ASSERT_TRUE(fpfh_pair_angles(p, n, q, m, a));
  ASSERT_TRUE(fpfh_pair_angles(q, m, p, n, b));
  EXPECT_LT((a - b).norm(), 1e-12);
  EXPECT_FALSE(fpfh_pair_angles(p, n, p, m, a));
  // Parallel normals perpendicular to the line: alpha 0, phi 0, theta 0.
  ASSERT_TRUE(fpfh_pair_angles(p, Eigen::Vector3d::UnitZ(), Eigen::Vector3d(1, 0, 0),
                               Eigen::Vector3d::UnitZ(), a));
  EXPECT_LT(a.norm(), 1e-12);
}

TEST(Fpfh, DescriptorsDoNotChangeWithARigidMotionOfCloudAndViewpoint) {
  sim::SimOptions so;
  so.preset = "campus-os1";
  so.frames = 1;
  const PointCloud cloud = voxel_downsample(sim::Simulator(so).frame(0), 0.5);
  const Pose T = from_xyz_rpy(3, -7, 0.5, 0.1, -0.05, 2.0);
  const PointCloud moved = transformed(cloud, T);
  std::vector<std::size_t> keypoints;
  for (std::size_t i = 0; i < cloud.size(); i += 50) keypoints.push_back(i);
  FpfhOptions o;
  const KdTree tree(cloud.points), moved_tree(moved.points);
  const auto a = compute_fpfh(
      cloud, tree, oriented_normals(cloud, tree, 12, Eigen::Vector3d::Zero()), keypoints, o);
  const auto b = compute_fpfh(
      moved, moved_tree, oriented_normals(moved, moved_tree, 12, T.translation()), keypoints, o);
  ASSERT_EQ(a.size(), keypoints.size());
  std::size_t described = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    // Bins can flip where an angle sits on a bin edge (float rounding): allow a little.
    EXPECT_LT((a[k] - b[k]).norm(), 0.05f * std::max(a[k].norm(), 1.0f)) << k;
    if (!a[k].isZero()) {
      ++described;
      for (int t = 0; t < 3; ++t) EXPECT_NEAR(a[k].segment<11>(11 * t).sum(), 100.0f, 1e-3f);
    }
  }
  EXPECT_GT(described, keypoints.size() / 2);
}

// campus-os1 frames 45 onto 40: 0.5 s (3 m) apart, so the two clouds sample the scene differently.
CloudPair campus_pair() {
  sim::SimOptions so;
  so.preset = "campus-os1";
  so.frames = 46;
  so.motion_distortion = false;
  const sim::Simulator s(so);
  return {s.frame(45), s.frame(40), s.pose(40).inverse() * s.pose(45)};
}

TEST(GlobalRegistration, SimulatedCarFramesFromRandomYawsAndTenMetres) {
  const CloudPair pair = campus_pair();
  std::mt19937 rng(43);
  std::uniform_real_distribution<double> yaw(-180.0, 180.0), direction(-180.0, 180.0);
  const int trials = scanmatch::testing::sanitized() ? 1 : 3;
  for (int k = 0; k < trials; ++k) {
    const double y = yaw(rng), d = direction(rng);
    expect_recovered(perturb(pair, y, d), fmt::format("campus-os1 yaw {:.1f} deg", y));
  }
}

TEST(GlobalRegistration, RealPairsFromFourYawsAndTenMetres) {
  const std::string hdl = scanmatch::testing::shared_data("data/3d/hdl32_pair");
  const std::string car = scanmatch::testing::shared_data("data/3d/car_pair");
  if (hdl.empty() || car.empty()) GTEST_SKIP() << "../shared/data/3d/{hdl32,car}_pair not present";
  std::ifstream reference(hdl + "/T_target_source.txt");
  const std::optional<Pose> car_truth = car_reference(car);
  ASSERT_TRUE(car_truth) << "no car_cloud401.csv row in carCloudList.csv";
  const std::vector<std::pair<std::string, CloudPair>> pairs = {
      {"hdl32_pair",
       {read_cloud(hdl + "/source.ply"), read_cloud(hdl + "/target.ply"), read_matrix(reference)}},
      {"car_pair",
       {read_cloud(car + "/car_cloud401.csv"), read_cloud(car + "/car_cloud400.csv"), *car_truth}}};
  // (yaw, direction of the 10 m offset) in degrees.
  std::vector<std::pair<double, double>> moves = {{0, 17}, {90, 200}, {180, 301}, {-135, 73}};
  if (scanmatch::testing::sanitized()) moves.resize(1);
  for (const auto& [name, pair] : pairs)
    for (const auto& [yaw, direction] : moves)
      expect_recovered(perturb(pair, yaw, direction), fmt::format("{} yaw {:.0f} deg", name, yaw));

  // Through the CLI, from a file: the viewpoint is unknown there (the origin is assumed), which
  // turns some normals the wrong way; still found.
  scanmatch::testing::TempDir dir;
  const Perturbed moved = perturb(pairs[0].second, -135, 73);
  write_cloud(dir.file("moved.pcd"), moved.pair.source);
  const auto run = scanmatch::testing::run_cli("register " + dir.file("moved.pcd") + " " + hdl +
                                               "/target.ply --global");
  ASSERT_EQ(run.status, 0) << run.output;
  std::istringstream rows(run.output);
  const Pose error = moved.pair.truth.inverse() * read_matrix(rows);
  EXPECT_LT(error.translation().norm(), 0.05) << run.output;
  EXPECT_LT(rotation_angle(error) * kDegreesPerRadian, 0.5) << run.output;
}

// A flat, featureless floor (any motion in its plane fits it) and random noise: nothing to
// register; both must fail and say why, never return a transform as if it were found.
TEST(GlobalRegistration, FailsAndSaysSoOnAPlaneOrOnNoise) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-20.0f, 20.0f), n(-0.01f, 0.01f);
  PointCloud floor_a, floor_b, noise;
  for (int i = 0; i < 20000; ++i) {
    floor_a.points.emplace_back(u(rng), u(rng), -1.5f + n(rng));
    floor_b.points.emplace_back(u(rng), u(rng), -1.5f + n(rng));
    noise.points.emplace_back(u(rng), u(rng), u(rng) / 4);
  }
  sim::SimOptions so;
  so.preset = "campus-os1";
  so.frames = 1;
  const PointCloud scan = sim::Simulator(so).frame(0);
  using Case = std::tuple<const char*, const PointCloud*, const PointCloud*>;
  for (const auto& [label, source, target] :
       {Case{"floor onto floor", &floor_a, &floor_b}, Case{"scan onto noise", &scan, &noise},
        Case{"noise onto scan", &noise, &scan}}) {
    const GlobalRegistrationResult r = register_global(*source, *target);
    std::cout << label << ": " << r.failure << "; " << r.summary() << "\n";
    EXPECT_FALSE(r.success) << label << ": " << r.summary();
    EXPECT_FALSE(r.failure.empty()) << label;
    EXPECT_FALSE(r.accepted().has_value()) << label;
  }
  EXPECT_THROW(register_global(PointCloud{}, scan), Error);
  GlobalRegistrationOptions bad;
  bad.noise_bound = 0.0;
  EXPECT_THROW(register_global(scan, scan, bad), Error);
}

// The target holds the same place twice (two copies 300 m apart, each with its own 2 cm noise, and
// the target's viewpoint, the origin, halfway between them): two motions fit equally well, so
// the answer must be "ambiguous", not one of them.
TEST(GlobalRegistration, RefusesWhenTwoPlacesFitEqually) {
  const CloudPair pair = campus_pair();
  const PointCloud &source = pair.source, &place = pair.target;
  PointCloud target;
  std::mt19937 rng(5);
  std::normal_distribution<float> jitter(0.0f, 0.02f);
  for (const float shift : {-150.0f, 150.0f})
    for (const Point& p : place.points)
      target.points.push_back(p + Point(shift + jitter(rng), jitter(rng), jitter(rng)));
  const GlobalRegistrationResult r = register_global(source, target);
  std::cout << r.failure << "; " << r.summary() << "\n";
  EXPECT_FALSE(r.success) << r.summary();
  EXPECT_GT(r.ambiguity, GlobalRegistrationOptions{}.max_ambiguity) << r.summary();
  EXPECT_NE(r.failure.find("ambiguous"), std::string::npos) << r.failure;
}

TEST(Cli, RegisterGlobalPrintsEvidenceAndFailsClearly) {
  scanmatch::testing::TempDir dir;
  sim::SimOptions so;
  so.preset = "campus-os1";
  so.frames = 41;
  so.motion_distortion = false;
  const sim::Simulator s(so);
  const Pose truth = s.pose(37).inverse() * s.pose(40);
  write_cloud(dir.file("s.pcd"), s.frame(40));
  write_cloud(dir.file("t.pcd"), s.frame(37));
  const auto ok = scanmatch::testing::run_cli("register " + dir.file("s.pcd") + " " +
                                              dir.file("t.pcd") + " --global --json");
  ASSERT_EQ(ok.status, 0) << ok.output;
  for (const char* key : {"\"transform\"", "\"inliers\"", "\"inlier_ratio\"", "\"ambiguity\"",
                          "\"overlap\"", "\"fitness\""})
    EXPECT_NE(ok.output.find(key), std::string::npos) << key << " in " << ok.output;
  const auto text = scanmatch::testing::run_cli("register " + dir.file("s.pcd") + " " +
                                                dir.file("t.pcd") + " --global");
  ASSERT_EQ(text.status, 0) << text.output;
  std::istringstream rows(text.output);
  const Pose error = truth.inverse() * read_matrix(rows);
  EXPECT_LT(error.translation().norm(), 0.05) << text.output;
  EXPECT_LT(rotation_angle(error) * kDegreesPerRadian, 0.5) << text.output;
  EXPECT_NE(text.output.find("inliers of"), std::string::npos) << text.output;

  PointCloud noise;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-20.0f, 20.0f);
  for (int i = 0; i < 20000; ++i) noise.points.emplace_back(u(rng), u(rng), u(rng) / 4);
  write_cloud(dir.file("noise.pcd"), noise);
  const auto no = scanmatch::testing::run_cli("register " + dir.file("s.pcd") + " " +
                                              dir.file("noise.pcd") + " --global");
  EXPECT_NE(no.status, 0) << no.output;
  EXPECT_NE(no.output.find("cannot register"), std::string::npos) << no.output;
  EXPECT_NE(scanmatch::testing::run_cli("register " + dir.file("s.pcd") + " " + dir.file("t.pcd") +
                                        " --global --init 0,0,0,0,0,0")
                .status,
            0);
}

}  // namespace
}  // namespace scanmatch
