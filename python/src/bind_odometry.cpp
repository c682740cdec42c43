// Odometry: the pipeline of odometry/odometry.hpp frame by frame, configured by keywords.

#include <pybind11/stl.h>

#include <cmath>
#include <optional>
#include <string>

#include "bindings.hpp"
#include "convert.hpp"
#include "options.hpp"
#include "records.hpp"
#include "scanmatch/odometry/odometry.hpp"
#include "scanmatch/odometry/odometry_pipeline.hpp"

namespace scanmatch::python {
namespace {

class PyOdometry {
 public:
  explicit PyOdometry(const OdometryConfig& config) : odometry_(config) {}

  py::array_t<double> register_frame(py::handle points, py::handle times,
                                     std::optional<double> timestamp) {
    std::optional<PointCloud> storage;
    const PointCloud* cloud = nullptr;
    if (times.is_none()) {
      cloud = &cloud_argument(points, "points", storage);
    } else {
      storage = py::isinstance<PointCloud>(points) ? points.cast<PointCloud>()
                                                   : cloud_from_array(points, "points");
      check_finite(*storage, "points");
      const auto t = as_vector(times, "times", static_cast<py::ssize_t>(storage->size()));
      storage->time.assign(t.data(), t.data() + storage->size());
      for (std::size_t i = 0; i < storage->size(); ++i)
        if (!std::isfinite(storage->time[i]))
          throw py::value_error("times: entry " + std::to_string(i) + " is not finite");
      cloud = &*storage;
    }
    double stamp = timestamps_.empty() ? 0.0 : timestamps_.back() + 0.1;
    if (timestamp) {
      stamp = *timestamp;
      if (!std::isfinite(stamp)) throw py::value_error("timestamp must be finite");
    }
    Pose pose;
    {
      py::gil_scoped_release release;
      pose = odometry_.register_frame(*cloud, stamp);
    }
    poses_.push_back(pose);
    // The first frames were returned in a provisional world; poses holds them as settled since.
    settle_early_poses(odometry_.pipeline(), poses_);
    timestamps_.push_back(stamp);
    stats_.push_back(odometry_.last_stats());
    return pose_to_array(pose);
  }

  const Odometry& odometry() const { return odometry_; }
  const std::vector<Pose>& poses() const { return poses_; }
  const std::vector<double>& timestamps() const { return timestamps_; }
  const std::vector<FrameStats>& stats() const { return stats_; }

 private:
  Odometry odometry_;
  std::vector<Pose> poses_;
  std::vector<double> timestamps_;
  std::vector<FrameStats> stats_;
};

// The docstring of last_stats: each key of the description (frame_stats.hpp) with its help text.
const char* frame_stats_doc() {
  static const std::string doc = record_doc<FrameStats>(
      "timing and diagnostics of the last frame (dict), None before the first:");
  return doc.c_str();
}

}  // namespace

void bind_odometry(py::module_& m) {
  py::class_<PyOdometry>(m, "Odometry", R"doc(
Odometry(method="ctf-icp", **config): LiDAR odometry frame by frame.

method is ctf-icp or any registration method (frame to frame). config keywords are the fields
of OdometryConfig by their JSON keys (odometry_options() lists them with their defaults), e.g.
voxel_size=0.5, map_radius=30, deskew=False, threads=2, max_iterations=20,
registration={"voxel_resolution": 0.5}. threads sets every stage's threads.
Unknown keys and wrong types raise TypeError; invalid values scanmatch.Error.)doc")
      .def(py::init([](const std::string& method, py::kwargs kwargs) {
             OdometryConfig config;
             config.method = method;
             FieldTable table(config, "Odometry()");
             table.apply(kwargs);
             return std::make_unique<PyOdometry>(config);
           }),
           py::arg("method") = "ctf-icp")
      .def("register_frame", &PyOdometry::register_frame, py::arg("points"),
           py::arg("times") = py::none(), py::arg("timestamp") = py::none(), R"doc(
register_frame(points, times=None, timestamp=None) -> 4x4 pose (float64 copy)

Registers the next frame and returns the sensor pose at the frame start in the world frame of
the first frame. points: an (N, 3) array in the sensor frame (copied once) or a PointCloud (used
in place; its `time` field enables deskewing). times: (N,) seconds since the frame start per
point (overrides the cloud's; then the cloud is copied). timestamp: the frame's start time, s
(None: 0.1 s after the previous frame). Frames that cannot be registered (empty, too few
points) are bridged by the motion prior (last_stats["bridged"]); NaN or infinite coordinates and
bad shapes raise ValueError.)doc")
      .def_property_readonly(
          "poses", [](const PyOdometry& o) { return poses_to_array(o.poses()); },
          "(N, 4, 4) float64 copy of every pose returned so far, the first frames' as settled "
          "once the world anchor is (register_frame returned them in a provisional one)")
      .def_property_readonly(
          "timestamps",
          [](const PyOdometry& o) {
            return py::array_t<double>(static_cast<py::ssize_t>(o.timestamps().size()),
                                       o.timestamps().data());
          },
          "(N,) frame timestamps used, s (copy)")
      .def_property_readonly(
          "frames", [](const PyOdometry& o) { return o.poses().size(); }, "frames registered")
      .def_property_readonly(
          "last_stats",
          [](const PyOdometry& o) -> py::object {
            if (o.stats().empty()) return py::none();
            return record_dict(o.stats().back());
          },
          frame_stats_doc())
      .def_property_readonly(
          "stats",
          [](const PyOdometry& o) {
            py::list out;
            for (const auto& s : o.stats()) out.append(record_dict(s));
            return out;
          },
          "last_stats of every frame (list of dicts)")
      .def_property_readonly(
          "config",
          [](const PyOdometry& o) {
            OdometryConfig config = o.odometry().config();
            FieldTable table(config, "Odometry.config");
            return table.values();
          },
          "the whole configuration in use, {dotted key: value}")
      .def("__len__", [](const PyOdometry& o) { return o.poses().size(); })
      .def("__repr__", [](const PyOdometry& o) {
        return "<scanmatch.Odometry " + o.odometry().config().method + ", " +
               std::to_string(o.poses().size()) + " frames>";
      });

  m.def(
      "odometry_options",
      [](bool help) {
        OdometryConfig config;
        FieldTable table(config, "odometry_options()");
        return help ? table.help() : table.values();
      },
      py::arg("help") = false,
      "Every keyword option of Odometry as {dotted key: default} ({key: help text} with "
      "help=True)");
  m.def("odometry_methods", &odometry_method_list, "the odometry's methods, comma-separated");
}

}  // namespace scanmatch::python
