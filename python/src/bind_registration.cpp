// register(): the 3D registration methods of registration/methods.hpp with keyword options.

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "convert.hpp"
#include "options.hpp"
#include "scanmatch/registration/methods.hpp"

namespace scanmatch::python {
namespace {

struct PyRegistrationResult {
  RegistrationResult result;
  std::string method;
};

py::array_t<double> matrix6(const Matrix6d& m) {
  py::array_t<double> out({6, 6});
  auto o = out.mutable_unchecked<2>();
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) o(r, c) = m(r, c);
  return out;
}

}  // namespace

void bind_registration(py::module_& m) {
  using R = PyRegistrationResult;
  py::class_<R>(m, "RegistrationResult",
                "What register() found. Arrays are copies (4x4 and 6x6 float64).")
      .def_property_readonly(
          "transform", [](const R& r) { return pose_to_array(r.result.transform); },
          "4x4 T_target_source: maps source points into the target frame")
      .def_readonly("method", &R::method)
      .def_property_readonly("iterations", [](const R& r) { return r.result.iterations; })
      .def_property_readonly("converged", [](const R& r) { return r.result.converged; })
      .def_property_readonly("stop_reason", [](const R& r) { return r.result.stop_reason; })
      .def_property_readonly(
          "fitness", [](const R& r) { return r.result.fitness; },
          "mean squared residual norm of the inliers, m^2")
      .def_property_readonly(
          "cost", [](const R& r) { return r.result.cost; }, "final robust cost")
      .def_property_readonly("inliers", [](const R& r) { return r.result.inliers; })
      .def_property_readonly(
          "information", [](const R& r) { return matrix6(r.result.information); },
          "6x6 information matrix at the solution, tangent order [rotation; translation]")
      .def_property_readonly(
          "eigenvalues",
          [](const R& r) {
            py::array_t<double> out(6);
            for (int i = 0; i < 6; ++i) out.mutable_at(i) = r.result.eigenvalues(i);
            return out;
          },
          "of the information, ascending")
      .def_property_readonly("condition_number",
                             [](const R& r) { return r.result.condition_number; })
      .def(
          "as_dict",
          [](py::object self) {
            py::dict d;
            for (const char* key :
                 {"method", "transform", "iterations", "converged", "stop_reason", "fitness",
                  "cost", "inliers", "information", "eigenvalues", "condition_number"})
              d[key] = self.attr(key);
            return d;
          },
          "every attribute in a dict")
      .def("__repr__", [](const R& r) {
        return "<scanmatch.RegistrationResult " + r.method + ": " + r.result.summary() + ">";
      });

  m.def(
      "register",
      [](py::handle source, py::handle target, const std::string& method, py::handle initial,
         py::kwargs kwargs) {
        RegistrationOptions options;
        options.method = method;
        FieldTable table(options, "register()");
        table.apply(kwargs);
        find_registration_method(method);  // an unknown method fails before any copy
        std::optional<PointCloud> source_storage, target_storage;
        const PointCloud& s = cloud_argument(source, "source", source_storage);
        const PointCloud& t = cloud_argument(target, "target", target_storage);
        const Pose guess = pose_from_array(initial, "initial");
        PyRegistrationResult out;
        out.method = method;
        {
          py::gil_scoped_release release;
          out.result = register_clouds(s, t, options, guess);
        }
        return out;
      },
      py::arg("source"), py::arg("target"), py::arg("method") = "gicp",
      py::arg("initial") = py::none(), R"doc(
register(source, target, method="gicp", initial=None, **options) -> RegistrationResult

Registers source onto target: the result's `transform` (4x4) maps source points into the
target frame. source and target are (N, 3) arrays (copied once into the library's layout) or
PointCloud objects (used in place); initial is a 4x4 guess of the transform (None: identity).
Methods: registration_methods(). Options are the fields of RegistrationOptions by their JSON
keys (registration_options() lists them with their defaults), e.g. max_correspondence_distance=2,
voxel_resolution=0.5, max_iterations=50, kernel="huber", solver={"levenberg_marquardt": True}.
Unknown keys and wrong types raise TypeError; NaN/inf coordinates and bad shapes ValueError;
library errors (too few points, unknown method) scanmatch.Error.)doc");

  m.def(
      "registration_methods",
      [] {
        py::dict out;
        for (const auto& method : registration_methods()) out[method.name] = method.summary;
        return out;
      },
      "{name: one-line summary} of every 3D registration method");
  m.def(
      "registration_options",
      [](bool help) {
        RegistrationOptions options;
        FieldTable table(options, "registration_options()");
        return help ? table.help() : table.values();
      },
      py::arg("help") = false,
      "Every keyword option of register() as {dotted key: default} ({key: help text} with "
      "help=True)");
}

}  // namespace scanmatch::python
