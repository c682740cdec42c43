// 2D scan matching: register2d and Mapper2D (bound last; see the 2D API).

#include "bindings.hpp"

namespace scanmatch::python {

void bind_planar(py::module_&) {}

}  // namespace scanmatch::python
