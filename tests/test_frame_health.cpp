// The health record of each frame (FrameStats: prior trust, prior miss, fine-stage pairing,
// coarse/fine agreement) against what the simulator's truth and a real recording say.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <vector>

#include "scanmatch/eval/metrics.hpp"
#include "scanmatch/io/sequence.hpp"
#include "scanmatch/io/trajectory.hpp"
#include "scanmatch/odometry/odometry.hpp"
#include "scanmatch/sim/keyframes.hpp"
#include "scanmatch/sim/simulator.hpp"
#include "test_helpers.hpp"

using namespace scanmatch;
using scanmatch::testing::TimedClouds;

namespace {

using scanmatch::testing::median;

}  // namespace

TEST(FrameHealth, ARegularDriveTrustsItsPriorAndPairsMostPointsWithTheMap) {
  sim::SimOptions o;
  o.preset = "dynamic-outdoor-fast";
  o.frames = 30;
  const sim::Simulator sim(o);
  Odometry odometry(OdometryConfig{});
  std::vector<double> paired, disagreement_m;
  for (std::size_t i = 0; i < sim.size(); ++i) {
    odometry.register_frame(sim.frame(i), sim.frame_time(i));
    const FrameStats& s = odometry.last_stats();
    EXPECT_FALSE(s.bridged) << i;
    if (i == 1) {
      EXPECT_TRUE(s.prior_uncertain);  // no motion measured yet
    }
    if (i < 5) continue;
    EXPECT_FALSE(s.prior_uncertain) << i;
    // Constant velocity on a smooth drive: the estimate stays within centimetres of the prior.
    EXPECT_LT(s.prior_miss_m, 0.1) << i;
    paired.push_back(s.fine_paired_fraction);
    disagreement_m.push_back(s.coarse_fine_m);
  }
  EXPECT_GT(median(paired), 0.6);
  EXPECT_LT(median(disagreement_m), 0.05);
}

namespace {

// The fine stage's paired fraction on the first 20 frames of avia_hku1 (frame 0 builds the map).
std::vector<double> avia_paired_fractions(const std::string& folder, const OdometryConfig& c) {
  auto source = open_sequence_folder(folder);
  Odometry odometry(c);
  Frame frame;
  std::vector<double> paired;
  while (paired.size() < 20 && source->next(frame)) {
    odometry.register_frame(frame.cloud, frame.timestamp);
    if (frame.index > 0) paired.push_back(odometry.last_stats().fine_paired_fraction);
  }
  return paired;
}

}  // namespace

TEST(FrameHealth, RealAviaKeyframesShowAThinMapWhichDenseMapPointsThicken) {
  const std::string folder = scanmatch::testing::shared_data("data/3d/avia_hku1/frames");
  if (folder.empty()) GTEST_SKIP() << "../shared/data/3d/avia_hku1 not present";
  // 3-5k points a frame, turning about 9 degrees a keyframe: most points find no map plane yet
  // (docs/odometry.md, "Recorded Avia keyframes"); the record must say so.
  const std::vector<double> plain = avia_paired_fractions(folder, OdometryConfig{});
  EXPECT_LT(median(plain), 0.6);
  EXPECT_GT(median(plain), 0.0);
  // The map fed with the frame at a quarter of the voxel: one keyframe makes usable voxels.
  // Frame 1 is refined against frame 0 at that density either way (0.24 paired; 0.04 against
  // frame 0's own map); from frame 2 on the plain map is the thinner: 0.22 against 0.35.
  OdometryConfig dense;
  dense.dense_sparse_map = true;
  const std::vector<double> thick = avia_paired_fractions(folder, dense);
  EXPECT_GT(plain[0], 0.15);
  EXPECT_NEAR(thick[0], plain[0], 1e-9);
  EXPECT_LT(plain[1], 0.3);
  EXPECT_GT(thick[1], 1.4 * plain[1]);
  EXPECT_GT(median(thick), median(plain));
}

