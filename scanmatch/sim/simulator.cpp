#include "scanmatch/sim/simulator.hpp"

#include <tbb/parallel_for.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "scanmatch/core/error.hpp"
#include "scanmatch/core/progress.hpp"
#include "scanmatch/geometry/beam_elevation.hpp"
#include "scanmatch/io/cloud_io.hpp"
#include "scanmatch/io/file_util.hpp"
#include "scanmatch/sim/random.hpp"

namespace scanmatch::sim {
namespace {

std::vector<PresetInfo> make_presets() {
  return {
      {"static-indoor", "office", "mid360", "still",
       "still sensor in the office lobby (CTF-ICP Static-1)", 152, 0.0},
      {"static-outdoor", "campus", "mid360", "still",
       "still sensor beside a campus road (Static-2)", 166, 0.0},
      {"dynamic-indoor", "office", "mid360", "robot",
       "ground robot through the office and its 36 m corridor (Dynamic-1)", 2666, 137.79},
      {"dynamic-outdoor", "campus", "mid360", "robot",
       "ground robot around the campus block (Dynamic-2)", 3433, 286.36},
      {"dynamic-outdoor-fast", "campus", "mid360", "robot",
       "fast ground robot around the campus block (Dynamic-3)", 763, 335.83},
      {"campus-os1", "campus", "os1-64", "car",
       "car drive with an Ouster OS1-64 (like MulRan KAIST02)", 3000, 1800.0},
      {"urban-hdl64", "campus", "hdl64", "car", "car drive with a Velodyne HDL-64E (KITTI-like)",
       1000, 800.0},
      {"highway-hdl64", "highway", "hdl64", "highway",
       "car on a long, nearly straight country road with a Velodyne HDL-64E, 11 m/s "
       "accelerating to 18 m/s (like KITTI raw 2011_09_26_drive_0027)",
       600, 1051.0},
      {"handheld-fast", "office", "mid360", "handheld",
       "hand-held sensor with fast rotations in the office", 300, 30.0},
      {"handheld-walk", "office", "avia", "walk",
       "hand-held Livox Avia carried at walking pace, looking around (like a hand-held recording)",
       1200, 72.0},
      {"room-2d", "rooms-2d", "neato", "robot", "2D laser on a robot through a few rooms", 500,
       45.0},
      {"corridor-2d", "corridors-2d", "sick-lms", "robot",
       "180 deg SICK laser logged at 1 Hz around a ring of long office corridors (like Radish "
       "ACES): scans about 0.9 m apart",
       196, 175.0},
  };
}

World make_world(const std::string& scene, std::uint64_t seed) {
  if (scene == "office") return make_office(seed);
  if (scene == "campus") return make_campus(seed);
  if (scene == "corridors-2d") return make_corridors_2d(seed);
  if (scene == "highway") return make_highway(seed);
  return make_rooms_2d(seed);
}

// KITTI raw 2011_09_26_drive_0027's first 60 scans: 11.1 m/s at the first, 16.3 m/s at the
// 60th (about 0.85 m/s^2, from its GNSS/INS poses and times); the road continues near 18 m/s.
constexpr SpeedProfile kHighwaySpeed{11.0, 0.9, 18.0};

double sensor_height(const PresetInfo& p) {
  if (p.motion == "car") return 1.8;
  if (p.motion == "highway") return 1.73;  // KITTI's Velodyne above the road
  if (p.motion == "handheld" || p.motion == "walk") return 1.3;
  if (is_2d_scene(p.scene)) return 0.2;
  return 0.5;
}

}  // namespace

bool is_2d_scene(const std::string& scene) {
  return scene == "rooms-2d" || scene == "corridors-2d";
}

const std::vector<PresetInfo>& presets() {
  static const std::vector<PresetInfo> kPresets = make_presets();
  return kPresets;
}

const PresetInfo& preset_info(const std::string& name) {
  for (const auto& p : presets())
    if (p.name == name) return p;
  std::string valid;
  for (const auto& p : presets()) valid += (valid.empty() ? "" : ", ") + p.name;
  throw Error("unknown simulator preset '" + name + "' (valid: " + valid + ")");
}

Simulator::Simulator(const SimOptions& options)
    : options_(options),
      preset_(&preset_info(options.preset)),
      sensor_(&sensor_model(options.sensor.empty() ? preset_->sensor : options.sensor)),
      world_(make_world(preset_->scene, options.seed)) {
  if (sensor_->is_2d() != is_2d_scene(preset_->scene))
    throw Error("sensor '" + sensor_->name + "' does not fit preset '" + preset_->name +
                "' (2D sensors go with 2D presets)");
  frames_ = options.frames.value_or(preset_->frames);
  if (frames_ == 0) throw Error("simulator: --frames must be at least 1");
  if (!(std::abs(options.elevation_bias_deg) <= 5.0))
    throw Error("simulator: --elevation-bias must lie within -5..5 degrees");
  const double period = sensor_->frame_period();
  // The motion spans the preset's full length so that truncated runs are prefixes of full ones.
  const double duration = static_cast<double>(std::max(frames_, preset_->frames)) * period + period;
  const Ground* ground = world_.scene.ground();
  const double height = sensor_height(*preset_);
  if (options.trajectory || !options.trajectory_file.empty()) {
    const Eigen::Vector2d at = world_.replay_start.value_or(world_.loop.front());
    const Pose start = from_xyz_rpy(
        at.x(), at.y(), height + (ground ? ground->height(at.x(), at.y()) : 0.0), 0, 0, 0);
    motion_ =
        replay(options.trajectory ? *options.trajectory : read_trajectory(options.trajectory_file),
               start, sensor_->rate_hz);
    frames_ = std::min(frames_, static_cast<std::size_t>(motion_.duration() / period) + 1);
  } else if (preset_->motion == "still") {
    const Eigen::Vector3d& s = world_.still_position;
    const double z = height + (ground ? ground->height(s.x(), s.y()) : 0.0);
    const Pose still = from_xyz_rpy(s.x(), s.y(), z, 0, 0, s.z());
    motion_ = DenseTrajectory(duration, [&](double) { return still; });
  } else if (preset_->motion == "highway") {
    // One drive down an open road, which ends: no longer runs than the road holds.
    const GroundPath road(world_.loop, world_.loop_closed);
    if (kHighwaySpeed.distance_at(duration) > road.length())
      throw Error("simulator: preset '" + preset_->name + "' drives off the end of its " +
                  std::to_string(static_cast<int>(road.length())) + " m road within " +
                  std::to_string(frames_) + " frames (fewer frames, please)");
    motion_ = cruise_along(road, ground, kHighwaySpeed, duration, height, 0.003);
  } else {
    const GroundPath path(world_.loop, true);
    const double travel_time = static_cast<double>(preset_->frames - 1) * period;
    const double scale =
        static_cast<double>(std::max(frames_, preset_->frames) - 1) * period / travel_time;
    const double length = preset_->path_length * scale;
    if (preset_->motion == "handheld")
      motion_ = handheld_along(path, ground, length, travel_time * scale, height);
    else if (preset_->motion == "walk")
      motion_ = walk_along(path, ground, length, travel_time * scale, height);
    else
      motion_ = drive_along(path, ground, length, travel_time * scale, height,
                            preset_->motion == "car" ? 0.003 : 0.006);
  }
  first_inverse_ = motion_.at(0.0).inverse();
}

Pose Simulator::pose(std::size_t i) const {
  return first_inverse_ * motion_.at(frame_time(i));
}

Trajectory Simulator::ground_truth() const {
  Trajectory t;
  for (std::size_t i = 0; i < frames_; ++i) {
    t.poses.push_back(pose(i));
    t.timestamps.push_back(frame_time(i));
  }
  return t;
}

double Simulator::path_length() const {
  double length = 0.0;
  for (std::size_t i = 1; i < frames_; ++i)
    length += (pose(i).translation() - pose(i - 1).translation()).norm();
  return length;
}

PointCloud Simulator::frame(std::size_t i) const {
  RayPattern pattern;
  generate_pattern(*sensor_, i, pattern);
  const std::size_t n = pattern.directions.size();
  struct Return {
    float range = -1.0f, intensity = 0.0f;
  };
  std::vector<Return> returns(n);
  const double t0 = frame_time(i);
  const SensorModel& s = *sensor_;
  const Pose frame_pose = motion_.at(t0);
  const bool biased = options_.elevation_bias_deg != 0.0 && !s.is_2d();
  const ElevationTurn beam_from_reported(-options_.elevation_bias_deg * M_PI / 180.0);
  // Each ray is independent (its own pose and random numbers), so the parallel loop gives the
  // same result as a serial one.
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, n, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t k = r.begin(); k < r.end(); ++k) {
          const Pose T =
              options_.motion_distortion ? motion_.at(t0 + pattern.times[k]) : frame_pose;
          const Eigen::Vector3d nominal = pattern.directions[k].cast<double>();
          const Eigen::Vector3d dir = T.linear() * (biased ? beam_from_reported(nominal) : nominal);
          const RayHit hit =
              world_.scene.raycast(T.translation(), dir, s.min_range,
                                   std::max(s.max_range, s.high_reflectivity_max_range));
          if (!hit.hit) continue;
          // Dark surfaces are lost earlier than bright ones.
          const double reach = s.high_reflectivity_max_range > 0
                                   ? s.max_range + (s.high_reflectivity_max_range - s.max_range) *
                                                       std::min(1.0, hit.reflectivity / 0.8)
                                   : s.max_range;
          if (hit.range > reach) continue;
          double range = hit.range;
          if (options_.noise) {
            Rng rng = ray_rng(options_.seed, i, k);
            if (rng.uniform() < s.dropout) continue;
            range += (s.range_noise + s.range_noise_fraction * range) * rng.normal();
            if (range < s.min_range) continue;
          }
          const double incidence = std::abs(hit.normal.dot(dir));
          returns[k].range = static_cast<float>(range);
          returns[k].intensity =
              static_cast<float>(255.0 * hit.reflectivity * (0.2 + 0.8 * incidence));
        }
      });
  PointCloud cloud;
  cloud.reserve(n);
  for (std::size_t k = 0; k < n; ++k) {
    if (returns[k].range < 0.0f) continue;
    cloud.points.push_back(pattern.directions[k] * returns[k].range);
    cloud.intensity.push_back(returns[k].intensity);
    cloud.ring.push_back(pattern.rings[k]);
    // Without distortion every point is measured at the frame's start: a time would claim a
    // motion across the frame that is not in the data (and odometry would deskew by it).
    if (options_.motion_distortion) cloud.time.push_back(pattern.times[k]);
  }
  return cloud;
}

