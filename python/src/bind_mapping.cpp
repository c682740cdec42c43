// Loop closure (scanmatch/mapping/): LoopClosure2D over a 2D odometry (scans are (N, 2) arrays as
// Mapper2D takes them; poses 3x3 float64 copies) and LoopClosure3D over a 3D one (frames are
// (N, 3) arrays or PointClouds; poses 4x4 float64 copies).

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "convert.hpp"
#include "options.hpp"
#include "records.hpp"
#include "scanmatch/mapping/loop_closure2d.hpp"
#include "scanmatch/mapping/loop_closure3d.hpp"
#include "scanmatch/mapping/loop_counts.hpp"

namespace scanmatch::python {
namespace {

py::dict loop_dict(const Loop2D& l) {
  py::dict d;
  d["from_scan"] = l.from_scan;
  d["to_scan"] = l.to_scan;
  d["from_keyframe"] = l.from_keyframe;
  d["to_keyframe"] = l.to_keyframe;
  d["relative"] = pose2_to_array(l.relative);
  d["paired_fraction"] = l.paired_fraction;
  d["error"] = l.error;
  d["sliding"] = l.sliding;
  // Unit vector in the to-scan's frame along which a sliding loop holds nothing (zero otherwise).
  d["slide_direction"] = py::make_tuple(l.slide_direction.x(), l.slide_direction.y());
  d["outlier"] = l.outlier;
  return d;
}

py::dict loop_dict(const Loop3D& l) {
  py::dict d;
  d["from_frame"] = l.from_frame;
  d["to_frame"] = l.to_frame;
  d["from_keyframe"] = l.from_keyframe;
  d["to_keyframe"] = l.to_keyframe;
  d["relative"] = pose_to_array(l.relative);
  d["overlap"] = l.overlap;
  d["error"] = l.error;
  d["outlier"] = l.outlier;
  return d;
}

// The docstring of counts: each key of the description (mapping/loop_counts.hpp).
template <typename Counts>
const char* counts_doc() {
  static const std::string doc = record_doc<Counts>("what loop closure did so far (dict):");
  return doc.c_str();
}

}  // namespace

void bind_mapping(py::module_& m) {
  py::class_<LoopClosure2D>(m, "LoopClosure2D", R"doc(
LoopClosure2D(**options): 2D loop closure over an odometry. Each scan comes with its odometry
pose; keyframes become nodes of a pose graph, candidates (nearby keyframes and place-descriptor
matches) are verified geometrically, verified loops become edges and the graph is optimized.
options: the fields of LoopClosure2DOptions (keyframe_distance, skip_recent, proximity_radius,
verification={...}, graph={...}, ...); loop_closure_2d_options() lists them.)doc")
      .def(py::init([](py::kwargs kwargs) {
        LoopClosure2DOptions options;
        FieldTable table(options, "LoopClosure2D()");
        table.apply(kwargs);
        try {
          return std::make_unique<LoopClosure2D>(options);
        } catch (const Error& e) {
          throw py::value_error(std::string("LoopClosure2D(): ") + e.what());
        }
      }))
      .def(
          "add_scan",
          [](LoopClosure2D& lc, py::handle points, py::handle pose, bool circular, bool weak_fit,
             bool unfit) {
            const Scan2D scan = scan_from_arrays(points, py::none(), circular, "points");
            const Pose2 odometry = pose2_from(pose, "pose");
            py::gil_scoped_release release;
            return lc.add_scan(scan, odometry, weak_fit, unfit);
          },
          py::arg("points"), py::arg("pose"), py::arg("circular") = false,
          py::arg("weak_fit") = false, py::arg("unfit") = false, R"doc(
add_scan(points, pose, circular=False, weak_fit=False, unfit=False) -> bool

The next scan ((N, 2) x y in beam order, as registered) with its odometry pose (3x3 or
(x, y, theta)). weak_fit: the odometry registered it poorly (Mapper2D's last_stats["weak_fit"]),
so its keyframe step is tested for an open rotation however little it turned. unfit: the
odometry could not register it (last_stats["bridged"] or ["unfit"]), so its keyframe step's edge
is held loosely (unfit_step_information). Returns True when it became a keyframe (and loops were
looked for).)doc")
      .def(
          "finish", [](LoopClosure2D& lc) { lc.finish(); },
          "Optimizes once more so that the outlier flags are current; call after the last scan")
      .def_property_readonly(
          "poses", [](const LoopClosure2D& lc) { return poses2_to_array(lc.poses()); },
          "(N, 3, 3) float64: every scan's optimized pose")
      .def_property_readonly(
          "loops",
          [](const LoopClosure2D& lc) {
            py::list out;
            for (const Loop2D& l : lc.loops()) out.append(loop_dict(l));
            return out;
          },
          "Accepted loop edges as dicts (from_scan, to_scan, relative 3x3, paired_fraction, "
          "error m, outlier)")
      .def_property_readonly(
          "counts", [](const LoopClosure2D& lc) { return record_dict(lc.counts()); },
          counts_doc<LoopClosure2DCounts>())
      .def("__len__", &LoopClosure2D::scans);

  py::class_<LoopClosure3D>(m, "LoopClosure3D", R"doc(
LoopClosure3D(**options): 3D loop closure over a LiDAR odometry. Each frame comes with its odometry
pose; keyframes (with a submap of their last frames) become nodes of a pose graph, candidates
(nearby keyframes and place-descriptor matches) are verified with NDT then GICP, verified loops
that agree with the estimate become edges and the graph is optimized. options: the fields of
LoopClosure3DOptions (keyframe_distance, submap_frames, proximity_radius, verification={...},
graph={...}, ...); loop_closure_3d_options() lists them.)doc")
      .def(py::init([](py::kwargs kwargs) {
        LoopClosure3DOptions options;
        FieldTable table(options, "LoopClosure3D()");
        table.apply(kwargs);
        try {
          return std::make_unique<LoopClosure3D>(options);
        } catch (const Error& e) {
          throw py::value_error(std::string("LoopClosure3D(): ") + e.what());
        }
      }))
      .def(
          "add_frame",
          [](LoopClosure3D& lc, py::handle points, py::handle pose) {
            std::optional<PointCloud> storage;
            const PointCloud& cloud = cloud_argument(points, "points", storage);
            const Pose odometry = pose_from_array(pose, "pose");
            py::gil_scoped_release release;
            return lc.add_frame(cloud, odometry);
          },
          py::arg("points"), py::arg("pose"), R"doc(
add_frame(points, pose) -> bool

The next frame ((N, 3) x y z in the sensor frame, deskewed and downsampled as registered, or a
PointCloud) with its odometry pose (4x4). Returns True when it became a keyframe (and loops were
looked for).)doc")
      .def(
          "finish", [](LoopClosure3D& lc) { lc.finish(); },
          "Optimizes once more so that the outlier flags are current; call after the last frame")
      .def_property_readonly(
          "poses", [](const LoopClosure3D& lc) { return poses_to_array(lc.poses()); },
          "(N, 4, 4) float64: every frame's optimized pose")
      .def_property_readonly(
          "loops",
          [](const LoopClosure3D& lc) {
            py::list out;
            for (const Loop3D& l : lc.loops()) out.append(loop_dict(l));
            return out;
          },
          "Accepted loop edges as dicts (from_frame, to_frame, relative 4x4, overlap, error m, "
          "outlier)")
      .def_property_readonly(
          "counts", [](const LoopClosure3D& lc) { return record_dict(lc.counts()); },
          counts_doc<LoopClosure3DCounts>())
      .def("__len__", &LoopClosure3D::frames);

  m.def(
      "loop_closure_3d_options",
      [](bool help) {
        LoopClosure3DOptions options;
        FieldTable table(options, "loop_closure_3d_options()");
        return help ? table.help() : table.values();
      },
      py::arg("help") = false, "Every keyword option of LoopClosure3D as {dotted key: default}");

  m.def(
      "loop_closure_2d_options",
      [](bool help) {
        LoopClosure2DOptions options;
        FieldTable table(options, "loop_closure_2d_options()");
        return help ? table.help() : table.values();
      },
      py::arg("help") = false, "Every keyword option of LoopClosure2D as {dotted key: default}");
}

}  // namespace scanmatch::python
