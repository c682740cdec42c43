#pragma once
// Conversions between numpy arrays and the library's types, with the checks that turn bad input
// (wrong shape or dtype, NaN, infinities) into Python exceptions instead of undefined behaviour.
//
// Copies: a PointCloud owns its positions (std::vector<Eigen::Vector3f>, x y z contiguous), so an
// array becomes a cloud with exactly one copy (float32 C-contiguous input is copied with memcpy,
// anything else converted on the way); a Python `PointCloud` is used in place. Going out, the
// fields of a PointCloud are numpy views into it that keep it alive (no copy). Poses are small and
// always copied (4x4 float64, row-major).

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <optional>
#include <string>
#include <vector>

#include "scanmatch/core/point_cloud.hpp"
#include "scanmatch/core/scan2d.hpp"
#include "scanmatch/core/se3.hpp"

namespace scanmatch::python {

namespace py = pybind11;

/// The numpy array `obj` as a 2D array of n x `columns` (any real dtype). Raises TypeError for a
/// non-numeric dtype, ValueError for another shape. `name` names the argument in messages.
py::array_t<double, py::array::c_style | py::array::forcecast> as_matrix(py::handle obj,
                                                                         const std::string& name,
                                                                         py::ssize_t columns);
/// A 1D array of `n` values (any real dtype), as float64.
py::array_t<double, py::array::c_style | py::array::forcecast> as_vector(py::handle obj,
                                                                         const std::string& name,
                                                                         py::ssize_t n);

/// An (N, 3) array as a cloud (one copy). With `finite`, NaN or infinite coordinates raise
/// ValueError naming the first such point.
PointCloud cloud_from_array(py::handle obj, const std::string& name, bool finite = true);

/// Raises ValueError when a coordinate of `cloud` is not finite.
void check_finite(const PointCloud& cloud, const std::string& name);

/// The cloud behind `obj`: a Python PointCloud in place (checked for finite coordinates), or an
/// array converted into `storage`.
const PointCloud& cloud_argument(py::handle obj, const std::string& name,
                                 std::optional<PointCloud>& storage);

/// A 4x4 rigid transform: finite, last row 0 0 0 1, orthonormal rotation (to 1e-4). None gives
/// the identity.
Pose pose_from_array(py::handle obj, const std::string& name);
py::array_t<double> pose_to_array(const Pose& pose);
/// An (N, 4, 4) array (or a sequence of 4x4 arrays) as poses.
std::vector<Pose> poses_from_array(py::handle obj, const std::string& name);
py::array_t<double> poses_to_array(const std::vector<Pose>& poses);

/// An (N, 2) array of x y (laser frame, beam order) as a 2D scan (one copy); `times`: None or
/// (N,) s after the first beam. Non-finite values raise ValueError.
Scan2D scan_from_arrays(py::handle points, py::handle times, bool circular,
                        const std::string& name);
/// A 3x3 homogeneous rigid transform or (x, y, theta); None gives the identity.
Pose2 pose2_from(py::handle obj, const std::string& name);
py::array_t<double> pose2_to_array(const Pose2& T);
/// An (N, 3, 3) array of such transforms or an (N, 3) array of (x, y, theta) rows (or a sequence
/// of either), each checked as pose2_from does.
std::vector<Pose2> poses2_from_array(py::handle obj, const std::string& name);
/// (N, 3, 3) float64 copies.
py::array_t<double> poses2_to_array(const std::vector<Pose2>& poses);

/// A writable-flag-cleared numpy view of `count` x `columns` values at `data`, owned by `owner`.
template <typename T>
py::array view_of(const T* data, py::ssize_t count, py::ssize_t columns, py::handle owner) {
  static const T empty{};
  std::vector<py::ssize_t> shape{count}, strides{static_cast<py::ssize_t>(sizeof(T)) * columns};
  if (columns > 1) {
    shape.push_back(columns);
    strides.push_back(sizeof(T));
  }
  py::array view(py::dtype::of<T>(), shape, strides, data ? data : &empty, owner);
  view.attr("setflags")(py::arg("write") = false);
  return view;
}

}  // namespace scanmatch::python
