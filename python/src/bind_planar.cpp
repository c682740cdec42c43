// 2D scan matching: register2d (registration/scan2d.hpp) and Mapper2D (mapping2d/mapper2d.hpp).
// Scans are (N, 2) arrays of x y in the laser frame, in beam order (copied once into the
// library's Scan2D); poses are 3x3 homogeneous float64 matrices (copies).

#include <pybind11/stl.h>

#include <cmath>

#include "bindings.hpp"
#include "convert.hpp"
#include "options.hpp"
#include "records.hpp"
#include "scanmatch/core/scan2d.hpp"
#include "scanmatch/io/carmen.hpp"
#include "scanmatch/mapping2d/mapper2d.hpp"
#include "scanmatch/registration/planar/correspondence_path.hpp"
#include "scanmatch/registration/planar/registration2d.hpp"
#include "scanmatch/run/run_config_fields.hpp"
#include "scanmatch/sim/simulator.hpp"

namespace scanmatch::python {
namespace {

struct PyRegistration2DResult {
  Registration2DResult result;
  std::string method;
};

class PyMapper2D {
 public:
  explicit PyMapper2D(const Mapper2DConfig& config) : mapper_(config), config_(config) {}

  py::array_t<double> add_scan(py::handle points, py::handle times, std::optional<double> timestamp,
                               bool circular) {
    const Scan2D scan = scan_from_arrays(points, times, circular, "points");
    double stamp = timestamps_.empty() ? 0.0 : timestamps_.back() + 0.2;
    if (timestamp) {
      stamp = *timestamp;
      if (!std::isfinite(stamp)) throw py::value_error("timestamp must be finite");
    }
    Pose2 pose;
    {
      py::gil_scoped_release release;
      pose = mapper_.add_scan(scan, stamp);
    }
    poses_.push_back(pose);
    timestamps_.push_back(stamp);
    stats_.push_back(mapper_.last_stats());
    return pose2_to_array(pose);
  }

  const std::vector<Pose2>& poses() const { return poses_; }
  const std::vector<double>& timestamps() const { return timestamps_; }
  const std::vector<Scan2DStats>& stats() const { return stats_; }
  const Mapper2DConfig& config() const { return config_; }

