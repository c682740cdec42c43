// Point times from azimuth (odometry/spin_times.hpp): the convention on known points, the
// simulator's true times recovered from its hdl64 frames, and odometry on re-timed frames.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "scanmatch/core/error.hpp"
#include "scanmatch/odometry/odometry_config.hpp"
#include "scanmatch/odometry/spin_times.hpp"
#include "scanmatch/run/odometry_run.hpp"
#include "scanmatch/sim/open_sequence.hpp"
#include "scanmatch/sim/simulator.hpp"
#include "test_helpers.hpp"
#include "untimed_sequence.hpp"

using namespace scanmatch;
using scanmatch::testing::sanitized;
using scanmatch::testing::TempDir;

namespace {

// The simulator's spinning sensors (sim/sensor.cpp) start their sweep along +x and turn
// counter-clockwise: azimuth grows with time.
SpinTiming simulator_timing(const sim::Simulator& s) {
  return SpinTiming{s.sensor().frame_period(), 0.0, false};
}

sim::SimOptions urban_hdl64(std::size_t frames) {
  sim::SimOptions o;
  o.preset = "urban-hdl64";
  o.frames = frames;
  return o;
}

// The share of points whose time is within `tolerance` s of `truth`'s.
double share_within(const PointCloud& truth, const PointCloud& derived, double tolerance) {
  std::size_t close = 0;
  for (std::size_t i = 0; i < truth.size(); ++i)
    close += std::abs(derived.time[i] - truth.time[i]) <= tolerance;
  return static_cast<double>(close) / static_cast<double>(truth.size());
}

std::unique_ptr<SequenceSource> simulated(std::size_t frames, bool timed) {
  SequenceOptions input;
  input.simulator = urban_hdl64(frames);
  auto source = open_sequence("sim:urban-hdl64", input);
  if (timed) return source;
  return std::make_unique<scanmatch::testing::UntimedSequence>(std::move(source));
}

RunSummary run(SequenceSource& source, const OdometryConfig& config) {
  RunOptions options;
  options.quiet = true;  // no out_dir: nothing written
  return run_odometry(source, config, options);
}

}  // namespace

TEST(SpinTimes, FollowTheSweepFromItsStartAzimuthInItsDirection) {
  PointCloud cloud;
  cloud.points = {Point(-5, 0.001f, 0), Point(0, 5, 1),
                  Point(5, 0, -1),      Point(0, -5, 0),
                  Point(0, 0, 3),       Point(std::numeric_limits<float>::quiet_NaN(), 1, 0)};
  // KITTI's HDL-64E: from behind (azimuth pi), clockwise: left, ahead, right, then behind again.
  assign_azimuth_times(cloud, SpinTiming{0.1, M_PI, true});
  ASSERT_EQ(cloud.time.size(), cloud.size());
  EXPECT_NEAR(cloud.time[0], 0.0, 1e-4);
  EXPECT_NEAR(cloud.time[1], 0.025, 1e-6);
  EXPECT_NEAR(cloud.time[2], 0.05, 1e-6);
  EXPECT_NEAR(cloud.time[3], 0.075, 1e-6);
  EXPECT_TRUE(std::isnan(cloud.time[4]));  // on the axis: no azimuth
  EXPECT_TRUE(std::isnan(cloud.time[5]));
  // Counter-clockwise from ahead: left is a quarter turn in, right three quarters; the old times
  // are replaced.
  assign_azimuth_times(cloud, SpinTiming{0.2, 0.0, false});
  EXPECT_NEAR(cloud.time[0], 0.1, 1e-4);
  EXPECT_NEAR(cloud.time[1], 0.05, 1e-6);
  EXPECT_NEAR(cloud.time[2], 0.0, 1e-6);
  EXPECT_NEAR(cloud.time[3], 0.15, 1e-6);
  // A period that is no period gives no times.
  assign_azimuth_times(cloud, SpinTiming{0.0, 0.0, false});
  EXPECT_FALSE(cloud.has_time());
}

TEST(SpinTimes, RecoverTheSimulatorsTrueTimesOfAnHdl64Frame) {
  const sim::Simulator s(urban_hdl64(4));
  const PointCloud truth = s.frame(3);
  ASSERT_TRUE(truth.has_time());
  PointCloud derived = truth;
  assign_azimuth_times(derived, simulator_timing(s));
  ASSERT_EQ(derived.time.size(), truth.size());
  // One azimuth step of the simulated HDL-64E is 0.05 ms; a point's azimuth moves only with its
  // range noise along the ray.
  EXPECT_GT(share_within(truth, derived, 0.001), 0.99);
  // The wrong direction is right only ahead and behind.
  SpinTiming reversed = simulator_timing(s);
  reversed.clockwise = true;
  assign_azimuth_times(derived, reversed);
  EXPECT_LT(share_within(truth, derived, 0.001), 0.05);
}

TEST(SpinTimes, OdometryOnRetimedFramesIsAsGoodAsOnTimedOnes) {
  // urban-hdl64 drives at 8 m/s: each frame is smeared by 0.8 m. 15 frames (2026-11-27): ATE
  // 0.264 m untimed, 0.0246 m re-timed, 0.0246 m with the true times.
  const std::size_t frames = sanitized() ? 8 : 15;
  OdometryConfig untimed_config, retimed_config;
  retimed_config.spin_times = true;
  retimed_config.spin_start_azimuth = 0.0;  // the simulator's convention
  retimed_config.spin_clockwise = false;
  auto untimed_source = simulated(frames, false), retimed_source = simulated(frames, false),
       timed_source = simulated(frames, true);
  const RunSummary untimed = run(*untimed_source, untimed_config),
                   retimed = run(*retimed_source, retimed_config),
                   timed = run(*timed_source, untimed_config);
  ASSERT_TRUE(untimed.ate && retimed.ate && timed.ate);
  EXPECT_LT(retimed.ate->rmse, 0.5 * untimed.ate->rmse);
  EXPECT_LT(retimed.ate->rmse, 1.5 * timed.ate->rmse + 0.01);
}

TEST(SpinTimes, FramesThatCarryTimesKeepThem) {
  // A convention the simulator does not follow would change every pose if it were applied.
  const std::size_t frames = sanitized() ? 5 : 8;
  OdometryConfig plain, spin;
  spin.spin_times = true;
  auto a = simulated(frames, true), b = simulated(frames, true);
  const RunSummary with = run(*a, spin), without = run(*b, plain);
  ASSERT_EQ(with.poses.size(), without.poses.size());
  for (std::size_t i = 0; i < with.poses.size(); ++i)
    EXPECT_TRUE(with.poses[i].isApprox(without.poses[i], 1e-12)) << "frame " << i;
}

TEST(SpinTimes, ASweepWithoutAPeriodIsRejectedByName) {
  OdometryConfig c;
  c.spin_period = 0.0;
  EXPECT_NE(scanmatch::testing::error_of([&] { check_odometry_config(c); }).find("spin_period"),
            std::string::npos);
  c = OdometryConfig{};
  c.spin_start_azimuth = std::numeric_limits<double>::infinity();
  EXPECT_NE(
      scanmatch::testing::error_of([&] { check_odometry_config(c); }).find("spin_start_azimuth"),
      std::string::npos);
}
