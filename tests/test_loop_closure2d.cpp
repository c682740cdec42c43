// 2D loop closure (mapping/loop_closure2d.hpp): on a simulated sequence it must reduce the error
// against the simulator's truth, verification must reject two different places, and
// `map2d --loop-closure` must write its files.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>

#include "planar_scene.hpp"
#include "scanmatch/core/error.hpp"
#include "scanmatch/eval/metrics2d.hpp"
#include "scanmatch/mapping/edge_information.hpp"
#include "scanmatch/mapping/loop_closure2d.hpp"
#include "scanmatch/mapping/loop_verification2d.hpp"
#include "scanmatch/mapping2d/mapper2d.hpp"
#include "scanmatch/run/map2d_run.hpp"
#include "scanmatch/sim/random.hpp"
#include "scanmatch/sim/simulator.hpp"
#include "test_helpers.hpp"

namespace scanmatch {
namespace {

using scanmatch::testing::Segment;

// A 180-degree laser (1-degree beams, returns up to 30 m) at `pose` among `walls`, in its frame.
Scan2D half_scan(const std::vector<Segment>& walls, const Pose2& pose) {
  Scan2D scan;
  const Eigen::Vector2d o = pose.translation();
  for (int beam = 0; beam <= 180; ++beam) {
    const double a = pose2_angle(pose) + (beam - 90) * M_PI / 180;
    const Eigen::Vector2d d(std::cos(a), std::sin(a));
    const double best = scanmatch::testing::nearest_wall(walls, o, d);
    if (best < 30.0) scan.points.push_back(pose.inverse() * (o + best * d));
  }
  return scan;
}

// An 8 x 6 m room centred on the origin with a 1 x 1 m block in one corner (not symmetric).
std::vector<Segment> room_walls() {
  return {{{-4, -3}, {4, -3}}, {{4, -3}, {4, 2}},   {{4, 2}, {3, 2}},     {{3, 2}, {3, 3}},
          {{3, 3}, {-4, 3}},   {{-4, 3}, {-4, -3}}, {{-4, -1}, {-3, -1}}, {{-3, -1}, {-3, -3}}};
}

Scans2D room_scans(std::size_t count) {
  SequenceOptions o;
  o.simulator.motion_distortion = false;
  return load_scans_2d("sim:room-2d", o, count);
}

/// The scans' true poses and an odometry that drifts in a known way: each step's true motion
/// with a heading bias of 0.04 deg and 1 % too long.
std::pair<std::vector<Pose2>, std::vector<Pose2>> reference_and_drifting_odometry(
    const Scans2D& input) {
  std::vector<Pose2> reference, odometry;
  for (std::size_t i = 0; i < input.scans.size(); ++i) {
    reference.push_back(pose2(input.scans[i].pose));
    if (i == 0) {
      odometry.push_back(Pose2::Identity());
    } else {
      Pose2 step = reference[i - 1].inverse() * reference[i];
      step.translation() *= 1.01;
      odometry.push_back(odometry.back() * step * pose2(0, 0, 0.04 * M_PI / 180));
    }
  }
  return {reference, odometry};
}

TEST(LoopClosure2D, ReducesTheErrorOfASimulatedSequence) {
  // The simulated scans with an odometry that drifts in a known way (1 % long, 0.04 deg a step).
  // room-2d's rooms are identical and its hallway has doors every 5 m, so the drift is kept below
  // the 2.5 m where those would alias.
  const Scans2D input = room_scans(500);
  const auto [reference, odometry] = reference_and_drifting_odometry(input);
  const auto close = [&](LoopClosure2D& loops) {
    for (std::size_t i = 0; i < input.scans.size(); ++i)
      loops.add_scan(scan_from_laser(input.scans[i], 0.05, 0.0, 0.0), odometry[i]);
    loops.finish();
  };
  LoopClosure2D loops;
  close(loops);
  const std::vector<Pose2> optimized = loops.poses();
  ASSERT_EQ(optimized.size(), odometry.size());
  const AbsoluteError2D before = absolute_trajectory_error_2d(reference, odometry);
  const AbsoluteError2D after = absolute_trajectory_error_2d(reference, optimized);
  const LoopClosure2DCounts& c = loops.counts();
  std::printf(
      "room-2d 500 scans: ATE odometry %.3f m, loop-closed %.3f m; %zu keyframes, %zu "
      "candidates, %zu verified, %zu outliers, %zu optimizations, %.2f ms per scan\n",
      before.rmse, after.rmse, c.keyframes, c.candidates, c.verified, c.outliers, c.optimizations,
      c.total_ms / static_cast<double>(optimized.size()));
  EXPECT_GT(before.rmse, 0.3);
  EXPECT_GT(c.verified, 0u);
  EXPECT_LT(after.rmse, 0.5 * before.rmse);
  // Every accepted loop agrees with the truth: its relative pose is within a few cm.
  for (const Loop2D& l : loops.loops()) {
    if (l.outlier) continue;
    const Pose2 truth = reference[l.from_scan].inverse() * reference[l.to_scan];
    Pose2 error = truth.inverse() * l.relative;
    // A sliding loop holds nothing along its open direction (where the estimate put it).
    if (l.sliding)
      error.translation() -= l.slide_direction * l.slide_direction.dot(error.translation());
    EXPECT_LT(error.translation().norm(), 0.15) << l.from_scan << " -> " << l.to_scan;
  }
  // Optimizing after every loop edge (optimize_above 0) runs more often and ends at the same map:
  // the loops that agreed with the estimate were only waiting for the next optimization.
  LoopClosure2DOptions every;
  every.optimize_above = 0.0;
  LoopClosure2D eager(every);
  close(eager);
  EXPECT_GT(eager.counts().optimizations, c.optimizations);
  EXPECT_NEAR(absolute_trajectory_error_2d(reference, eager.poses()).rmse, after.rmse, 0.03);
  // A keyframe's pause after each one that added a loop verifies fewer candidates; loops a
  // keyframe or two apart still hold the map.
  LoopClosure2DOptions paused;
  paused.keyframes_between_loops = 1;
  LoopClosure2D sparse(paused);
  close(sparse);
  EXPECT_LT(sparse.counts().candidates, c.candidates);
  EXPECT_LT(absolute_trajectory_error_2d(reference, sparse.poses()).rmse, 0.5 * before.rmse);
  // Place-database matches beyond the estimate gate's reach are not verified: verified, none of
  // them is added, so the same loops come out of fewer verifications.
  LoopClosure2DOptions all_verified;
  all_verified.registration_reach = -1.0;
  LoopClosure2D unfiltered(all_verified);
  close(unfiltered);
  EXPECT_GT(c.ruled_out_by_estimate, 0u);
  EXPECT_EQ(unfiltered.counts().ruled_out_by_estimate, 0u);
  EXPECT_EQ(unfiltered.counts().candidates, c.candidates + c.ruled_out_by_estimate);
  ASSERT_EQ(unfiltered.loops().size(), loops.loops().size());
  for (std::size_t i = 0; i < loops.loops().size(); ++i) {
    EXPECT_EQ(unfiltered.loops()[i].from_keyframe, loops.loops()[i].from_keyframe);
    EXPECT_EQ(unfiltered.loops()[i].to_keyframe, loops.loops()[i].to_keyframe);
  }
  const std::vector<Pose2> all = unfiltered.poses();
  for (std::size_t i = 0; i < all.size(); ++i)
    EXPECT_TRUE(all[i].matrix() == optimized[i].matrix()) << "scan " << i;
}

TEST(LoopClosure2D, KeyframeStepsMadeAheadCloseTheSameLoops) {
  // The keyframe steps depend on the odometry alone: made for the whole run before the graph sees
  // any of them (as a run makes them on the odometry's thread), they give the same keyframes,
  // loops and poses as add_scan, to the bit; also past a non-finite odometry pose and weak fits.
  const Scans2D input = room_scans(300);
  auto [reference, odometry] = reference_and_drifting_odometry(input);
  odometry[57].translation().x() = std::numeric_limits<double>::quiet_NaN();
  const auto weak = [](std::size_t i) { return i % 23 == 5; };
  std::vector<Scan2D> scans;
  for (const LaserScan2D& laser : input.scans)
    scans.push_back(scan_from_laser(laser, 0.05, 0.0, 0.0));
  LoopClosure2D inline_steps;
  for (std::size_t i = 0; i < scans.size(); ++i)
    inline_steps.add_scan(scans[i], odometry[i], weak(i));
  inline_steps.finish();
  LoopKeyframes2D keyframes;
  std::vector<KeyframeStep2D> steps;
  for (std::size_t i = 0; i < scans.size(); ++i)
    steps.push_back(keyframes.add_scan(scans[i], odometry[i], weak(i)));
  LoopClosure2D ahead;
  std::size_t keyframe_steps = 0;
  for (std::size_t i = 0; i < scans.size(); ++i)
    keyframe_steps += ahead.add_step(scans[i], steps[i]);
  ahead.finish();
  const LoopClosure2DCounts &a = inline_steps.counts(), &b = ahead.counts();
  EXPECT_EQ(keyframe_steps, a.keyframes);
  EXPECT_EQ(b.keyframes, a.keyframes);
  EXPECT_EQ(b.candidates, a.candidates);
  EXPECT_EQ(b.verified, a.verified);
  EXPECT_EQ(b.open_odometry_edges, a.open_odometry_edges);
  EXPECT_EQ(b.rotation_open_odometry_edges, a.rotation_open_odometry_edges);
  EXPECT_GT(a.verified, 0u);
  ASSERT_EQ(ahead.loops().size(), inline_steps.loops().size());
  for (std::size_t i = 0; i < ahead.loops().size(); ++i)
    EXPECT_TRUE(ahead.loops()[i].relative.matrix() == inline_steps.loops()[i].relative.matrix());
  const std::vector<Pose2> p = ahead.poses(), q = inline_steps.poses();
  ASSERT_EQ(p.size(), scans.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_TRUE(p[i].matrix().allFinite()) << "scan " << i;
    EXPECT_TRUE(p[i].matrix() == q[i].matrix()) << "scan " << i;
  }
  // A run whose first step is not a keyframe's was fed steps from another run: refused.
  const auto not_keyframe =
      std::find_if(steps.begin(), steps.end(), [](const KeyframeStep2D& k) { return !k.keyframe; });
  ASSERT_NE(not_keyframe, steps.end());
  LoopClosure2D fresh;
  EXPECT_THROW(fresh.add_step(scans[0], *not_keyframe), Error);
}

TEST(LoopClosure2D, PairingErrorIsTheMeanDistanceOfThePairedPoints) {
  const Scan2D scan = half_scan(room_walls(), pose2(0.0, 0.0, 0.0));
  ASSERT_GT(scan.points.size(), 100u);
  EXPECT_NEAR(pairing_error_2d(scan, scan, Pose2::Identity(), 0.1), 0.0, 1e-9);
  // Moved 3 cm towards +x, the points of the wall ahead (x = 4) lie 3 cm from it; every other
  // wall slides along itself or moves 3 cm too: the mean is at most 3 cm and well above 1 cm.
  const double moved = pairing_error_2d(scan, scan, pose2(0.03, 0.0, 0.0), 0.1);
  EXPECT_GT(moved, 0.01);
  EXPECT_LE(moved, 0.03 + 1e-9);
  // Nothing pairs 50 m away; bad input gives no error rather than a number.
  EXPECT_LT(pairing_error_2d(scan, scan, pose2(50.0, 50.0, 0.0), 0.1), 0.0);
  EXPECT_LT(pairing_error_2d(Scan2D{}, scan, Pose2::Identity(), 0.1), 0.0);
  Scan2D bad = scan;
  bad.points[3].x() = std::nan("");
  EXPECT_LT(pairing_error_2d(bad, scan, Pose2::Identity(), 0.1), 0.0);
  EXPECT_LT(pairing_error_2d(scan, bad, Pose2::Identity(), 0.1), 0.0);
}

TEST(LoopClosure2D, ANoisierSensorsTrueLoopsPairWithinItsOwnFloor) {
  // A laser much noisier than the fixed bound assumes (8 cm along each beam): many true loops pair
  // at more than verification.max_error's 4 cm and the fixed bound rejects them. The run's own
  // floor (its keyframe steps paired at the odometry) raises the bound to what this sensor
  // gives: more loops, a few of them off (room-2d's rooms are alike), and a closer map.
  const Scans2D input = room_scans(500);
  const auto [reference, odometry] = reference_and_drifting_odometry(input);
  sim::Rng rng(7);
  std::vector<Scan2D> scans;
  for (const LaserScan2D& laser : input.scans) {
    Scan2D scan = scan_from_laser(laser, 0.05, 0.0, 0.0);
    for (Eigen::Vector2d& p : scan.points) p += 0.08 * rng.normal() * p.normalized();
    scans.push_back(std::move(scan));
  }
  const auto close = [&](const LoopClosure2DOptions& options) {
    LoopClosure2D loops(options);
    for (std::size_t i = 0; i < scans.size(); ++i) loops.add_scan(scans[i], odometry[i]);
    loops.finish();
    int wrong = 0;
    for (const Loop2D& l : loops.loops()) {
      if (l.outlier) continue;
      Pose2 error =
          (reference[l.from_scan].inverse() * reference[l.to_scan]).inverse() * l.relative;
      if (l.sliding)
        error.translation() -= l.slide_direction * l.slide_direction.dot(error.translation());
      wrong += error.translation().norm() > 0.3;
    }
    return std::tuple(loops.counts().verified, wrong,
                      absolute_trajectory_error_2d(reference, loops.poses()).rmse,
                      loops.counts().max_error_m);
  };
  LoopClosure2DOptions fixed;
  fixed.max_error_per_floor = 0.0;
  const auto [verified_fixed, wrong_fixed, ate_fixed, bound_fixed] = close(fixed);
  const auto [verified, wrong, ate, bound] = close(LoopClosure2DOptions{});
  const double drift = absolute_trajectory_error_2d(reference, odometry).rmse;
  std::printf(
      "room-2d, 8 cm beam noise: %zu loops (%d off by > 0.3 m) with the fixed bound, %zu (%d) "
      "with the run's floor (%.3f m); ATE %.3f / %.3f m (odometry %.3f)\n",
      verified_fixed, wrong_fixed, verified, wrong, bound, ate_fixed, ate, drift);
  EXPECT_EQ(bound_fixed, LoopVerification2DOptions{}.max_error);
  EXPECT_GT(bound, bound_fixed);
  EXPECT_GT(verified, verified_fixed + verified_fixed / 10);
  EXPECT_LE(wrong, static_cast<int>(verified / 20));
  EXPECT_LT(ate, 0.25 * drift);
  EXPECT_LT(ate, 0.75 * ate_fixed);
}

TEST(LoopClosure2D, FreiburgCampusRevisitPairsWithinTheRunsFloorIfPresent) {
  // freiburg-campus scan 1184 passes scan 222 again, the same way: the search scores it 0.9 and
  // nearly every point pairs, but outdoors (long ranges, vegetation) the paired points lie 4-6 cm
  // apart on average, past the fixed 4 cm. Consecutive scans of this log, paired at their
  // corrected poses, show the same floor: 1.8 times their lower quartile lets the loop in, at
  // the corrected poses' relative pose.
  const std::string log =
      scanmatch::testing::shared_data("data/2d/carmen/freiburg-campus-corrected.log.gz");
  if (log.empty()) GTEST_SKIP() << "../shared/data/2d/carmen is absent";
  const Scans2D input = load_scans_2d(log, {}, 1185);
  ASSERT_EQ(input.scans.size(), 1185u);
  std::vector<Scan2D> scans;
  std::vector<Pose2> reference;
  for (const LaserScan2D& laser : input.scans) {
    scans.push_back(scan_from_laser(laser));
    reference.push_back(pose2(laser.pose));
  }
  LoopVerification2DOptions options;
  std::vector<double> floors;
  for (std::size_t i = 1; i < 400; ++i) {
    const double e = pairing_error_2d(
        scans[i], scans[i - 1], reference[i - 1].inverse() * reference[i], options.pair_distance);
    if (e >= 0.0) floors.push_back(e);
  }
  ASSERT_GT(floors.size(), 100u);
  std::nth_element(floors.begin(), floors.begin() + floors.size() / 4, floors.end());
  const double floor = floors[floors.size() / 4];
  const std::size_t current = 1184, candidate = 222;
  std::vector<PosedScan2D> neighbours;
  for (std::size_t j = candidate - 6; j <= candidate + 6; ++j)
    if (j != candidate)
      neighbours.push_back({&scans[j], reference[candidate].inverse() * reference[j]});
  const Pose2 truth = reference[candidate].inverse() * reference[current];
  const Pose2 initial = truth * pose2(0.6, -0.4, 0.03);  // the search finds it from there
  const LoopVerification2D fixed =
      verify_loop_2d(scans[current], scans[candidate], initial, options, neighbours);
  options.max_error =
      std::max(options.max_error, LoopClosure2DOptions{}.max_error_per_floor * floor);
  const LoopVerification2D raised =
      verify_loop_2d(scans[current], scans[candidate], initial, options, neighbours);
  const Pose2 off = truth.inverse() * raised.transform;
  std::printf(
      "freiburg-campus 1184 -> 222: score %.2f, paired %.2f, error %.3f m; floor %.3f m, bound "
      "%.3f m; accepted %d -> %d, %.3f m and %.2f deg from the corrected poses\n",
      fixed.search_score, fixed.paired_fraction, fixed.error, floor, options.max_error,
      fixed.accepted, raised.accepted, off.translation().norm(), pose2_angle(off) * 180.0 / M_PI);
  EXPECT_GT(fixed.paired_fraction, 0.85);
  EXPECT_GT(fixed.error, 0.04);
  EXPECT_FALSE(fixed.accepted);
  EXPECT_GT(options.max_error, fixed.error);
  EXPECT_TRUE(raised.accepted);
  EXPECT_LT(off.translation().norm(), 0.3);
  EXPECT_LT(std::abs(pose2_angle(off) * 180.0 / M_PI), 1.0);
}

TEST(LoopClosure2D, ASubmapVerifiesWhatTwoHalfViewsCannot) {
  // corridor-2d's 180-degree laser, 4 scans (~3.6 m) apart along a corridor: the older scan saw the
  // stretch between them, which the newer one cannot, so scan against scan the share of points
  // paired both ways stays low. Joined by its older neighbours (in its frame, by the true poses)
  // the candidate becomes a submap onto which the newer scan pairs nearly everywhere.
  const Scans2D input = load_scans_2d("sim:corridor-2d", {}, 44);
  ASSERT_EQ(input.scans.size(), 44u);
  const auto scan = [&](std::size_t i) { return scan_from_laser(input.scans[i], 0.05, 0.0, 0.0); };
  const auto pose = [&](std::size_t i) { return pose2(input.scans[i].pose); };
  const std::size_t current = 42, candidate = 38;  // past door recesses: not ambiguous
  std::vector<Scan2D> older;
  for (std::size_t j = candidate - 6; j < candidate; ++j) older.push_back(scan(j));
  std::vector<PosedScan2D> neighbours;
  for (std::size_t j = candidate - 6; j < candidate; ++j)
    neighbours.push_back({&older[j - (candidate - 6)], pose(candidate).inverse() * pose(j)});
  const Pose2 truth = pose(candidate).inverse() * pose(current);
  const Pose2 guess = truth * pose2(0.4, -0.3, 0.05);
  const LoopVerification2DOptions options;
  const LoopVerification2D alone = verify_loop_2d(scan(current), scan(candidate), guess, options);
  const LoopVerification2D joined =
      verify_loop_2d(scan(current), scan(candidate), guess, options, neighbours);
  EXPECT_FALSE(alone.accepted) << alone.paired_fraction;
  EXPECT_LT(alone.paired_fraction, options.min_paired_fraction);
  EXPECT_TRUE(joined.accepted) << joined.paired_fraction << " " << joined.error << " "
                               << joined.free_violations << " " << joined.constraint;
  EXPECT_LT((joined.transform.translation() - truth.translation()).norm(), 0.05);
  EXPECT_NEAR(pose2_angle(joined.transform), pose2_angle(truth), 0.5 * M_PI / 180);
}

TEST(LoopClosure2D, PreparedScansVerifyAsTheScansThemselves) {
  // One prepared submap serves several current scans and one prepared current scan several
  // candidates, in any order, after the scans they were made from are gone: each verification as
  // verify_loop_2d on the scans (accepted or not, to the last bit).
  const Scans2D input = load_scans_2d("sim:corridor-2d", {}, 44);
  ASSERT_EQ(input.scans.size(), 44u);
  const auto scan = [&](std::size_t i) { return scan_from_laser(input.scans[i], 0.05, 0.0, 0.0); };
  const auto pose = [&](std::size_t i) { return pose2(input.scans[i].pose); };
  const LoopVerification2DOptions options;
  const auto neighbours_of = [&](std::size_t candidate, std::vector<Scan2D>& scans) {
    scans.clear();
    for (std::size_t j = candidate - 6; j < candidate; ++j) scans.push_back(scan(j));
    std::vector<PosedScan2D> posed;
    for (std::size_t j = candidate - 6; j < candidate; ++j)
      posed.push_back({&scans[j - (candidate - 6)], pose(candidate).inverse() * pose(j)});
    return posed;
  };
  const auto same = [](const LoopVerification2D& a, const LoopVerification2D& b) {
    return a.accepted == b.accepted && a.transform.matrix() == b.transform.matrix() &&
           a.paired_fraction == b.paired_fraction && a.error == b.error &&
           a.free_violations == b.free_violations && a.constraint == b.constraint &&
           a.search_score == b.search_score && a.hessian == b.hessian &&
           a.shifted_fraction == b.shifted_fraction && a.sliding == b.sliding &&
           a.slide_direction == b.slide_direction;
  };
  std::vector<std::unique_ptr<LoopReference2D>> prepared;
  for (const std::size_t candidate : {30u, 38u}) {
    std::vector<Scan2D> scans;
    prepared.push_back(std::make_unique<LoopReference2D>(scan(candidate),
                                                         neighbours_of(candidate, scans), options));
  }
  std::size_t accepted = 0, rejected = 0;
  for (const std::size_t current : {43u, 40u, 42u, 33u}) {
    const LoopCurrent2D here(scan(current), options);
    for (std::size_t c = 0; c < prepared.size(); ++c) {
      const std::size_t candidate = c == 0 ? 30 : 38;
      const Pose2 guess = pose(candidate).inverse() * pose(current) * pose2(0.3, -0.2, 0.04);
      std::vector<Scan2D> scans;
      const LoopVerification2D expected = verify_loop_2d(scan(current), scan(candidate), guess,
                                                         options, neighbours_of(candidate, scans));
      const LoopVerification2D v = verify_loop_2d(here, *prepared[c], guess, options);
      EXPECT_TRUE(same(v, expected)) << current << " against " << candidate;
      (expected.accepted ? accepted : rejected) += 1;
    }
  }
  // Both outcomes were compared.
  EXPECT_GT(accepted, 0u);
  EXPECT_GT(rejected, 0u);
}

TEST(LoopClosure2D, AMatchAlongAPlainCorridorHoldsNothingAlongIt) {
  // A 180-degree scan down a corridor of plain walls (y = +-1.2 m): the match determines the
  // across direction and the heading, nothing along x. The loop edge's information (the
  // verification's Hessian) must say so; the verification accepts it only as sliding along x,
  // at the initial guess's x, and not at all without accept_sliding.
  Scan2D scan;
  for (int beam = 0; beam <= 180; ++beam) {
    const double a = (beam - 90) * M_PI / 180;
    if (std::abs(std::sin(a)) < 0.05) continue;  // beyond 24 m: no return
    const double r = 1.2 / std::abs(std::sin(a));
    scan.points.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  LoopVerification2DOptions options;
  const LoopVerification2D v = verify_loop_2d(scan, scan, pose2(0.3, 0.1, 0.02), options);
  ASSERT_GT(v.hessian(1, 1), 0.0);
  EXPECT_LT(v.hessian(0, 0), 1e-3 * v.hessian(1, 1));
  EXPECT_GT(v.hessian(2, 2), 0.0);
  ASSERT_TRUE(v.accepted);
  EXPECT_TRUE(v.sliding);
  EXPECT_NEAR(std::abs(v.slide_direction.x()), 1.0, 1e-3);
  EXPECT_NEAR(v.transform.translation().x(), 0.3, 0.02);  // held where the guess put it
  EXPECT_NEAR(v.transform.translation().y(), 0.0, 0.01);  // across and heading: determined
  EXPECT_NEAR(pose2_angle(v.transform), 0.0, 0.2 * M_PI / 180);
  options.accept_sliding = false;
  EXPECT_FALSE(verify_loop_2d(scan, scan, pose2(0.3, 0.1, 0.02), options).accepted);
}

TEST(LoopClosure2D, AStepAPlainCorridorLeavesOpenIsHeldLooselyAlongIt) {
  // Down a corridor of plain walls the odometry reports 0.1 m for a 1 m step (it slid, as ACES's
  // did): the scans fit anywhere along it, so the odometry edge must hold x loosely (for a loop to
  // stretch it back) and y and the heading as firmly as ever; the scan becomes a keyframe though
  // the odometry hardly moved. Past the corridor's end wall the step is determined again.
  Scan2D corridor;  // both walls sampled every 5 cm from x = -20 to 20 m
  for (double y : {-1.2, 1.2})
    for (int i = -400; i <= 400; ++i) corridor.points.emplace_back(0.05 * i, y);
  Scan2D ended;  // walls from x = 0 to 6 m and a wall across at x = 6 m
  for (double y : {-1.2, 1.2})
    for (int i = 0; i <= 120; ++i) ended.points.emplace_back(0.05 * i, y);
  for (int i = -23; i <= 23; ++i) ended.points.emplace_back(6.0, 0.05 * i);
  LoopClosure2DOptions options;
  LoopClosure2D loops(options);
  loops.add_scan(corridor, Pose2::Identity());
  EXPECT_TRUE(loops.add_scan(corridor, pose2(0.1, 0.0, 0.0)));
  ASSERT_EQ(loops.counts().open_odometry_edges, 1u);
  ASSERT_EQ(loops.graph().edges().size(), 1u);
  const Eigen::Matrix3d& open = loops.graph().edges()[0].information;
  const double firm = 1.0 / (options.odometry_sigma_xy * options.odometry_sigma_xy);
  EXPECT_LT(open(0, 0), 0.05 * firm);
  EXPECT_NEAR(open(1, 1), firm, 1e-6 * firm);
  EXPECT_NEAR(open(2, 2), 1.0 / std::pow(options.odometry_sigma_theta, 2), 1e-6);
  // A 1 m step towards the end wall: determined, the fixed information.
  LoopClosure2D towards_the_end(options);
  towards_the_end.add_scan(ended, Pose2::Identity());
  Scan2D closer = ended;  // seen from 1 m further along x
  for (Eigen::Vector2d& p : closer.points) p.x() -= 1.0;
  towards_the_end.add_scan(closer, pose2(1.0, 0.0, 0.0));
  EXPECT_EQ(towards_the_end.counts().open_odometry_edges, 0u);
  ASSERT_EQ(towards_the_end.graph().edges().size(), 1u);
  EXPECT_NEAR(towards_the_end.graph().edges()[0].information(0, 0), firm, 1e-6 * firm);
  // Off: every edge fixed, and a scan that hardly moved is no keyframe.
  options.odometry_spread_window = 0.0;
  LoopClosure2D fixed(options);
  fixed.add_scan(corridor, Pose2::Identity());
  EXPECT_FALSE(fixed.add_scan(corridor, pose2(0.1, 0.0, 0.0)));
  EXPECT_EQ(fixed.counts().open_odometry_edges, 0u);
}

TEST(LoopClosure2D, AnOpenStepThatTurnsIsLooseAlongTheCorridorNotAlongItsTurnedFrame) {
  // The scans fit anywhere along the previous keyframe's x (a corridor), and the robot turned 60
  // degrees during the step (ACES's wrong step turned 41). Another edge pulls the step 1 m along
  // that corridor: the open edge must give way along it and hold across it, whatever the turn.
  const double sigma_xy = 0.05, sigma_theta = 0.5 * M_PI / 180;
  Eigen::Matrix2d spread = Eigen::Matrix2d::Zero();
  spread(0, 0) = 1.0;  // m^2 along x, nothing across
  for (const double turn : {0.0, 60.0 * M_PI / 180, -120.0 * M_PI / 180}) {
    const Pose2 measured = pose2(0.1, 0.0, turn);
    const Eigen::Matrix3d open =
        spread_odometry_information(spread, measured, sigma_xy, sigma_theta, 0.1);
    PoseGraph2D graph;
    graph.add_node(Pose2::Identity());
    graph.add_node(measured);
    graph.add_edge(0, 1, measured, open, EdgeKind::kOdometry);
    const Eigen::Vector3d firm(1 / (sigma_xy * sigma_xy), 1 / (sigma_xy * sigma_xy),
                               1 / (sigma_theta * sigma_theta));
    graph.add_edge(0, 1, pose2(1.1, 0.0, turn), firm.asDiagonal(), EdgeKind::kOdometry);
    graph.optimize();
    EXPECT_NEAR(graph.pose(1).translation().x(), 1.1, 0.05) << "turn " << turn;
    EXPECT_NEAR(graph.pose(1).translation().y(), 0.0, 0.01) << "turn " << turn;
    // Without a spread: the fixed sigmas.
    EXPECT_TRUE(
        spread_odometry_information(Eigen::Matrix2d::Zero(), measured, sigma_xy, sigma_theta, 0.1)
            .isApprox(firm.asDiagonal().toDenseMatrix()));
  }
}

namespace {

/// Once around the yard (yard_fronts) and back to the start: 1 m steps along a 12 x 8 m
/// rectangle, each corner turned in three steps, then one step past the start.
std::vector<Pose2> yard_loop_truth() {
  std::vector<Pose2> truth;
  const auto drive = [&](Eigen::Vector2d from, Eigen::Vector2d to, double heading) {
    const int steps = static_cast<int>(std::round((to - from).norm()));
    for (int i = 0; i < steps; ++i) {
      const Eigen::Vector2d p = from + (to - from) * (static_cast<double>(i) / steps);
      truth.push_back(pose2(p.x(), p.y(), heading));
    }
  };
  const auto turn = [&](Eigen::Vector2d at, double from, double to) {
    for (int i = 0; i < 3; ++i) truth.push_back(pose2(at.x(), at.y(), from + (to - from) * i / 3));
  };
  drive({0, 0}, {12, 0}, 0.0);
  turn({12, 0}, 0.0, M_PI / 2);
  drive({12, 0}, {12, 8}, M_PI / 2);
  turn({12, 8}, M_PI / 2, M_PI);
  drive({12, 8}, {0, 8}, M_PI);
  turn({0, 8}, M_PI, 1.5 * M_PI);
  drive({0, 8}, {0, 0}, 1.5 * M_PI);
  truth.push_back(pose2(0.0, 0.0, 2 * M_PI));
  truth.push_back(pose2(1.0, 0.0, 2 * M_PI));
  return truth;
}

}  // namespace

TEST(LoopClosure2D, WeakStepsBetweenKeyframesWidenTheirSearch) {
  // A robot drives once around a yard of building fronts and returns to its start. On the far
  // side its odometry jumps 3.5 m sideways (freiburg-campus: scans that fit nothing and weave),
  // so back at the start the estimate lies 3.5 m beside it: within the 4 m proximity radius, but
  // beyond the verification's 2 m search window. Where the scans that went wrong were weak, the
  // search between the keyframes about them widens and the loop closes; where the odometry
  // fitted, the search stays narrow.
  const std::vector<Segment> fronts = scanmatch::testing::yard_fronts();
  const std::vector<Pose2> truth = yard_loop_truth();
  // The odometry: the truth, but for a 3.5 m jump sideways on the far side.
  constexpr std::size_t kJump = 22;
  const auto final_error = [&](bool weak, std::size_t& closing) {
    LoopClosure2DOptions options;
    options.widening_per_weak_step = 0.2;  // few weak scans here: the widening's full 2.5x
    options.max_correction_per_m = 0.1;    // a 48 m loop: the gate lets 5.8 m through
    LoopClosure2D loops(options);
    for (std::size_t i = 0; i < truth.size(); ++i) {
      const Pose2 odometry = i >= kJump ? pose2(0.0, 3.5, 0.0) * truth[i] : truth[i];
      const bool weak_here = weak && i >= kJump - 4 && i < kJump + 4;
      loops.add_scan(half_scan(fronts, truth[i]), odometry, weak_here);
    }
    loops.finish();
    closing = 0;
    for (const Loop2D& l : loops.loops())
      closing += !l.outlier && l.from_scan < kJump && l.to_scan + 10 >= truth.size();
    const Pose2 error = truth.back().inverse() * loops.poses().back();
    return error.translation().norm();
  };
  std::size_t closing_weak = 0, closing_firm = 0;
  const double widened = final_error(true, closing_weak);
  const double narrow = final_error(false, closing_firm);
  std::printf(
      "yard loop with a 3.5 m jump: last pose %.3f m off with weak steps, %.3f m without; "
      "%zu and %zu loops to the start\n",
      widened, narrow, closing_weak, closing_firm);
  EXPECT_GT(closing_weak, 0u);
  EXPECT_EQ(closing_firm, 0u);
  EXPECT_LT(widened, 0.3);
  EXPECT_GT(narrow, 3.0);
}

TEST(LoopClosure2D, ATurnOnTheSpotIsHeldByTheWallsItStartedFrom) {
  // A 180-degree laser turns 25 deg a step on the spot for 20 steps (500 deg); the odometry
  // turns each step 0.5 deg too far (ACES's dead end: 6 deg over 15 steps). After a full turn the
  // scans show the walls of the first steps again, a few keyframes back: edges there hold the
  // heading. With the newest 30 keyframes skipped nothing can.
  const std::vector<Segment> walls = room_walls();
  const Eigen::Vector2d spot(0.5, 0.3);
  const double step = -25.0 * M_PI / 180, bias = -0.5 * M_PI / 180;
  const auto final_heading_error = [&](const LoopClosure2DOptions& options) {
    LoopClosure2D loops(options);
    for (int i = 0; i <= 20; ++i) {
      const Pose2 truth = pose2(spot.x(), spot.y(), i * step);
      loops.add_scan(half_scan(walls, truth), pose2(spot.x(), spot.y(), i * (step + bias)));
    }
    loops.finish();
    // The scans are exact, the submaps they are verified against are joined by the drifting
    // estimate (6 keyframes either side: up to 3 deg apart).
    for (const Loop2D& loop : loops.loops()) {
      const Pose2 truth = pose2(0, 0, (loop.to_scan - loop.from_scan) * step);
      EXPECT_LT((loop.relative.translation() - truth.translation()).norm(), 0.05);
      EXPECT_LT(std::abs(pose2_angle(truth.inverse() * loop.relative)), 3.0 * M_PI / 180);
    }
    return std::abs(std::remainder(pose2_angle(loops.poses().back()) - 20 * step, 2 * M_PI));
  };
  const LoopClosure2DOptions defaults;
  const double odometry_error = 20 * 0.5 * M_PI / 180;
  EXPECT_LT(final_heading_error(defaults), odometry_error / 3);
  LoopClosure2DOptions skip_30 = defaults;
  skip_30.skip_recent = 30;
  EXPECT_NEAR(final_heading_error(skip_30), odometry_error, 0.5 * M_PI / 180);
}

// A round room of `radius` m about the origin, as 72 straight walls.
std::vector<Segment> round_room(double radius) {
  std::vector<Segment> walls;
  for (int i = 0; i < 72; ++i) {
    const double a = i * 5.0 * M_PI / 180, b = (i + 1) * 5.0 * M_PI / 180;
    walls.push_back({radius * Eigen::Vector2d(std::cos(a), std::sin(a)),
                     radius * Eigen::Vector2d(std::cos(b), std::sin(b))});
  }
  return walls;
}

TEST(LoopClosure2D, ATurnInARoundRoomLeavesTheRotationOpen) {
  // Turning 30 degrees on the spot: in a round room every rotation fits as well (fhw's spin among
  // visitors came near that), in the asymmetric room only the step's own. The rotation-open step
  // gets a loose rotation, the other the fixed sigma.
  const Pose2 step = pose2(0.0, 0.0, 30.0 * M_PI / 180);
  struct Room {
    std::vector<Segment> walls;
    Eigen::Vector2d spot;
  };
  const Room round{round_room(4.0), Eigen::Vector2d::Zero()};
  const Room walled{room_walls(), Eigen::Vector2d(0.5, 0.3)};
  const auto scans = [](const Room& room, const Pose2& step_taken) {
    const Pose2 start = pose2(room.spot.x(), room.spot.y(), 0.0);
    return std::make_pair(half_scan(room.walls, start), half_scan(room.walls, start * step_taken));
  };
  const auto [round_before, round_after] = scans(round, step);
  const auto [walled_before, walled_after] = scans(walled, step);
  const double round_ratio = rotation_ambiguity_2d(round_after, round_before, step);
  const double walled_ratio = rotation_ambiguity_2d(walled_after, walled_before, step);
  std::printf("rotation ambiguity: round room %.2f, walled room %.2f\n", round_ratio, walled_ratio);
  const LoopClosure2DOptions options;
  EXPECT_GE(round_ratio, options.rotation_open_ratio);
  EXPECT_LT(walled_ratio, 0.75);
  EXPECT_EQ(rotation_ambiguity_2d(Scan2D{}, walled_before, step), 0.0);  // nothing to score
  // Asked only for ratios reaching a threshold, the far search ends early: the ratio is the same
  // where it reaches it (also exactly at it), and below it where it does not.
  EXPECT_EQ(rotation_ambiguity_2d(round_after, round_before, step, 0.5, 0.9), round_ratio);
  EXPECT_EQ(rotation_ambiguity_2d(round_after, round_before, step, 0.5, round_ratio), round_ratio);
  EXPECT_EQ(rotation_ambiguity_2d(walled_after, walled_before, step, 0.5, walled_ratio),
            walled_ratio);
  EXPECT_LT(rotation_ambiguity_2d(walled_after, walled_before, step, 0.5, 0.9), 0.9);
  EXPECT_LT(rotation_ambiguity_2d(walled_after, walled_before, step, 0.5, walled_ratio + 0.05),
            walled_ratio + 0.05);

  const auto edge_rotation_information = [&](const Scan2D& before, const Scan2D& after,
                                             const LoopClosure2DOptions& o) {
    LoopClosure2D loops(o);
    loops.add_scan(before, Pose2::Identity());
    EXPECT_TRUE(loops.add_scan(after, step));
    EXPECT_EQ(loops.graph().edges().size(), 1u);
    return std::make_pair(loops.graph().edges().at(0).information(2, 2),
                          loops.counts().rotation_open_odometry_edges);
  };
  const double firm = 1.0 / std::pow(options.odometry_sigma_theta, 2);
  const double loose = 1.0 / std::pow(options.rotation_open_sigma_theta, 2);
  const auto [round_information, round_open] =
      edge_rotation_information(round_before, round_after, options);
  EXPECT_EQ(round_open, 1u);
  EXPECT_NEAR(round_information, loose, 1e-6 * loose);
  const auto [walled_information, walled_open] =
      edge_rotation_information(walled_before, walled_after, options);
  EXPECT_EQ(walled_open, 0u);
  EXPECT_NEAR(walled_information, firm, 1e-6 * firm);
  LoopClosure2DOptions off = options;
  off.rotation_open_ratio = 0.0;
  const auto [off_information, off_open] =
      edge_rotation_information(round_before, round_after, off);
  EXPECT_EQ(off_open, 0u);
  EXPECT_NEAR(off_information, firm, 1e-6 * firm);
}

TEST(LoopClosure2D, AStepWithAWeakFitIsTestedForItsRotationHoweverLittleItTurned) {
  // corridor-2d driven for 800 scans turns a 90-degree corner between scans 81 and 82, where
  // going straight on fits about as well (half the points either way). The odometry goes straight
  // on and flags the step weak (Scan2DStats::weak_fit): only then does the step take the rotation
  // test, for it turned 0 degrees, below rotation_open_min_turn. A loop across the loose step can
  // then turn the rest of the map (ALoopAcrossARotationOpenStepTurnsTheMapIfPresent).
  sim::SimOptions sim_options;
  sim_options.preset = "corridor-2d";
  sim_options.frames = 800;
  const sim::Simulator simulator(sim_options);
  LoopClosure2DOptions options;
  options.keyframe_distance = 0.5;  // each step a keyframe step
  const auto open_edges = [&](std::size_t first, const Pose2& step, bool weak_fit) {
    LoopClosure2D loops(options);
    loops.add_scan(scan_from_laser(simulator.scan_2d(first), 0.05, 0.0, 0.0), Pose2::Identity());
    EXPECT_TRUE(loops.add_scan(scan_from_laser(simulator.scan_2d(first + 1), 0.05, 0.0, 0.0), step,
                               weak_fit));
    return loops.counts().rotation_open_odometry_edges;
  };
  const Pose2 straight_on = pose2(0.81, 0.15, 0.0);  // what the odometry took at the corner
  const Pose2 corner =
      pose2(simulator.scan_2d(81).pose).inverse() * pose2(simulator.scan_2d(82).pose);
  ASSERT_GT(std::abs(pose2_angle(corner)), 80.0 * M_PI / 180);
  EXPECT_EQ(open_edges(81, straight_on, false), 0u);
  EXPECT_EQ(open_edges(81, straight_on, true), 1u);
  // Along the corridor before the corner the flag alone makes no step open: the test decides.
  const Pose2 along =
      pose2(simulator.scan_2d(40).pose).inverse() * pose2(simulator.scan_2d(41).pose);
  EXPECT_EQ(open_edges(40, along, true), 0u);
  std::printf(
      "rotation ambiguity: corner taken straight on %.2f, along the corridor %.2f\n",
      rotation_ambiguity_2d(scan_from_laser(simulator.scan_2d(82), 0.05, 0.0, 0.0),
                            scan_from_laser(simulator.scan_2d(81), 0.05, 0.0, 0.0), straight_on),
      rotation_ambiguity_2d(scan_from_laser(simulator.scan_2d(41), 0.05, 0.0, 0.0),
                            scan_from_laser(simulator.scan_2d(40), 0.05, 0.0, 0.0), along));
}

TEST(LoopClosure2D, ACorridorWithEvenlySpacedDoorsIsAmbiguous) {
  // Walls at y = +-1.2 m with a 0.6 m wide, 0.3 m deep door recess every 2 m on both sides, seen
  // by a 180-degree laser (1 deg beams, 30 m). A scan matched 2 m along (one door further) fits as
  // well as in place: without the shift test it would be accepted as determined; with it, it is
  // sliding (or rejected without accept_sliding), fitted again where the anchor puts it along x.
  std::vector<Segment> walls;
  for (double x = -10.0; x < 40.0; x += 2.0)
    for (double side : {-1.0, 1.0}) {
      const double y = 1.2 * side, deep = 1.5 * side;
      walls.push_back({{x, y}, {x + 1.4, y}});
      walls.push_back({{x + 1.4, y}, {x + 1.4, deep}});
      walls.push_back({{x + 1.4, deep}, {x + 2.0, deep}});
      walls.push_back({{x + 2.0, deep}, {x + 2.0, y}});
    }
  const auto scan_at = [&](double x0) { return half_scan(walls, pose2(x0, 0.0, 0.0)); };
  const Scan2D here = scan_at(0.3), later = scan_at(2.3);  // one door further along
  LoopVerification2DOptions options;
  const LoopVerification2D checked = verify_loop_2d(later, here, pose2(0.1, 0.0, 0.0), options);
  options.max_shifted_fraction = 0.0;
  const LoopVerification2D unchecked = verify_loop_2d(later, here, pose2(0.1, 0.0, 0.0), options);
  EXPECT_TRUE(unchecked.accepted) << unchecked.paired_fraction << " " << unchecked.constraint;
  EXPECT_FALSE(unchecked.sliding);
  EXPECT_TRUE(checked.accepted);
  EXPECT_TRUE(checked.sliding);
  EXPECT_GT(checked.shifted_fraction, 0.8);
  EXPECT_NEAR(std::abs(checked.slide_direction.x()), 1.0, 0.05);
  // The truth is 2 m along: anchored 0.15 m from it, the fit finds the right door (where the
  // scans' sparse far samples no longer coincide, so fewer points pair than at the alias).
  options.max_shifted_fraction = 0.8;
  const LoopVerification2D anchored =
      verify_loop_2d(later, here, pose2(0.1, 0.0, 0.0), options, {}, pose2(1.85, 0.0, 0.0));
  ASSERT_TRUE(anchored.accepted) << anchored.paired_fraction << " " << anchored.error << " "
                                 << anchored.free_violations << " "
                                 << anchored.transform.translation().transpose();
  EXPECT_TRUE(anchored.sliding);
  EXPECT_NEAR(anchored.transform.translation().x(), 2.0, 0.05);
  EXPECT_NEAR(anchored.transform.translation().y(), 0.0, 0.03);
  options.accept_sliding = false;
  EXPECT_FALSE(verify_loop_2d(later, here, pose2(0.1, 0.0, 0.0), options).accepted);
}

TEST(LoopClosure2D, FreeSpaceIsSeenBetweenOneDegreeBeams) {
  // The candidate saw a 1 m box at x = 2.5 m (an object moved away since, or another place) where
  // the current scan, 1 m further along, sees the far wall: a tenth of the candidate's points lie
  // in the current scan's free space. With bearings binned finer than the beams this went unseen
  // (every other bin empty).
  std::vector<Segment> with_box = room_walls();
  with_box.push_back({{2.5, -0.5}, {2.5, 0.5}});
  const Pose2 truth = pose2(1.0, 0.2, 0.05);
  const Scan2D current = half_scan(room_walls(), truth);
  const LoopVerification2DOptions options;
  const LoopVerification2D same =
      verify_loop_2d(current, half_scan(room_walls(), Pose2::Identity()), truth, options);
  EXPECT_TRUE(same.accepted) << same.paired_fraction << " " << same.free_violations;
  EXPECT_LT(same.free_violations, 0.01);
  const LoopVerification2D moved =
      verify_loop_2d(current, half_scan(with_box, Pose2::Identity()), truth, options);
  EXPECT_FALSE(moved.accepted);
  EXPECT_GT(moved.free_violations, 0.08);
  // Joined scans: each saw free space from its own pose. The candidate faces away (it sees x < 0)
  // and a neighbour taken at its side sees the room without the box: the box in the current scan
  // lies in the neighbour's free space, though not in the candidate's.
  const Scan2D facing_away = half_scan(room_walls(), pose2(0.0, 0.0, M_PI));
  const Scan2D beside = half_scan(room_walls(), Pose2::Identity());
  const std::vector<PosedScan2D> neighbours{{&beside, pose2(0.0, 0.0, M_PI)}};  // in facing_away's
  const Pose2 in_facing_away = pose2(0.0, 0.0, M_PI).inverse() * truth;
  const LoopVerification2D boxed =
      verify_loop_2d(half_scan(with_box, truth), facing_away, in_facing_away, options, neighbours);
  EXPECT_FALSE(boxed.accepted);
  EXPECT_GT(boxed.free_violations, 0.08);
  // And without the box the same place is a loop, though the candidate alone pairs nothing of the
  // current scan (they look opposite ways): the way back then has no error or constraint to
  // report, only its free space.
  const LoopVerification2D loop =
      verify_loop_2d(current, facing_away, in_facing_away, options, neighbours);
  EXPECT_TRUE(loop.accepted) << loop.paired_fraction << " " << loop.error << " "
                             << loop.free_violations << " " << loop.constraint;
  EXPECT_LT((loop.transform.translation() - in_facing_away.translation()).norm(), 0.03);
}

TEST(LoopClosure2D, StepsTheOdometryCouldNotRegisterBendFirst) {
  // The yard driven once around, the odometry jumping 1 m sideways on the far side where its
  // scans fit nothing (freiburg-campus 490-497): the loop back at the start takes the metre out.
  // Held as firmly as the measured steps, the jump's edges give back a share of it only and the
  // rest bends every step of the far side; held loosely (unfit_step_information), they take
  // most of it where it was made.
  const std::vector<Segment> fronts = scanmatch::testing::yard_fronts();
  const std::vector<Pose2> truth = yard_loop_truth();
  constexpr std::size_t kJump = 22;
  const auto ground_scan = [](std::size_t i) {
    Scan2D scan;
    const double k = static_cast<double>(i);
    for (int beam = 0; beam < 181; ++beam) {
      const double a = -M_PI / 2 + beam * M_PI / 180;
      const double r = 7.5 + 1.5 * std::sin(1.9 * k) - 3.0 * std::abs(std::sin(a)) +
                       1.2 * std::sin(2.7 * beam * beam + 1.3 * k);
      scan.points.emplace_back(r * std::cos(a), r * std::sin(a));
    }
    return scan;
  };
  const auto rms_error = [&](bool mark_unfit, std::size_t& closing) {
    LoopClosure2D loops;
    for (std::size_t i = 0; i < truth.size(); ++i) {
      // Spread over the four scans that fit nothing, as a registration on little spreads it.
      const double jumped =
          0.25 * static_cast<double>(std::clamp<std::size_t>(i, kJump, kJump + 4) - kJump);
      const Pose2 odometry = pose2(0.0, jumped, 0.0) * truth[i];
      const bool unfit_here = mark_unfit && i > kJump && i <= kJump + 4;
      // Those scans show rough ground only: no loop can be verified onto them or across them.
      const bool ground = i > kJump && i <= kJump + 4;
      loops.add_scan(ground ? ground_scan(i) : half_scan(fronts, truth[i]), odometry, false,
                     unfit_here);
    }
    loops.finish();
    closing = 0;
    for (const Loop2D& l : loops.loops())
      closing += !l.outlier && l.from_scan < kJump && l.to_scan + 10 >= truth.size();
    const std::vector<Pose2> poses = loops.poses();
    double sum = 0.0;
    for (std::size_t i = 0; i < truth.size(); ++i)
      sum += (poses[i].translation() - truth[i].translation()).squaredNorm();
    return std::sqrt(sum / static_cast<double>(truth.size()));
  };
  std::size_t closing_loose = 0, closing_firm = 0;
  const double loose = rms_error(true, closing_loose);
  const double firm = rms_error(false, closing_firm);
  std::printf("yard loop with a 1 m jump: RMS error %.3f m held loosely, %.3f m held firmly\n",
              loose, firm);
  EXPECT_GT(closing_loose, 0u);
  EXPECT_GT(closing_firm, 0u);
  EXPECT_LT(loose, 0.8 * firm);
}

TEST(LoopClosure2D, OptionsOutOfRangeAreRefused) {
  const auto refused = [](auto change) {
    LoopClosure2DOptions o;
    change(o);
    EXPECT_THROW(LoopClosure2D{o}, Error);
  };
  refused([](LoopClosure2DOptions& o) { o.loop_sigma_xy = 0.0; });
  refused([](LoopClosure2DOptions& o) { o.keyframe_distance = -1.0; });
  refused([](LoopClosure2DOptions& o) { o.verification.max_shifted_fraction = -0.5; });
  refused([](LoopClosure2DOptions& o) { o.max_error_per_floor = -1.0; });
  refused([](LoopClosure2DOptions& o) { o.max_error_per_floor = std::nan(""); });
  refused([](LoopClosure2DOptions& o) { o.verification.min_search_score = 1.2; });
  refused([](LoopClosure2DOptions& o) { o.optimize_above = -0.1; });
  refused([](LoopClosure2DOptions& o) { o.recheck_above = std::nan(""); });
  refused([](LoopClosure2DOptions& o) { o.registration_reach = std::nan(""); });
  refused([](LoopClosure2DOptions& o) { o.widening_per_weak_step = -0.01; });
  refused([](LoopClosure2DOptions& o) { o.max_doubt_widening = std::nan(""); });
  refused([](LoopClosure2DOptions& o) { o.odometry_spread_margin = -0.01; });
  refused([](LoopClosure2DOptions& o) { o.odometry_spread_window = std::nan(""); });
  refused([](LoopClosure2DOptions& o) { o.rotation_open_ratio = -0.1; });
  refused([](LoopClosure2DOptions& o) { o.rotation_open_sigma_theta = 0.0; });
  refused([](LoopClosure2DOptions& o) { o.rotation_open_min_turn = std::nan(""); });
  refused([](LoopClosure2DOptions& o) { o.sliding_information_kept = 1.5; });
  refused([](LoopClosure2DOptions& o) { o.unfit_step_information = 0.0; });
  refused([](LoopClosure2DOptions& o) { o.unfit_step_information = std::nan(""); });
  refused([](LoopClosure2DOptions& o) { o.verification.method = "no-such-method"; });
  EXPECT_NO_THROW(LoopClosure2D{LoopClosure2DOptions{}});
}

TEST(LoopClosure2D, VerificationRejectsTwoDifferentPlaces) {
  const Scans2D input = room_scans(400);
  const auto scan = [&](std::size_t i) { return scan_from_laser(input.scans[i], 0.05, 0.0, 0.0); };
  const LoopVerification2DOptions options;
  // A scan against itself from a guess 0.3 m and 5 deg off: the same place.
  const LoopVerification2D same =
      verify_loop_2d(scan(10), scan(10), pose2(0.3, -0.2, 0.09), options);
  EXPECT_TRUE(same.accepted) << same.paired_fraction << " " << same.error << " "
                             << same.free_violations;
  EXPECT_LT(same.transform.translation().norm(), 0.02);
  EXPECT_GT(same.search_score, 0.8);
  // A scan in a room against scans in the hallway (the rooms are identical copies, so only a
  // room against the hallway is surely two different places): every guess the candidate sources
  // could give (the identity, and the descriptor's best yaw) must be rejected.
  sim::SimOptions so;
  so.preset = "room-2d";
  const sim::Simulator simulator(so);
  const Pose scene_from_world = simulator.scene_pose_at(0.0);
  const Pose2 first = pose2(input.scans[0].pose);
  const auto scene_y = [&](std::size_t i) {
    const Eigen::Vector2d p = (first.inverse() * pose2(input.scans[i].pose)).translation();
    return (scene_from_world * Eigen::Vector3d(p.x(), p.y(), 0.0)).y();
  };
  std::size_t compared = 0;
  for (std::size_t a = 0; a < input.scans.size(); a += 20)
    for (std::size_t b = 10; b < input.scans.size(); b += 40) {
      if (!(scene_y(a) < 3.0 && scene_y(b) > 4.8)) continue;
      ++compared;
      const PlaceMatch match =
          compare(make_place_descriptor(scan(b)), make_place_descriptor(scan(a)));
      for (const Pose2& guess : {Pose2(Pose2::Identity()), pose2(0, 0, match.yaw)}) {
        const LoopVerification2D v = verify_loop_2d(scan(b), scan(a), guess, options);
        EXPECT_FALSE(v.accepted) << a << " vs " << b << ": " << v.paired_fraction << " " << v.error
                                 << " " << v.free_violations << " " << v.constraint;
      }
    }
  std::printf("%zu room / hallway pairs compared\n", compared);
  EXPECT_GT(compared, 0u);
  // Bad input never crashes: empty and non-finite scans are rejected.
  Scan2D empty, broken = scan(0);
  broken.points[3].x() = std::nan("");
  EXPECT_FALSE(verify_loop_2d(empty, scan(0), Pose2::Identity(), options).accepted);
  EXPECT_FALSE(verify_loop_2d(broken, scan(0), Pose2::Identity(), options).accepted);
}

TEST(LoopClosure2D, CliWritesTheLoopClosedRun) {
  scanmatch::testing::TempDir dir;
  const auto r = scanmatch::testing::run_cli(
      "map2d sim:room-2d --scans 300 --method pl-icp --no-motion-distortion --loop-closure "
      "--reference-map --quiet --out " +
      dir.file("run"));
  ASSERT_EQ(r.status, 0) << r.output;
  for (const char* name : {"poses_tum.txt", "poses_optimized_tum.txt", "loops.json", "summary.json",
                           "config.json", "map.pgm", "map.yaml", "map.png", "map_odometry.pgm",
                           "map_odometry.yaml", "map_odometry.png", "map_reference.pgm"})
    EXPECT_TRUE(std::filesystem::exists(dir.file(std::string("run/") + name))) << name;
  std::ifstream poses(dir.file("run/poses_optimized_tum.txt"));
  std::size_t lines = 0;
  for (std::string l; std::getline(poses, l);) lines += !l.empty() && l[0] != '#';
  EXPECT_EQ(lines, 300u);
  const auto loops = nlohmann::json::parse(std::ifstream(dir.file("run/loops.json")));
  ASSERT_TRUE(loops.is_array());
  for (const auto& l : loops) {
    EXPECT_LT(l.at("from").get<int>(), l.at("to").get<int>());
    EXPECT_GE(l.at("paired_fraction").get<double>(), 0.6);
  }
  const auto summary = nlohmann::json::parse(std::ifstream(dir.file("run/summary.json")));
  ASSERT_TRUE(summary.contains("loop_closure"));
  EXPECT_EQ(summary["loop_closure"]["accepted"].get<std::size_t>(), loops.size());
  EXPECT_TRUE(summary.contains("ate") && summary.contains("ate_odometry"));
  const auto config = nlohmann::json::parse(std::ifstream(dir.file("run/config.json")));
  EXPECT_TRUE(config.at("loop_closure").get<bool>());
  EXPECT_TRUE(summary["loop_closure"]["thread"].get<bool>());
}

TEST(LoopClosure2D, OnItsOwnThreadItClosesTheSameLoopsAsInline) {
  // Loop closure sees the same scans in the same order either way: the same loops and poses.
  // (CliWritesTheLoopClosedRun runs the thread under the sanitizers.)
  if (scanmatch::testing::sanitized()) GTEST_SKIP() << "600 scans twice: too slow sanitized";
  scanmatch::testing::TempDir dir;
  const std::string common =
      "map2d sim:room-2d --scans 600 --method pl-icp --no-motion-distortion --loop-closure "
      "--quiet ";
  const auto threaded = scanmatch::testing::run_cli(common + "--out " + dir.file("thread"));
  ASSERT_EQ(threaded.status, 0) << threaded.output;
  const auto inline_run =
      scanmatch::testing::run_cli(common + "--no-loop-closure-thread --out " + dir.file("inline"));
  ASSERT_EQ(inline_run.status, 0) << inline_run.output;
  const auto text = [&](const std::string& name) {
    std::ifstream in(dir.file(name));
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const auto loops = nlohmann::json::parse(text("thread/loops.json"));
  EXPECT_GE(loops.size(), 10u);
  EXPECT_EQ(text("thread/loops.json"), text("inline/loops.json"));
  EXPECT_EQ(text("thread/poses_optimized_tum.txt"), text("inline/poses_optimized_tum.txt"));
  const auto summary = [&](const std::string& name) {
    return nlohmann::json::parse(text(name + "/summary.json"));
  };
  EXPECT_TRUE(summary("thread")["loop_closure"]["thread"].get<bool>());
  EXPECT_FALSE(summary("inline")["loop_closure"]["thread"].get<bool>());
  EXPECT_GT(summary("thread")["wall_ms_per_scan"].get<double>(), 0.0);
}

TEST(LoopClosure2D, CarmenLogStartIfPresent) {
  const std::string log = scanmatch::testing::shared_data("data/2d/carmen/intel-corrected.log.gz");
  if (log.empty()) GTEST_SKIP() << "../shared/data/2d/carmen is absent";
  if (scanmatch::testing::sanitized()) GTEST_SKIP() << "1500 scans: too slow sanitized";
  scanmatch::testing::TempDir dir;
  const auto r = scanmatch::testing::run_cli(
      "map2d " + log + " --scans 1500 --loop-closure --quiet --out " + dir.file("run"));
  ASSERT_EQ(r.status, 0) << r.output;
  const auto summary = nlohmann::json::parse(std::ifstream(dir.file("run/summary.json")));
  EXPECT_LE(summary["ate"]["rmse_m"].get<double>(),
            summary["ate_odometry"]["rmse_m"].get<double>() * 1.05);
}

// `map2d LOG --scans N --loop-closure` into dir/name, with `config` (JSON; empty: none) as its
// --config; its summary.json. The run's loops.json is dir/name/loops.json.
nlohmann::json run_loop_closed_log(const std::string& log, int scans, const std::string& config,
                                   const scanmatch::testing::TempDir& dir,
                                   const std::string& name) {
  std::string options;
  if (!config.empty()) {
    std::ofstream(dir.file(name + ".json")) << config;
    options = " --config " + dir.file(name + ".json");
  }
  const auto r =
      scanmatch::testing::run_cli("map2d " + log + " --scans " + std::to_string(scans) +
                                  " --loop-closure --quiet" + options + " --out " + dir.file(name));
  EXPECT_EQ(r.status, 0) << r.output;
  return nlohmann::json::parse(std::ifstream(dir.file(name + "/summary.json")));
}

TEST(LoopClosure2D, KeyframesBeforeABigCorrectionLookAgainIfPresent) {
  // ACES's first 270 scans: a long dead end (scans 163-251) whose way back reaches its mouth, by
  // the start, with the odometry 4 m off; the proximity candidates there lie beyond the search
  // window, and the start is joined first by the descriptor's candidates at scans 255-257. The
  // optimization then moves the estimate by metres: the keyframes just before look for loops
  // again (recheck_keyframes) and join the mouth to the start: nearly half the error. Scan-to-scan
  // odometry with the no-return readings as points makes that premise; with today's defaults the
  // rechecks still join more of the mouth to the start (13 loops against 8) but the error they
  // mend is gone (0.138 against 0.146 m).
  const std::string log = scanmatch::testing::shared_data("data/2d/carmen/aces-corrected.log.gz");
  if (log.empty()) GTEST_SKIP() << "../shared/data/2d/carmen is absent";
  if (scanmatch::testing::sanitized()) GTEST_SKIP() << "too slow under the sanitizers";
  scanmatch::testing::TempDir dir;
  struct Run {
    double ate = 0.0, ate_odometry = 0.0;
    std::size_t start_to_mouth = 0;  ///< loops from the first 60 scans to scans 240 and later
  };
  const auto run = [&](const std::string& name, const std::string& config) {
    Run out;
    const auto summary =
        run_loop_closed_log(log + " --range-codes-as-points", 270, config, dir, name);
    out.ate = summary["ate"]["rmse_m"].get<double>();
    out.ate_odometry = summary["ate_odometry"]["rmse_m"].get<double>();
    for (const auto& l : nlohmann::json::parse(std::ifstream(dir.file(name + "/loops.json"))))
      out.start_to_mouth += l.at("from").get<int>() < 60 && l.at("to").get<int>() >= 240;
    return out;
  };
  const std::string then = R"("mapper": {"submap_scans": 1})";
  const Run rechecked = run("recheck", "{" + then + "}");
  const Run once = run("once", "{" + then + R"(, "loop": {"recheck_keyframes": 0}})");
  std::printf(
      "ACES 270 scans: ATE odometry %.3f m, loop-closed %.3f m with rechecks (%zu loops "
      "start-mouth), %.3f m without (%zu)\n",
      rechecked.ate_odometry, rechecked.ate, rechecked.start_to_mouth, once.ate,
      once.start_to_mouth);
  EXPECT_GT(rechecked.start_to_mouth, once.start_to_mouth);
  EXPECT_LT(rechecked.ate, 0.7 * once.ate);
  EXPECT_LT(once.ate, rechecked.ate_odometry);
}

TEST(LoopClosure2D, ACornerTheOdometryWentStraightThroughIsTurnedByALoop) {
  // corridor-2d driven for 800 scans (four laps): at scan 82 the odometry goes straight on where
  // the robot turned 90 degrees (AStepWithAWeakFitIsTestedFor...), and the map after it lies
  // turned. The weak step's rotation is loose; the first loop back to the start, turned about
  // that step, agrees with the estimate and turns the map. Scan-to-scan odometry (submap_scans 1)
  // makes the premise; scored against the references before the last too, it turns the corner.
  // Without the speed prior after a corner (open_step_speed_steps 0), as these figures were set:
  // with it, the steps after the corners hold and the sliding loops matter less (0.149 m
  // loop-closed against 0.189 m holding nothing along).
  if (scanmatch::testing::sanitized()) GTEST_SKIP() << "too slow under the sanitizers";
  scanmatch::testing::TempDir dir;
  const std::string scan_to_scan = R"("mapper": {"submap_scans": 1, "open_step_speed_steps": 0})";
  const auto turned =
      run_loop_closed_log("sim:corridor-2d", 800, "{" + scan_to_scan + "}", dir, "turned");
  const auto held = run_loop_closed_log(
      "sim:corridor-2d", 800, "{" + scan_to_scan + R"(, "loop": {"rotation_open_ratio": 0}})", dir,
      "held");
  // Its loops between laps mostly slide (door recesses every 3-9 m fit 1-3 m along as well):
  // holding nothing along the corridors, the graph stretched the loosest steps there.
  const auto free_along = run_loop_closed_log(
      "sim:corridor-2d", 800, "{" + scan_to_scan + R"(, "loop": {"sliding_information_kept": 0}})",
      dir, "free_along");
  const double odometry = turned["ate_odometry"]["rmse_m"].get<double>();
  const double closed = turned["ate"]["rmse_m"].get<double>();
  const double without = held["ate"]["rmse_m"].get<double>();
  const double sliding_free = free_along["ate"]["rmse_m"].get<double>();
  std::printf(
      "corridor-2d 800 scans: ATE odometry %.3f m, loop-closed %.3f m, without turning "
      "%.3f m, sliding loops holding nothing along %.3f m\n",
      odometry, closed, without, sliding_free);
  EXPECT_GE(turned["loop_closure"]["turned_at_open_rotation"].get<int>(), 1);
  EXPECT_GT(odometry, 5.0);
  EXPECT_LT(closed, 0.45);
  EXPECT_GT(without, 0.5 * odometry);
  EXPECT_LT(closed, 0.75 * sliding_free);
  EXPECT_GT(turned["loop_closure"]["sliding"].get<int>(),
            turned["loop_closure"]["verified"].get<int>() / 3);
}

TEST(LoopClosure2D, ALoopAcrossARotationOpenStepTurnsTheMapIfPresent) {
  // fhw's first 420 scans: the robot turns on the spot among visitors (scans 40-65) and the
  // odometry takes one step about 80 degrees wrong; scans 389-406 come back to scans 0-30. The
  // loops there disagree with the estimate by 26-39 m, but agree with it once the keyframes after
  // the rotation-open step are turned about it: accepted, the map turns there.
  const std::string log = scanmatch::testing::shared_data("data/2d/carmen/fhw-corrected.log.gz");
  if (log.empty()) GTEST_SKIP() << "../shared/data/2d/carmen is absent";
  if (scanmatch::testing::sanitized()) GTEST_SKIP() << "too slow under the sanitizers";
  scanmatch::testing::TempDir dir;
  const auto turned = run_loop_closed_log(log, 420, "", dir, "turned");
  const auto held =
      run_loop_closed_log(log, 420, R"({"loop": {"rotation_open_ratio": 0}})", dir, "held");
  const double odometry = turned["ate_odometry"]["rmse_m"].get<double>();
  const double closed = turned["ate"]["rmse_m"].get<double>();
  const double without = held["ate"]["rmse_m"].get<double>();
  std::printf("fhw 420 scans: ATE odometry %.3f m, loop-closed %.3f m, without turning %.3f m\n",
              odometry, closed, without);
  EXPECT_GE(turned["loop_closure"]["turned_at_open_rotation"].get<int>(), 1);
  EXPECT_GE(turned["loop_closure"]["rotation_open_odometry_edges"].get<int>(), 1);
  EXPECT_EQ(held["loop_closure"]["turned_at_open_rotation"].get<int>(), 0);
  EXPECT_LT(closed, 0.1 * odometry);
  EXPECT_GT(without, 0.5 * odometry);
}

}  // namespace
}  // namespace scanmatch