namespace {

struct Tracked {
  AteResult ate;
  std::size_t recoveries = 0;
};

// Every frame of `simulator`, thinned like a keyframe folder when `thin` is given.
TimedClouds frames_of(const sim::Simulator& simulator, const sim::KeyframeOptions* thin = nullptr) {
  TimedClouds f;
  for (std::size_t i = 0; i < simulator.size(); ++i) {
    f.clouds.push_back(thin ? sim::thin_keyframe(simulator.frame(i), *thin, i)
                            : simulator.frame(i));
    f.times.push_back(simulator.frame_time(i));
  }
  return f;
}

Tracked track(const TimedClouds& frames, const std::vector<Pose>& truth,
              const OdometryConfig& config) {
  Odometry odometry(config);
  Tracked t;
  std::vector<Pose> poses;
  for (std::size_t i = 0; i < frames.clouds.size(); ++i) {
    poses.push_back(odometry.register_frame(frames.clouds[i], frames.times[i]));
    t.recoveries += odometry.last_stats().recovered;
  }
  t.ate = compute_ate({truth.begin(), truth.begin() + static_cast<std::ptrdiff_t>(poses.size())},
                      poses);
  return t;
}

// The state before turned starts: a turning prior was trusted and no start turned it.
OdometryConfig without_turned_starts() {
  OdometryConfig c;
  c.rotation_starts = 0;
  c.uncertain_rotation = M_PI;
  return c;
}

}  // namespace

TEST(RecordedAvia, KeyframesAreTrackedBelowTwoPercentWithDefaults) {
  const std::string folder = scanmatch::testing::shared_data("data/3d/avia_hku1");
  if (folder.empty()) GTEST_SKIP() << "../shared/data/3d/avia_hku1 not present";
  if (scanmatch::testing::sanitized()) GTEST_SKIP() << "314 keyframes: too slow sanitized";
  // What a user types: the frames folder alone (no times: 0.1 s steps). FAST-LIO2's
  // LiDAR-inertial poses are the reference. Measured 0.24 % (5.28 % before the turned starts;
  // KISS-ICP 9.18 %).
  auto source = open_sequence_folder(folder + "/frames");
  TimedClouds frames;
  Frame frame;
  while (source->next(frame)) {
    frames.clouds.push_back(frame.cloud);
    frames.times.push_back(frame.timestamp);
  }
  const Trajectory reference = read_trajectory(folder + "/odom_poses.txt");
  ASSERT_EQ(reference.size(), frames.clouds.size());
  const Tracked tracked = track(frames, reference.poses, OdometryConfig{});
  EXPECT_LT(tracked.ate.rmse_percent_of_path, 2.0);
  EXPECT_GT(tracked.recoveries, 0u);  // the record says which frames another start rescued
}

TEST(RecordedAvia, ItsMotionReplayedInTheSimulatorFailsAlikeAndIsTrackedAfterTheFix) {
  const std::string poses = scanmatch::testing::shared_data("data/3d/avia_hku1/odom_poses.txt");
  if (poses.empty()) GTEST_SKIP() << "../shared/data/3d/avia_hku1 not present";
  if (scanmatch::testing::sanitized()) GTEST_SKIP() << "314 frames twice: too slow sanitized";
  // The recording's own motion (turns of 8-12 degrees between keyframes that move a few
  // centimetres, sweeps that reverse) through the simulated campus with an Avia, as keyframes
  // like FAST-LIO2's: the frames that fail are the recording's (13, 26-29, 90...).
  sim::SimOptions o;
  o.preset = "dynamic-outdoor";
  o.sensor = "avia";
  o.trajectory_file = poses;
  o.frames = 314;
  o.motion_distortion = false;
  const sim::Simulator simulator(o);
  sim::KeyframeOptions thin;
  thin.max_points = 5000;
  thin.point_time = false;
  const TimedClouds frames = frames_of(simulator, &thin);
  const std::vector<Pose>& truth = simulator.ground_truth().poses;
  const Tracked fixed = track(frames, truth, OdometryConfig{});
  const Tracked before = track(frames, truth, without_turned_starts());
  // Measured 3.0 % against 7.0 % (gicp 12.6 %); what is left are views of one wall.
  EXPECT_LT(fixed.ate.rmse_percent_of_path, 4.0);
  EXPECT_GT(before.ate.rmse_percent_of_path, 1.5 * fixed.ate.rmse_percent_of_path);
}

TEST(HandHeld, FastTurnsInTheOfficeAreTrackedWithTurnedStarts) {
  if (scanmatch::testing::sanitized()) GTEST_SKIP() << "200 hand-held frames: too slow sanitized";
  // The intro's named weakness: handheld-fast, 200 frames, 8.3 % ATE before (gicp 3.8 %).
  sim::SimOptions o;
  o.preset = "handheld-fast";
  o.frames = 200;
  const sim::Simulator simulator(o);
  const Tracked tracked =
      track(frames_of(simulator), simulator.ground_truth().poses, OdometryConfig{});
  EXPECT_LT(tracked.ate.rmse_percent_of_path, 3.0);  // measured 1.6 %
}
