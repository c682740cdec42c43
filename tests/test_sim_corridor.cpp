// The corridor-2d preset: a 180 deg SICK LMS logged at 1 Hz around a ring of long corridors, the
// regime of the Radish ACES log in which scan-to-scan 2D odometry slides along corridors.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "scanmatch/core/error.hpp"
#include "scanmatch/registration/planar/correlative_search.hpp"
#include "scanmatch/run/map2d_run.hpp"
#include "scanmatch/sim/simulator.hpp"
#include "scanmatch/sim/worlds.hpp"
#include "test_helpers.hpp"

using namespace scanmatch;
using namespace scanmatch::sim;

namespace {
constexpr double kDeg = M_PI / 180.0;

using scanmatch::testing::median;

double yaw_of(const Pose& pose) {
  return std::atan2(pose.linear()(1, 0), pose.linear()(0, 0));
}

Simulator corridor(std::optional<std::size_t> frames = std::nullopt, bool noise = true) {
  SimOptions o;
  o.preset = "corridor-2d";
  o.frames = frames;
  o.noise = noise;
  return Simulator(o);
}
}  // namespace

TEST(SimCorridor, SickLmsSweepsTheFrontHalfPlaneInAFractionOfItsTurn) {
  const SensorModel& sick = sensor_model("sick-lms");
  ASSERT_TRUE(sick.is_2d());
  RayPattern p;
  generate_pattern(sick, 0, p);
  ASSERT_EQ(p.directions.size(), 181u);
  for (std::size_t k = 0; k < p.directions.size(); ++k) {
    const double azimuth = std::atan2(p.directions[k].y(), p.directions[k].x());
    EXPECT_NEAR(azimuth, (-90.0 + static_cast<double>(k)) * kDeg, 1e-6) << "beam " << k;
    EXPECT_NEAR(p.directions[k].z(), 0.0f, 1e-7f);
    // Half a turn of a 75 Hz mirror, not the 1 s between logged scans.
    EXPECT_LE(p.times[k], 0.5 / 75.0 + 1e-6);
  }
  EXPECT_DOUBLE_EQ(sick.rotation_period(), 1.0 / 75.0);
  // The full-turn Neato keeps its layout: beam 0 straight ahead, 1 deg apart.
  const SensorModel& neato = sensor_model("neato");
  EXPECT_DOUBLE_EQ(neato.planar_angle_min(), 0.0);
  EXPECT_DOUBLE_EQ(neato.planar_angle_increment(), 2 * M_PI / 360.0);
  EXPECT_DOUBLE_EQ(neato.rotation_period(), neato.frame_period());
}

TEST(SimCorridor, ScansCoverOnlyTheFrontHalfPlane) {
  const Simulator sim = corridor(30);
  for (std::size_t i = 0; i < sim.size(); ++i) {
    const PointCloud cloud = sim.frame(i);
    ASSERT_GT(cloud.size(), 120u) << "frame " << i;  // walls on both sides, most beams return
    for (const Point& point : cloud.points) ASSERT_GE(point.x(), -1e-5f) << "frame " << i;
    const LaserScan2D scan = sim.scan_2d(i);
    ASSERT_EQ(scan.ranges.size(), 181u);
    EXPECT_DOUBLE_EQ(scan.angle_min, -M_PI / 2);
    EXPECT_NEAR(scan.angle_increment, kDeg, 1e-12);
    EXPECT_FLOAT_EQ(scan.max_range, 50.0f);
  }
  EXPECT_TRUE(is_2d_scene("corridors-2d"));
  SimOptions spinning;
  spinning.preset = "corridor-2d";
  spinning.sensor = "vlp16";
  EXPECT_THROW(Simulator{spinning}, Error);  // 3D sensors do not go with 2D scenes
}

TEST(SimCorridor, ScansAreAboutAMetreApartAndTurnUpTo80Degrees) {
  const Simulator sim = corridor();
  ASSERT_EQ(sim.size(), preset_info("corridor-2d").frames);
  std::vector<double> steps;
  double largest_turn = 0.0;
  for (std::size_t i = 1; i < sim.size(); ++i) {
    steps.push_back((sim.pose(i).translation() - sim.pose(i - 1).translation()).norm());
    largest_turn =
        std::max(largest_turn,
                 std::abs(std::remainder(yaw_of(sim.pose(i)) - yaw_of(sim.pose(i - 1)), 2 * M_PI)));
  }
  EXPECT_GT(median(steps), 0.8);
  EXPECT_LT(median(steps), 1.1);
  // ACES turns up to 78 deg between scans; the square corridor corners give about as much.
  EXPECT_GT(largest_turn, 60 * kDeg);
  EXPECT_LT(largest_turn, 85 * kDeg);
  EXPECT_NEAR(sim.path_length(), preset_info("corridor-2d").path_length,
              0.01 * preset_info("corridor-2d").path_length);
}

