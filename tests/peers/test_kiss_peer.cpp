// The KISS-ICP peer (built with -DSCANMATCH_WITH_KISS=ON against an installed KISS-ICP): it tracks
// a simulated drive through the same runner as our methods.

#include <gtest/gtest.h>

#include "scanmatch/odometry/frame_odometry.hpp"
#include "scanmatch/odometry/run.hpp"
#include "scanmatch/sim/simulator.hpp"

using namespace scanmatch;

#if SCANMATCH_HAS_KISS_PEER
TEST(KissPeer, TracksFortyFramesOfAFastDrive) {
  // Measured on 40 frames of dynamic-outdoor-fast: 0.37 % (deskewed with the point times).
  OdometryConfig config;
  config.method = "kiss-icp";
  const auto source = sim::open_sequence("sim:dynamic-outdoor-fast");
  RunOptions options;
  options.max_frames = 40;
  options.quiet = true;
  const RunSummary run = run_odometry(*source, config, options);
  ASSERT_EQ(run.frames, 40u);
  ASSERT_TRUE(run.ate.has_value());
  EXPECT_LT(run.ate->rmse_percent_of_path, 0.8);
  EXPECT_GT(run.ate->rmse_percent_of_path, 0.0);
}
#endif
