// The FrameOdometry interface and the peer registry (scanmatch/odometry/frame_odometry.hpp):
// always built, whichever peers this build has.

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "scanmatch/core/error.hpp"
#include "scanmatch/odometry/frame_odometry.hpp"
#include "scanmatch/odometry/odometry.hpp"
#include "scanmatch/odometry/odometry_pipeline.hpp"
#include "scanmatch/sim/simulator.hpp"
#include "test_helpers.hpp"

using namespace scanmatch;
using scanmatch::testing::run_cli;

namespace {

bool built(const std::string& peer) {
  const std::vector<std::string> peers = odometry_peers();
  return std::any_of(peers.begin(), peers.end(),
                     [&](const std::string& p) { return p.rfind(peer + ":", 0) == 0; });
}

std::string error_of(const std::string& method) {
  try {
    check_odometry_method(method);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Peers, APeerNotBuiltNamesTheOptionThatBuildsIt) {
  for (const std::string peer : {"pcl-icp", "pcl-ndt", "pcl-gicp", "kiss-icp"}) {
    const std::string error = error_of(peer);
    // The bench lists a known peer it lacks instead of failing: it asks missing_peer_option.
    EXPECT_EQ(scanmatch::missing_peer_option(peer).empty(), built(peer)) << peer;
    const auto known = scanmatch::known_odometry_peers();
    EXPECT_NE(std::find(known.begin(), known.end(), peer), known.end()) << peer;
    if (built(peer)) {
      EXPECT_EQ(error, "") << peer;
    } else {
      const std::string option = peer == "kiss-icp" ? "SCANMATCH_WITH_KISS" : "SCANMATCH_WITH_PCL";
      EXPECT_NE(error.find(option), std::string::npos) << peer << ": " << error;
    }
  }
  const std::string unknown = error_of("no-such-method");
  EXPECT_NE(unknown.find("unknown odometry method 'no-such-method'"), std::string::npos);
  EXPECT_NE(unknown.find("ctf-icp"), std::string::npos);
  EXPECT_EQ(error_of("ctf-icp"), "");
  EXPECT_EQ(error_of("gicp"), "");
}

TEST(Peers, OurOdometryThroughTheInterfaceGivesTheSamePoses) {
  sim::SimOptions o;
  o.preset = "dynamic-outdoor-fast";
  o.frames = 12;
  const sim::Simulator sim(o);
  for (const std::string method : {"ctf-icp", "ndt"}) {
    OdometryConfig config;
    config.method = method;
    Odometry direct(config);
    const std::unique_ptr<FrameOdometry> through = make_frame_odometry(config);
    for (std::size_t i = 0; i < sim.size(); ++i) {
      const PointCloud frame = sim.frame(i);
      const Pose a = direct.register_frame(frame, sim.frame_time(i));
      const Pose b = through->register_frame(frame, sim.frame_time(i));
      ASSERT_TRUE(a.isApprox(b, 0.0)) << method << " frame " << i;
      ASSERT_EQ(direct.last_stats().points_downsampled, through->last_stats().points_downsampled);
    }
    Pose registration_from_frame;
    const PointCloud* last = through->last_map_frame(registration_from_frame);
    ASSERT_NE(last, nullptr);
    const OdometryPipeline& pipeline = direct.pipeline();
    EXPECT_EQ(last->size(), pipeline.last_frame().size());
    EXPECT_TRUE(registration_from_frame.isApprox(pipeline.last_internal_pose()));
    EXPECT_TRUE(through->world_from_registration().isApprox(pipeline.world_from_internal()));
  }
}

TEST(Peers, TheCliRejectsAPeerItWasNotBuiltWith) {
  const scanmatch::testing::TempDir dir;
  for (const std::string peer : {"pcl-gicp", "kiss-icp"}) {
    if (built(peer)) continue;
    const auto run = run_cli("odometry sim:static-indoor --frames 3 --method " + peer + " --out " +
                             dir.file("run") + " --quiet");
    EXPECT_NE(run.status, 0) << run.output;
    EXPECT_NE(run.output.find("configure with -DSCANMATCH_WITH_"), std::string::npos) << run.output;
  }
}
