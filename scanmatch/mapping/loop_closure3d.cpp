// 3D loop closure's orchestration: keyframes and their submaps, odometry edges, searches,
// optimizations (loop_closure3d.hpp).
#include "scanmatch/mapping/loop_closure3d.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "scanmatch/core/error.hpp"
#include "scanmatch/core/stopwatch.hpp"
#include "scanmatch/geometry/voxel_filter.hpp"
#include "scanmatch/mapping/edge_information.hpp"
#include "scanmatch/mapping/loop_candidates.hpp"
#include "scanmatch/registration/methods.hpp"

namespace scanmatch {
namespace {

// The cloud without non-finite points, downsampled (an empty cloud when even that fails, e.g. a
// coordinate too far away for a voxel index).
PointCloud clean_points(const PointCloud& cloud, double voxel) {
  PointCloud positions;
  positions.points = cloud.points;  // only positions are needed
  remove_non_finite(positions);
  try {
    return voxel_downsample(positions, voxel);
  } catch (const Error&) {
    return {};
  }
}

}  // namespace

LoopClosure3D::LoopClosure3D(const LoopClosure3DOptions& options)
    : options_(options), graph_(options.graph), frame_voxel_(options.submap_voxel) {
  find_registration_method(options.verification.coarse_method);
  find_registration_method(options.verification.fine_method);
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(options.odometry_sigma_translation) || !positive(options.odometry_sigma_rotation) ||
      !positive(options.loop_sigma_translation) || !positive(options.loop_sigma_rotation))
    throw Error("loop closure: the edge standard deviations must be positive");
  if (!positive(options.submap_voxel) || !positive(options.verification.pair_distance) ||
      !positive(options.verification.coarse_resolution))
    throw Error("loop closure: submap voxel, pair distance and coarse resolution must be positive");
  if (!(options.keyframe_distance >= 0.0) || !(options.keyframe_angle >= 0.0))
    throw Error("loop closure: keyframe thresholds must not be negative");
  if (!(options.verification_memory_mb >= 0.0))
    throw Error("loop closure: the verification memory must not be negative");
  options_.search_every = std::max<std::size_t>(options_.search_every, 1);
  options_.submap_frames = std::max<std::size_t>(options_.submap_frames, 1);
}

bool LoopClosure3D::add_frame(const PointCloud& points, const Pose& odometry_pose) {
  const Stopwatch stopwatch;
  // A non-finite or non-rigid odometry pose would poison the graph: hold the last one instead.
  Pose odometry = odometry_pose;
  if (!is_valid_pose(odometry.matrix(), 1e-3))
    odometry = keyframes_.empty() ? Pose::Identity()
                                  : keyframes_.back().odometry * offset_in_keyframe(frames() - 1);
  odometry = orthonormalized(odometry);
  recent_.push_back({clean_points(points, frame_voxel_), odometry});
  while (recent_.size() > options_.submap_frames) recent_.pop_front();

  bool new_keyframe = keyframes_.empty();
  if (!new_keyframe) {
    const Pose motion = keyframes_.back().odometry.inverse() * odometry;
    new_keyframe = motion.translation().norm() >= options_.keyframe_distance ||
                   rotation_angle(motion) >= options_.keyframe_angle;
  }
  if (new_keyframe) {
    Keyframe k;
    k.frame = frames();
    k.submap = build_submap(odometry);
    k.odometry = odometry;
    const std::size_t index = keyframes_.size();
    if (index == 0) {
      graph_.graph().add_node(odometry);
    } else {
      const Keyframe& previous = keyframes_.back();
      const Pose measurement = orthonormalized(previous.odometry.inverse() * odometry);
      k.path = previous.path + measurement.translation().norm();
      graph_.graph().add_node(orthonormalized(graph().pose(index - 1) * measurement));
      graph_.graph().add_edge(index - 1, index, measurement,
                              diagonal_information<3>(options_.odometry_sigma_translation,
                                                      options_.odometry_sigma_rotation),
                              EdgeKind::kOdometry);
    }
    places_.add(make_place_descriptor(k.submap, options_.descriptor));
    keyframes_.push_back(std::move(k));
    ++counts_.keyframes;
    const bool pausing =
        !loops().empty() && index <= last_loop_keyframe_ + options_.keyframes_between_loops;
    if (index % options_.search_every == 0 && !pausing) close_loops(index);
  }
  graph_.add_frame(keyframes_.size() - 1, keyframes_.back().odometry.inverse() * odometry);
  counts_.total_ms += stopwatch.ms();
  return new_keyframe;
}

