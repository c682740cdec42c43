// Optional peer benchmark (-DSCANMATCH_WITH_PCL=ON, Debian libpcl-dev): PCL's ICP, GICP and NDT
// against scanmatch's icp, gicp and ndt on the same simulated pair, from the same initial guess,
// single-threaded, in the same run.
//   build/bench/scanmatch_bench_pcl

#include <benchmark/benchmark.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>
#include <pcl/registration/icp.h>
#include <pcl/registration/ndt.h>

#include <map>

#include "scanmatch/geometry/voxel_filter.hpp"
#include "scanmatch/registration/methods.hpp"
#include "scanmatch/sim/simulator.hpp"

namespace {
using namespace scanmatch;

struct PeerPair {
  PointCloud source, target;
  pcl::PointCloud<pcl::PointXYZ>::Ptr pcl_source, pcl_target;
  Pose truth, guess;
};

pcl::PointCloud<pcl::PointXYZ>::Ptr to_pcl(const PointCloud& cloud) {
  auto out = pcl::PointCloud<pcl::PointXYZ>::Ptr(new pcl::PointCloud<pcl::PointXYZ>);
  for (const Point& p : cloud.points) out->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  return out;
}

const PeerPair& pair_for(const std::string& preset) {
  static std::map<std::string, PeerPair> cache;
  if (auto it = cache.find(preset); it != cache.end()) return it->second;
  sim::SimOptions o;
  o.preset = preset;
  o.frames = 42;
  o.motion_distortion = false;
  const sim::Simulator s(o);
  PeerPair p;
  p.source = voxel_downsample(s.frame(41), 0.25);
  p.target = voxel_downsample(s.frame(40), 0.25);
  p.pcl_source = to_pcl(p.source);
  p.pcl_target = to_pcl(p.target);
  p.truth = s.pose(40).inverse() * s.pose(41);
  p.guess = s.pose(39).inverse() * s.pose(40);
  return cache.emplace(preset, std::move(p)).first->second;
}

const std::vector<std::string> kPresets = {"campus-os1", "dynamic-outdoor"};
const std::vector<std::string> kMethods = {"icp", "gicp", "ndt"};

void report(benchmark::State& state, const PeerPair& pair, const Pose& estimate, int iterations,
            const std::string& label) {
  const Pose error = pair.truth.inverse() * estimate;
  state.counters["error_cm"] = 100.0 * error.translation().norm();
  state.counters["error_deg"] = rotation_angle(error) * 180.0 / M_PI;
  state.counters["iterations"] = iterations;
  state.SetLabel(label);
}

void BM_Pcl(benchmark::State& state) {
  const std::string& preset = kPresets[static_cast<std::size_t>(state.range(1))];
  const std::string& method = kMethods[static_cast<std::size_t>(state.range(0))];
  const PeerPair& pair = pair_for(preset);
  const Eigen::Matrix4f guess = to_matrix(pair.guess).cast<float>();
  pcl::PointCloud<pcl::PointXYZ> aligned;
  Eigen::Matrix4f result = Eigen::Matrix4f::Identity();
  int iterations = 0;
  for (auto _ : state) {
    if (method == "icp") {
      pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> icp;
      icp.setMaxCorrespondenceDistance(1.0);
      icp.setMaximumIterations(30);
      icp.setTransformationEpsilon(1e-10);
      icp.setInputSource(pair.pcl_source);
      icp.setInputTarget(pair.pcl_target);
      icp.align(aligned, guess);
      result = icp.getFinalTransformation();
      iterations = icp.nr_iterations_;
    } else if (method == "gicp") {
      pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> gicp;
      gicp.setMaxCorrespondenceDistance(1.0);
      gicp.setMaximumIterations(30);
      gicp.setCorrespondenceRandomness(20);
      gicp.setInputSource(pair.pcl_source);
      gicp.setInputTarget(pair.pcl_target);
      gicp.align(aligned, guess);
      result = gicp.getFinalTransformation();
      iterations = gicp.nr_iterations_;
    } else {
      pcl::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ> ndt;
      ndt.setResolution(1.0f);
      ndt.setStepSize(0.1);
      ndt.setTransformationEpsilon(0.001);
      ndt.setMaximumIterations(30);
      ndt.setInputSource(pair.pcl_source);
      ndt.setInputTarget(pair.pcl_target);
      ndt.align(aligned, guess);
      result = ndt.getFinalTransformation();
      iterations = ndt.getFinalNumIteration();
    }
  }
  report(state, pair, from_matrix(result.cast<double>()), iterations,
         "PCL " + method + " " + preset);
}

void BM_Ours(benchmark::State& state) {
  const std::string& preset = kPresets[static_cast<std::size_t>(state.range(1))];
  const std::string& method = kMethods[static_cast<std::size_t>(state.range(0))];
  const PeerPair& pair = pair_for(preset);
  RegistrationOptions o;
  o.method = method;
  RegistrationResult r;
  for (auto _ : state) r = register_clouds(pair.source, pair.target, o, pair.guess);
  report(state, pair, r.transform, r.iterations, "scanmatch " + method + " " + preset);
}

BENCHMARK(BM_Pcl)->ArgsProduct({{0, 1, 2}, {0, 1}})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Ours)->ArgsProduct({{0, 1, 2}, {0, 1}})->Unit(benchmark::kMillisecond);

}  // namespace
