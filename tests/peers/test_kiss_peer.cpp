// The KISS-ICP peer (built with -DSCANMATCH_WITH_KISS=ON against an installed KISS-ICP): it tracks
// a simulated drive through the same runner as our methods, and leaves the process-wide TBB limit
// as it found it for the methods run after it.

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include "peer_run.hpp"
#include "scanmatch/odometry/frame_odometry.hpp"
#include "scanmatch/run/odometry_run.hpp"
#include "scanmatch/sim/simulator.hpp"

using namespace scanmatch;

#if SCANMATCH_HAS_KISS_PEER
TEST(KissPeer, TracksThirtyFramesOfAFastDrive) {
  // Measured on 30 frames of dynamic-outdoor-fast, one thread: 0.48 % of the path (200 frames:
  // 0.35 %, docs/benchmarks.md, Peers).
  const RunSummary run = scanmatch::testing::run_peer("kiss-icp", "dynamic-outdoor-fast", 30);
  ASSERT_EQ(run.frames, 30u);
  ASSERT_TRUE(run.ate.has_value());
  EXPECT_LT(run.ate->rmse_percent_of_path, 1.0);
  EXPECT_GT(run.ate->rmse_percent_of_path, 0.0);
}

TEST(KissPeer, LeavesTheProcessWideThreadLimitAlone) {
  // KISS-ICP's constructors keep a static tbb::global_control of their thread count; with one
  // thread asked for, a limit of one would hold every later method of the process to one thread.
  std::vector<PointCloud> frames;
  std::vector<double> times;
  {  // the simulator's Embree device limits TBB while it lives: frames first, then the check
    sim::SimOptions o;
    o.preset = "dynamic-outdoor-fast";
    o.frames = 3;
    const sim::Simulator sim(o);
    for (std::size_t i = 0; i < sim.size(); ++i) {
      frames.push_back(sim.frame(i));
      times.push_back(sim.frame_time(i));
    }
  }
  const auto limit = [] {
    return tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
  };
  // The default is the machine's concurrency (on one core this test cannot tell).
  const std::size_t before = limit();
  ASSERT_EQ(before, static_cast<std::size_t>(tbb::info::default_concurrency()));
  OdometryConfig config;
  config.method = "kiss-icp";
  config.threads = 1;
  const std::unique_ptr<FrameOdometry> kiss = make_frame_odometry(config);
  for (std::size_t i = 0; i < frames.size(); ++i) kiss->register_frame(frames[i], times[i]);
  EXPECT_EQ(limit(), before);
}
#endif