TEST(SimCorridor, FirstScanSeesStraightCorridorWallsFarAhead) {
  // The first scan is taken on the bottom corridor's centre line heading along it, so its walls
  // are the lines y = +-(half width - half wall thickness) in the scan's frame.
  const double wall = kCorridorHalfWidth - 0.05;
  const PointCloud cloud = corridor(1).frame(0);
  std::size_t on_walls = 0;
  double squares = 0.0, farthest = 0.0;
  for (const Point& point : cloud.points) {
    const double offset = std::abs(point.y()) - wall;
    if (std::abs(offset) > 0.05) continue;  // door recesses, boxes, end walls
    ++on_walls;
    squares += offset * offset;
    farthest = std::max(farthest, static_cast<double>(point.x()));
  }
  ASSERT_GT(on_walls, cloud.size() * 6 / 10);
  EXPECT_LT(std::sqrt(squares / static_cast<double>(on_walls)), 0.015);  // within range noise
  EXPECT_GT(farthest, 30.0);  // grazing returns far down the corridor
}

TEST(SimCorridor, RevisitsItsStart) {
  const Simulator sim = corridor();
  const Eigen::Vector3d start = sim.pose(0).translation();
  double closest_late = 1e9, farthest = 0.0;
  for (std::size_t i = 0; i < sim.size(); ++i) {
    const double distance = (sim.pose(i).translation() - start).norm();
    farthest = std::max(farthest, distance);
    if (i > sim.size() / 2) closest_late = std::min(closest_late, distance);
  }
  EXPECT_GT(farthest, 50.0);     // around the 60 m x 25 m ring
  EXPECT_LT(closest_late, 1.0);  // and back past the start
}

TEST(SimCorridor, Map2DLoadsItWithTheMirrorPeriod) {
  const Scans2D input = load_scans_2d("sim:corridor-2d", {}, 3);
  ASSERT_EQ(input.scans.size(), 3u);
  EXPECT_TRUE(input.has_reference);
  EXPECT_DOUBLE_EQ(input.rotation_period, 1.0 / 75.0);
  const Scan2D scan = scan_from_laser(input.scans[0], 0.1, 0.0, input.rotation_period);
  EXPECT_FALSE(scan.circular);
  EXPECT_GT(scan.points.size(), 150u);
}

TEST(SimCorridor, CorrelativeSearchFindsTheStepsAlongACorridorOnceWallsAreFilled) {
  // Straight steps of ~0.9 m along the first corridors, searched from the identity as map2d does.
  // Scored against the reference's samples alone, a scan fits best where its samples fall on
  // them, i.e. where the sensor did not move: about half the steps come out short. Filling the
  // straight surfaces between samples removes that preference.
  const Scans2D input = load_scans_2d("sim:corridor-2d", {}, 60);
  ASSERT_EQ(input.scans.size(), 60u);
  const auto off_steps = [&](double fill_gap, double& path) {
    int off = 0;
    path = 0.0;
    for (std::size_t i = 1; i < input.scans.size(); ++i) {
      const Pose2 truth = pose2(input.scans[i - 1].pose).inverse() * pose2(input.scans[i].pose);
      const Pose2 found = correlative_search(scan_from_laser(input.scans[i], 0.05),
                                             scan_from_laser(input.scans[i - 1], 0.05),
                                             Pose2::Identity(), 1.3, 45 * kDeg, 0.05, fill_gap);
      off += (found.translation() - truth.translation()).norm() > 0.2;
      path += found.translation().norm() - truth.translation().norm();
    }
    return off;
  };
  double short_by_samples = 0.0, short_by_filled = 0.0;
  const int off_samples = off_steps(0.0, short_by_samples);
  const int off_filled = off_steps(Registration2DOptions{}.search_fill_gap, short_by_filled);
  EXPECT_GT(off_samples, 15) << "the bias this guards against is gone from the scene";
  EXPECT_LE(off_filled, 5);
  EXPECT_LT(short_by_samples, -10.0);  // metres, over ~52 m
  EXPECT_GT(short_by_filled, -4.0);
}
