// Loop closure (scanmatch/mapping/): LoopClosure2D over a 2D odometry. Scans are (N, 2) arrays
// as Mapper2D takes them; poses 3x3 float64 copies.

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "convert.hpp"
#include "options.hpp"
#include "scanmatch/mapping/loop_closure2d.hpp"

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
  d["outlier"] = l.outlier;
  return d;
}

py::dict counts_dict(const LoopClosure2DCounts& c) {
  py::dict d;
  d["keyframes"] = c.keyframes;
  d["candidates"] = c.candidates;
  d["verified"] = c.verified;
  d["rejected_by_verification"] = c.rejected_by_verification;
  d["rejected_by_estimate"] = c.rejected_by_estimate;
  d["outliers"] = c.outliers;
  d["optimizations"] = c.optimizations;
  d["total_ms"] = c.total_ms;
  return d;
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
          [](LoopClosure2D& lc, py::handle points, py::handle pose, bool circular) {
            const Scan2D scan = scan_from_arrays(points, py::none(), circular, "points");
            const Pose2 odometry = pose2_from(pose, "pose");
            py::gil_scoped_release release;
            return lc.add_scan(scan, odometry);
          },
          py::arg("points"), py::arg("pose"), py::arg("circular") = false, R"doc(
add_scan(points, pose, circular=False) -> bool

The next scan ((N, 2) x y in beam order, as registered) with its odometry pose (3x3 or
(x, y, theta)). Returns True when it became a keyframe (and loops were looked for).)doc")
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
          "counts", [](const LoopClosure2D& lc) { return counts_dict(lc.counts()); },
          "keyframes, candidates, verified, rejections, outliers, optimizations, total_ms")
      .def("__len__", &LoopClosure2D::scans);

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