LaserScan2D Simulator::scan_2d(std::size_t i) const {
  const PointCloud cloud = frame(i);
  LaserScan2D scan;
  const std::size_t n = sensor_->rays_per_frame;
  const bool full_turn = sensor_->is_full_turn();
  scan.timestamp = frame_time(i);
  scan.angle_min = sensor_->planar_angle_min();
  scan.angle_increment = sensor_->planar_angle_increment();
  scan.max_range = static_cast<float>(sensor_->max_range);
  scan.ranges.assign(n, scan.max_range);
  for (std::size_t k = 0; k < cloud.size(); ++k) {
    const double angle = std::atan2(cloud.points[k].y(), cloud.points[k].x());
    // A full turn wraps at 2 pi; a partial field of view (centred on x) never reaches it.
    const long beam =
        full_turn ? std::lround((angle < 0 ? angle + 2 * M_PI : angle) / scan.angle_increment) %
                        static_cast<long>(n)
                  : std::clamp(std::lround((angle - scan.angle_min) / scan.angle_increment), 0L,
                               static_cast<long>(n) - 1);
    scan.ranges[static_cast<std::size_t>(beam)] = cloud.points[k].head<2>().norm();
  }
  const Pose gt = pose(i);
  const double yaw = std::atan2(gt.linear()(1, 0), gt.linear()(0, 0));
  scan.pose = Eigen::Vector3d(gt.translation().x(), gt.translation().y(), yaw);
  scan.odom_pose = scan.pose;
  return scan;
}

