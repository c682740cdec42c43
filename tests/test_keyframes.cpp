// Sparse keyframes: the simulator's keyframe output (exact ground truth of the kept frames) and
// CTF-ICP with default options on keyframe sequences (a spinning 64-ring sensor every 5th frame,
// Livox Avia keyframes 0.75 m and 0.5-1 m apart with 4000 points and no point time), against the
// adaptive rules of scanmatch/odometry/motion_model.hpp and preprocessor.hpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "scanmatch/eval/metrics.hpp"
#include "scanmatch/geometry/kdtree.hpp"
#include "scanmatch/geometry/voxel_filter.hpp"
#include "scanmatch/io/cloud_io.hpp"
#include "scanmatch/io/trajectory.hpp"
#include "scanmatch/odometry/coarse_ndt.hpp"
#include "scanmatch/odometry/motion_model.hpp"
#include "scanmatch/odometry/odometry.hpp"
#include "scanmatch/odometry/preprocessor.hpp"
#include "scanmatch/sim/keyframes.hpp"
#include "test_helpers.hpp"

using namespace scanmatch;
using scanmatch::testing::run_cli;
using scanmatch::testing::sanitized;
using scanmatch::testing::TempDir;

namespace {

struct Keyframes {
  std::vector<PointCloud> frames;
  std::vector<double> times;
  std::vector<Pose> truth;
  std::vector<std::size_t> indices;
};

Keyframes simulate(sim::SimOptions options, const sim::KeyframeOptions& keyframes) {
  const sim::Simulator simulator(options);
  Keyframes k;
  k.indices = sim::select_keyframes(simulator, keyframes);
  for (std::size_t i : k.indices) {
    k.frames.push_back(sim::thin_keyframe(simulator.frame(i), keyframes, i));
    k.times.push_back(simulator.frame_time(i));
    k.truth.push_back(simulator.pose(i));
  }
  return k;
}

// Every `n`th of the first `frames` frames of `preset`, with point times.
Keyframes every_nth(const std::string& preset, std::size_t frames, std::size_t n) {
  sim::SimOptions o;
  o.preset = preset;
  o.frames = frames;
  sim::KeyframeOptions every;
  every.every = n;
  return simulate(o, every);
}

AteResult track(const Keyframes& k, const OdometryConfig& config = {}) {
  Odometry odometry(config);
  std::vector<Pose> poses;
  for (std::size_t i = 0; i < k.frames.size(); ++i)
    poses.push_back(odometry.register_frame(k.frames[i], k.times[i]));
  return compute_ate(k.truth, poses);
}

// The state before the adaptive rules: constant velocity over whatever step, one coarse start,
// the fixed gate, the fixed voxel, no global start.
OdometryConfig without_adaptive_rules() {
  OdometryConfig c;
  c.time_scaled_prior = false;
  c.uncertain_starts = false;
  c.wide_start_iterations = 0;
  c.uncertain_jump_scale = 1.0;
  c.min_downsampled_points = 0;
  c.redeskew_translation = c.redeskew_rotation = 0.0;
  c.global_start_below = 0.0;
  return c;
}

// Avia keyframes like a FAST-LIO keyframe folder: 4000 points, no point time, no distortion.
sim::SimOptions avia(const std::string& preset, std::size_t frames) {
  sim::SimOptions o;
  o.preset = preset;
  o.sensor = "avia";
  o.frames = frames;
  o.motion_distortion = false;
  return o;
}

sim::KeyframeOptions fast_lio_like(double distance, double distance_max) {
  sim::KeyframeOptions k;
  k.distance = distance;
  k.distance_max = distance_max;
  k.max_points = 4000;
  k.point_time = false;
  return k;
}

}  // namespace

TEST(SimulatorKeyframes, KeptFramesKeepTheirExactGroundTruthAndTimes) {
  sim::SimOptions o;
  o.preset = "dynamic-outdoor-fast";
  o.frames = 200;
  const sim::Simulator simulator(o);
  sim::KeyframeOptions every;
  every.every = 5;
  const std::vector<std::size_t> fifth = sim::select_keyframes(simulator, every);
  ASSERT_EQ(fifth.size(), 40u);
  for (std::size_t k = 0; k < fifth.size(); ++k) EXPECT_EQ(fifth[k], 5 * k);

  // Irregular distances: every step at least the minimum, the thresholds spread over the range.
  const sim::KeyframeOptions irregular = fast_lio_like(0.5, 1.0);
  const std::vector<std::size_t> kept = sim::select_keyframes(simulator, irregular);
  ASSERT_GT(kept.size(), 20u);
  EXPECT_EQ(kept.front(), 0u);
  double shortest = 1e9, longest = 0.0;
  for (std::size_t k = 1; k < kept.size(); ++k) {
    const double step =
        (simulator.pose(kept[k]).translation() - simulator.pose(kept[k - 1]).translation()).norm();
    // The frame before a kept one had not yet moved the threshold (<= 1 m).
    const double before =
        (simulator.pose(kept[k] - 1).translation() - simulator.pose(kept[k - 1]).translation())
            .norm();
    EXPECT_GE(step, 0.5);
    EXPECT_LT(before, 1.0);
    shortest = std::min(shortest, step);
    longest = std::max(longest, step);
  }
  EXPECT_GT(longest - shortest, 0.2);

  // Thinning: a subset of the frame's points, no time field, the same for the same seed.
  const PointCloud full = simulator.frame(10);
  const PointCloud thin = sim::thin_keyframe(full, irregular, 10);
  ASSERT_EQ(thin.size(), 4000u);
  EXPECT_FALSE(thin.has_time());
  EXPECT_TRUE(thin.has_intensity());
  EXPECT_EQ(sim::thin_keyframe(full, irregular, 10).points, thin.points);
  std::size_t found = 0;
  for (std::size_t i = 0, j = 0; i < thin.size() && j < full.size(); ++j)
    if (full.points[j] == thin.points[i]) ++found, ++i;
  EXPECT_EQ(found, thin.size());  // in the original order, each one of the frame's points
}

