// The PCL peers (built with -DSCANMATCH_WITH_PCL=ON): they track a simulated drive through the
// same runner as our methods.

#include <gtest/gtest.h>

#include "peer_run.hpp"

using namespace scanmatch;

#if SCANMATCH_HAS_PCL_PEERS
TEST(PclPeers, NdtAndGicpTrackFortyFramesOfAFastDrive) {
  // Measured on 40 frames of dynamic-outdoor-fast: pcl-ndt 1.23 %, pcl-gicp 1.83 % (pcl-icp 8.7 %,
  // a point-to-point matcher on a non-repetitive pattern, is not held to a bound).
  for (const auto& [method, bound] : {std::pair{"pcl-ndt", 2.5}, std::pair{"pcl-gicp", 3.5}}) {
    const RunSummary run = scanmatch::testing::run_peer(method, "dynamic-outdoor-fast", 40);
    ASSERT_EQ(run.frames, 40u);
    ASSERT_TRUE(run.ate.has_value());
    EXPECT_LT(run.ate->rmse_percent_of_path, bound) << method;
    EXPECT_GT(run.ate->rmse_percent_of_path, 0.0) << method;
    EXPECT_EQ(run.bridged_frames, 0u) << method;
  }
}
#endif
