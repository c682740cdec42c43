// PointCloud (numpy views of its fields), read_cloud and write_cloud.

#include <pybind11/stl.h>

#include <cmath>

#include "bindings.hpp"
#include "convert.hpp"
#include "scanmatch/io/cloud_io.hpp"

namespace scanmatch::python {
namespace {

std::vector<float> float_field(py::handle obj, const std::string& name, std::size_t n) {
  const auto a = as_vector(obj, name, static_cast<py::ssize_t>(n));
  const double* d = a.data();
  std::vector<float> out(d, d + n);
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(out[i]))
      throw py::value_error(name + ": entry " + std::to_string(i) + " is not finite");
  return out;
}

std::vector<std::uint16_t> ring_field(py::handle obj, const std::string& name, std::size_t n) {
  const auto a = as_vector(obj, name, static_cast<py::ssize_t>(n));
  std::vector<std::uint16_t> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double v = a.data()[i];
    if (!(v >= 0 && v <= 65535) || v != std::floor(v))
      throw py::value_error(name + ": entry " + std::to_string(i) +
                            " is not a ring index (an integer in 0..65535)");
    out[i] = static_cast<std::uint16_t>(v);
  }
  return out;
}

// Sets the optional fields given (not None) on `cloud`.
void set_fields(PointCloud& cloud, py::handle intensity, py::handle ring, py::handle time) {
  if (!intensity.is_none()) cloud.intensity = float_field(intensity, "intensity", cloud.size());
  if (!ring.is_none()) cloud.ring = ring_field(ring, "ring", cloud.size());
  if (!time.is_none()) cloud.time = float_field(time, "time", cloud.size());
}

CloudWriteOptions::Encoding parse_encoding(const std::string& name) {
  if (name == "binary") return CloudWriteOptions::Encoding::kBinary;
  if (name == "ascii") return CloudWriteOptions::Encoding::kAscii;
  if (name == "binary_compressed") return CloudWriteOptions::Encoding::kBinaryCompressed;
  throw py::value_error("write_cloud: unknown encoding '" + name +
                        "' (valid: binary, ascii, binary_compressed)");
}

const float* first(const std::vector<Point>& points) {
  return points.empty() ? nullptr : points.front().data();
}
template <typename T>
const T* first(const std::vector<T>& values) {
  return values.empty() ? nullptr : values.data();
}

}  // namespace