TEST(SimulatorKeyframes, TheCliWritesAKeyframeFolderThatOdometryTracksWithDefaults) {
  TempDir dir;
  const std::string data = dir.file("kf"), run = dir.file("run");
  auto r = run_cli(
      "simulate dynamic-outdoor --sensor avia --frames 600 --keyframe-distance 0.5 "
      "--keyframe-distance-max 1.0 --max-points 4000 --no-point-time --no-motion-distortion "
      "--quiet --out " +
      data);
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json info = nlohmann::json::parse(std::ifstream(data + "/dataset.json"));
  const std::size_t frames = info["frames"];
  ASSERT_GT(frames, 40u);
  EXPECT_EQ(info["keyframes"]["frame_indices"].size(), frames);
  const std::size_t first = info["keyframes"]["frame_indices"][1];
  char name[48];
  std::snprintf(name, sizeof name, "/frames/%06zu.pcd", first);
  const PointCloud cloud = read_cloud(data + name);
  EXPECT_EQ(cloud.size(), 4000u);
  EXPECT_FALSE(cloud.has_time());

  r = run_cli("odometry " + data + " --method ctf-icp --quiet --out " + run);
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json summary = nlohmann::json::parse(std::ifstream(run + "/summary.json"));
  EXPECT_EQ(summary["frames"], frames);
  // Measured 0.121 % of the path since the campus drives follow the roads (2026-11-26; 0.048 %
  // on the old path, 4.7 % before the adaptive rules).
  EXPECT_LT(summary["ate"]["rmse_percent_of_path"].get<double>(), 0.25);

  r = run_cli("simulate dynamic-outdoor --keyframe-distance 1 --keyframe-distance-max 0.5 --out " +
              dir.file("bad"));
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("--keyframe-distance-max"), std::string::npos) << r.output;
}

TEST(Keyframes, ASpinning64RingSensorEveryFifthFrameIsTracked) {
  // campus-os1 every 5th frame: 64 rings 0.5 s apart, the car 3 m from one to the next.
  const Keyframes k = every_nth("campus-os1", sanitized() ? 50 : 150, 5);
  const AteResult ate = track(k);
  // Measured 0.45 % of the 84 m (the first 30 keyframes, the car speeding up to 6 m/s; 0.29 %
  // before frame 1 was refined against frame 0 at map density, 1.25 % before each keyframe was
  // deskewed again by its registered motion, 0.50 % over 10 keyframes).
  EXPECT_LT(ate.rmse_percent_of_path, 1.0);
  // Without the adaptive rules the constant-velocity prior sticks at the first slow steps: 9.2 %
  // (46 % before frame 1 was refined against frame 0 at map density).
  if (!sanitized()) {
    EXPECT_GT(track(k, without_adaptive_rules()).rmse_percent_of_path,
              5.0 * ate.rmse_percent_of_path);
  }
}

TEST(Keyframes, KeyframesWithPointTimesAreDeskewedWithinTheirOwnSweep) {
  // dynamic-outdoor-fast every 3rd frame: Mid-360 sweeps of 0.1 s, 0.3 s apart, with point times.
  // Each frame's points belong to its own 0.1 s; moved to the middle of the 0.3 s step instead,
  // every frame was shifted along an extrapolated motion.
  const Keyframes k = every_nth("dynamic-outdoor-fast", sanitized() ? 90 : 300, 3);
  const AteResult ate = track(k);
  // Measured 0.062 % of the 30 m (0.275 % moved to the middle of the step).
  EXPECT_LT(ate.rmse_percent_of_path, 0.15);
}

// The worst rotation error of one step between keyframes, deg.
double worst_step_rotation_error_deg(const Keyframes& k, const std::vector<Pose>& poses) {
  double worst = 0.0;
  for (std::size_t i = 1; i < poses.size(); ++i) {
    const Pose error =
        (k.truth[i - 1].inverse() * k.truth[i]).inverse() * (poses[i - 1].inverse() * poses[i]);
    worst = std::max(worst, rotation_angle(error) * kDegreesPerRadian);
  }
  return worst;
}