 private:
  Mapper2D mapper_;
  Mapper2DConfig config_;
  std::vector<Pose2> poses_;
  std::vector<double> timestamps_;
  std::vector<Scan2DStats> stats_;
};

// The docstring of Mapper2D.last_stats: each key of the description (scan2d_stats.hpp).
const char* scan_stats_doc() {
  static const std::string doc = record_doc<Scan2DStats>(
      "timing and diagnostics of the last scan (dict), None before the first:");
  return doc.c_str();
}

}  // namespace

void bind_planar(py::module_& m) {
  using R = PyRegistration2DResult;
  py::class_<R>(m, "Registration2DResult", "What register2d() found (3x3 float64 copies).")
      .def_property_readonly(
          "transform", [](const R& r) { return pose2_to_array(r.result.transform); },
          "3x3: maps current-scan points into the reference frame")
      .def_property_readonly("x", [](const R& r) { return r.result.transform.translation().x(); })
      .def_property_readonly("y", [](const R& r) { return r.result.transform.translation().y(); })
      .def_property_readonly(
          "theta", [](const R& r) { return pose2_angle(r.result.transform); }, "rad")
      .def_readonly("method", &R::method)
      .def_property_readonly("iterations", [](const R& r) { return r.result.iterations; })
      .def_property_readonly("converged", [](const R& r) { return r.result.converged; })
      .def_property_readonly(
          "error", [](const R& r) { return r.result.error; },
          "mean distance of the final correspondences, m")
      .def_property_readonly("pairs", [](const R& r) { return r.result.pairs; })
      .def_property_readonly(
          "search_pose_kept", [](const R& r) { return r.result.search_pose_kept; },
          "the method fitted worse than the correlative search's pose, which was kept")
      .def("__repr__", [](const R& r) {
        const Pose2& T = r.result.transform;
        return "<scanmatch.Registration2DResult " + r.method + ": x " +
               std::to_string(T.translation().x()) + " y " + std::to_string(T.translation().y()) +
               " theta " + std::to_string(pose2_angle(T)) + ", " +
               std::to_string(r.result.iterations) + " iterations" +
               (r.result.converged ? ", converged>" : ">");
      });

  m.def(
      "register2d",
      [](py::handle current, py::handle reference, const std::string& method, py::handle initial,
         bool circular, py::kwargs kwargs) {
        Registration2DOptions options;
        options.method = method;
        FieldTable table(options, "register2d()");
        table.apply(kwargs);
        check_registration_2d_method(method);
        const Scan2D c = scan_from_arrays(current, py::none(), circular, "current");
        const Scan2D r = scan_from_arrays(reference, py::none(), circular, "reference");
        const Pose2 guess = pose2_from(initial, "initial");
        R out;
        out.method = method;
        {
          py::gil_scoped_release release;
          out.result = register_scans(c, r, options, guess);
        }
        return out;
      },
      py::arg("current"), py::arg("reference"), py::arg("method") = "sparse-icp",
      py::arg("initial") = py::none(), py::arg("circular") = false, R"doc(
register2d(current, reference, method="sparse-icp", initial=None, circular=False, **options)

Registers a 2D laser scan onto another: both (N, 2) arrays of x y in the laser frame, in beam
order (copied once). circular: the scans cover 360 degrees (the last beam neighbours the first).
initial: a 3x3 transform or (x, y, theta) (None: identity). Methods: registration_2d_methods().
Options are the fields of Registration2DOptions by name (registration_2d_options() lists them),
e.g. max_correspondence_distance=0.3, search_window=1.0, path_rules={"max_step": 1}. Returns a
Registration2DResult whose transform maps current points into the reference frame.)doc");

  m.def("registration_2d_methods", &registration_2d_method_names, "the 2D registration methods");
  m.def(
      "registration_2d_options",
      [](bool help) {
        Registration2DOptions options;
        FieldTable table(options, "registration_2d_options()");
        return help ? table.help() : table.values();
      },
      py::arg("help") = false, "Every keyword option of register2d as {dotted key: default}");

  py::class_<PyMapper2D>(m, "Mapper2D", R"doc(
Mapper2D(method="sparse-icp", **config): 2D scan-to-scan mapping; each scan is registered onto
the previous one (or the last keyframe) and the results are chained. config: the fields of
Mapper2DConfig (constant_velocity, min_range, max_correction, keyframe_distance, deskew, ...)
and of its registration options, flat (max_iterations=20) or as registration={...};
mapper2d_options() lists them.)doc")
      .def(py::init([](const std::string& method, py::kwargs kwargs) {
             Mapper2DConfig config;
             config.registration.method = method;
             FieldTable table(config, "Mapper2D()");
             table.apply(kwargs);
             return std::make_unique<PyMapper2D>(config);
           }),
           py::arg("method") = "sparse-icp")
      .def("add_scan", &PyMapper2D::add_scan, py::arg("points"), py::arg("times") = py::none(),
           py::arg("timestamp") = py::none(), py::arg("circular") = false, R"doc(
add_scan(points, times=None, timestamp=None, circular=False) -> 3x3 pose

Registers the next scan ((N, 2) x y in beam order, copied once; times: (N,) s after the first
beam, for deskew=True; timestamp: s, None: 0.2 s after the previous scan) and returns the
laser's pose in the frame of the first scan. Scans too small to register are bridged by the
motion prior (last_stats["bridged"]).)doc")
      .def_property_readonly(
          "poses", [](const PyMapper2D& p) { return poses2_to_array(p.poses()); },
          "(N, 3, 3) float64 copy of every pose returned so far")
      .def_property_readonly(
          "last_stats",
          [](const PyMapper2D& p) -> py::object {
            if (p.stats().empty()) return py::none();
            return record_dict(p.stats().back());
          },
          scan_stats_doc())
      .def_property_readonly("stats",
                             [](const PyMapper2D& p) {
                               py::list out;
                               for (const auto& s : p.stats()) out.append(record_dict(s));
                               return out;
                             })
      .def_property_readonly("config",
                             [](const PyMapper2D& p) {
                               Mapper2DConfig config = p.config();
                               FieldTable table(config, "Mapper2D.config");
                               py::dict d = table.values();
                               d["registration.method"] = config.registration.method;
                               return d;
                             })
      .def("__len__", [](const PyMapper2D& p) { return p.poses().size(); });

  m.def(
      "mapper2d_options",
      [](bool help) {
        Mapper2DConfig config;
        FieldTable table(config, "mapper2d_options()");
        return help ? table.help() : table.values();
      },
      py::arg("help") = false, "Every keyword option of Mapper2D as {dotted key: default}");

  // 2D presets of the simulator: scans as the mappers take them.
  py::reinterpret_borrow<py::class_<sim::Simulator>>(m.attr("Simulator"))
      .def(
          "scan2d",
          [](const sim::Simulator& s, std::size_t i) {
            if (!s.sensor().is_2d())
              throw py::value_error("scan2d: the sensor " + s.sensor().name + " is not a 2D laser");
            if (i >= s.size())
              throw py::index_error("scan " + std::to_string(i) + " of " +
                                    std::to_string(s.size()));
            Scan2D scan;
            {
              py::gil_scoped_release release;
              scan = scan_from_laser(s.scan_2d(i));
            }
            py::array_t<double> points(
                {static_cast<py::ssize_t>(scan.points.size()), py::ssize_t{2}});
            auto o = points.mutable_unchecked<2>();
            for (std::size_t k = 0; k < scan.points.size(); ++k) {
              o(static_cast<py::ssize_t>(k), 0) = scan.points[k].x();
              o(static_cast<py::ssize_t>(k), 1) = scan.points[k].y();
            }
            return py::make_tuple(points, scan.circular);
          },
          py::arg("index"),
          "Scan i of a 2D preset (room-2d, corridor-2d): ((N, 2) x y in beam order, circular), as "
          "register2d and Mapper2D take them");
}

}  // namespace scanmatch::python
