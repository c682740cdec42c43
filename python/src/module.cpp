// scanmatch._scanmatch: the compiled half of the Python package (python/scanmatch/ is the other).

#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "scanmatch/core/error.hpp"

PYBIND11_MODULE(_scanmatch, m) {
  namespace py = pybind11;
  using namespace scanmatch::python;
  m.doc() = "scanmatch: LiDAR registration, odometry and simulation (C++ core)";
  m.attr("__version__") = SCANMATCH_VERSION;
  // scanmatch::Error (bad files, unknown methods, invalid options) as scanmatch.Error, a
  // ValueError carrying the library's message.
  py::register_exception<scanmatch::Error>(m, "Error", PyExc_ValueError);
  bind_cloud(m);
  bind_registration(m);
  bind_odometry(m);
  bind_simulator(m);
  bind_eval(m);
  bind_planar(m);
  bind_mapping(m);
}
