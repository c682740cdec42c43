// The method table drives names, validation and minimum sizes; ctf-fine runs one code path.

#include <gtest/gtest.h>

#include <random>
#include <set>

#include "scanmatch/core/error.hpp"
#include "scanmatch/odometry/odometry.hpp"
#include "scanmatch/registration/factors/ctf_fine.hpp"
#include "scanmatch/registration/methods.hpp"
#include "test_helpers.hpp"

namespace scanmatch {
namespace {

// Three walls and a floor: every direction is constrained. Walls and floor do not touch, so no
// voxel holds two planes (a corner voxel's Gaussian is no plane and biases the voxel methods).
PointCloud room(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-4.0f, 4.0f), f(-3.0f, 3.0f), h(1.0f, 3.0f),
      n(-0.002f, 0.002f);
  PointCloud cloud;
  for (int i = 0; i < 1500; ++i) {
    cloud.points.emplace_back(f(rng), f(rng), n(rng));
    cloud.points.emplace_back(4.0f + n(rng), u(rng), h(rng));
    cloud.points.emplace_back(u(rng), 4.0f + n(rng), h(rng));
    cloud.points.emplace_back(-4.0f + n(rng), u(rng), h(rng));
  }
  return cloud;
}

TEST(RegistrationMethods, NamesAreUniqueAndEveryOneIsFoundByName) {
  std::set<std::string> seen;
  for (const auto& m : registration_methods()) {
    EXPECT_TRUE(seen.insert(m.name).second) << m.name;
    EXPECT_EQ(&find_registration_method(m.name), &m);
    EXPECT_TRUE(is_registration_method(m.name));
    EXPECT_GE(m.minimum_points(RegistrationOptions{}), 6u) << m.name;
  }
  EXPECT_EQ(registration_method_names().size(), registration_methods().size());
}

TEST(RegistrationMethods, AnUnknownNameListsEveryValidMethod) {
  EXPECT_FALSE(is_registration_method("sparse-icp"));
  try {
    find_registration_method("sparse-icp");
    FAIL() << "no error";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("'sparse-icp'"), std::string::npos) << message;
    for (const auto& name : registration_method_names())
      EXPECT_NE(message.find(name), std::string::npos) << name;
  }
  OdometryConfig config;
  config.method = "sparse-icp";
  try {
    Odometry odometry(config);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("valid: ctf-icp, icp"), std::string::npos) << e.what();
  }
}

TEST(RegistrationMethods, TooSmallCloudsAreRefusedWithTheMethodsMinimum) {
  RegistrationOptions options;
  options.method = "gicp";
  const PointCloud target = room(1);
  PointCloud tiny;
  tiny.points.assign(target.points.begin(), target.points.begin() + 5);
  try {
    register_clouds(tiny, target, options);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("needs at least " +
                                         std::to_string(minimum_points("gicp", options))),
              std::string::npos)
        << e.what();
  }
}

TEST(RegistrationMethods, EveryMethodRecoversASmallOffsetInARoom) {
  const PointCloud target = room(2);
  const Pose truth = from_xyz_rpy(0.04, -0.03, 0.02, 0.005, -0.004, 0.008);
  PointCloud source;
  for (const Point& q : target.points)
    source.points.push_back((truth.inverse() * q.cast<double>()).cast<float>());
  for (const auto& m : registration_methods()) {
    // LOAM needs rings (a spinning sensor); the room cloud has none.
    if (std::string(m.name).rfind("loam", 0) == 0) continue;
    RegistrationOptions options;
    options.method = m.name;
    options.voxel_resolution = 0.5;
    const RegistrationResult r = register_clouds(source, target, options);
    EXPECT_LT((r.transform.translation() - truth.translation()).norm(), 0.01) << m.name;
    EXPECT_LT(rotation_angle(r.transform.inverse() * truth), 0.002) << m.name;
  }
}

TEST(RegistrationMethods, CtfFineMethodIsTheOdometrysFineStage) {
  // `register --method ctf-fine` builds the target's map and runs register_ctf_fine: the same
  // result as calling it directly with the same settings.
  const PointCloud target = room(3);
  const Pose truth = from_xyz_rpy(0.05, 0.04, -0.02, 0.0, 0.01, -0.01);
  PointCloud source;
  for (const Point& q : target.points)
    source.points.push_back((truth.inverse() * q.cast<double>()).cast<float>());
  RegistrationOptions options;
  options.method = "ctf-fine";
  options.voxel_resolution = 0.5;
  const RegistrationResult via_table = register_clouds(source, target, options);

  GaussianVoxelMapOptions map_options;
  map_options.voxel_size = options.voxel_resolution;
  map_options.planar_epsilon = options.ctf_epsilon;
  GaussianVoxelMap map(map_options);
  map.insert(target);
  CtfFineOptions fine;
  fine.max_iterations = options.solver.max_iterations;
  fine.tolerance = options.solver.translation_tolerance;
  const RegistrationResult direct = register_ctf_fine(source, map, Pose::Identity(), fine);
  EXPECT_TRUE(via_table.transform.isApprox(direct.transform, 1e-12));
  EXPECT_EQ(via_table.iterations, direct.iterations);
  EXPECT_LT((direct.transform.translation() - truth.translation()).norm(), 0.01);
}

// Counts linearisations to show what final_linearization saves.
struct CountingFactor {
  const PointCloud& source;
  const PointCloud& target;
  int* calls;
  std::size_t size() const { return source.size(); }
  bool linearize(const Pose& T, std::size_t i, LinearSystem& system,
                 const RobustKernel& kernel) const {
    if (i == 0) ++*calls;
    const Eigen::Vector3d p = source.points[i].cast<double>();
    system.add<3>(point_jacobian(T, p), T * p - target.points[i].cast<double>(),
                  Eigen::Matrix3d::Identity(), kernel);
    return true;
  }
};

TEST(Solver, SkippingTheFinalLinearizationKeepsThePoseAndSavesOnePass) {
  const PointCloud target = room(4);
  const Pose truth = from_xyz_rpy(0.2, -0.1, 0.05, 0.05, 0.02, -0.03);
  PointCloud source;
  for (const Point& q : target.points)
    source.points.push_back((truth.inverse() * q.cast<double>()).cast<float>());
  int with = 0, without = 0;
  SolverOptions options;
  options.relative_cost_tolerance = 0.0;  // stop on the step size only, as the fine stage does
  const RegistrationResult a =
      optimize(CountingFactor{source, target, &with}, Pose::Identity(), options);
  options.final_linearization = false;
  const RegistrationResult b =
      optimize(CountingFactor{source, target, &without}, Pose::Identity(), options);
  ASSERT_TRUE(a.converged);
  ASSERT_TRUE(b.converged);
  EXPECT_TRUE(a.transform.isApprox(b.transform, 1e-15));
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(without, with - 1);
  EXPECT_TRUE(b.transform.isApprox(truth, 1e-6));
  // The iteration limit ends without the extra pass too.
  options.max_iterations = 1;
  int limited = 0;
  const RegistrationResult c =
      optimize(CountingFactor{source, target, &limited}, Pose::Identity(), options);
  EXPECT_FALSE(c.converged);
  EXPECT_EQ(limited, 1);
}

}  // namespace
}  // namespace scanmatch
