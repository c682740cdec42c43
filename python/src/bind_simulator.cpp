// The LiDAR simulator (sim/simulator.hpp): frames with exact ground truth. simulate() in
// python/scanmatch/__init__.py builds on the Simulator class bound here.

#include <pybind11/stl.h>

#include <memory>

#include "bindings.hpp"
#include "convert.hpp"
#include "scanmatch/sim/simulator.hpp"

namespace scanmatch::python {

void bind_simulator(py::module_& m) {
  using sim::Simulator;
  py::class_<Simulator>(m, "Simulator", R"doc(
Simulator(preset="dynamic-outdoor", frames=None, seed=1, sensor="", motion_distortion=True,
noise=True): a simulated sequence, rendered frame by frame on request. presets() lists the
presets; frames truncates (or extends a still preset); sensor overrides the preset's sensor.)doc")
      .def(py::init([](const std::string& preset, std::optional<std::size_t> frames,
                       std::uint64_t seed, const std::string& sensor, bool motion_distortion,
                       bool noise) {
             sim::SimOptions options;
             options.preset = preset;
             options.frames = frames;
             options.seed = seed;
             options.sensor = sensor;
             options.motion_distortion = motion_distortion;
             options.noise = noise;
             py::gil_scoped_release release;
             return std::make_unique<Simulator>(options);
           }),
           py::arg("preset") = "dynamic-outdoor", py::arg("frames") = py::none(),
           py::arg("seed") = 1, py::arg("sensor") = "", py::arg("motion_distortion") = true,
           py::arg("noise") = true)
      .def("__len__", &Simulator::size)
      .def(
          "frame",
          [](const Simulator& s, std::size_t i) {
            if (i >= s.size())
              throw py::index_error("frame " + std::to_string(i) + " of " +
                                    std::to_string(s.size()));
            PointCloud cloud;
            {
              py::gil_scoped_release release;
              cloud = s.frame(i);
            }
            return cloud;
          },
          py::arg("index"),
          "Frame i as a PointCloud (x y z intensity ring time, sensor frame; each point measured "
          "from the pose at its own time unless motion_distortion=False)")
      .def(
          "pose",
          [](const Simulator& s, std::size_t i) {
            if (i >= s.size())
              throw py::index_error("frame " + std::to_string(i) + " of " +
                                    std::to_string(s.size()));
            return pose_to_array(s.pose(i));
          },
          py::arg("index"), "Ground truth of frame i: 4x4 sensor pose at the frame start")
      .def_property_readonly(
          "poses", [](const Simulator& s) { return poses_to_array(s.ground_truth().poses); },
          "(N, 4, 4) ground truth of every frame, world frame of frame 0 (copy)")
      .def_property_readonly(
          "timestamps",
          [](const Simulator& s) {
            py::array_t<double> out(static_cast<py::ssize_t>(s.size()));
            for (std::size_t i = 0; i < s.size(); ++i)
              out.mutable_at(static_cast<py::ssize_t>(i)) = s.frame_time(i);
            return out;
          },
          "(N,) frame start times, s")
      .def_property_readonly("preset", [](const Simulator& s) { return s.preset().name; })
      .def_property_readonly("sensor", [](const Simulator& s) { return s.sensor().name; })
      .def_property_readonly("rate_hz", [](const Simulator& s) { return s.sensor().rate_hz; })
      .def_property_readonly("is_2d", [](const Simulator& s) { return s.sensor().is_2d(); })
      .def_property_readonly("path_length", &Simulator::path_length, "m")
      .def("__repr__", [](const Simulator& s) {
        return "<scanmatch.Simulator " + s.preset().name + " (" + s.sensor().name + "), " +
               std::to_string(s.size()) + " frames>";
      });

  m.def(
      "presets",
      [] {
        py::dict out;
        for (const auto& p : sim::presets()) {
          py::dict d;
          d["scene"] = p.scene;
          d["sensor"] = p.sensor;
          d["motion"] = p.motion;
          d["frames"] = p.frames;
          d["path_length"] = p.path_length;
          d["description"] = p.description;
          out[py::str(p.name)] = d;
        }
        return out;
      },
      "{preset name: {scene, sensor, motion, frames, path_length, description}}");
}

}  // namespace scanmatch::python