void bind_cloud(py::module_& m) {
  py::class_<PointCloud>(m, "PointCloud", R"doc(
A point cloud as the library stores it: x y z (float32) and optional per-point intensity,
ring and time (seconds since the frame start).

Constructing one from arrays copies them once (to float32). The attributes `points`
(N x 3 float32), `intensity`, `ring` (uint16) and `time` are read-only numpy VIEWS into the
cloud, without a copy; a view keeps its cloud alive. Absent fields are None. Passing a
PointCloud to register(), Odometry.register_frame() or write_cloud() uses it in place, so
convert once when a cloud is used many times.
)doc")
      .def(py::init([](py::handle points, py::handle intensity, py::handle ring, py::handle time,
                       bool keep_non_finite) {
             PointCloud cloud = cloud_from_array(points, "points", !keep_non_finite);
             set_fields(cloud, intensity, ring, time);
             return cloud;
           }),
           py::arg("points"), py::arg("intensity") = py::none(), py::arg("ring") = py::none(),
           py::arg("time") = py::none(), py::arg("keep_non_finite") = false,
           "PointCloud(points (N, 3), intensity=None, ring=None, time=None, "
           "keep_non_finite=False): copies the arrays once; NaN or infinite coordinates raise "
           "ValueError unless keep_non_finite")
      .def_property_readonly(
          "points",
          [](py::object self) {
            const auto& c = self.cast<const PointCloud&>();
            return view_of(first(c.points), static_cast<py::ssize_t>(c.size()), 3, self);
          },
          "(N, 3) float32 view of x y z, m (no copy)")
      .def_property_readonly(
          "intensity",
          [](py::object self) -> py::object {
            const auto& c = self.cast<const PointCloud&>();
            if (!c.has_intensity()) return py::none();
            return view_of(first(c.intensity), static_cast<py::ssize_t>(c.size()), 1, self);
          },
          "(N,) float32 view of the return strength, or None")
      .def_property_readonly(
          "ring",
          [](py::object self) -> py::object {
            const auto& c = self.cast<const PointCloud&>();
            if (!c.has_ring()) return py::none();
            return view_of(first(c.ring), static_cast<py::ssize_t>(c.size()), 1, self);
          },
          "(N,) uint16 view of the laser line index, or None")
      .def_property_readonly(
          "time",
          [](py::object self) -> py::object {
            const auto& c = self.cast<const PointCloud&>();
            if (!c.has_time()) return py::none();
            return view_of(first(c.time), static_cast<py::ssize_t>(c.size()), 1, self);
          },
          "(N,) float32 view of each point's time since the frame start, s, or None")
      .def("__len__", &PointCloud::size)
      .def(
          "__array__",
          [](py::object self, py::object dtype) -> py::object {
            const auto& c = self.cast<const PointCloud&>();
            py::object view = view_of(first(c.points), static_cast<py::ssize_t>(c.size()), 3, self);
            if (dtype.is_none()) return view;
            return view.attr("astype")(dtype);
          },
          py::arg("dtype") = py::none(), "numpy.asarray(cloud): the points view")
      .def("__repr__", [](const PointCloud& c) {
        std::string fields = "x y z";
        if (c.has_intensity()) fields += " intensity";
        if (c.has_ring()) fields += " ring";
        if (c.has_time()) fields += " time";
        return "<scanmatch.PointCloud " + std::to_string(c.size()) + " points: " + fields + ">";
      });

  m.def(
      "read_cloud",
      [](const std::string& path, bool keep_non_finite) {
        CloudReadOptions options;
        options.keep_non_finite = keep_non_finite;
        PointCloud cloud;
        {
          py::gil_scoped_release release;
          cloud = read_cloud(path, options);
        }
        return cloud;  // moved into the Python object: no copy
      },
      py::arg("path"), py::arg("keep_non_finite") = false, R"doc(
Reads a PCD, PLY, KITTI .bin or text (.xyz/.txt/.csv) cloud, optionally .gz, by its extension.
Returns a PointCloud whose fields are numpy views (no copy). Points with a NaN or infinite
coordinate are dropped unless keep_non_finite. Raises scanmatch.Error naming the file and the
problem.)doc");

  m.def(
      "write_cloud",
      [](const std::string& path, py::handle points, py::handle intensity, py::handle ring,
         py::handle time, const std::string& encoding) {
        CloudWriteOptions options;
        options.encoding = parse_encoding(encoding);
        if (py::isinstance<PointCloud>(points)) {
          if (!intensity.is_none() || !ring.is_none() || !time.is_none())
            throw py::value_error(
                "write_cloud: give intensity, ring and time either in the PointCloud or as "
                "arrays with an (N, 3) points array, not both");
          const auto& cloud = points.cast<const PointCloud&>();
          py::gil_scoped_release release;
          write_cloud(path, cloud, options);
          return;
        }
        PointCloud cloud = cloud_from_array(points, "points", false);
        set_fields(cloud, intensity, ring, time);
        py::gil_scoped_release release;
        write_cloud(path, cloud, options);
      },
      py::arg("path"), py::arg("points"), py::arg("intensity") = py::none(),
      py::arg("ring") = py::none(), py::arg("time") = py::none(), py::arg("encoding") = "binary",
      R"doc(
Writes a cloud (a PointCloud, used in place, or an (N, 3) array plus optional (N,) intensity,
ring and time arrays, copied once) atomically. The format follows the extension (.pcd, .ply,
.bin, .xyz/.txt/.csv); encoding is binary, ascii or binary_compressed (PCD; PLY: binary or
ascii).)doc");
}

}  // namespace scanmatch::python