PointCloud LoopClosure3D::build_submap(const Pose& keyframe_odometry) {
  const Pose keyframe_inverse = keyframe_odometry.inverse();
  PointCloud merged;
  for (const RecentFrame& f : recent_) {
    const Eigen::Isometry3f T = (keyframe_inverse * f.odometry).cast<float>();
    for (const Point& p : f.points.points) merged.points.push_back(T * p);
  }
  double voxel = frame_voxel_;
  PointCloud submap = clean_points(merged, voxel);
  while (submap.size() > options_.max_submap_points && voxel < 100.0) {
    voxel *= 1.5;
    submap = clean_points(submap, voxel);
  }
  // The next frames are kept at the voxel this submap needed (a dense sensor's frames are then
  // not kept at 0.25 m only to be merged and coarsened again: on urban-hdl64 that was most of the
  // time loop closure took), and finer again once submaps fit easily.
  if (voxel > frame_voxel_)
    frame_voxel_ = voxel;
  else if (frame_voxel_ > options_.submap_voxel &&
           static_cast<double>(submap.size()) * 1.5 * 1.5 <
               static_cast<double>(options_.max_submap_points))
    frame_voxel_ = std::max(options_.submap_voxel, frame_voxel_ / 1.5);
  return submap;
}

void LoopClosure3D::close_loops(std::size_t keyframe) {
  const Pose here = graph().pose(keyframe);
  // Look-alike places often match better than the true one: the database's best few matches are
  // looked at. A registration moves its start (the descriptor's, without translation) by a few
  // metres at most, so a match this far from the estimate could not end within its gate (the
  // check after verification, below).
  const LoopCandidates found = find_loop_candidates(
      keyframe, options_.skip_recent, graph(), places_, options_.candidates,
      options_.descriptor_matches,
      [&](std::size_t k) { return correction_allowed(keyframe, k) + options_.registration_reach; });
  counts_.ruled_out_by_estimate += found.ruled_out;
  bool added = false;
  for (const LoopCandidate& candidate : found.candidates) {
    const std::size_t k = candidate.keyframe;
    ++counts_.candidates;
    const Pose estimated = graph().pose(k).inverse() * here;
    // The descriptor knows the yaw only: the coarse registration finds the translation.
    const Pose initial = candidate.by_descriptor ? from_xyz_rpy(0, 0, 0, 0, 0, candidate.yaw)
                                                 : orthonormalized(estimated);
    const double allowed = correction_allowed(keyframe, k);
    const LoopVerification3D v =
        verify_loop_3d(prepared(keyframe), prepared(k), initial, options_.verification,
                       LoopExpectation{estimated.translation(), allowed});
    trim_prepared(keyframe);
    if (!v.accepted) {
      ++counts_.rejected_by_verification;
      counts_.prechecked_out += v.prechecked_out;
      counts_.beyond_estimate_before_fine += v.beyond_expectation;
      continue;
    }
    if ((estimated.translation() - v.transform.translation()).norm() > allowed) {
      ++counts_.rejected_by_estimate;
      continue;
    }
    ++counts_.verified;
    Loop3D loop;
    loop.from_keyframe = k;
    loop.to_keyframe = keyframe;
    loop.from_frame = keyframes_[k].frame;
    loop.to_frame = keyframes_[keyframe].frame;
    loop.relative = orthonormalized(v.transform);
    loop.overlap = v.overlap;
    loop.error = v.error;
    graph_.add_loop(loop, loop_information_3d(v.hessian, options_.loop_sigma_translation,
                                              options_.loop_sigma_rotation));
    added = true;
  }
  trim_prepared(kNoKeyframe);
  if (added) {
    last_loop_keyframe_ = keyframe;
    optimize();
  }
}

PreparedCloud& LoopClosure3D::prepared(std::size_t keyframe) {
  std::unique_ptr<PreparedCloud>& p = keyframes_[keyframe].prepared;
  if (p) {
    prepared_order_.remove(keyframe);
  } else {
    p = std::make_unique<PreparedCloud>(keyframes_[keyframe].submap);
    ++counts_.submaps_prepared;
  }
  prepared_order_.push_front(keyframe);
  return *p;
}

std::size_t LoopClosure3D::verification_memory_bytes() const {
  std::size_t bytes = 0;
  for (const std::size_t k : prepared_order_) bytes += keyframes_[k].prepared->memory_bytes();
  return bytes;
}

void LoopClosure3D::trim_prepared(std::size_t keep) {
  const double budget = options_.verification_memory_mb * 1024.0 * 1024.0;
  double bytes = 0.0;
  for (auto it = prepared_order_.begin(); it != prepared_order_.end();) {
    std::unique_ptr<PreparedCloud>& p = keyframes_[*it].prepared;
    bytes += static_cast<double>(p->memory_bytes());
    if (bytes <= budget || *it == keep) {
      ++it;
      continue;
    }
    bytes -= static_cast<double>(p->memory_bytes());
    p.reset();
    it = prepared_order_.erase(it);
  }
}

double LoopClosure3D::correction_allowed(std::size_t keyframe, std::size_t candidate) const {
  return options_.max_correction +
         options_.max_correction_per_m * (keyframes_[keyframe].path - keyframes_[candidate].path);
}

void LoopClosure3D::optimize() {
  counts_.outliers = graph_.optimize();
  ++counts_.optimizations;
}

void LoopClosure3D::finish() {
  const Stopwatch stopwatch;
  if (!loops().empty()) optimize();
  counts_.total_ms += stopwatch.ms();
}

Pose LoopClosure3D::pose(std::size_t index) const {
  return graph_.pose(index);
}

std::vector<Pose> LoopClosure3D::poses() const {
  return graph_.poses();
}

}  // namespace scanmatch
