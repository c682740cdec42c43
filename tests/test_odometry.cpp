#include <gtest/gtest.h>

#include <cstdlib>

#include "scanmatch/core/error.hpp"
#include "scanmatch/eval/metrics.hpp"
#include "scanmatch/odometry/odometry.hpp"
#include "scanmatch/sim/simulator.hpp"

using namespace scanmatch;

namespace {
AteResult run(const std::string& method, const std::vector<PointCloud>& frames,
              const std::vector<Pose>& truth, bool deskew = true) {
  OdometryConfig config;
  config.method = method;
  config.deskew = deskew;
  Odometry odometry(config);
  std::vector<Pose> estimate;
  for (std::size_t i = 0; i < frames.size(); ++i)
    estimate.push_back(odometry.register_frame(frames[i], 0.1 * i));
  return compute_ate(truth, estimate);
}
}  // namespace

TEST(Odometry, CtfIcpTracksAFastDriveBetterThanIcp) {
  // 40 frames (17 m at 4.4 m/s; 20 under the sanitizers, which are ~10x slower) of
  // dynamic-outdoor-fast with motion distortion, deskewed:
  // CTF-ICP stays within 0.1 m (0.5 % of the path); plain ICP drifts more.
  sim::SimOptions o;
  o.preset = "dynamic-outdoor-fast";
  o.frames = std::getenv("SCANMATCH_SANITIZED") ? 20 : 40;
  const sim::Simulator s(o);
  std::vector<PointCloud> frames;
  for (std::size_t i = 0; i < s.size(); ++i) frames.push_back(s.frame(i));
  const std::vector<Pose> truth = s.ground_truth().poses;
  const AteResult ctf = run("ctf-icp", frames, truth);
  const AteResult icp = run("icp", frames, truth);
  EXPECT_LT(ctf.rmse, 0.1) << "ctf-icp";
  EXPECT_LT(ctf.rmse, icp.rmse);
  // Deskewing helps: without it the distorted frames bias the estimate.
  EXPECT_LT(ctf.rmse, run("ctf-icp", frames, truth, false).rmse);
}

TEST(Odometry, EmptyFramesAreBridgedByTheMotionPrior) {
  OdometryConfig config;
  Odometry odometry(config);
  PointCloud empty;
  EXPECT_NO_THROW(odometry.register_frame(empty, 0.0));
  EXPECT_NO_THROW(odometry.register_frame(empty, 0.1));
  EXPECT_TRUE(odometry.last_stats().bridged);
  config.method = "magic";
  EXPECT_THROW(Odometry{config}, Error);
}