std::vector<Pose> tracked_poses(const Keyframes& k) {
  Odometry odometry(OdometryConfig{});
  std::vector<Pose> poses;
  for (std::size_t i = 0; i < k.frames.size(); ++i)
    poses.push_back(odometry.register_frame(k.frames[i], k.times[i]));
  return poses;
}

TEST(Keyframes, ACarsKeyframesHalfASecondApartTurnThroughCorners) {
  // urban-hdl64 every 5th frame: the car turns up to 20 deg from one keyframe to the next, beyond
  // the coarse stage's basin (about 5 deg here), and a constant-velocity prior first misses each
  // turn and then carries it on into the straight after it.
  const Keyframes k = every_nth("urban-hdl64", sanitized() ? 100 : 300, 5);
  const std::vector<Pose> poses = tracked_poses(k);
  // Measured: worst step 2.0 deg (the first), 1.25 % of the path; 19-20 deg and 19.5 % before
  // the turned starts reached a keyframe's turn (one missed 20 deg turn after another).
  EXPECT_LT(worst_step_rotation_error_deg(k, poses), 3.0);
  EXPECT_LT(compute_ate(k.truth, poses).rmse_percent_of_path, 4.0);
}

TEST(Keyframes, ACarsKeyframesMetresApartTurnThroughCorners) {
  // campus-os1 keyframes 2-10 m apart (1-1.8 s, like riverside02_keyframes): at the first corner
  // the car turns 47 deg between keyframes 10 m apart and ends 4 m beside the straight prior.
  if (sanitized()) GTEST_SKIP() << "400 OS1-64 frames: too slow under the sanitizers";
  sim::SimOptions o;
  o.preset = "campus-os1";
  o.frames = 400;
  sim::KeyframeOptions apart;
  apart.distance = 2.0;
  apart.distance_max = 10.0;
  const Keyframes k = simulate(o, apart);
  ASSERT_GT(k.frames.size(), 35u);
  const std::vector<Pose> poses = tracked_poses(k);
  // Measured: worst step 0.96 deg, 0.12 % of the path; 48 deg and 5.9 % before the starts and
  // the gate followed an arc (the turned starts kept the straight prior's translation, and the
  // gate, 1 m around that prior, refused the turn).
  EXPECT_LT(worst_step_rotation_error_deg(k, poses), 3.0);
  EXPECT_LT(compute_ate(k.truth, poses).rmse_percent_of_path, 1.0);
}

TEST(Keyframes, AviaKeyframesWithoutPointTimeAreTracked) {
  // dynamic-outdoor-fast with an Avia, a keyframe every 0.75 m: 4000 points, no point time.
  const Keyframes k =
      simulate(avia("dynamic-outdoor-fast", sanitized() ? 40 : 150), fast_lio_like(0.75, 0.0));
  ASSERT_GT(k.frames.size(), sanitized() ? 15u : 60u);
  const AteResult ate = track(k);
  // Measured 2.7 % of the path since the campus drives follow the roads (2026-11-26; 3.8 % before
  // the wide start of slow solves): keyframes 2-3 look straight down the road from a one-frame
  // map while the robot speeds up, and their coarse solves stop in a ripple of the NDT grid
  // 0.8-0.96 m short of their ~0.9 m steps. On the old path, which turned across the block from
  // the start, 0.079 %. What is left to do: docs/odometry.md, "A prior that stops in a ripple".
  const AteResult without = track(k, without_adaptive_rules());
  std::printf("[ avia keyframes ] ATE %.3f %% (without the adaptive rules %.3f %%)\n",
              ate.rmse_percent_of_path, without.rmse_percent_of_path);
  // Sanitized, the first 40 frames: the failing frames weigh more on the short path (10.8 %).
  EXPECT_LT(ate.rmse_percent_of_path, sanitized() ? 15.0 : 5.0);
  if (!sanitized()) {
    EXPECT_GT(without.rmse_percent_of_path, 1.5 * ate.rmse_percent_of_path);
  }
}

// A motion model that has measured `velocity` over 0.1 s steps (frames 0 to 4 at 0.1 s).
MotionModel measured(const OdometryConfig& c, const Pose& velocity) {
  MotionModel model(c);
  for (std::size_t frame = 0; frame < 5; ++frame) {
    model.predict(0.1 * static_cast<double>(frame), frame);
    if (frame > 0) model.record(velocity, false);
  }
  return model;
}

