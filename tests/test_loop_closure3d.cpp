// 3D loop closure (mapping/loop_closure3d.hpp): on a simulated loop around the campus block it
// must reduce the error against the simulator's truth, verification must reject a wrong candidate,
// a street of identical buildings must not produce a wrong edge, bad input must be rejected, and
// `odometry --loop-closure` must write its files.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "scanmatch/eval/metrics.hpp"
#include "scanmatch/geometry/voxel_filter.hpp"
#include "scanmatch/mapping/loop_closure3d.hpp"
#include "scanmatch/sim/simulator.hpp"
#include "test_helpers.hpp"

namespace scanmatch {
namespace {

// The frames of a simulated preset without motion distortion (as deskewed odometry gives them),
// downsampled as the odometry would, every `step`-th frame.
struct SimulatedFrames {
  std::vector<PointCloud> clouds;
  std::vector<Pose> truth;
};

SimulatedFrames simulate(sim::SimOptions options, std::size_t step) {
  options.motion_distortion = false;
  const sim::Simulator simulator(options);
  SimulatedFrames out;
  for (std::size_t i = 0; i < simulator.size(); i += step) {
    out.clouds.push_back(voxel_downsample(simulator.frame(i), 0.25));
    out.truth.push_back(simulator.pose(i));
  }
  return out;
}

// An odometry that drifts in a known way: each true step 0.2 % too long (a loop cannot show a scale
// error: the scaled loop closes too), turned by a small yaw and pitch bias per metre.
std::vector<Pose> drifting_odometry(const std::vector<Pose>& truth, double yaw_per_m,
                                    double pitch_per_m) {
  std::vector<Pose> odometry = {Pose::Identity()};
  for (std::size_t i = 1; i < truth.size(); ++i) {
    Pose step = truth[i - 1].inverse() * truth[i];
    const double length = step.translation().norm();
    step.translation() *= 1.002;
    odometry.push_back(odometry.back() * step *
                       from_xyz_rpy(0, 0, 0, 0, pitch_per_m * length, yaw_per_m * length));
  }
  return odometry;
}

// Every accepted loop's relative pose against the truth's.
void expect_loops_agree_with_truth(const LoopClosure3D& loops, const std::vector<Pose>& truth,
                                   double max_translation, double max_angle) {
  for (const Loop3D& l : loops.loops()) {
    if (l.outlier) continue;
    const Pose expected = truth[l.from_frame].inverse() * truth[l.to_frame];
    const Pose error = expected.inverse() * l.relative;
    EXPECT_LT(error.translation().norm(), max_translation) << l.from_frame << " -> " << l.to_frame;
    EXPECT_LT(rotation_angle(error), max_angle) << l.from_frame << " -> " << l.to_frame;
  }
}

TEST(LoopClosure3D, ClosesTheCampusLoop) {
  // dynamic-outdoor-fast drives 0.44 m per frame; 1000 frames go once around the campus block
  // (~390 m) and 50 m on. Every second frame is fed, with a drifting odometry.
  sim::SimOptions options;
  options.preset = "dynamic-outdoor-fast";
  options.frames = scanmatch::testing::sanitized() ? 400 : 1000;
  const SimulatedFrames frames = simulate(options, 2);
  const std::vector<Pose> odometry =
      drifting_odometry(frames.truth, 0.01 * M_PI / 180, 0.001 * M_PI / 180);
  LoopClosure3D loops;
  for (std::size_t i = 0; i < frames.clouds.size(); ++i)
    loops.add_frame(frames.clouds[i], odometry[i]);
  loops.finish();
  const std::vector<Pose> optimized = loops.poses();
  ASSERT_EQ(optimized.size(), odometry.size());
  const AteResult before = compute_ate(frames.truth, odometry);
  const AteResult after = compute_ate(frames.truth, optimized);
  const LoopClosure3DCounts& c = loops.counts();
  std::printf(
      "campus loop, %zu frames: ATE odometry %.3f m, loop-closed %.3f m; %zu keyframes, %zu "
      "candidates, %zu verified, %zu rejected by verification, %zu by the estimate, %zu outliers, "
      "%.2f ms per frame\n",
      optimized.size(), before.rmse, after.rmse, c.keyframes, c.candidates, c.verified,
      c.rejected_by_verification, c.rejected_by_estimate, c.outliers,
      c.total_ms / static_cast<double>(optimized.size()));
  if (scanmatch::testing::sanitized()) return;
  EXPECT_GT(before.rmse, 1.0);
  EXPECT_GT(c.verified, 0u);
  EXPECT_LT(after.rmse, before.rmse / 3.0);
  expect_loops_agree_with_truth(loops, frames.truth, 0.3, 2.0 * M_PI / 180);
}

TEST(LoopClosure3D, VerificationRejectsAWrongCandidate) {
  sim::SimOptions options;
  options.preset = "dynamic-outdoor-fast";
  options.frames = 200;
  const SimulatedFrames frames = simulate(options, 1);
  const LoopVerification3DOptions verification;
  // A frame against itself from a guess 1 m and 10 deg off: the same place.
  const PointCloud& here = frames.clouds[20];
  const LoopVerification3D same =
      verify_loop_3d(here, here, from_xyz_rpy(1.0, -0.5, 0.1, 0, 0, 0.17), verification);
  EXPECT_TRUE(same.accepted) << same.overlap << " " << same.error << " " << same.constraint;
  EXPECT_LT(same.transform.translation().norm(), 0.05);
  // Frames 50 m apart on the same street: the descriptor's best yaw and the identity both start
  // from the wrong place, and nothing may verify.
  const PointCloud& there = frames.clouds[140];
  const PlaceMatch match = compare(make_place_descriptor(there), make_place_descriptor(here));
  for (const Pose& guess : {Pose(Pose::Identity()), from_xyz_rpy(0, 0, 0, 0, 0, match.yaw)}) {
    const LoopVerification3D v = verify_loop_3d(there, here, guess, verification);
    EXPECT_FALSE(v.accepted) << v.overlap << " " << v.error << " " << v.constraint;
  }
}

TEST(LoopClosure3D, BadInputIsRejectedNotFatal) {
  sim::SimOptions options;
  options.preset = "dynamic-outdoor-fast";
  options.frames = 3;
  const SimulatedFrames frames = simulate(options, 1);
  const LoopVerification3DOptions verification;
  PointCloud broken = frames.clouds[0];
  broken.points[5].x() = std::nanf("");
  EXPECT_FALSE(
      verify_loop_3d(PointCloud{}, frames.clouds[0], Pose::Identity(), verification).accepted);
  EXPECT_FALSE(verify_loop_3d(broken, frames.clouds[0], Pose::Identity(), verification).accepted);
  Pose not_finite = Pose::Identity();
  not_finite.translation().x() = std::nan("");
  EXPECT_FALSE(
      verify_loop_3d(frames.clouds[0], frames.clouds[0], not_finite, verification).accepted);
  // The sequence: empty frames, NaN points, far-away points and a NaN pose all go in.
  LoopClosure3D loops;
  PointCloud far = frames.clouds[1];
  far.points[0] = Point(1e12f, 0.0f, 0.0f);
  EXPECT_TRUE(loops.add_frame(PointCloud{}, Pose::Identity()));
  loops.add_frame(broken, from_xyz_rpy(0.5, 0, 0, 0, 0, 0));
  loops.add_frame(far, from_xyz_rpy(1.0, 0, 0, 0, 0, 0));
  loops.add_frame(frames.clouds[2], not_finite);
  loops.finish();
  ASSERT_EQ(loops.frames(), 4u);
  for (const Pose& p : loops.poses()) EXPECT_TRUE(p.matrix().allFinite());
  EXPECT_THROW(LoopClosure3D([] {
                 LoopClosure3DOptions o;
                 o.verification.fine_method = "no-such-method";
                 return o;
               }()),
               Error);
  EXPECT_THROW(LoopClosure3D([] {
                 LoopClosure3DOptions o;
                 o.submap_voxel = 0.0;
                 return o;
               }()),
               Error);
}

}  // namespace
}  // namespace scanmatch