void write_dataset(const Simulator& sim, const std::string& folder, bool quiet,
                   const DatasetSelection& selection) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) throw Error(folder + ": cannot create the folder: " + ec.message());
  const bool planar = sim.sensor().is_2d();
  if (!planar) fs::create_directories(fs::path(folder) / "frames", ec);
  std::vector<std::size_t> frames = selection.frames;
  if (frames.empty())
    for (std::size_t i = 0; i < sim.size(); ++i) frames.push_back(i);
  ProgressReporter progress("simulate " + sim.preset().name, frames.size(), "frames", quiet);
  TrajectoryWriter kitti((fs::path(folder) / "poses_gt.txt").string(), TrajectoryFormat::kKitti);
  TrajectoryWriter tum((fs::path(folder) / "poses_gt_tum.txt").string(), TrajectoryFormat::kTum);
  std::string times;
  CarmenLog log;
  std::size_t points = 0;
  double path = 0.0;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const std::size_t i = frames[k];
    if (i >= sim.size()) throw Error("simulate: frame " + std::to_string(i) + " does not exist");
    if (planar) {
      log.scans.push_back(sim.scan_2d(i));
    } else {
      const PointCloud cloud =
          selection.prepare ? selection.prepare(sim.frame(i), i) : sim.frame(i);
      points += cloud.size();
      char name[32];
      std::snprintf(name, sizeof name, "%06zu.pcd", i);
      write_cloud((fs::path(folder) / "frames" / name).string(), cloud);
    }
    kitti.write(sim.pose(i), sim.frame_time(i));
    tum.write(sim.pose(i), sim.frame_time(i));
    char line[64];
    std::snprintf(line, sizeof line, "%.6f\n", sim.frame_time(i));
    times += line;
    if (k > 0) path += (sim.pose(i).translation() - sim.pose(frames[k - 1]).translation()).norm();
    progress.update(k + 1);
  }
  progress.finish();
  if (planar) write_carmen_log((fs::path(folder) / "scans.log").string(), log);
  write_file_atomic((fs::path(folder) / "times.txt").string(), times);
  nlohmann::ordered_json info = {
      {"preset", sim.preset().name},
      {"scene", sim.preset().scene},
      {"sensor", sim.sensor().name},
      {"rate_hz", sim.sensor().rate_hz},
      {"seed", sim.options().seed},
      {"frames", frames.size()},
      {"path_length_m", selection.frames.empty() ? sim.path_length() : path},
      {"motion_distortion", sim.options().motion_distortion},
      {"noise", sim.options().noise},
      {"elevation_bias_deg", sim.options().elevation_bias_deg},
      {"points", points},
      {"description", sim.preset().description}};
  if (selection.describe) selection.describe(info);
  write_file_atomic((fs::path(folder) / "dataset.json").string(), info.dump(2) + "\n");
}

namespace {
class SimulatedSequence : public SequenceSource {
 public:
  explicit SimulatedSequence(const SimOptions& options) : sim_(options) {}
  std::size_t size() const override { return sim_.size(); }
  bool next(Frame& frame) override {
    if (next_ >= sim_.size()) return false;
    frame.index = next_;
    frame.timestamp = sim_.frame_time(next_);
    frame.name = "sim:" + sim_.preset().name + "#" + std::to_string(next_);
    frame.cloud = sim_.frame(next_);
    ++next_;
    return true;
  }
  std::optional<Trajectory> ground_truth() const override { return sim_.ground_truth(); }
  std::string describe() const override {
    return "simulated " + sim_.preset().name + " (" + sim_.sensor().name + ", " +
           std::to_string(sim_.size()) + " frames, seed " + std::to_string(sim_.options().seed) +
           ")";
  }

 private:
  Simulator sim_;
  std::size_t next_ = 0;
};
}  // namespace

std::unique_ptr<SequenceSource> simulated_sequence(const SimOptions& options) {
  return std::make_unique<SimulatedSequence>(options);
}

}  // namespace scanmatch::sim