TEST(AdaptiveRules, ThePriorScalesWithTheTimeStepAndIsUncertainWhenTheStepIsUnknown) {
  OdometryConfig c;
  // Turning 0.02 rad a step: twice that is still below uncertain_rotation (0.05).
  const Pose velocity = from_xyz_rpy(0.5, 0.1, 0.0, 0.0, 0.0, 0.02);
  const auto prior_after = [&](double step) {
    MotionModel model = measured(c, velocity);
    return model.predict(0.4 + step, 5);
  };
  // Regular steps (jitter included): the last motion itself, certain.
  MotionPrior p = prior_after(0.1 + 1e-4);
  EXPECT_FALSE(p.uncertain);
  EXPECT_TRUE(p.motion.isApprox(velocity, 0.0));
  // Twice the step: the same motion twice (constant twist).
  p = prior_after(0.2);
  EXPECT_FALSE(p.uncertain);
  const Pose twice = velocity * velocity;
  EXPECT_NEAR((p.motion.translation() - twice.translation()).norm(), 0.0, 1e-9);
  EXPECT_NEAR(rotation_angle(p.motion), 0.04, 1e-9);
  // A gap of 10 steps: scaled by max_step_ratio at most, and uncertain.
  p = prior_after(1.0);
  EXPECT_TRUE(p.uncertain);
  EXPECT_NEAR(rotation_angle(p.motion), 0.02 * c.max_step_ratio, 1e-9);
  // No increasing stamps; the first registered frame; after a bridged frame: uncertain.
  EXPECT_TRUE(prior_after(0.0).uncertain);
  EXPECT_TRUE(MotionModel(c).predict(0.1, 1).uncertain);
  MotionModel bridged = measured(c, velocity);
  bridged.predict(0.5, 5);
  bridged.record(velocity, true);
  EXPECT_TRUE(bridged.predict(0.6, 6).uncertain);
  // The gate: max_jump around the prediction, widened under an uncertain prior.
  MotionModel regular = measured(c, velocity);
  regular.predict(0.5, 5);
  const Pose beyond = from_xyz_rpy(1.5 * c.max_jump, 0.0, 0.0, 0.0, 0.0, 0.0);
  EXPECT_TRUE(regular.within_gate(Pose::Identity(), Pose::Identity()));
  EXPECT_FALSE(regular.within_gate(Pose::Identity(), beyond));
  // An estimate far from its prior (irregular steps without stamps) makes the next one uncertain.
  MotionModel missed = measured(c, velocity);
  missed.predict(0.5, 5);
  missed.record(from_xyz_rpy(1.0, 0.1, 0.0, 0.0, 0.0, 0.02), false);
  EXPECT_TRUE(missed.predict(0.6, 6).uncertain);
  EXPECT_TRUE(missed.within_gate(Pose::Identity(), beyond));
  EXPECT_FALSE(missed.within_gate(
      Pose::Identity(), from_xyz_rpy(1.01 * c.uncertain_jump_scale * c.max_jump, 0, 0, 0, 0, 0)));
}

// A steady sensor whose stamps come from a coarse clock (KITTI raw: a 0.1036 s period stamped by a
// 100 Hz clock reads 0.10 or 0.11 s) keeps its last motion as the prior: the stamps' jitter is not
// timing. A dropped frame still doubles the prior, and keyframes 0.4 and 0.5 s apart (a real 20 %
// difference, never steady) are still scaled.
TEST(AdaptiveRules, ASteadySensorsStampJitterDoesNotScaleThePrior) {
  OdometryConfig c;
  const Pose velocity = from_xyz_rpy(1.8, 0.0, 0.0, 0.0, 0.0, 0.002);  // a car at 18 m/s
  const double period = 0.1036;
  const auto stamp = [&](std::size_t frame) {  // truncated to the 100 Hz clock
    return std::floor(period * static_cast<double>(frame) * 100.0) / 100.0;
  };
  MotionModel model(c);
  std::size_t frame = 0;
  const auto next = [&](double t) {
    const MotionPrior prior = model.predict(t, frame);
    if (frame > 0) model.record(velocity, false);
    ++frame;
    return prior;
  };
  for (; frame < 10;) next(stamp(frame));
  int scaled = 0;
  for (int k = 0; k < 30; ++k) {
    const MotionPrior prior = next(stamp(frame));
    EXPECT_FALSE(prior.uncertain) << "frame " << frame - 1;
    scaled += prior.scale != 1.0;
  }
  EXPECT_EQ(scaled, 0);
  // The stamps do jitter by 10 %: without the steady period half the priors would scale.
  std::set<long> steps_ms;
  for (std::size_t f = 10; f < 40; ++f)
    steps_ms.insert(std::lround(1000 * (stamp(f + 1) - stamp(f))));
  EXPECT_EQ(steps_ms, (std::set<long>{100, 110}));
  // A dropped frame: twice the motion.
  const MotionPrior dropped = next(stamp(frame + 1));
  EXPECT_NEAR(dropped.scale, 2.0, 0.15);
  EXPECT_NEAR(rotation_angle(dropped.motion), dropped.scale * 0.002, 1e-9);

  // Keyframes stamped 0.4 or 0.5 s apart are scaled by their ratio.
  MotionModel keyframes(c);
  const double steps[] = {0.5, 0.4, 0.5, 0.5, 0.4, 0.5, 0.4, 0.4, 0.5, 0.5, 0.4, 0.5};
  double t = 0.0;
  double last_step = 0.0;
  int keyframe_scaled = 0;
  for (std::size_t i = 0; i < std::size(steps); ++i) {
    const MotionPrior prior = keyframes.predict(t, i);
    if (i >= 2 && last_step != steps[i - 1]) {
      EXPECT_NEAR(prior.scale, steps[i - 1] / last_step, 1e-9) << "keyframe " << i;
      ++keyframe_scaled;
    }
    if (i > 0) keyframes.record(velocity, false);
    if (i > 0) last_step = steps[i - 1];
    t += steps[i];
  }
  EXPECT_GT(keyframe_scaled, 4);
}

