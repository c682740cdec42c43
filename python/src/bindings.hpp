#pragma once
// The parts of the module, one file each; module.cpp calls them in order.

#include <pybind11/pybind11.h>

namespace scanmatch::python {

namespace py = pybind11;

void bind_cloud(py::module_& m);         // PointCloud, read_cloud, write_cloud
void bind_registration(py::module_& m);  // register, RegistrationResult, method lists
void bind_odometry(py::module_& m);      // Odometry
void bind_simulator(py::module_& m);     // simulate, presets
void bind_eval(py::module_& m);          // ate, rpe and the 2D metrics
void bind_planar(py::module_& m);        // register2d, Mapper2D
void bind_mapping(py::module_& m);       // LoopClosure2D, LoopClosure3D

}  // namespace scanmatch::python
