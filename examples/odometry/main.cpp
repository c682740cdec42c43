// Using scanmatch as a library: CTF-ICP odometry on a simulated Livox MID-360 drive (or on a
// folder of frames given as the argument), printing each pose and the accuracy at the end.
//
//   cmake -S examples/odometry -B build-example -DCMAKE_PREFIX_PATH=<scanmatch install prefix>
//   cmake --build build-example && build-example/odometry_example [FOLDER]

#include <cstdio>

#include "scanmatch/eval/metrics.hpp"
#include "scanmatch/odometry/ctf_icp_odometry.hpp"
#include "scanmatch/sim/open_sequence.hpp"

int main(int argc, char** argv) {
  try {
    scanmatch::SequenceOptions input;
    input.simulator.frames = 50;
    const auto source =
        scanmatch::open_sequence(argc > 1 ? argv[1] : "sim:dynamic-outdoor-fast", input);

    scanmatch::OdometryConfig config;  // ctf-icp with the documented defaults
    scanmatch::CtfIcpOdometry odometry(config);
    std::vector<scanmatch::Pose> poses;
    scanmatch::Frame frame;
    while (poses.size() < 50 && source->next(frame)) {
      poses.push_back(odometry.register_frame(frame.cloud, frame.timestamp));
      const Eigen::Vector3d t = poses.back().translation();
      std::printf("frame %3zu: x %8.3f y %8.3f z %7.3f  (%.1f ms)\n", frame.index, t.x(), t.y(),
                  t.z(), odometry.last_stats().total_ms);
    }
    std::printf("map: %zu Gaussian voxels\n", odometry.map().size());
    if (const auto truth = source->ground_truth()) {
      const std::vector<scanmatch::Pose> gt(
          truth->poses.begin(), truth->poses.begin() + static_cast<std::ptrdiff_t>(poses.size()));
      const scanmatch::AteResult ate = scanmatch::compute_ate(gt, poses);
      std::printf("ATE: %.3f m RMSE over %.1f m (%.2f %%)\n", ate.rmse, ate.path_length,
                  ate.rmse_percent_of_path);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "odometry_example: %s\n", e.what());
    return 1;
  }
  return 0;
}