TEST(AdaptiveRules, APriorThatTurnsSharplyIsUncertain) {
  OdometryConfig c;
  const auto prior_turning = [&](double yaw) {
    MotionModel model = measured(c, from_xyz_rpy(0.1, 0.0, 0.0, 0.0, 0.0, yaw));
    return model.predict(0.5, 5);
  };
  EXPECT_FALSE(prior_turning(0.9 * c.uncertain_rotation).uncertain);
  EXPECT_TRUE(prior_turning(1.1 * c.uncertain_rotation).uncertain);
  EXPECT_TRUE(prior_turning(-1.1 * c.uncertain_rotation).uncertain);
}

TEST(AdaptiveRules, ASparseFrameKeepsMorePointsADenseOneIsUnchanged) {
  OdometryConfig c;
  PointCloud sparse, dense;
  // 1500 points on a 3 m x 3 m wall: 0.25 m voxels keep at most 144.
  for (int i = 0; i < 1500; ++i)
    sparse.points.emplace_back(5.0f, -1.5f + 3.0f * float(i % 39) / 39.0f,
                               -1.5f + 3.0f * float(i / 39) / 39.0f);
  const PreprocessOptions o = preprocess_options(c, false);
  const PointCloud more = adaptive_downsample(sparse, sparse.size(), o);
  EXPECT_GT(more.size(), 4 * voxel_downsample(sparse, c.voxel_size).size());
  EXPECT_LE(more.size(), sparse.size());
  // A frame delivered dense (10x the floor) that sees only a near wall keeps the plain filter.
  PointCloud wall;
  for (int i = 0; i < 10000; ++i)
    wall.points.emplace_back(1.0f, -1.0f + 2.0f * float(i % 100) / 100.0f,
                             -1.0f + 2.0f * float(i / 100) / 100.0f);
  EXPECT_EQ(adaptive_downsample(wall, wall.size(), o).points,
            voxel_downsample(wall, c.voxel_size).points);
  // 30 x 30 m of ground every 0.1 m: 14400 voxels, more than enough and under the ceiling.
  for (int i = 0; i < 300; ++i)
    for (int j = 0; j < 300; ++j)
      dense.points.emplace_back(-15.0f + 0.1f * i, -15.0f + 0.1f * j, -1.0f);
  ASSERT_LT(voxel_downsample(dense, c.voxel_size).size(), c.max_downsampled_points);
  EXPECT_EQ(adaptive_downsample(dense, dense.size(), o).points,
            voxel_downsample(dense, c.voxel_size).points);
}

TEST(AdaptiveRules, ADenseScanIsThinnedToThePointCeiling) {
  // A simulated 64-beam car scan (~117k points) keeps more than max_downsampled_points at
  // voxel_size: it is thinned to about that many, and as evenly (every kept point still stands
  // for a voxel of the plain filter's cloud nearby).
  sim::SimOptions so;
  so.preset = "urban-hdl64";
  so.motion_distortion = false;
  const sim::Simulator simulator(so);
  const PointCloud scan = simulator.frame(10);
  OdometryConfig c;
  const PointCloud plain = voxel_downsample(scan, c.voxel_size);
  c.max_downsampled_points = static_cast<std::uint32_t>(plain.size() / 2);
  const PointCloud thinned = adaptive_downsample(scan, scan.size(), preprocess_options(c, false));
  EXPECT_GT(thinned.size(), 0.6 * c.max_downsampled_points);
  EXPECT_LT(thinned.size(), 1.25 * c.max_downsampled_points);
  // The thinned cloud covers what the plain one covers: each plain point has a thinned one within
  // the larger voxel's diagonal.
  const KdTree tree(thinned.points);
  const double larger_voxel = c.voxel_size * std::sqrt(2.0);
  std::size_t far = 0;
  for (const Point& p : plain.points) {
    std::size_t index = 0;
    float squared = 0.0f;
    if (!tree.nearest(p, static_cast<float>(3.0 * larger_voxel * larger_voxel), index, squared))
      ++far;
  }
  EXPECT_EQ(far, 0u);
  // Off (0), or under the ceiling: the plain filter.
  c.max_downsampled_points = 0;
  EXPECT_EQ(adaptive_downsample(scan, scan.size(), preprocess_options(c, false)).points,
            plain.points);
}

TEST(AdaptiveRules, ADenseSequenceIsFilteredOnceAtTheVoxelItsLastFrameNeeded) {
  // Consecutive 64-beam car scans are alike: the first one above the ceiling finds the voxel that
  // keeps it under; the next is filtered once at that voxel, from its own points (not thinned
  // from a finer filter's centroids), and stays under the ceiling too.
  sim::SimOptions so;
  so.preset = "urban-hdl64";
  so.motion_distortion = false;
  const sim::Simulator simulator(so);
  const PointCloud first = simulator.frame(10), second = simulator.frame(11);
  OdometryConfig c;
  c.max_downsampled_points = static_cast<std::uint32_t>(
      voxel_downsample(first, c.voxel_size).size() / 2);  // well above the ceiling at voxel_size
  const PreprocessOptions o = preprocess_options(c, false);
  DenseVoxelMemory memory;
  const PointCloud a = adaptive_downsample(first, first.size(), o, &memory);
  EXPECT_LE(a.size(), c.max_downsampled_points);
  EXPECT_GT(a.size(), 0.6 * c.max_downsampled_points);
  EXPECT_GT(memory.voxel, 1.2 * c.voxel_size);
  const double learned = memory.voxel;
  const PointCloud b = adaptive_downsample(second, second.size(), o, &memory);
  EXPECT_EQ(b.points, voxel_downsample(second, learned).points);
  EXPECT_LE(b.size(), c.max_downsampled_points);
  EXPECT_DOUBLE_EQ(memory.voxel, learned);  // within the band: the voxel stays
  // A frame far under the ceiling (the near half of the scan) lets the voxel shrink, never below
  // voxel_size.
  const PointCloud near = crop_range(second, 0.0, 12.0);
  ASSERT_LT(voxel_downsample(near, learned).size(), 0.6 * c.max_downsampled_points);
  adaptive_downsample(near, second.size(), o, &memory);
  EXPECT_LT(memory.voxel, learned);
  EXPECT_GE(memory.voxel, c.voxel_size);
}

namespace {

// Two recorded Avia keyframes (12 and 13: the sensor turns 12.5 degrees and moves 0.13 m), their
// reference motion (FAST-LIO2, good to centimetres) and a prior that missed the turn by 15
// degrees, as when a hand-held sweep reverses. Empty frames without ../shared.
struct MissedTurn {
  PointCloud reference_frame, frame;
  Pose truth = Pose::Identity();
  MotionPrior prior;
};

MissedTurn avia_missed_turn() {
  MissedTurn m;
  const std::string folder = scanmatch::testing::shared_data("data/3d/avia_hku1");
  if (folder.empty()) return m;
  const std::size_t a = 12, b = 13;
  const auto frame_at = [&](std::size_t i) {
    char name[48];
    std::snprintf(name, sizeof(name), "/frames/%06zu.pcd", i);
    return voxel_downsample(read_cloud(folder + name), 0.25);
  };
  const Trajectory reference = read_trajectory(folder + "/odom_poses.txt");
  m.reference_frame = frame_at(a);
  m.frame = frame_at(b);
  m.truth = reference.poses[a].inverse() * reference.poses[b];
  m.prior.uncertain = true;
  m.prior.motion = m.truth;
  m.prior.motion.linear() =
      m.truth.linear() * Eigen::AngleAxisd(0.26, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return m;
}

// The coarse stage of configuration `c` on the missed turn.
CoarseResult align_missed_turn(const MissedTurn& m, const OdometryConfig& c) {
  CoarseNdt coarse(c);
  coarse.set_reference(m.reference_frame, false);
  return coarse.align(m.frame, m.prior);
}

}  // namespace

TEST(AdaptiveRules, ATurnedStartRecoversAPriorThatMissedTheTurn) {
  // The other starts (identity, half and twice the prior) end 8 degrees and 0.9 m off, the
  // recording's failure; a turned start brings it back.
  const MissedTurn m = avia_missed_turn();
  if (m.frame.empty()) GTEST_SKIP() << "../shared/data/3d/avia_hku1 not present";
  const Pose& truth = m.truth;
  const auto align = [&](int rotation_starts) {
    OdometryConfig c;
    c.rotation_starts = rotation_starts;
    return align_missed_turn(m, c);
  };
  const auto error_deg = [&](const CoarseResult& r) {
    return rotation_angle(truth.inverse() * r.motion) * kDegreesPerRadian;
  };
  const CoarseResult turned = align(OdometryConfig{}.rotation_starts);
  const CoarseResult unturned = align(0);
  EXPECT_TRUE(turned.recovered);
  EXPECT_LT(error_deg(turned), 1.0);  // measured 0.08 deg, 0.026 m
  EXPECT_LT((truth.inverse() * turned.motion).translation().norm(), 0.1);
  EXPECT_GT(error_deg(unturned), 3.0);  // measured 8.1 deg
}

TEST(AdaptiveRules, RankedStartsRecoverTheTurnWithFewerFullSolves) {
  // Ranking the starts on a subset of the coarse points first (start_screen_points) must pick the
  // turned start that solving every start on every point picks, at a fraction of the solves on
  // every point.
  const MissedTurn m = avia_missed_turn();
  if (m.frame.empty()) GTEST_SKIP() << "../shared/data/3d/avia_hku1 not present";
  const Pose& truth = m.truth;
  const auto align = [&](std::uint32_t screen_points) {
    OdometryConfig c;
    c.start_screen_points = screen_points;
    return align_missed_turn(m, c);
  };
  const CoarseResult ranked = align(150);
  const CoarseResult every = align(0);
  const Pose between = every.motion.inverse() * ranked.motion;
  std::printf(
      "[ ranked ] %.3f deg %.4f m from solving every start; iterations on every point "
      "%d (every start: %d), on the subset %d\n",
      rotation_angle(between) * kDegreesPerRadian, between.translation().norm(), ranked.iterations,
      every.iterations, ranked.screen_iterations);
  EXPECT_TRUE(every.recovered);
  EXPECT_TRUE(ranked.recovered);
  EXPECT_LT(rotation_angle(between) * kDegreesPerRadian, 0.2);
  EXPECT_LT(between.translation().norm(), 0.02);
  EXPECT_LT(rotation_angle(truth.inverse() * ranked.motion) * kDegreesPerRadian, 1.0);
  EXPECT_EQ(every.screen_iterations, 0);
  EXPECT_GT(ranked.screen_iterations, 0);
  EXPECT_LT(ranked.iterations, every.iterations / 2);
}

TEST(AdaptiveRules, AThinnedWideDescentRecoversTheSameTurn) {
  // The starts' descent on the wider grid with one point per start_voxel_size (1 m) instead of
  // every coarse point (each of its iterations then costs less): the turned start must still win,
  // where the descents on every point put it. (Speed: docs/benchmarks.md.)
  const MissedTurn m = avia_missed_turn();
  if (m.frame.empty()) GTEST_SKIP() << "../shared/data/3d/avia_hku1 not present";
  const auto align = [&](double start_voxel_size) {
    OdometryConfig c;
    c.start_voxel_size = start_voxel_size;
    return align_missed_turn(m, c);
  };
  const CoarseResult thinned = align(OdometryConfig{}.start_voxel_size);
  const CoarseResult every = align(0.0);
  ASSERT_GT(OdometryConfig{}.start_voxel_size, OdometryConfig{}.coarse_voxel_size);
  const Pose between = every.motion.inverse() * thinned.motion;
  EXPECT_TRUE(thinned.recovered);
  EXPECT_LT(rotation_angle(between) * kDegreesPerRadian, 0.2);
  EXPECT_LT(between.translation().norm(), 0.02);
  EXPECT_LT(rotation_angle(m.truth.inverse() * thinned.motion) * kDegreesPerRadian, 1.0);
}

TEST(AdaptiveRules, AWideStartRecoversACarEnteringATurn) {
  // urban-hdl64 frames 216 -> 217: the car (8 m/s) enters a 12 m turn at the crossing and turns
  // 3.2 deg in the step, while the constant-velocity prior (the straight step before) turns none.
  // On the 1 m NDT grid the solve from that prior is slow and stops short of the turn; the same
  // prior started on the 3 m grid, then refined, reaches it.
  sim::SimOptions o;
  o.preset = "urban-hdl64";
  o.motion_distortion = false;
  const sim::Simulator simulator(o);
  const std::size_t a = 216, b = 217;
  const Pose truth = simulator.pose(a).inverse() * simulator.pose(b);
  ASSERT_GT(rotation_angle(truth) * kDegreesPerRadian, 2.5);
  MotionPrior prior;
  prior.motion = simulator.pose(a - 1).inverse() * simulator.pose(a);
  ASSERT_LT(rotation_angle(prior.motion) * kDegreesPerRadian, 0.5);
  const auto align = [&](int wide_start_iterations) {
    OdometryConfig c;
    c.wide_start_iterations = wide_start_iterations;
    CoarseNdt coarse(c);
    coarse.set_reference(voxel_downsample(simulator.frame(a), c.voxel_size), false);
    return coarse.align(voxel_downsample(simulator.frame(b), c.voxel_size), prior);
  };
  const auto error_deg = [&](const CoarseResult& r) {
    return rotation_angle(truth.inverse() * r.motion) * kDegreesPerRadian;
  };
  const CoarseResult wide = align(OdometryConfig{}.wide_start_iterations);
  const CoarseResult plain = align(0);
  std::printf("[ wide start ] error %.2f deg %.3f m (plain %.2f deg %.3f m), iterations %d (%d)\n",
              error_deg(wide), (truth.inverse() * wide.motion).translation().norm(),
              error_deg(plain), (truth.inverse() * plain.motion).translation().norm(),
              wide.iterations, plain.iterations);
  EXPECT_GE(plain.iterations, OdometryConfig{}.wide_start_iterations);  // slow: the trigger
  EXPECT_GT(error_deg(plain), 1.0);
  EXPECT_TRUE(wide.recovered);
  EXPECT_LT(error_deg(wide), 0.3);
}

TEST(AdaptiveRules, AStartOutsideTheGateGivesWayToTheOptimumInside) {
  // riverside02_keyframes 0-40: a car whose keyframes fall 3-14 m and 0.3-1.4 s apart. At 32-35
  // the time-scaled prior is right (14.2 m predicted and true) but uncertain (the step changed),
  // and an overlay near the identity wins the NDT score; outside the gate it used to be thrown
  // away and the frame bridged by the bare prior (steps 2.5-6 deg off the reference's). The
  // prior's own solve, inside the gate, now serves: no frame is bridged and every step's
  // rotation is within 1.5 degrees of the reference's (measured at most 1.17).
  const std::string folder = scanmatch::testing::shared_data("data/3d/riverside02_keyframes");
  if (folder.empty()) GTEST_SKIP() << "../shared/data/3d/riverside02_keyframes not present";
  // Every start on 1-6 s steps: the simulated keyframe sets run that path sanitized.
  if (sanitized()) GTEST_SKIP() << "41 keyframes with every start: too slow sanitized";
  const Trajectory reference = read_trajectory(folder + "/odom_poses.txt");
  std::vector<double> times;
  {
    std::ifstream in(folder + "/times.txt");
    for (double t = 0.0; in >> t;) times.push_back(t);
  }
  const std::size_t frames = 41;
  ASSERT_GE(times.size(), frames);
  Odometry odometry(OdometryConfig{});
  std::vector<Pose> poses;
  std::size_t bridged = 0;
  for (std::size_t i = 0; i < frames; ++i) {
    char name[48];
    std::snprintf(name, sizeof(name), "/frames/%06zu.pcd", i);
    poses.push_back(odometry.register_frame(read_cloud(folder + name), times[i]));
    bridged += odometry.last_stats().bridged;
  }
  EXPECT_EQ(bridged, 0u);
  for (std::size_t i = 30; i < frames; ++i) {
    const Pose truth = reference.poses[i - 1].inverse() * reference.poses[i];
    const Pose step = poses[i - 1].inverse() * poses[i];
    EXPECT_LT(rotation_angle(truth.inverse() * step) * kDegreesPerRadian, 1.5) << "step " << i;
  }
}

TEST(AdaptiveRules, AfterATimeGapTheGateAdmitsAStop) {
  // A car (urban-hdl64, 8 m/s at 10 Hz) waits: its next frame comes 2 s later from where it
  // stood (riverside02_keyframes 57-59: 16-21 s apart, the car at lights). The prior, scaled by
  // the clamped time ratio, puts it 3.2 m on, beyond the uncertain gate's 3 m; standing still is
  // as likely as going on over such a gap, and the gate spans both.
  sim::SimOptions so;
  so.preset = "urban-hdl64";
  so.motion_distortion = false;
  const sim::Simulator simulator(so);
  Odometry odometry(OdometryConfig{});
  constexpr std::size_t kFirst = 40, kLast = 46;
  Pose before;
  for (std::size_t i = kFirst; i <= kLast; ++i)
    before = odometry.register_frame(simulator.frame(i), simulator.frame_time(i));
  const double step =
      (simulator.pose(kLast).translation() - simulator.pose(kLast - 1).translation()).norm();
  ASSERT_GT(4.0 * step, 3.0);  // the scaled prior lies outside the gate around a stop
  const Pose after =
      odometry.register_frame(simulator.frame(kLast), simulator.frame_time(kLast) + 2.0);
  EXPECT_FALSE(odometry.last_stats().bridged);
  EXPECT_TRUE(odometry.last_stats().prior_uncertain);
  EXPECT_LT((before.inverse() * after).translation().norm(), 0.05);
}

TEST(AdaptiveRules, AFirstStepMetresLongIsFoundByTheGlobalStart) {
  // Keyframes metres apart, the first motion unknown (sim campus-os1 keyframes 3-14 m apart came
  // out 29.5 % of the path, frames 1-28 left standing): the identity start lies metres outside
  // every local basin, and the frame-to-frame global registration (no prior) finds the step.
  // Here a straight street: standing still, the walls and the road overlay well enough to pair a
  // quarter of the frame with the map, but a third of it lies near the last frame (0.59 at the
  // truth).
  sim::SimOptions so;
  so.preset = "urban-hdl64";
  so.motion_distortion = false;
  const sim::Simulator simulator(so);
  constexpr std::size_t kFirst = 40, kSecond = 52;
  const Pose truth = simulator.pose(kFirst).inverse() * simulator.pose(kSecond);
  ASSERT_GT(truth.translation().norm(), 8.0);
  const auto first_step = [&](const OdometryConfig& config, FrameStats& stats) {
    Odometry odometry(config);
    odometry.register_frame(simulator.frame(kFirst), 0.0);
    const Pose second = odometry.register_frame(simulator.frame(kSecond), 1.0);
    stats = odometry.last_stats();
    return (truth.inverse() * second).translation().norm();
  };
  FrameStats with, without;
  EXPECT_LT(first_step(OdometryConfig{}, with), 0.1);
  EXPECT_TRUE(with.global_start);
  OdometryConfig off;
  off.global_start_below = 0.0;
  EXPECT_GT(first_step(off, without), 2.0);
  EXPECT_FALSE(without.global_start);
  EXPECT_TRUE(without.prior_uncertain);  // the first motion: no prior to trust
}
